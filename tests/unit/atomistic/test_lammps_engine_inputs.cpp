// Embedded LAMMPS with the user's atom style and per-atom attributes (charges, molecules,
// bonds), and LAMMPS errors reported as InputErrors. References: the `lmp` executable run
// from the test on the same data file (dump of fx fy fz and pe/atom at %.17g).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "pdcg/atomistic/data_file.hpp"
#include "pdcg/atomistic/families.hpp"
#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/lammps_potential.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"

using namespace pdcg::atomistic;
namespace fs = std::filesystem;

#if PDCG_WITH_LAMMPS
namespace {

fs::path scratch(const std::string& tag) {
  const auto dir = fs::temp_directory_path() / ("pdcg_lmpin_" + tag);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream f(p);
  f << text;
}

struct Dump {
  std::vector<double> f, pe;
};

/// Runs `lmp` on `script` in `dir`; reads the dump `out.dump` (id fx fy fz c_pe), ids 1..n.
Dump run_lmp(const fs::path& dir, const std::string& script, std::size_t n) {
  write(dir / "in.lmp", script);
  const std::string cmd =
      "cd " + dir.string() + " && lmp -in in.lmp -log none -screen none -nocite > lmp.out 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << "lmp failed, see " << dir / "lmp.out";
  Dump d;
  d.f.assign(3 * n, 0.0);
  d.pe.assign(n, 0.0);
  std::ifstream dump(dir / "out.dump");
  std::string line;
  bool atoms = false;
  std::size_t read = 0;
  while (std::getline(dump, line)) {
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      atoms = true;
      continue;
    }
    if (!atoms) continue;
    std::istringstream ss(line);
    long id;
    double fx, fy, fz, pe;
    ss >> id >> fx >> fy >> fz >> pe;
    const auto k = static_cast<std::size_t>(id - 1);
    d.f[3 * k] = fx;
    d.f[3 * k + 1] = fy;
    d.f[3 * k + 2] = fz;
    d.pe[k] = pe;
    ++read;
  }
  EXPECT_EQ(read, n);
  return d;
}

const char* kDumpLines =
    "compute pe all pe/atom\n"
    "dump d all custom 1 out.dump id fx fy fz c_pe\n"
    "dump_modify d format float %.17g sort id\n"
    "run 0\n";

struct BodyResult {
  std::vector<double> f, psi;
  double total = 0.0;
};

/// PD forces of the body of `at` with `pot` (families as LAMMPS sees the model).
BodyResult body_forces(const Potential& pot, const PotentialSpec& spec, const Atoms& at) {
  const Families fam = build_families(at, family_options(pot, spec, &at.bonds));
  std::vector<double> bonds(3 * fam.bonds()), t(3 * fam.bonds());
  BodyResult r;
  r.psi.assign(at.size(), 0.0);
  r.f.assign(3 * at.size(), 0.0);
  deformed_bonds(fam, at.x, fam.h, bonds);
  r.total = force_states(pot, fam, at.type, bonds, r.psi, t);
  pd_forces(fam, t, r.f);
  return r;
}

/// The InputError `f` throws (fails the test if it throws nothing or something else).
template <class F>
pdcg::InputError input_error(F&& f) {
  try {
    f();
  } catch (const pdcg::InputError& e) {
    return e;
  }
  ADD_FAILURE() << "expected an InputError";
  return pdcg::InputError("none");
}

// NaCl-like rocksalt (a = 5.64 Å, 64 ions, displaced by up to 0.05 Å), charges ±1 set per
// type by the deck, lj/cut/coul/cut 5.0.
const char* kRocksaltDeck =
    "units metal\n"
    "atom_style charge\n"
    "boundary p p p\n"
    "lattice custom 5.64 a1 1 0 0 a2 0 1 0 a3 0 0 1 basis 0 0 0 basis 0.5 0.5 0 &\n"
    "  basis 0.5 0 0.5 basis 0 0.5 0.5 basis 0.5 0 0 basis 0 0.5 0 basis 0 0 0.5 &\n"
    "  basis 0.5 0.5 0.5\n"
    "region b block 0 2 0 2 0 2\n"
    "create_box 2 b\n"
    "create_atoms 1 region b basis 1 1 basis 2 1 basis 3 1 basis 4 1 basis 5 2 basis 6 2 &\n"
    "  basis 7 2 basis 8 2\n"
    "mass 1 22.99\n"
    "mass 2 35.45\n"
    "set type 1 charge 1.0\n"
    "set type 2 charge -1.0\n"
    "pair_style lj/cut/coul/cut 5.0\n"
    "pair_coeff 1 1 0.1 2.5\n"
    "pair_coeff 2 2 0.1 4.0\n"
    "pair_coeff 1 2 0.1 3.2\n"
    "displace_atoms all random 0.05 0.05 0.05 42 units box\n"
    "write_data nacl.data nocoeff\n";

