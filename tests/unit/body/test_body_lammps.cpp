// Delta bodies built from LAMMPS potential commands against embedded LAMMPS (the independent
// reference): PD internal forces f_k = Σ_j (t_kj − t_jk) and energies Σ ψ_k through the Body
// and its Evaluator, for the native styles on periodic (orthogonal, triclinic) and free
// configurations, and after a write/read of the model file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <tuple>

#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg_test.hpp"

using namespace pdcg;
using namespace pdcg::body;
using atomistic::Atoms;

namespace {

Atoms fcc(int n, double a, double noise, int ntypes, unsigned seed) {
  Atoms at;
  at.box.hi = {n * a, n * a, n * a};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> ut(1, ntypes);
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::int64_t id = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const auto& b : basis) {
          at.id.push_back(++id);
          at.type.push_back(ut(rng));
          for (int c = 0; c < 3; ++c)
            at.x.push_back(((c == 0 ? i : c == 1 ? j : k) + b[c]) * a + noise * a * u(rng));
        }
  at.type_mass.assign(static_cast<std::size_t>(ntypes + 1), 1.0);
  return at;
}

void shear(Atoms& at, double xy, double xz, double yz) {
  const Eigen::Vector3d L = at.box.lengths();
  for (std::size_t i = 0; i < at.size(); ++i) {
    const double y = at.x[3 * i + 1], z = at.x[3 * i + 2];
    at.x[3 * i] += xy * y / L[1] + xz * z / L[2];
    at.x[3 * i + 1] += yz * z / L[2];
  }
  at.box.xy = xy;
  at.box.xz = xz;
  at.box.yz = yz;
}

Atoms ball(const Atoms& at, double radius) {
  Atoms c;
  c.box = at.box;
  c.box.periodic = {false, false, false};
  c.type_mass = at.type_mass;
  const Eigen::Vector3d centre = 0.5 * (at.box.lo + at.box.hi);
  for (std::size_t i = 0; i < at.size(); ++i) {
    const Eigen::Vector3d x(at.x[3 * i], at.x[3 * i + 1], at.x[3 * i + 2]);
    if ((x - centre).norm() > radius) continue;
    c.id.push_back(static_cast<std::int64_t>(c.size()) + 1);
    c.type.push_back(at.type[i]);
    c.x.insert(c.x.end(), {x[0], x[1], x[2]});
  }
  return c;
}

/// Beads of 4 in each fcc cell bonded 1-2-3-4 (molecular styles).
void add_chains(Atoms& at) {
  for (std::int64_t first = 1; first + 3 <= static_cast<std::int64_t>(at.size()); first += 4)
    for (int k = 0; k < 3; ++k) at.bonds.push_back({1, first + k, first + k + 1});
}

void compare(const std::string& commands, const Atoms& atoms, const char* label) {
  if (!atomistic::lammps_available()) GTEST_SKIP() << "embedded LAMMPS not enabled";
  const int ntypes = *std::max_element(atoms.type.begin(), atoms.type.end());
  const auto spec = atomistic::read_potential_commands_from_string(commands, label, ntypes);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  Body b = make_delta_body(atoms, pot, spec, {.dimension = 3, .cutoff = 0.0, .source = label});
  b.potential_files = embed_potential_files(b.potential_spec);
  const atomistic::LammpsEngine engine(spec);
  const auto ref = engine.evaluate(atoms);  // atoms are sorted by id already: same order
  Evaluator ev(b);
  const Evaluation e = ev.reference();
  const double ferr = test::max_norm_relative_error(e.forces, ref.force);
  std::printf("  [%s, %s] %zu atoms: force error %.2e, energy %.12g vs LAMMPS %.12g\n", label,
              pot->style().c_str(), atoms.size(), ferr, e.energy, ref.total_energy);
  // same double-precision formulas, different summation order: round-off (required: 1e-9)
  EXPECT_LT(ferr, 1e-9) << label;
  EXPECT_TRUE(test::close(e.energy, ref.total_energy, {0, 1e-9})) << label;
  // the model file rebuilds the same potential from its stored lines and embedded files
  const auto path = std::filesystem::temp_directory_path() /
                    (std::string("pdcg_body_lammps_") + std::to_string(::getpid()) + ".h5");
  write_body(b, path);
  const Body c = read_body(path);
  std::filesystem::remove(path);
  Evaluator ev2(c);
  const Evaluation e2 = ev2.reference();
  EXPECT_LT(test::max_norm_relative_error(e2.forces, ref.force), 1e-9)
      << label << " after read_body";
}

