// Native potentials against embedded LAMMPS on the same configurations: per-atom energies
// (pe/atom) and forces. Both evaluate the same double-precision formulas, so they agree to
// round-off: tolerance 1e-10 in the max norm relative to the largest entry.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"
#include "potential_test_util.hpp"

using namespace pdcg::atomistic;
using pdcg::test::cluster;
using pdcg::test::fcc;
using pdcg::test::make_triclinic;
using pdcg::test::max_norm_relative_error;

namespace {

// Same formulas in double precision, different summation order: round-off only.
constexpr double kTol = 1e-10;

void compare(const std::string& commands, const Atoms& atoms, double family_margin = 1.15) {
  // the configuration declares the type count (as a data file header does)
  const int ntypes = *std::max_element(atoms.type.begin(), atoms.type.end());
  const PotentialSpec spec =
      read_potential_commands_from_string(commands, "test-potential", ntypes);
  const auto pot = make_potential(spec);
  const FamilyOptions opt = family_options(*pot, spec, &atoms.bonds);
  const auto pd =
      pdcg::test::pd_evaluate(*pot, atoms, family_margin, opt.molecular_bonds, opt.special_lj);
#if PDCG_WITH_LAMMPS
  const LammpsEngine engine(spec);
  const LammpsResult ref = engine.evaluate(atoms);
  ASSERT_EQ(ref.energy.size(), atoms.size());
  const double fmax = *std::max_element(ref.force.begin(), ref.force.end(), [](double a, double b) {
    return std::abs(a) < std::abs(b);
  });
  EXPECT_GT(std::abs(fmax), 0.0) << "configuration must be strained for a meaningful force test";
  const double e_err = max_norm_relative_error(pd.psi, ref.energy),
               f_err = max_norm_relative_error(pd.force, ref.force);
  std::printf("  [%s] %zu atoms: energy error %.2e, force error %.2e (|f|max %.3g, U %.10g)\n",
              pot->style().c_str(), atoms.size(), e_err, f_err, std::abs(fmax), ref.total_energy);
  EXPECT_LT(e_err, kTol) << spec.pair_style << " energies";
  EXPECT_LT(f_err, kTol) << spec.pair_style << " forces";
  EXPECT_TRUE(pdcg::test::close(pd.total, ref.total_energy, {0, kTol}));
#else
  GTEST_SKIP() << "embedded LAMMPS not enabled";
#endif
  // Σ f = 0 (Newton's third law holds for every PD bond pair)
  double s[3] = {0, 0, 0}, fm = 0;
  for (std::size_t i = 0; i < atoms.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      s[k] += pd.force[3 * i + static_cast<std::size_t>(k)];
      fm = std::max(fm, std::abs(pd.force[3 * i + static_cast<std::size_t>(k)]));
    }
  for (double v : s)
    EXPECT_LT(std::abs(v), 1e-11 * fm * static_cast<double>(atoms.size()));  // round-off of N terms
  // Σ y × f = 0 for a free cluster (central bond forces; docs/theory.md §1 objectivity check)
  if (!atoms.box.periodic[0] && !atoms.box.periodic[1] && !atoms.box.periodic[2]) {
    Eigen::Vector3d torque = Eigen::Vector3d::Zero();
    double scale = 0;
    for (std::size_t i = 0; i < atoms.size(); ++i) {
      const Eigen::Vector3d y(atoms.x[3 * i], atoms.x[3 * i + 1], atoms.x[3 * i + 2]);
      const Eigen::Vector3d f(pd.force[3 * i], pd.force[3 * i + 1], pd.force[3 * i + 2]);
      torque += y.cross(f);
      scale += y.norm() * f.norm();
    }
    EXPECT_LT(torque.norm(), 1e-12 * scale);  // round-off of N cross products
  }
}

const char* kLJ = R"(
# LJ, one type
units lj
atom_style atomic
mass 1 1.0
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0
)";

const char* kLJShift2Types = R"(
units lj
mass * 1.0
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0
pair_coeff 2 2 0.5 0.9 2.2   # per-type cutoff
pair_coeff 1 3 0.8 1.05 2.4
pair_coeff 3 3 1.2 1.1 &
   2.7
pair_modify shift yes mix arithmetic
)";

}  // namespace

