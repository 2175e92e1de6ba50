// Model dispersion of PD bodies of 1D chains against the closed forms (acceptance:
// 1e-12), and the finite-difference tangent default against an analytic one.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "pdcg/atomistic/families.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/dispersion/closed_form.hpp"
#include "pdcg/dispersion/grid.hpp"
#include "pdcg/dispersion/model.hpp"
#include "pdcg_test.hpp"

using namespace pdcg;
using namespace pdcg::atomistic;
using namespace pdcg::dispersion;

namespace {

/// ψ_k = ½ Σ_j ½ μ_n (r − n h)², n = round(r0/h): springs to the n-th neighbours of a chain.
class ChainSprings final : public Potential {
 public:
  ChainSprings(double h, std::vector<double> mu, bool analytic)
      : h_(h), mu_(std::move(mu)), analytic_(analytic) {}
  std::string style() const override { return "test chain springs"; }
  double cutoff() const override { return (static_cast<double>(mu_.size()) + 0.5) * h_; }
  int ntypes() const override { return 1; }
  bool pairwise() const override { return true; }
  double force_state(const FamilyState& f, double* t) const override {
    double psi = 0;
    for (std::int64_t b = 0; b < f.size; ++b) {
      const double* y = f.bond + 3 * b;
      const double r = std::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
      const auto [mu, r0] = spring(b, f);
      psi += 0.25 * mu * (r - r0) * (r - r0);
      for (int k = 0; k < 3; ++k) t[3 * b + k] = 0.5 * mu * (r - r0) / r * y[k];
    }
    return psi;
  }
  void force_state_tangent(const FamilyState& f, double* K, double* w) const override {
    if (!analytic_) return Potential::force_state_tangent(f, K, w);
    const std::int64_t n = f.size;
    std::fill(K, K + n * n * 9, 0.0);
    for (std::int64_t b = 0; b < n; ++b) {
      const double* y = f.bond + 3 * b;
      const double r = std::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
      const auto [mu, r0] = spring(b, f);
      // ½[φ'' e⊗e + φ'/r (I − e⊗e)], φ = ½μ(r − r0)²
      const double d2 = mu, d1r = mu * (r - r0) / r;
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c)
          K[(b * n + b) * 9 + 3 * a + c] =
              0.5 * ((d2 - d1r) * y[a] * y[c] / (r * r) + (a == c ? d1r : 0.0));
    }
  }

 private:
  // The spring of a bond is chosen by its reference length (|Y| ≈ n h for small motions).
  std::pair<double, double> spring(std::int64_t b, const FamilyState& f) const {
    const double* y = f.bond + 3 * b;
    const double r = std::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    const auto nn = static_cast<std::size_t>(std::lround(r / h_));
    return {mu_[nn - 1], static_cast<double>(nn) * h_};
  }
  double h_;
  std::vector<double> mu_;
  bool analytic_;
};

/// A periodic chain along x: `cell` atoms in a box of length cell·h (y, z free).
Atoms chain(std::size_t cell, double h) {
  Atoms a;
  a.box.lo = {0, -1, -1};
  a.box.hi = {static_cast<double>(cell) * h, 1, 1};
  a.box.periodic = {true, false, false};
  for (std::size_t i = 0; i < cell; ++i) {
    a.id.push_back(static_cast<std::int64_t>(i + 1));
    a.type.push_back(1);
    a.x.insert(a.x.end(), {static_cast<double>(i) * h, 0.0, 0.0});
  }
  return a;
}

double longitudinal(const LinearisedFamilies& lin, std::span<const double> mass, double kappa) {
  const std::pair<std::int32_t, double> site[] = {{0, 1.0}};
  return point_omega(lin, site, mass, {kappa, 0, 0}).maxCoeff();
}

}  // namespace