const char* kLJ =
    "units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\npair_coeff 2 2 0.8 0.9\n"
    "pair_modify mix arithmetic\n";
const char* kMorse = "units metal\npair_style morse 6.0\npair_coeff * * 0.34 1.36 2.85\n";
const char* kEam = "units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n";
const char* kAlloy = "units metal\npair_style eam/alloy\npair_coeff * * AlCu.eam.alloy Al Cu\n";
const char* kFs = "units metal\npair_style eam/fs\npair_coeff * * AlFe_mm.eam.fs Al Fe\n";
const char* kHarmonic =
    "units lj\natom_style bond\npair_style lj/cut 2.5\npair_coeff * * 1.0 1.0\nbond_style "
    "harmonic\n"
    "bond_coeff 1 100.0 1.05\nspecial_bonds lj 0.0 0.5 0.8\n";
const char* kFene =
    "units lj\natom_style bond\npair_style lj/cut 1.122462048309373\npair_coeff * * 1.0 "
    "1.0\npair_modify shift yes\n"
    "bond_style fene\nbond_coeff 1 30.0 1.5 1.0 1.0\nspecial_bonds fene\n";

struct Case {
  const char* name;
  const char* commands;
  double a;
  int ntypes;
  bool chains;
};

}  // namespace

TEST(BodyVsLammps, NativeStylesPeriodicTriclinicAndFree) {
  const Case cases[] = {{"lj/cut", kLJ, 1.5599, 2, false}, {"morse", kMorse, 3.615, 1, false},
                        {"eam", kEam, 3.615, 1, false},    {"eam/alloy", kAlloy, 3.85, 2, false},
                        {"eam/fs", kFs, 3.9, 2, false},    {"harmonic", kHarmonic, 1.5599, 1, true},
                        {"fene", kFene, 1.5599, 1, true}};
  unsigned seed = 100;
  for (const auto& c : cases) {
    Atoms per = fcc(3, c.a, 0.04, c.ntypes, ++seed);
    if (c.chains) add_chains(per);
    compare(c.commands, per, (std::string(c.name) + " periodic").c_str());
    Atoms tri = per;
    shear(tri, 0.31 * c.a, -0.2 * c.a, 0.17 * c.a);
    compare(c.commands, tri, (std::string(c.name) + " triclinic").c_str());
    Atoms fr = per;
    fr.box.periodic = {false, false, false};
    if (!c.chains) fr = ball(fcc(4, c.a, 0.04, c.ntypes, ++seed), 1.6 * c.a);
    compare(c.commands, fr, (std::string(c.name) + " free").c_str());
  }
}

// Periodic boxes smaller than twice the cutoff: a special partner (by atom id) is weighted only
// at its minimum image; its other images within the cutoff are ordinary pairs, as in LAMMPS's
// neighbour lists (Domain::minimum_image_check). Two fcc cells of the LJ lattice (3.12 < 2·2.5)
// with 4-bead chains and special_bonds lj 0 0.5 0.8: the chains' images are within the cutoff.
TEST(BodyVsLammps, SpecialBondsAtImagesInSmallBoxes) {
  Atoms per = fcc(2, 1.5599, 0.04, 1, 7);
  add_chains(per);
  compare(kHarmonic, per, "harmonic, 2 cells");
  Atoms tri = per;
  shear(tri, 0.4, -0.25, 0.3);
  compare(kHarmonic, tri, "harmonic, 2 cells, triclinic");
  compare(kFene, per, "fene, 2 cells");
}

