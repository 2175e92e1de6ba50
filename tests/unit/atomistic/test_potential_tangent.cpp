// Analytic force_state_tangent of the native styles against the central-difference default
// of Potential (differences of force_state, an independent path through the code that is
// itself checked against LAMMPS forces in test_potentials.cpp), on perturbed configurations
// with several types, mixing, shift, special_bonds factors and molecular bonds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pdcg/atomistic/families.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "potential_test_util.hpp"

using namespace pdcg::atomistic;
using pdcg::test::fcc;

namespace {

// FD default: truncation O(s²) and round-off O(ε/s) ≈ 1e-11 of the entries for smooth
// pieces; 1e-7 of the largest entry leaves room for a bond whose ±s stencil straddles one of
// the EAM spline knots (where the cubic's second derivative jumps) but not for a wrong term.
constexpr double kTol = 1e-7;

/// Central differences of force_state like Potential's default, but with the step of bond m
/// kept below 0.3× its distance to the nearest tabulation knot r = i·knot (EAM tables are
/// piecewise cubics whose second derivative jumps at the knots: a stencil straddling one
/// measures a mix of both pieces). knot = 0: the default's step.
void fd_tangent(const Potential& pot, const FamilyState& f, double* K, double knot) {
  const std::int64_t n = f.size;
  std::vector<double> y(f.bond, f.bond + 3 * n), tp(static_cast<std::size_t>(3 * n)),
      tm(static_cast<std::size_t>(3 * n));
  FamilyState g = f;
  g.bond = y.data();
  for (std::int64_t m = 0; m < n; ++m) {
    const double* ym = f.bond + 3 * m;
    const double len = std::sqrt(ym[0] * ym[0] + ym[1] * ym[1] + ym[2] * ym[2]);
    double s = 6e-6 * std::max(1.0, len);
    if (knot > 0.0) {
      const double frac = len / knot - std::floor(len / knot);
      s = std::min(s, 0.3 * knot * std::min(frac, 1.0 - frac));
    }
    for (int b = 0; b < 3; ++b) {
      const auto idx = static_cast<std::size_t>(3 * m + b);
      y[idx] = f.bond[idx] + s;
      pot.force_state(g, tp.data());
      y[idx] = f.bond[idx] - s;
      pot.force_state(g, tm.data());
      y[idx] = f.bond[idx];
      for (std::int64_t j = 0; j < n; ++j)
        for (int a = 0; a < 3; ++a)
          K[static_cast<std::size_t>((j * n + m) * 9 + 3 * a + b)] =
              (tp[static_cast<std::size_t>(3 * j + a)] - tm[static_cast<std::size_t>(3 * j + a)]) /
              (2.0 * s);
    }
  }
}

double check_tangent(const std::string& commands, const Atoms& atoms, int max_families = 12,
                     double knot = 0.0) {
  const int ntypes = *std::max_element(atoms.type.begin(), atoms.type.end());
  const PotentialSpec spec = read_potential_commands_from_string(commands, "tangent", ntypes);
  const auto pot = make_potential(spec);
  FamilyOptions opt = family_options(*pot, spec, &atoms.bonds);
  opt.cutoff = pot->cutoff() * 1.1;  // bonds beyond the cutoff must give zero blocks
  const Families fam = build_families(atoms, opt);
  std::vector<double> Y(3 * fam.bonds());
  deformed_bonds(fam, atoms.x, fam.h, Y);
  double worst = 0.0;
  const auto step = std::max<std::size_t>(1, fam.points() / static_cast<std::size_t>(max_families));
  for (std::size_t k = 0; k < fam.points(); k += step) {
    const std::int64_t b0 = fam.offset[k], n = fam.offset[k + 1] - b0;
    std::vector<int> nt(static_cast<std::size_t>(n));
    for (std::int64_t b = 0; b < n; ++b)
      nt[static_cast<std::size_t>(b)] =
          atoms.type[static_cast<std::size_t>(fam.neighbor[static_cast<std::size_t>(b0 + b)])];
    FamilyState f;
    f.type = atoms.type[k];
    f.size = n;
    f.neighbor_type = nt.data();
    f.bond = Y.data() + 3 * b0;
    f.pair_factor = fam.pair_factor.empty() ? nullptr : fam.pair_factor.data() + b0;
    f.bond_type = fam.bond_type.empty() ? nullptr : fam.bond_type.data() + b0;
    const auto nn = static_cast<std::size_t>(9 * n * n);
    std::vector<double> Ka(nn, -1.0), Kf(nn), work(Potential::tangent_workspace(n));
    pot->force_state_tangent(f, Ka.data(), work.data());
    if (knot > 0.0)
      fd_tangent(*pot, f, Kf.data(), knot);
    else
      pot->Potential::force_state_tangent(f, Kf.data(), work.data());
    double scale = 0.0, diff = 0.0;
    for (std::size_t i = 0; i < nn; ++i) {
      scale = std::max(scale, std::abs(Kf[i]));
      diff = std::max(diff, std::abs(Ka[i] - Kf[i]));
    }
    EXPECT_GT(scale, 0.0);
    worst = std::max(worst, diff / scale);
  }
  std::printf("  [%s] worst relative tangent difference %.2e\n", pot->style().c_str(), worst);
  EXPECT_LT(worst, kTol) << commands;
  return worst;
}

Atoms chains(int n, double a, double noise, int nbondtypes, unsigned seed) {
  Atoms at = fcc(n, n, n, a, noise, 1, seed);
  for (std::int64_t first = 1; first <= static_cast<std::int64_t>(at.size()); first += 4)
    for (int k = 0; k < 3; ++k)
      at.bonds.push_back({1 + (k % nbondtypes), first + k, first + k + 1});
  for (std::size_t i = 0; i < at.size(); ++i) at.type[i] = 1 + static_cast<int>(i % 4 == 0);
  return at;
}

}  // namespace

