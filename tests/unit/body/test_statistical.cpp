// Statistical bodies (docs/theory.md §2): the harmonic chain closed form, sampling convergence,
// empirical densities as the frame average, Gaussian fits from frames.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "pdcg/body/statistics.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"
#include "toy_potentials.hpp"

using namespace pdcg;
using namespace pdcg::body;

namespace {

/// Periodic 1D chain along x: n atoms, spacing a, in a box with free y, z.
atomistic::Atoms chain(int n, double a) {
  atomistic::Atoms c;
  c.box.lo = {0, -5, -5};
  c.box.hi = {n * a, 5, 5};
  c.box.periodic = {true, false, false};
  for (int i = 0; i < n; ++i) {
    c.id.push_back(i + 1);
    c.type.push_back(1);
    c.x.insert(c.x.end(), {(i + 0.25) * a, 0.0, 0.0});
  }
  c.type_mass = {NAN, 1.0, 1.0};
  return c;
}

atomistic::PotentialSpec spec() {
  atomistic::PotentialSpec s;
  s.lines = {"pair_style test"};
  return s;
}

}  // namespace

TEST(Statistical, GaussHermiteIntegratesMomentsOfTheNormal) {
  std::vector<double> z, w;
  for (int n = 1; n <= 12; ++n) {
    gauss_hermite(n, z, w);
    // E[Z^(2m)] = (2m−1)!!, exact for 2m ≤ 2n − 1
    double dfact = 1;
    for (int m = 0; 2 * m <= 2 * n - 1; ++m) {
      if (m > 0) dfact *= 2 * m - 1;
      double s = 0;
      for (int i = 0; i < n; ++i) s += w[i] * std::pow(z[i], 2 * m);
      EXPECT_TRUE(test::close(s, dfact, {0, 1e-12}))
          << "n " << n << " m " << m;  // eigen-solver round-off
    }
  }
  EXPECT_THROW(gauss_hermite(0, z, w), InputError);
}

TEST(Statistical, HarmonicChainClosedForm) {
  // ½c(r − h)² per bond with Gaussian atoms: E = ½c((d̄ − h)² + σ_j² + σ_k²) exactly.
  const int n = 12;
  const double a = 1.0, h = 0.93, c = 3.0;
  auto pot = std::make_shared<test::Springs>(c, h, 1.5 * a);
  Body b =
      make_delta_body(chain(n, a), pot, spec(), {.dimension = 1, .cutoff = 0.0, .source = "chain"});
  ASSERT_EQ(b.families.bonds(), 2u * n);
  Statistics s;
  s.covariance.assign(6 * n, 0.0);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0.01, 0.06);
  std::vector<double> sigma(n);
  for (int i = 0; i < n; ++i) {
    sigma[i] = u(rng);
    s.covariance[6 * i] = sigma[i] * sigma[i];  // Σxx (upper triangle, row by row)
  }
  for (int order : {2, 3, 6}) {
    s.order = order;
    Body sb = b;
    make_statistical(sb, s);
    Evaluator ev(sb);
    std::mt19937 frng(5);
    for (double stretch : {1.0, 1.3, 0.8}) {
      Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
      F(0, 0) = stretch;
      const Evaluation e = ev.homogeneous(F);
      double expect = 0;
      for (int i = 0; i < n; ++i) {
        const int j = (i + 1) % n;
        const double dbar = stretch * a;
        // the deformation maps the fluctuations too (conforming): σ → stretch·σ
        expect += 0.5 * c *
                  (std::pow(dbar - h, 2) + std::pow(stretch * sigma[i], 2) +
                   std::pow(stretch * sigma[j], 2));
      }
      // Gauss–Hermite of order ≥ 2 is exact for quadratics: round-off only
      EXPECT_TRUE(test::close(e.energy, expect, {0, 1e-12}))
          << "order " << order << " stretch " << stretch;
    }
  }
}

TEST(Statistical, SamplingConvergesAsInverseSquareRoot) {
  const int n = 10;
  const double a = 1.0, h = 0.93, c = 3.0, sigma = 0.05;
  auto pot = std::make_shared<test::Springs>(c, h, 1.5 * a);
  Body b =
      make_delta_body(chain(n, a), pot, spec(), {.dimension = 1, .cutoff = 0.0, .source = "chain"});
  const double expect = n * 0.5 * c * (std::pow(a - h, 2) + 2 * sigma * sigma);
  std::vector<double> errs;
  for (std::int64_t S : {100, 2500}) {
    Body sb = b;
    Statistics s = isotropic_gaussian(sb, sigma);
    s.method = Statistics::Method::sampling;
    s.samples = S;
    make_statistical(sb, s);
    Evaluator ev(sb);
    errs.push_back(std::abs(ev.reference().energy - expect));
  }
  // Single-sample standard deviation of U = ½c Σ_b (a − h + Δ_b)², Δ_b = η_{b+1} − η_b ~ N(0, 2σ²):
  // the linear term Σ_b Δ_b vanishes around the ring; Var(Δ_b²) = 8σ⁴ and adjacent bonds share
  // an atom, Cov(Δ_b², Δ_{b+1}²) = 2 Cov(Δ_b, Δ_{b+1})² = 2σ⁴, so Var U = (c²/4)·12nσ⁴.
  const double sd1 = 0.5 * c * std::sqrt(n * (8 + 4) * std::pow(sigma, 4));
  EXPECT_LT(errs[0], 5 * sd1 / std::sqrt(100.0));  // 5 standard errors: fails with p < 1e-6
  EXPECT_LT(errs[1], 5 * sd1 / std::sqrt(2500.0));
}

TEST(Statistical, EmpiricalIsTheFrameAverageAndGaussianFitMatchesMoments) {
  const int n = 8;
  auto pot = std::make_shared<test::Glue>(3.0, 1.0, 1.5, 1.6);
  atomistic::Atoms ref = test::cubic_lattice(n, 2, 2, 1.0, 0.0, true);
  std::vector<atomistic::Atoms> frames;
  std::mt19937 rng(8);
  std::normal_distribution<double> g(0, 0.04);
  for (int f = 0; f < 5; ++f) {
    atomistic::Atoms fr = ref;
    for (auto& v : fr.x) v += g(rng);
    frames.push_back(fr);
  }
  // energy of each frame as its own delta body with the families of the reference
  Body b = make_delta_body(ref, pot, spec());
  double avg = 0;
  {
    Evaluator ev(b);
    for (const auto& fr : frames) avg += ev.deformed(fr.x).energy / frames.size();
  }
  Body eb = b;
  make_statistical(eb, empirical_from_frames(eb, frames));
  Evaluator ev(eb);
  EXPECT_TRUE(test::close(ev.reference().energy, avg, {0, 1e-12}));  // same sums, other order
  // Gaussian fit: means and covariances are the frames' moments
  Body gb = b;
  const Statistics gs = gaussian_from_frames(gb, frames);
  for (int i = 0; i < 3; ++i) {
    double m = 0, v = 0;
    for (const auto& fr : frames) m += fr.x[3 * i] / 5.0;
    for (const auto& fr : frames) v += std::pow(fr.x[3 * i] - m, 2) / 5.0;
    EXPECT_NEAR(gb.x[3 * i], m, 1e-14);
    EXPECT_NEAR(gs.covariance_of(static_cast<std::size_t>(i))(0, 0), v, 1e-15);
  }
  // cubature with a many-body potential is refused
  Statistics bad = gs;
  EXPECT_THROW(make_statistical(gb, bad), InputError);
}
