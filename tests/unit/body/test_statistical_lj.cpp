// Statistical LJ crystal: Gauss–Hermite cubature error falls with order, sampling error falls
// as N^(-1/2). Prints the table quoted in docs/bodies.md. The LJ pair potential is written here
// (φ = 4[(1/r)¹² − (1/r)⁶], ε = σ = 1, cut at 2.5) as the model under test.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "pdcg/body/statistics.hpp"
#include "pdcg_test.hpp"
#include "toy_potentials.hpp"

using namespace pdcg;
using namespace pdcg::body;

namespace {

class LJ final : public atomistic::Potential {
 public:
  explicit LJ(bool shift) : shift_(shift ? 4.0 * (std::pow(2.5, -12) - std::pow(2.5, -6)) : 0.0) {}
  std::string style() const override { return "test lj"; }
  double cutoff() const override { return 2.5; }
  int ntypes() const override { return 1; }
  bool pairwise() const override { return true; }
  double force_state(const atomistic::FamilyState& f, double* t) const override {
    double psi = 0;
    for (std::int64_t b = 0; b < f.size; ++b) {
      const double* y = f.bond + 3 * b;
      const double r2 = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
      if (r2 >= 6.25) {
        t[3 * b] = t[3 * b + 1] = t[3 * b + 2] = 0;
        continue;
      }
      const double i6 = 1.0 / (r2 * r2 * r2);
      psi += 0.5 * (4.0 * (i6 * i6 - i6) - shift_);
      const double s = 0.5 * (-48.0 * i6 * i6 + 24.0 * i6) / r2;  // ½ φ'(r)/r
      for (int k = 0; k < 3; ++k) t[3 * b + k] = s * y[k];
    }
    return psi;
  }

 private:
  double shift_;  // pair_modify shift yes: φ(r_c) subtracted
};

atomistic::Atoms fcc(int n, double a) {
  atomistic::Atoms at;
  at.box.hi = {n * a, n * a, n * a};
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::int64_t id = 1;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const auto& b : basis) {
          at.id.push_back(id++);
          at.type.push_back(1);
          at.x.insert(at.x.end(),
                      {(i + b[0] + 0.25) * a, (j + b[1] + 0.25) * a, (k + b[2] + 0.25) * a});
        }
  at.type_mass = {NAN, 1.0};
  return at;
}

}  // namespace

TEST(StatisticalLJ, CubatureConvergesWithOrderAndSamplingAsInverseSqrtN) {
  atomistic::PotentialSpec spec;
  const double width = 0.06;  // σ of every atom, in units of the LJ σ
  for (const bool shifted : {false, true}) {
    auto pot = std::make_shared<LJ>(shifted);
    const Body b = make_delta_body(fcc(2, 1.5874), pot, spec);
    auto energy = [&](Statistics s) {
      Body sb = b;
      make_statistical(sb, std::move(s));
      Evaluator ev(sb);
      return ev.reference().energy / static_cast<double>(b.size());
    };
    Statistics base = isotropic_gaussian(b, width);
    base.order = 16;
    const double ref = energy(base);
    std::printf(
        "statistical LJ fcc (32 atoms, a = 1.5874, r_c = 2.5, %s, width %.2f): E/N (order 16) = "
        "%.15f\n",
        shifted ? "shifted" : "unshifted", width, ref);
    std::printf("  cubature order | |E/N - ref| | time [ms]\n");
    std::vector<double> err;
    for (int order : {1, 2, 3, 4, 6, 8, 10, 12}) {
      Statistics s = isotropic_gaussian(b, width);
      s.order = order;
      const auto t0 = std::chrono::steady_clock::now();
      const double e = energy(s);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      err.push_back(std::abs(e - ref));
      std::printf("  %14d | %.3e   | %.1f\n", order, err.back(), ms);
    }
    // monotone decrease through order 4 (beyond, the cutoff discontinuity limits the rate)
    for (std::size_t k = 1; k < 4; ++k) EXPECT_LT(err[k], err[k - 1]) << "shifted " << shifted;
    EXPECT_LT(err[3], 1e-3 * err[0]);
    if (shifted) continue;
    std::printf("  samples N | rms |E/N - ref| over 8 seeds | rms*sqrt(N)\n");
    std::vector<double> scaled;
    for (std::int64_t N : {16, 64, 256, 1024}) {
      double ss = 0;
      for (std::uint64_t seed = 1; seed <= 8; ++seed) {
        Statistics s = isotropic_gaussian(b, width);
        s.method = Statistics::Method::sampling;
        s.samples = N;
        s.seed = seed;
        ss += std::pow(energy(s) - ref, 2);
      }
      const double rms = std::sqrt(ss / 8);
      std::printf("  %9lld | %.3e                  | %.3e\n", static_cast<long long>(N), rms,
                  rms * std::sqrt(static_cast<double>(N)));
      scaled.push_back(rms * std::sqrt(static_cast<double>(N)));
    }
    // rms·√N constant up to the scatter of an 8-seed rms (χ² with 8 dof: within ×2.5 at >99%)
    for (double sc : scaled) {
      EXPECT_LT(sc, 2.5 * scaled[0]);
      EXPECT_GT(sc, scaled[0] / 2.5);
    }
  }
}