const std::string kRocksaltPair =
    "pair_style lj/cut/coul/cut 5.0\n"
    "pair_coeff 1 1 0.1 2.5\n"
    "pair_coeff 2 2 0.1 4.0\n"
    "pair_coeff 1 2 0.1 3.2\n";
const std::string kRocksaltPotential = "units metal\natom_style charge\n" + kRocksaltPair;

/// Four-atom chains (types 1-2-2-1, charges −0.3/+0.3 per type), 8 molecules in a
/// 16 × 12 × 12 Å box, written as a user writes a data file by hand (atom_style full).
std::string chain_data(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  std::ostringstream d;
  d.precision(17);
  d << "four-atom chains\n\n32 atoms\n24 bonds\n2 atom types\n1 bond types\n\n"
    << "0 16 xlo xhi\n0 12 ylo yhi\n0 12 zlo zhi\n\nMasses\n\n1 15.0\n2 14.0\n\nAtoms # full\n\n";
  const double dx[4] = {-2.25, -0.75, 0.75, 2.25}, dy[4] = {0.5, -0.5, 0.5, -0.5};
  const int type[4] = {1, 2, 2, 1};
  const double q[3] = {0, -0.3, 0.3};
  int id = 0, mol = 0;
  std::ostringstream bonds;
  int bid = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) {
        ++mol;
        for (int a = 0; a < 4; ++a) {
          ++id;
          d << id << ' ' << mol << ' ' << type[a] << ' ' << q[type[a]] << ' '
            << 4 + 8 * i + dx[a] + u(rng) << ' ' << 3 + 6 * j + dy[a] + u(rng) << ' '
            << 3 + 6 * k + u(rng) << '\n';
          if (a > 0) bonds << ++bid << " 1 " << id - 1 << ' ' << id << '\n';
        }
      }
  d << "\nBonds\n\n" << bonds.str();
  return d.str();
}

const char* kChainPotential =
    "units real\n"
    "atom_style full\n"
    "pair_style lj/cut/coul/cut 5.5\n"
    "pair_coeff 1 1 0.1 3.0\n"
    "pair_coeff 2 2 0.08 3.2\n"
    "bond_style harmonic\n"
    "bond_coeff 1 300.0 1.8\n"
    "special_bonds lj/coul 0.0 0.0 0.5\n";

}  // namespace

