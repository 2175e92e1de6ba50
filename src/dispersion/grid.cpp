#include "pdcg/dispersion/grid.hpp"

#include <fftw3.h>
#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <complex>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>

#include "pdcg/core/error.hpp"

namespace pdcg::dispersion {

namespace {
std::mutex g_planner;  // FFTW's planner is not thread-safe (FFTW manual §5.4)
struct FftwFree {
  void operator()(void* p) const { fftw_free(p); }
};
double signed_sqrt(double w2) { return w2 >= 0 ? std::sqrt(w2) : -std::sqrt(-w2); }
}  // namespace

KappaGrid point_omega_grid(const LinearisedFamilies& lin,
                           std::span<const std::pair<std::int32_t, double>> atoms,
                           std::span<const double> mass, const atomistic::Box& box, double mvv2e,
                           int max_grid) {
  if (!box.periodic[0] && !box.periodic[1] && !box.periodic[2])
    throw InputError("a κ-grid needs a periodic body")
        .key("--grid")
        .expected("a body with at least one periodic direction")
        .fix("use --direction or --path");
  const Eigen::Matrix3d Hinv = box.h_inverse();
  // Φ(R) as a map over the fractional coordinates of R (exact keys after rounding to 1e-9).
  struct Key {
    std::array<long long, 3> q;
    bool operator<(const Key& o) const { return q < o.q; }
  };
  std::map<Key, std::pair<Eigen::Vector3d, Eigen::Matrix3d>> phi;  // key -> (s, Φ)
  auto add = [&](const Eigen::Vector3d& R, const Eigen::Matrix3d& K) {
    const Eigen::Vector3d s = Hinv * R;
    Key key{{std::llround(s[0] * 1e9), std::llround(s[1] * 1e9), std::llround(s[2] * 1e9)}};
    auto [it, fresh] = phi.try_emplace(key, s, Eigen::Matrix3d::Zero());
    it->second.second += K;
  };
  double M = 0.0;
  for (const auto& [k, w] : atoms) {
    const auto kk = static_cast<std::size_t>(k);
    const LinearisedFamilies::Atom at = lin.atom(kk, "point_omega_grid: atom was not linearised");
    const std::int64_t n = at.n;
    auto xi = [&](std::int64_t b) {
      const double* p = at.xi + 3 * b;
      return Eigen::Vector3d(p[0], p[1], p[2]);
    };
    for (std::int64_t b = 0; b < n; ++b)
      for (std::int64_t c = 0; c < n; ++c) {
        if (at.zero_block(b, c)) continue;
        const double* p = at.block(b, c);
        Eigen::Matrix3d Kbc;
        for (int r = 0; r < 3; ++r)
          for (int q = 0; q < 3; ++q) Kbc(r, q) = w * p[3 * r + q];
        add(xi(c) - xi(b), Kbc);
        add(-xi(b), -Kbc);
        add(xi(c), -Kbc);
        add(Eigen::Vector3d::Zero(), Kbc);
      }
    M += w * mass[kk];
  }
  // The finest grid G_i with s_i G_i integral for every R (periodic directions only).
  KappaGrid g;
  for (int i = 0; i < 3; ++i) {
    if (!box.periodic[static_cast<std::size_t>(i)]) continue;  // κ has no component there
    int G = 1;
    for (; G <= max_grid; ++G) {
      bool ok = true;
      for (const auto& [key, v] : phi) {
        const double x = v.first[i] * G;
        if (std::abs(x - std::round(x)) > 1e-6) {
          ok = false;
          break;
        }
      }
      if (ok) break;
    }
    if (G > max_grid)
      throw InputError("the bonds do not lie on a lattice commensurate with the box")
          .key("--grid")
          .value(fmt::format("no grid of ≤ {} divisions along box edge {}", max_grid, i + 1))
          .expected("a periodic Bravais-lattice body (perfect lattice)")
          .fix("use --direction or --path (any κ), or build the body from a perfect lattice");
    g.size[static_cast<std::size_t>(i)] = G;
  }
  const int G0 = g.size[0], G1 = g.size[1], G2 = g.size[2];
  const std::size_t n = static_cast<std::size_t>(G0) * G1 * G2;
  // nine interleaved transforms (howmany = 9, stride 9, distance 1)
  std::unique_ptr<fftw_complex, FftwFree> data(
      static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * 9 * n)));
  for (std::size_t i = 0; i < 9 * n; ++i) data.get()[i][0] = data.get()[i][1] = 0.0;
  auto wrap = [](double s, int G) {
    const long long j = std::llround(s * G);
    return static_cast<std::size_t>(((j % G) + G) % G);
  };
  for (const auto& [key, v] : phi) {
    const auto& [s, P] = v;
    const std::size_t idx =
        (wrap(s[0], G0) * static_cast<std::size_t>(G1) + wrap(s[1], G1)) * G2 + wrap(s[2], G2);
    for (int r = 0; r < 3; ++r)
      for (int q = 0; q < 3; ++q) data.get()[9 * idx + 3 * r + q][0] += P(r, q);
  }
  const int dims[3] = {G0, G1, G2};
  fftw_plan plan;
  {
    std::lock_guard<std::mutex> lock(g_planner);
    plan = fftw_plan_many_dft(3, dims, 9, data.get(), nullptr, 9, 1, data.get(), nullptr, 9, 1,
                              FFTW_BACKWARD, FFTW_ESTIMATE);
  }
  fftw_execute(plan);  // Σ_j Φ_j e^{+2πi m·j/G}
  {
    std::lock_guard<std::mutex> lock(g_planner);
    fftw_destroy_plan(plan);
  }
  const Eigen::Matrix3d Bt = 2.0 * std::numbers::pi * Hinv.transpose();
  g.kappa.resize(n);
  g.omega.resize(n);
  for (int a = 0; a < G0; ++a)
    for (int b = 0; b < G1; ++b)
      for (int c = 0; c < G2; ++c) {
        const std::size_t idx = (static_cast<std::size_t>(a) * G1 + b) * G2 + c;
        auto fold = [](int m, int G) { return m >= (G + 1) / 2 ? m - G : m; };
        g.kappa[idx] = Bt * Eigen::Vector3d(fold(a, G0), fold(b, G1), fold(c, G2));
        if (idx ==
            0) {  // κ = 0: a rigid translation. D(0) = Σ_R Φ(R) = 0 by construction (the four
          // terms of each K_bc cancel); the FFT's sum leaves ~1e-13, whose root 3e-7 (or a
          // spurious "unstable" −3e-7) is noise — write the exact 0.
          g.omega[idx] = Eigen::Vector3d::Zero();
          continue;
        }
        Eigen::Matrix3cd D;
        for (int r = 0; r < 3; ++r)
          for (int q = 0; q < 3; ++q)
            D(r, q) = std::complex<double>(data.get()[9 * idx + 3 * r + q][0],
                                           data.get()[9 * idx + 3 * r + q][1]);
        const Eigen::Matrix3cd Hm = 0.5 * (D + D.adjoint()) / (M * mvv2e);
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3cd> es(Hm, Eigen::EigenvaluesOnly);
        const Eigen::Vector3d w2 = es.eigenvalues();
        g.omega[idx] = {signed_sqrt(w2[0]), signed_sqrt(w2[1]), signed_sqrt(w2[2])};
      }
  return g;
}

}  // namespace pdcg::dispersion