TEST(PotentialsLJ, OrthogonalPeriodic) { compare(kLJ, fcc(4, 4, 4, 1.5599, 0.05, 1, 11)); }

TEST(PotentialsLJ, TriclinicPeriodic) {
  Atoms a = fcc(4, 4, 4, 1.5599, 0.05, 1, 12);
  make_triclinic(a, 0.9, -0.6, 0.4);
  compare(kLJ, a);
}

TEST(PotentialsLJ, FreeCluster) { compare(kLJ, cluster(fcc(5, 5, 5, 1.5599, 0.04, 1, 13), 3.3)); }

TEST(PotentialsLJ, ShiftMixingThreeTypes) {
  for (const char* mix : {"geometric", "arithmetic", "sixthpower"}) {
    std::string cmds = kLJShift2Types;
    cmds.replace(cmds.find("arithmetic"), 10, mix);
    Atoms a = fcc(4, 4, 4, 1.5599, 0.05, 3, 14);
    compare(cmds, a);
    make_triclinic(a, -0.7, 0.5, 0.3);
    compare(cmds, a);
    compare(cmds, cluster(fcc(5, 5, 5, 1.5599, 0.04, 3, 15), 3.3));
  }
}

TEST(PotentialsLJ, BoxSmallerThanTwiceTheCutoff) {
  // 2×2×2 cells of 1.56: 3.12 < 2·2.5, several images of one atom in a family
  compare(kLJ, fcc(2, 2, 2, 1.5599, 0.05, 1, 16));
}

// ---------------------------------------------------------------------------------------
// morse

namespace {
const char* kMorse = R"(
units metal
pair_style morse 6.0
pair_coeff 1 1 0.3429 1.3588 2.866
pair_coeff 1 2 0.30 1.40 2.75 5.5
pair_coeff 2 2 0.25 1.30 2.70
)";
}  // namespace

TEST(PotentialsMorse, PeriodicTriclinicClusterWithAndWithoutShift) {
  for (const bool shift : {false, true}) {
    const std::string cmds = std::string(kMorse) + (shift ? "pair_modify shift yes\n" : "");
    Atoms a = fcc(4, 4, 4, 3.615, 0.04, 2, 21);
    compare(cmds, a);
    make_triclinic(a, 2.0, -1.5, 1.0);
    compare(cmds, a);
    compare(cmds, cluster(fcc(5, 5, 5, 3.615, 0.03, 2, 22), 8.0));
  }
}

// ---------------------------------------------------------------------------------------
// EAM: funcfl (one and two files: regridding and Z_i Z_j pair term), setfl, Finnis–Sinclair

namespace {
void compare_eam(const std::string& cmds, double a0, int ntypes, unsigned seed) {
  Atoms a = fcc(4, 4, 4, a0, 0.03, ntypes, seed);
  compare(cmds, a);
  make_triclinic(a, 0.25 * a0 * 4, -0.2 * a0 * 4, 0.15 * a0 * 4);
  compare(cmds, a);
  compare(cmds, cluster(fcc(5, 5, 5, a0, 0.03, ntypes, seed + 1), 2.2 * a0));
}
}  // namespace

TEST(PotentialsEAM, FuncflCu) {
  compare_eam("units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n", 3.615, 1, 31);
}

TEST(PotentialsEAM, FuncflTwoFilesCuNi) {
  // different dr and cutoffs: LAMMPS regrids both files (Lagrange) onto the larger spacing
  compare_eam("units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\npair_coeff 2 2 Ni_u3.eam\n",
              3.57, 2, 33);
}

TEST(PotentialsEAM, SetflCuMishin) {
  compare_eam("units metal\npair_style eam/alloy\npair_coeff * * Cu_mishin1.eam.alloy Cu\n", 3.615,
              1, 35);
}

TEST(PotentialsEAM, SetflAlCuTwoTypes) {
  compare_eam("units metal\npair_style eam/alloy\npair_coeff * * AlCu.eam.alloy Al Cu\n", 3.85, 2,
              37);
}

TEST(PotentialsEAM, FinnisSinclairAlFe) {
  compare_eam("units metal\npair_style eam/fs\npair_coeff * * AlFe_mm.eam.fs Al Fe\n", 3.9, 2, 39);
}