TEST(ModelDispersion, DeltaChainEqualsClosedForm) {
  const Atoms a = chain(1, 1.0);  // one atom, its images are the chain
  const ChainSprings pot(1.0, {1.0}, true);
  const Families fam = build_families(a, {pot.cutoff()});
  ASSERT_EQ(fam.bonds(), 2u);
  const LinearisedFamilies lin(pot, fam, a.x, a.type);
  const std::vector<double> mass{1.0};
  // reference values: 0.958851 at κ = 1, 2 at κ = π (μ = M = h = 1); same formulas, round-off only
  EXPECT_NEAR(longitudinal(lin, mass, 1.0), 0.958851077208406, 1e-12);
  EXPECT_NEAR(longitudinal(lin, mass, std::numbers::pi), 2.0, 1e-12);
  const std::vector<double> mu{1.0};
  for (double k = 0.05; k < std::numbers::pi; k += 0.1)
    EXPECT_NEAR(longitudinal(lin, mass, k), chain_omega(k, 1.0, 1.0, mu), 1e-12);
}

TEST(ModelDispersion, NextNearestChainAndZoneEdgeStayFinite) {
  const Atoms a = chain(1, 1.0);
  const ChainSprings pot(1.0, {1.0, 0.25}, true);
  const Families fam = build_families(a, {pot.cutoff()});
  const LinearisedFamilies lin(pot, fam, a.x, a.type);
  const std::vector<double> mass{1.0};
  const std::vector<double> mu{1.0, 0.25};
  for (double k = 0.05; k <= std::numbers::pi + 1e-9; k += 0.1) {
    const double w = longitudinal(lin, mass, k);
    EXPECT_TRUE(std::isfinite(w));
    EXPECT_NEAR(w, chain_omega(k, 1.0, 1.0, mu), 1e-12);
  }
}

TEST(ModelDispersion, RescaledChainFollowsOmegaOfEpsKappaOverEps) {
  // A chain rescaled by ε: bonds εh, K_ε = ε⁻² K per bond (ψ_ε(Y) = ψ(Y/ε)), same mass.
  for (double eps : {2.0, 4.0, 16.0}) {
    const Atoms a = chain(1, eps);
    const ChainSprings pot(eps, {1.0 / (eps * eps)}, true);
    const Families fam = build_families(a, {pot.cutoff()});
    const LinearisedFamilies lin(pot, fam, a.x, a.type);
    const std::vector<double> mass{1.0};
    const std::vector<double> mu{1.0};
    auto w = [&](double k) { return chain_omega(k, 1.0, 1.0, mu); };
    for (double k : {0.1, 0.5, 1.0, std::numbers::pi / 2, std::numbers::pi / eps})
      EXPECT_NEAR(longitudinal(lin, mass, k), rescaled_omega(w, k, eps), 1e-12) << "ε = " << eps;
    if (eps == 2.0) {  // reference values: ε = 2 gives 0.841471 at κ = 1 (= sin 1) and 1 at κ = π/2
      EXPECT_NEAR(longitudinal(lin, mass, 1.0), 0.841470984807897, 1e-12);
      EXPECT_NEAR(longitudinal(lin, mass, std::numbers::pi / 2), 1.0, 1e-12);
    }
  }
}

TEST(ModelDispersion, CellWithBasisFoldsTheChainBands) {
  const Atoms a = chain(2, 1.0);  // 2-atom cell: bands ω(κ) and ω(κ + π)
  const ChainSprings pot(1.0, {1.0, 0.25}, true);
  const Families fam = build_families(a, {pot.cutoff()});
  const LinearisedFamilies lin(pot, fam, a.x, a.type);
  const std::vector<double> mass{1.0, 1.0};
  const std::vector<double> mu{1.0, 0.25};
  for (double k : {0.1, 0.7, 1.3}) {
    const Eigen::VectorXd w = cell_omega(lin, mass, {k, 0, 0});
    ASSERT_EQ(w.size(), 6);
    EXPECT_NEAR(w[5],
                std::max(chain_omega(k, 1, 1, mu), chain_omega(k + std::numbers::pi, 1, 1, mu)),
                1e-12);
    EXPECT_NEAR(w[4],
                std::min(chain_omega(k, 1, 1, mu), chain_omega(k + std::numbers::pi, 1, 1, mu)),
                1e-12);
  }
}

