// Hard case: dispersion at the Brillouin-zone edge and for ε = 16 — finite, positive
// ω², no NaN — for a 1D chain (delta, homogenised, rescaled, homogenised + rescaled) and the
// FCC Lennard-Jones crystal (delta and rescaled), and the values right (closed form, or the
// scaling law ω_ε(κ) = ω(εκ)/ε against the delta body).
//
// Safeguard: the dynamical matrix is symmetrised and ω² = eig(D/M) is mapped to ω by
// signed_sqrt, so an unstable mode (ω² < 0) is reported as −√|ω²| — finite, negative, and the
// CLI warns — instead of NaN. Without it, std::sqrt of a negative eigenvalue is NaN and goes
// silently into the CSV and the plot. CompressedChainReportsUnstableModesFinite proves both:
// a chain whose bonds are compressed has transverse ω² = (2/M)(φ'(h)/h)(1 − cos κh) < 0
// (closed form), the plain square root of that eigenvalue is NaN, point_omega returns −√|ω²|.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "../../atomistic/potential_test_util.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/body.hpp"
#include "pdcg/coarsen/homogenise.hpp"
#include "pdcg/coarsen/kernels.hpp"
#include "pdcg/coarsen/rescale.hpp"
#include "pdcg/dispersion/body_dispersion.hpp"
#include "pdcg/dispersion/model.hpp"

using namespace pdcg;
constexpr double kPi = std::numbers::pi;

namespace {

body::Body make_body(const atomistic::Atoms& atoms, const std::string& commands, int dimension) {
  const auto spec = atomistic::read_potential_commands_from_string(commands, "test potential", 1);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  return body::make_delta_body(atoms, pot, spec,
                               {.dimension = dimension, .cutoff = 0.0, .source = "test"});
}

/// Periodic chain of n atoms at spacing 1 along x with harmonic bonds to the first and second
/// neighbours (LAMMPS bond harmonic E = K (r − r0)², K = μ/2).
body::Body chain_body(double mu1, double mu2, double r0 = 1.0) {
  const int n = 32;
  atomistic::Atoms a;
  a.box.lo = {0, -0.5, -0.5};
  a.box.hi = {n, 0.5, 0.5};
  a.box.periodic = {true, false, false};
  a.type_mass = {0.0, 1.0};
  for (int i = 0; i < n; ++i) {
    a.id.push_back(i + 1);
    a.type.push_back(1);
    a.x.insert(a.x.end(), {static_cast<double>(i), 0.0, 0.0});
    a.bonds.push_back({1, i + 1, (i + 1) % n + 1});
    a.bonds.push_back({2, i + 1, (i + 2) % n + 1});
  }
  const std::string pot =
      "units lj\nmass 1 1.0\npair_style zero 2.5\npair_coeff * *\nbond_style harmonic\n" +
      std::string("bond_coeff 1 ") + std::to_string(mu1 / 2) + " " + std::to_string(r0) +
      "\nbond_coeff 2 " + std::to_string(mu2 / 2) + " " + std::to_string(2 * r0) +
      "\nspecial_bonds lj/coul 0.0 1.0 1.0\n";
  return make_body(a, pot, 1);
}

double chain_omega(double k, double mu2) {
  return std::sqrt(2 * (1 - std::cos(k)) + 2 * mu2 * (1 - std::cos(2 * k)));
}

body::Body fcc_lj_body() {
  const int n = 4;
  const double a = 1.5874010519681994;  // lattice fcc 1.0 in LJ units (ρ* = 1)
  atomistic::Atoms at = test::cubic_lattice(n, n, n, a, 4, 0.0, false, 0);
  at.type_mass = {0.0, 1.0};
  return make_body(at, "units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0 2.5\n",
                   3);
}

/// ω² finite and ≥ 0 for every branch; > 0 for the top branch away from Γ.
void expect_stable(const Eigen::VectorXd& w, bool at_gamma, const std::string& what) {
  for (Eigen::Index b = 0; b < w.size(); ++b) {
    EXPECT_TRUE(std::isfinite(w[b])) << what;
    EXPECT_GE(w[b], 0.0) << what << " branch " << b;  // ω ≥ 0 ⇔ ω² ≥ 0 (signed_sqrt)
  }
  if (!at_gamma) {
    EXPECT_GT(w.maxCoeff(), 0.0) << what;
  }
}

}  // namespace