// EAM files (UNITS: metal) in real units: LAMMPS converts the energies (× 23.060549; funcfl:
// Z(r) × its square root). Debian's files, and tables written here whose densities run past
// ρ_max, where eam/alloy's conversion leaves the last point of F unconverted (PairEAMAlloy
// loops j < nrho) while eam and eam/fs convert every point: pdcg does as LAMMPS does.
TEST(BodyVsLammps, EamInRealUnitsConvertedAsLammps) {
  const auto real = [](std::string commands) {
    commands.replace(commands.find("units metal"), 11, "units real");
    return commands;
  };
  unsigned seed = 300;
  for (const auto& [name, commands, a, ntypes] : {std::tuple{"eam", kEam, 3.615, 1},
                                                  {"eam/alloy", kAlloy, 3.85, 2},
                                                  {"eam/fs", kFs, 3.9, 2}}) {
    const Atoms per = fcc(3, a, 0.04, ntypes, ++seed);
    compare(real(commands), per, (std::string(name) + ", real").c_str());
  }
  // tables with a small ρ_max (1.95): 12 neighbours at 2.556 Å give ρ̄ ≈ 33, far beyond it
  const auto dir =
      std::filesystem::temp_directory_path() / ("pdcg_eam_real_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const int nrho = 40, nr = 200;
  const double drho = 0.05, dr = 0.025, cut = 4.95;
  auto block = [](std::ofstream& out, const std::vector<double>& v) {
    out.precision(17);
    for (std::size_t i = 0; i < v.size(); ++i) out << v[i] << (i % 5 == 4 ? "\n" : " ");
    out << "\n";
  };
  std::vector<double> F(nrho), rho(nr), z2r(nr), Z(nr);
  for (int i = 0; i < nrho; ++i) F[i] = -std::sqrt(1 + i * drho) + 0.3 * i * drho;
  for (int i = 0; i < nr; ++i) {
    const double r = i * dr;
    rho[i] = 3.0 * std::exp(-1.5 * (r - 2.5));
    const double s = std::max(0.0, 1 - r / cut);
    z2r[i] = r * 0.5 * (std::exp(-2 * (r - 2.5)) - 2 * std::exp(-(r - 2.5))) * s * s;
    Z[i] = 2.0 * std::exp(-1.2 * r) + 0.3;
  }
  for (const char* ext : {"eam.alloy", "eam.fs"}) {
    std::ofstream out(dir / (std::string("X.") + ext));
    out << "DATE: 2024-01-01 UNITS: metal CONTRIBUTOR: pdcg test\nsynthetic\n\n1 Cu\n"
        << nrho << " " << drho << " " << nr << " " << dr << " " << cut << "\n29 63.546 3.615 fcc\n";
    block(out, F);
    block(out, rho);
    block(out, z2r);
  }
  {
    std::ofstream out(dir / "X.eam");
    out << "DATE: 2024-01-01 UNITS: metal synthetic funcfl\n29 63.546 3.615 fcc\n"
        << nrho << " " << drho << " " << nr << " " << dr << " " << cut << "\n";
    block(out, F);
    block(out, Z);
    block(out, rho);
  }
  const Atoms cu = fcc(2, 3.615, 0.01, 1, 17);
  for (const std::string units : {"metal", "real"}) {
    const std::string d = dir.string();
    compare("units " + units + "\npair_style eam\npair_coeff 1 1 " + d + "/X.eam\n", cu,
            ("synthetic eam, " + units).c_str());
    compare("units " + units + "\npair_style eam/alloy\npair_coeff * * " + d + "/X.eam.alloy Cu\n",
            cu, ("synthetic eam/alloy, " + units).c_str());
    compare("units " + units + "\npair_style eam/fs\npair_coeff * * " + d + "/X.eam.fs Cu\n", cu,
            ("synthetic eam/fs, " + units).c_str());
  }
  std::filesystem::remove_all(dir);
}