TEST(PotentialsEAM, FinnisSinclairAsymmetricDensityTypesMappedToSameElement) {
  // NiAlH_jea.eam.fs has ρ_NiAl ≠ ρ_AlNi (AlFe_mm and CuZr_mm are symmetric): only this file
  // tells which element pair feeds which host density
  compare_eam("units metal\npair_style eam/fs\npair_coeff * * NiAlH_jea.eam.fs Ni Al Ni\n", 3.6, 3,
              41);
}

TEST(PotentialsEAM, MassesComeFromTheFile) {
  const auto pot = make_potential(read_potential_commands_from_string(
      "units metal\npair_style eam/alloy\npair_coeff * * AlCu.eam.alloy Cu Al\n", "x"));
  const auto m = pot->type_masses();
  ASSERT_EQ(m.size(), 3u);
  // the file's header lines for Al and Cu (checked by hand: "13 26.982 …", "29 63.546 …")
  EXPECT_NEAR(m[1], 63.546, 0.01);
  EXPECT_NEAR(m[2], 26.982, 0.01);
}

// ---------------------------------------------------------------------------------------
// Molecular bonds: chains of 4 beads inside each FCC cell (all four are nearest neighbours,
// so 1-2, 1-3 and 1-4 partners all lie within the pair cutoff and the special factors
// matter); the configuration is shifted and wrapped so that chains cross the boundaries.

namespace {
Atoms chains(int n, double a, double noise, int nbondtypes, unsigned seed, bool periodic = true) {
  Atoms at = fcc(n, n, n, a, noise, 1, seed);
  for (std::int64_t first = 1; first <= static_cast<std::int64_t>(at.size()); first += 4)
    for (int k = 0; k < 3; ++k)
      at.bonds.push_back({1 + (k % nbondtypes), first + k, first + k + 1});
  for (std::size_t i = 0; i < at.size(); ++i) at.type[i] = 1 + static_cast<int>(i % 4 == 0);
  if (periodic) {
    for (std::size_t i = 0; i < at.size(); ++i) {
      Eigen::Vector3i image(0, 0, 0);
      const Eigen::Vector3d x =
          at.box.wrap(Eigen::Vector3d(at.x[3 * i], at.x[3 * i + 1], at.x[3 * i + 2]) +
                          Eigen::Vector3d::Constant(0.3 * a),
                      image);
      for (int k = 0; k < 3; ++k) at.x[3 * i + static_cast<std::size_t>(k)] = x[k];
    }
  } else {
    at.box.periodic = {false, false, false};
  }
  return at;
}

const char* kFene = R"(
units lj
atom_style bond
pair_style lj/cut 1.122462048309373
pair_coeff * * 1.0 1.0
pair_modify shift yes
bond_style fene
bond_coeff 1 30.0 1.5 1.0 1.0
special_bonds fene
)";

const char* kHarmonic = R"(
units lj
atom_style molecular
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0
pair_coeff 2 2 0.8 0.95
bond_style harmonic
bond_coeff 1 100.0 1.05
bond_coeff 2 50.0 1.15
special_bonds lj 0.0 0.5 0.8
)";
}  // namespace

TEST(PotentialsBonds, FeneWithWcaAndSpecialBonds) {
  Atoms a = chains(4, 1.5599, 0.04, 1, 51);
  compare(kFene, a);
  make_triclinic(a, 1.2, -0.8, 0.5);
  compare(kFene, a);
  compare(kFene, chains(3, 1.5599, 0.04, 1, 52, false));
}

TEST(PotentialsBonds, HarmonicTwoBondTypesFractionalSpecialFactors) {
  Atoms a = chains(4, 1.5599, 0.04, 2, 53);
  compare(kHarmonic, a);
  make_triclinic(a, -1.0, 0.7, -0.4);
  compare(kHarmonic, a);
  compare(kHarmonic, chains(3, 1.5599, 0.04, 2, 54, false));
}

TEST(PotentialsBonds, BondsWithPairStyleZero) {
  const std::string cmds =
      "units lj\natom_style bond\npair_style zero 1.3\npair_coeff * *\nbond_style harmonic\n"
      "bond_coeff 1 100.0 1.05\nspecial_bonds lj/coul 0 1 1\n";
  compare(cmds, chains(4, 1.5599, 0.05, 1, 55));
}