// atom_style charge through the fallback Potential (lj/cut/coul/cut is not native): the
// clusters carry the charges of the types, so the body forces and ψ_k are LAMMPS's.
TEST(LammpsEngineInputs, RocksaltLjCutCoulCutBodyMatchesLmp) {
  const fs::path dir = scratch("nacl");
  write(dir / "in.build", kRocksaltDeck);
  ASSERT_EQ(std::system(("cd " + dir.string() +
                         " && lmp -in in.build -log none -screen none -nocite > build.out 2>&1")
                            .c_str()),
            0);
  Atoms at = read_data_file((dir / "nacl.data").string());
  sort_by_id(at);  // write_data does not write the atoms in id order
  ASSERT_EQ(at.size(), 64u);
  ASSERT_EQ(at.charge.size(), 64u);
  const Dump ref = run_lmp(
      dir, "units metal\natom_style charge\nread_data nacl.data\n" + kRocksaltPair + kDumpLines,
      at.size());
  PotentialSpec spec = read_potential_commands_from_string(kRocksaltPotential, "nacl.in", 2);
  take_type_charges(spec, at);  // from the data file, one charge per type
  ASSERT_EQ(spec.type_charge.size(), 3u);
  EXPECT_EQ(spec.type_charge[1], 1.0);
  EXPECT_EQ(spec.type_charge[2], -1.0);
  const auto pot = make_potential(spec);
  EXPECT_EQ(pot->style(), "lj/cut/coul/cut (embedded LAMMPS)");
  // pairwise (measured): families of r_c = 5.0 (bisection to 1e-9), not 2 r_c
  EXPECT_NEAR(pot->cutoff(), 5.0, 1e-7);
  const BodyResult b = body_forces(*pot, spec, at);
  const double ef = pdcg::test::max_norm_relative_error(b.f, ref.f);
  const double ee = pdcg::test::max_norm_relative_error(b.psi, ref.pe);
  std::printf("rocksalt lj/cut/coul/cut body vs lmp: forces %.3g, pe/atom %.3g\n", ef, ee);
  // pairwise style: t_kj = −½ F_j of LAMMPS's analytic dimer forces (no finite differences);
  // measured 3.7e-14 (summation order; dimers sit up to 12 r_c from the origin, which rounds
  // their bond vectors at ~1e-15 relative). 1e-12 leaves a factor 25. The central differences
  // used before for every fallback style gave 8.7e-9 here.
  EXPECT_LT(ef, 1e-12);
  EXPECT_LT(ee, 1e-12);  // ψ_k = Σ ½φ of LAMMPS's pe/atom on the dimers: summation order only
  // the whole-configuration engine (data file with q) is the same LAMMPS code: I/O only
  // (positions written and read at 17 digits)
  const LammpsResult direct = LammpsEngine(spec).evaluate(at);
  EXPECT_LT(pdcg::test::max_norm_relative_error(direct.force, ref.f), 1e-12);
  EXPECT_LT(pdcg::test::max_norm_relative_error(direct.energy, ref.pe), 1e-12);
  // charges also from `set type T charge Q` in the commands (no data-file charges)
  PotentialSpec spec2 = read_potential_commands_from_string(
      kRocksaltPotential + "set type 1 charge 1.0\nset type 2 charge -1.0\n", "nacl-set.in", 2);
  at.charge.clear();
  const BodyResult b2 = body_forces(*make_potential(spec2), spec2, at);
  EXPECT_LT(pdcg::test::max_norm_relative_error(b2.f, ref.f), 1e-12);  // as above
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

// Charges that differ within a type cannot be carried per type: refused with the fix.
TEST(LammpsEngineInputs, ChargesDifferingWithinATypeAreRefused) {
  PotentialSpec spec = read_potential_commands_from_string(kRocksaltPotential, "nacl.in", 2);
  Atoms at;
  at.id = {1, 2, 3};
  at.type = {1, 1, 2};
  at.x = {0, 0, 0, 2.8, 0, 0, 0, 2.8, 0};
  at.charge = {1.0, 0.9, -1.0};
  const auto e = input_error([&] { take_type_charges(spec, at); });
  EXPECT_NE(std::string(e.what()).find("own atom type"), std::string::npos) << e.what();
}

// atom_style full: chains with harmonic bonds, charges, special_bonds lj/coul 0 0 0.5 (1-4
// pairs at half strength), lj/cut/coul/cut through the fallback; bonds native.
TEST(LammpsEngineInputs, MolecularFullChainsMatchLmp) {
  const fs::path dir = scratch("chains");
  write(dir / "chains.data", chain_data(7));
  const Atoms at = read_data_file((dir / "chains.data").string());
  ASSERT_EQ(at.bonds.size(), 24u);
  ASSERT_EQ(at.molecule.size(), 32u);
  const Dump ref = run_lmp(dir,
                           std::string("units real\natom_style full\nread_data chains.data\n") +
                               "pair_style lj/cut/coul/cut 5.5\npair_coeff 1 1 0.1 3.0\n"
                               "pair_coeff 2 2 0.08 3.2\nbond_style harmonic\n"
                               "bond_coeff 1 300.0 1.8\nspecial_bonds lj/coul 0.0 0.0 0.5\n" +
                               kDumpLines,
                           at.size());
  PotentialSpec spec = read_potential_commands_from_string(kChainPotential, "chains.in", 2);
  take_type_charges(spec, at);
  const auto pot = make_potential(spec);
  EXPECT_EQ(pot->style(), "lj/cut/coul/cut (embedded LAMMPS) + bond harmonic");
  const BodyResult b = body_forces(*pot, spec, at);
  const double ef = pdcg::test::max_norm_relative_error(b.f, ref.f);
  const double ee = pdcg::test::max_norm_relative_error(b.psi, ref.pe);
  std::printf("full chains lj/cut/coul/cut + harmonic body vs lmp: forces %.3g, pe/atom %.3g\n", ef,
              ee);
  EXPECT_LT(ef, 1e-12);  // analytic dimer forces, as for the rocksalt (measured 7.8e-17)
  EXPECT_LT(ee, 1e-12);  // 1-4 pairs at s = 0.5, 1-2 and 1-3 left out: round-off (1.4e-16)
  const LammpsResult direct = LammpsEngine(spec).evaluate(at);
  EXPECT_LT(pdcg::test::max_norm_relative_error(direct.force, ref.f), 1e-12);
  EXPECT_LT(pdcg::test::max_norm_relative_error(direct.energy, ref.pe), 1e-12);
  // different lj and coul factors cannot be carried by one factor per pair: refused
  PotentialSpec amber = read_potential_commands_from_string(
      std::string(kChainPotential) + "special_bonds amber\n", "amber.in", 2);
  const auto e = input_error([&] { (void)make_potential(amber); });
  EXPECT_EQ(e.key_name(), "special_bonds");
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

// LAMMPS errors become InputErrors with LAMMPS's message and the user's command line.
TEST(LammpsEngineInputs, TruncatedTersoffModFileIsAnInputError) {
  const fs::path dir = scratch("trunc");
  {  // the Si entry cut after its second line (7 of 20 parameters)
    std::ifstream in(*find_potential_file("Si.tersoff.mod"));
    std::ofstream out(dir / "cut.tersoff.mod");
    std::string l;
    for (int k = 0; k < 25 && std::getline(in, l); ++k) out << l << '\n';
  }
  const auto spec = read_potential_commands_from_string(
      "units metal\nmass 1 28.0855\npair_style tersoff/mod\npair_coeff * * " +
          (dir / "cut.tersoff.mod").string() + " Si\n",
      "si.in", 1);
  const auto e = input_error([&] { (void)make_potential(spec); });
  EXPECT_EQ(e.source_name(), "si.in");
  EXPECT_EQ(e.line_number(), 4);
  EXPECT_EQ(e.key_name(), "pair_coeff");
  EXPECT_NE(e.bad_value().find("Incorrect format in tersoff/mod potential file"), std::string::npos)
      << e.what();
  fs::remove_all(dir);
}

TEST(LammpsEngineInputs, ElementMissingFromTheFileIsAnInputError) {
  const auto spec = read_potential_commands_from_string(
      "units metal\npair_style tersoff/mod\npair_coeff * * Si.tersoff.mod C\n", "c.in", 1);
  const auto e = input_error([&] { (void)make_potential(spec); });
  EXPECT_EQ(e.line_number(), 3);
  EXPECT_NE(e.bad_value().find("missing an entry"), std::string::npos) << e.what();
  // the whole-configuration engine reports the same (edip with an element not in Si.edip)
  const auto edip = read_potential_commands_from_string(
      "units metal\nmass * 28.0855\npair_style edip\npair_coeff * * Si.edip C\n", "e.in", 1);
  Atoms at;
  at.id = {1, 2};
  at.type = {1, 1};
  at.box.hi = {20, 20, 20};
  at.x = {5, 5, 5, 7.3, 5, 5};
  const auto e2 = input_error([&] { (void)LammpsEngine(edip).evaluate(at); });
  EXPECT_EQ(e2.line_number(), 4);
  EXPECT_FALSE(e2.bad_value().empty()) << e2.what();
}

TEST(LammpsEngineInputs, ChargeStyleWithoutChargesIsAnInputError) {
  // buck/coul/cut needs atom attribute q: LAMMPS's "requires atom attribute q"
  const auto spec = read_potential_commands_from_string(
      "units metal\npair_style buck/coul/cut 6.0\npair_coeff * * 1000.0 0.3 10.0\n", "b.in", 1);
  const auto e = input_error([&] { (void)make_potential(spec); });
  EXPECT_EQ(e.line_number(), 2);  // the pair_style line: LAMMPS fails in `run 0`
  EXPECT_NE(e.bad_value().find("atom attribute q"), std::string::npos) << e.what();
}

TEST(LammpsEngineInputs, TableKeywordMissingIsAnInputError) {
  const fs::path dir = scratch("table");
  write(dir / "t.table", "# table\nOTHER\nN 3\n\n1 1.0 1.0 0.0\n2 2.0 0.5 0.0\n3 3.0 0.0 0.0\n");
  const auto spec =
      read_potential_commands_from_string("units lj\npair_style table linear 3\npair_coeff 1 1 " +
                                              (dir / "t.table").string() + " PAIR 2.9\n",
                                          "t.in", 1);
  const auto e = input_error([&] { (void)make_potential(spec); });
  EXPECT_EQ(e.line_number(), 3);
  EXPECT_NE(e.bad_value().find("keyword"), std::string::npos) << e.what();
  fs::remove_all(dir);
}

// Long-range electrostatics is refused with the reason and the fix, not computed without its
// k-space part.
TEST(LammpsEngineInputs, KspaceStylesAreRefused) {
  const auto spec = read_potential_commands_from_string(
      "units metal\natom_style charge\npair_style lj/cut/coul/long 5.0\npair_coeff * * 0.1 3.0\n",
      "long.in", 1);
  const auto e = input_error([&] { (void)make_potential(spec); });
  EXPECT_EQ(e.line_number(), 3);
  EXPECT_NE(std::string(e.what()).find("coul/cut"), std::string::npos) << e.what();
  const auto e2 = input_error([&] {
    (void)read_potential_commands_from_string(
        "units metal\natom_style charge\npair_style lj/cut/coul/cut 5.0\npair_coeff * * 0.1 "
        "3.0\nkspace_style ewald 1e-6\n",
        "ewald.in", 1);
  });
  EXPECT_EQ(e2.line_number(), 5);
  EXPECT_EQ(e2.key_name(), "kspace_style");
}
#endif  // PDCG_WITH_LAMMPS