TEST(ModelDispersion, FiniteDifferenceTangentMatchesAnalytic) {
  const Atoms a = chain(1, 1.0);
  const ChainSprings exact(1.0, {1.0, 0.25}, true), fd(1.0, {1.0, 0.25}, false);
  const Families fam = build_families(a, {exact.cutoff()});
  const LinearisedFamilies le(exact, fam, a.x, a.type), lf(fd, fam, a.x, a.type);
  const std::vector<double> mass{1.0};
  // central differences, step 6e-6: error ≈ 1e-10 relative (see potential.hpp)
  for (double k : {0.3, 1.7, 3.1})
    EXPECT_NEAR(longitudinal(lf, mass, k), longitudinal(le, mass, k), 1e-8);
}

TEST(ModelDispersion, SymmetryPathsAndBadLabels) {
  const auto p = path("fcc", 2.0, "G-X-L", 10);
  ASSERT_EQ(p.size(), 21u);
  EXPECT_NEAR(p[10].second.norm(), std::numbers::pi, 1e-14);  // X = 2π/a (1,0,0)
  EXPECT_NEAR(p.back().second.norm(), std::numbers::pi * std::sqrt(0.75), 1e-14);
  try {
    path("fcc", 2.0, "G-Q", 4);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'Q'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("G, X, L, K, W, U"), std::string::npos) << e.what();
  }
  // labels of another lattice: K on a chain (whose labels are G and X), M on fcc
  try {
    path("chain", 1.0, "G-K", 4);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'K'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("one of G, X for lattice chain"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(path("fcc", 1.0, "G-M", 4), InputError);
  EXPECT_NO_THROW(path("hex", 1.0, "G-M-K-G", 4));
  EXPECT_NO_THROW(path("chain", 1.0, "Γ-X", 4));
  EXPECT_THROW(symmetry_points("quasicrystal", 1.0), InputError);
}

// The whole κ-grid at once (FFTW): the chain against the closed form at κ_m = 2πm/(N h), the
// FCC LJ crystal against the direct sum point_omega at every grid κ (two code paths; the direct
// one is checked against LAMMPS in test_lattice_dispersion).
TEST(ModelDispersionGrid, ChainGridEqualsClosedForm) {
  const Atoms a = chain(32, 1.0);
  const ChainSprings pot(1.0, {1.0, 0.25}, true);
  const Families fam = build_families(a, {pot.cutoff()});
  const std::int32_t atom0[] = {0};
  const LinearisedFamilies lin(pot, fam, a.x, a.type, atom0);
  const std::vector<double> mass(32, 1.0);
  const std::pair<std::int32_t, double> site[] = {{0, 1.0}};
  const KappaGrid g = point_omega_grid(lin, site, mass, a.box);
  ASSERT_EQ(g.size[0], 32);
  ASSERT_EQ(g.size[1], 1);
  ASSERT_EQ(g.kappa.size(), 32u);
  const std::vector<double> mu{1.0, 0.25};
  for (std::size_t i = 0; i < g.kappa.size(); ++i) {
    const double k = g.kappa[i][0];
    const int m = static_cast<int>(i) >= 16 ? static_cast<int>(i) - 32 : static_cast<int>(i);
    EXPECT_NEAR(k, 2 * std::numbers::pi * m / 32.0, 1e-14);
    EXPECT_NEAR(g.omega[i][2], chain_omega(k, 1.0, 1.0, mu), 1e-12)
        << "κ = " << k;  // same formula: round-off
  }
}

TEST(ModelDispersionGrid, FccLennardJonesGridEqualsDirectSum) {
  const auto spec = read_potential_commands_from_string(
      "pair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0 2.5\n", "lj", 1);
  const auto pot = make_potential(spec);
  const double a0 = 1.5874010519681994;
  Atoms at;
  at.box.lo = {0, 0, 0};
  at.box.hi = {4 * a0, 4 * a0, 4 * a0};
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k)
        for (const auto& b : basis) {
          at.id.push_back(static_cast<std::int64_t>(at.id.size() + 1));
          at.type.push_back(1);
          at.x.insert(at.x.end(), {(i + b[0]) * a0, (j + b[1]) * a0, (k + b[2]) * a0});
        }
  const Families fam = build_families(at, {pot->cutoff()});
  const std::int32_t atom0[] = {0};
  const LinearisedFamilies lin(*pot, fam, at.x, at.type, atom0);
  const std::vector<double> mass(at.size(), 1.0);
  const std::pair<std::int32_t, double> site[] = {{0, 1.0}};
  const KappaGrid g = point_omega_grid(lin, site, mass, at.box);
  EXPECT_EQ(g.size, (std::array<int, 3>{8, 8, 8}));  // bonds on the a/2 grid of a 4a box
  double wmax = 0, worst = 0;
  for (std::size_t i = 0; i < g.kappa.size(); ++i) {
    const Eigen::Vector3d w = point_omega(lin, site, mass, g.kappa[i]);
    wmax = std::max(wmax, w.maxCoeff());
    // compare ω² (signed): √ amplifies round-off near ω = 0 (at Γ the FFT's Σ_R Φ(R) = 0
    // cancels to ~1e-13, whose root is 3e-7)
    worst = std::max(worst,
                     (w.cwiseProduct(w.cwiseAbs()) - g.omega[i].cwiseProduct(g.omega[i].cwiseAbs()))
                         .cwiseAbs()
                         .maxCoeff());
  }
  EXPECT_LT(worst, 1e-12 * wmax * wmax);           // FFT vs direct sum: round-off only
  EXPECT_EQ(g.omega[0], Eigen::Vector3d::Zero());  // κ = 0: exact zero, not round-off
  EXPECT_GT(wmax, 20.0);  // the grid reaches the zone edge (ω_max ≈ 21.4 at X)
  // a perturbed crystal has no lattice grid; a free body has no κ-grid
  Atoms bad = at;
  bad.x[3] += 0.01;
  const Families fb = build_families(bad, {pot->cutoff()});
  const LinearisedFamilies lb(*pot, fb, bad.x, bad.type, atom0);
  EXPECT_THROW(point_omega_grid(lb, site, mass, bad.box), InputError);
  Atoms free = at;
  free.box.periodic = {false, false, false};
  EXPECT_THROW(point_omega_grid(lin, site, mass, free.box), InputError);
}