TEST(PotentialTangent, LJShiftMixingThreeTypes) {
  check_tangent(
      "units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\npair_coeff 2 2 0.7 1.1 2.2\n"
      "pair_coeff 3 3 1.3 0.9\npair_coeff 1 3 0.5 1.05 2.0\npair_modify shift yes mix arithmetic\n",
      fcc(3, 3, 3, 1.5599, 0.06, 3, 3));
}

TEST(PotentialTangent, MorseTwoTypes) {
  check_tangent(
      "units metal\npair_style morse 6.0\npair_coeff 1 1 0.34 1.36 2.87\n"
      "pair_coeff 2 2 0.2 1.5 2.7 5.5\npair_coeff 1 2 0.3 1.4 2.8\npair_modify shift yes\n",
      fcc(3, 3, 3, 4.05, 0.05, 2, 5));
}

TEST(PotentialTangent, EamFuncflCu) {
  check_tangent("units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n",
                fcc(3, 3, 3, 3.615, 0.04, 1, 7));
}

TEST(PotentialTangent, EamAlloyAlCuTwoTypesCompressed) {
  check_tangent("units metal\npair_style eam/alloy\npair_coeff * * AlCu.eam.alloy Al Cu\n",
                fcc(3, 3, 3, 3.6, 0.05, 2, 9));
}

TEST(PotentialTangent, EamFinnisSinclairAlFe) {
  // AlFe_mm tabulates r with Δr = 6.5e-4 Å (file header); its spline's curvature jumps at
  // the knots by ~1e-4 relative, which the default FD step (~2e-5 Å) often straddles.
  check_tangent("units metal\npair_style eam/fs\npair_coeff * * AlFe_mm.eam.fs Al Fe\n",
                fcc(3, 3, 3, 3.9, 0.05, 2, 13), 12, 6.5e-4);
}

TEST(PotentialTangent, FeneWithWcaAndSpecialBonds) {
  check_tangent(
      "units lj\natom_style bond\npair_style lj/cut 1.122462048309373\npair_coeff * * 1.0 1.0\n"
      "pair_modify shift yes\nbond_style fene\nbond_coeff 1 30.0 1.5 1.0 1.0\nspecial_bonds fene\n",
      chains(3, 1.5599, 0.04, 1, 51));
}

TEST(PotentialTangent, HarmonicTwoBondTypesFractionalSpecialFactors) {
  check_tangent(
      "units lj\natom_style molecular\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n"
      "pair_coeff 2 2 0.8 0.95\nbond_style harmonic\nbond_coeff 1 100.0 1.05\n"
      "bond_coeff 2 50.0 1.15\nspecial_bonds lj 0.0 0.5 0.8\n",
      chains(3, 1.5599, 0.04, 2, 53));
}