TEST(DispersionStability, ChainAtZoneEdgeAndEpsilon16) {
  const double mu2 = 0.25;
  const body::Body delta = chain_body(1.0, mu2);
  const body::Body hom = coarsen::homogenise_on_grid(
      delta, coarsen::make_kernel("wendland-c2", 2.0), {.spacing = 0.8});
  struct Case {
    std::string name;
    body::Body body;
    double eps;
  };
  std::vector<Case> cases;
  cases.push_back({"delta", delta, 1});
  cases.push_back({"homogenised", hom, 1});
  for (double eps : {2.0, 4.0, 16.0})
    cases.push_back({"rescaled", coarsen::rescale(delta, eps), eps});
  cases.push_back({"homogenised + rescaled", coarsen::rescale(hom, 16.0), 16});
  for (const auto& c : cases) {
    const dispersion::BodyDispersion model(c.body, std::nullopt, false);
    // κ up to twice the zone edge π/ε (the periodic image beyond it), the edge itself exactly
    for (int i = 0; i <= 64; ++i) {
      const double k = (i == 32 ? kPi / c.eps : 2 * kPi / c.eps * i / 64.0);
      const Eigen::VectorXd w = model.omega({k, 0, 0});
      const std::string what =
          c.name + " ε = " + std::to_string(c.eps) + " κ = " + std::to_string(k);
      expect_stable(w, i == 0 || i == 64, what);
      // same formula up to round-off (acceptance: 1e-12)
      EXPECT_NEAR(w.maxCoeff(), chain_omega(c.eps * k, mu2) / c.eps, 1e-12) << what;
    }
    // the zone edge: ω_ε(π/ε) = ω(π)/ε = 2/ε
    EXPECT_NEAR(model.omega({kPi / c.eps, 0, 0}).maxCoeff(), 2.0 / c.eps, 1e-12) << c.name;
  }
}

TEST(DispersionStability, FccLennardJonesAtZoneEdgesAndEpsilon16) {
  const body::Body delta = fcc_lj_body();
  const body::Body res = coarsen::rescale(delta, 16.0);
  const dispersion::BodyDispersion m1(delta, std::nullopt, false), m16(res, std::nullopt, false);
  const double a = 1.5874010519681994;
  // the path through every zone-edge point of the fcc zone, 10 points per segment
  const auto pts = dispersion::path("fcc", a, "G-X-W-L-G-K-U-X", 10);
  double wmax = 0;
  for (const auto& [s, k] : pts) wmax = std::max(wmax, m1.omega(k).maxCoeff());
  for (const auto& [s, k] : pts) {
    const bool gamma = k.norm() == 0.0;
    const Eigen::VectorXd w1 = m1.omega(k), w16 = m16.omega(k / 16.0);
    expect_stable(w1, gamma, "delta at s = " + std::to_string(s));
    expect_stable(w16, gamma, "ε = 16 at s = " + std::to_string(s));
    if (!gamma) {
      EXPECT_GT(w1.minCoeff(), 0.0);  // all three branches are strictly stable off Γ
    }
    // ω₁₆(κ/16) = ω(κ)/16 (rescaling, docs/theory.md §4): round-off only (relative to ω_max)
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(16.0 * w16[b], w1[b], 1e-12 * wmax);
  }
  // zone-edge values stay bounded by the Γ-X-… maximum (no blow-up at the edge)
  EXPECT_GT(wmax, 20.0);  // ω_max ≈ 21.4 at X (LJ units; cf. docs/dispersion.md)
  EXPECT_LT(wmax, 23.0);
}

TEST(DispersionStability, CompressedChainReportsUnstableModesFinite) {
  // Springs of rest length 1.1 on a chain of spacing 1: compressed, φ'(1) = μ(1 − 1.1) = −0.1.
  const body::Body b = chain_body(1.0, 0.0, 1.1);
  const dispersion::BodyDispersion model(b, std::nullopt, false);
  for (double k : {0.5, 2.0, kPi}) {
    const Eigen::VectorXd w = model.omega({k, 0, 0});
    // closed form (Born & Huang ch. V): transverse ω² = (2/M)(φ'(h)/h)(1 − cos κh) < 0,
    // longitudinal ω² = (2/M) φ''(h)(1 − cos κh) = 2(1 − cos κh)
    const double w2_transverse = 2 * (-0.1) * (1 - std::cos(k));
    ASSERT_LT(w2_transverse, 0.0);
    // without the safeguard: the plain square root of this eigenvalue is NaN
    EXPECT_TRUE(std::isnan(std::sqrt(w2_transverse)));
    // with it: finite, negative, −√|ω²| (two transverse branches), the longitudinal one intact
    ASSERT_EQ(w.size(), 3);
    for (Eigen::Index i = 0; i < 3; ++i) EXPECT_TRUE(std::isfinite(w[i]));
    EXPECT_NEAR(w[0], -std::sqrt(-w2_transverse), 1e-12);
    EXPECT_NEAR(w[1], -std::sqrt(-w2_transverse), 1e-12);
    EXPECT_NEAR(w[2], std::sqrt(2 * (1 - std::cos(k))), 1e-12);
  }
}