// High-symmetry points by name for the cubic, hexagonal and 1D lattices (textbook values,
// e.g. Ashcroft & Mermin ch. 8; Setyawan & Curtarolo, Comput. Mater. Sci. 49 (2010) 299).
TEST(ModelDispersion, SymmetryPointsOfEveryLattice) {
  const double a = 2.0, pi = std::numbers::pi;
  auto norm = [&](const std::string& lattice, const std::string& label) {
    for (const auto& p : symmetry_points(lattice, a))
      if (p.label == label) return p.kappa.norm();
    ADD_FAILURE() << label << " missing for " << lattice;
    return 0.0;
  };
  EXPECT_NEAR(norm("fcc", "X"), 2 * pi / a, 1e-14);
  EXPECT_NEAR(norm("fcc", "L"), std::sqrt(3.0) * pi / a, 1e-14);
  EXPECT_NEAR(norm("fcc", "K"), 1.5 * std::sqrt(2.0) * pi / a, 1e-14);
  EXPECT_NEAR(norm("fcc", "W"), std::sqrt(5.0) * pi / a, 1e-14);
  EXPECT_NEAR(norm("bcc", "H"), 2 * pi / a, 1e-14);
  EXPECT_NEAR(norm("bcc", "N"), std::sqrt(2.0) * pi / a, 1e-14);
  EXPECT_NEAR(norm("bcc", "P"), std::sqrt(3.0) * pi / a, 1e-14);
  EXPECT_NEAR(norm("sc", "X"), pi / a, 1e-14);
  EXPECT_NEAR(norm("sc", "M"), std::sqrt(2.0) * pi / a, 1e-14);
  EXPECT_NEAR(norm("sc", "R"), std::sqrt(3.0) * pi / a, 1e-14);
  EXPECT_NEAR(norm("hex", "M"), 2 * pi / (std::sqrt(3.0) * a),
              1e-14);  // triangular lattice, spacing a
  EXPECT_NEAR(norm("hex", "K"), 4 * pi / (3 * a), 1e-14);
  EXPECT_NEAR(norm("chain", "X"), pi / a, 1e-14);
  for (const char* l : {"fcc", "bcc", "sc", "hex", "chain"}) EXPECT_EQ(norm(l, "G"), 0.0);
}