TEST(PotentialsEAM, StronglyCompressedAndStretched) {
  // far from equilibrium: other spline intervals, short distances (r·rdr near the table start)
  const std::string cmds =
      "units metal\npair_style eam/alloy\npair_coeff * * Cu_mishin1.eam.alloy Cu\n";
  compare(cmds, fcc(4, 4, 4, 3.615 * 0.72, 0.05, 1, 43));
  compare(cmds, fcc(3, 3, 3, 3.615 * 1.25, 0.05, 1, 44));
}

// ---------------------------------------------------------------------------------------
// A user setfl file given by path (not in the LAMMPS directory), written here from analytic
// functions, with ρ_max small enough that bulk atoms exceed it: exercises LAMMPS's linear
// extension of F beyond the table.

namespace {
std::string write_setfl(double rhomax) {
  const int nrho = 200, nr = 500;
  const double drho = rhomax / (nrho - 1), dr = 0.01, cut = 4.9;
  const auto path = std::filesystem::temp_directory_path() / "pdcg_test_AB.eam.alloy";
  std::ofstream out(path);
  out.precision(17);
  out << "synthetic two-element setfl for pdcg tests\nF = -a sqrt(rho) + b rho^2, rho(r) = c "
         "(rc-r)^2, "
         "r phi = d r (rc-r)^3 (e - r)\n#\n2 A B\n"
      << nrho << ' ' << drho << ' ' << nr << ' ' << dr << ' ' << cut << '\n';
  auto block = [&](int n, auto f) {
    for (int m = 0; m < n; ++m) out << f(m) << ((m % 5 == 4 || m == n - 1) ? '\n' : ' ');
  };
  const double a[2] = {1.0, 1.3}, b[2] = {0.002, 0.001}, c[2] = {0.25, 0.18};
  for (int e = 0; e < 2; ++e) {
    out << (e + 10) << ' ' << (20.0 + e) << " 3.6 fcc\n";
    block(nrho, [&](int m) {
      const double rho = m * drho;
      return -a[e] * std::sqrt(rho) + b[e] * rho * rho;
    });
    block(nr, [&](int m) {
      const double r = m * dr;
      return r < cut ? c[e] * (cut - r) * (cut - r) : 0.0;
    });
  }
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j <= i; ++j)
      block(nr, [&](int m) {
        const double r = m * dr, d = 0.02 * (1 + i + j);
        return r < cut ? d * r * std::pow(cut - r, 3) * (2.4 - r) : 0.0;
      });
  return path.string();
}
}  // namespace

TEST(PotentialsEAM, UserSetflByPathBeyondRhoMax) {
  // bulk ρ̄ ≈ 12·0.25·(4.9−2.55)² + … ≈ 20: ρ_max = 8 puts every atom on the linear extension
  const std::string file = write_setfl(8.0);
  const std::string cmds = "units metal\npair_style eam/alloy\npair_coeff * * " + file + " A B\n";
  compare(cmds, fcc(3, 3, 3, 3.6, 0.03, 2, 45));
  compare(cmds, cluster(fcc(4, 4, 4, 3.6, 0.03, 2, 46), 6.0));
  // and a table that covers the densities
  const std::string cmds2 =
      "units metal\npair_style eam/alloy\npair_coeff * * " + write_setfl(60.0) + " B A\n";
  compare(cmds2, fcc(3, 3, 3, 3.6, 0.03, 2, 47));
}

TEST(Potentials, AtomTypeBeyondThePotentialGivesNaNNotGarbage) {
  for (const char* cmds :
       {"pair_style lj/cut 2.5\npair_coeff 1 1 1 1\n",
        "units metal\npair_style eam/alloy\npair_coeff * * Cu_mishin1.eam.alloy Cu\n"}) {
    const auto pot = make_potential(read_potential_commands_from_string(cmds, "x", 1));
    const int types[2] = {1, 2};
    const double bond[6] = {1.1, 0, 0, 0, 1.1, 0};
    double t[6];
    FamilyState f;
    f.type = 1;
    f.size = 2;
    f.neighbor_type = types;
    f.bond = bond;
    EXPECT_TRUE(std::isnan(pot->force_state(f, t)));
    EXPECT_TRUE(std::isnan(t[0]));
  }
}
