#include "pdcg/dispersion/measured.hpp"

#include <fftw3.h>
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <mutex>
#include <numbers>

#include "pdcg/core/error.hpp"

namespace pdcg::dispersion {

namespace {
// FFTW's planner is not thread-safe (FFTW manual §5.4); executing a plan is.
std::mutex g_fftw_planner;

struct FftwFree {
  void operator()(void* p) const { fftw_free(p); }
};
}  // namespace

Spectrum space_time_spectrum(std::span<const double> u, std::size_t frames, std::size_t sites,
                             double spacing, double dt, Window window, double min_resolution) {
  if (frames < 4)
    throw InputError("too few frames for a frequency spectrum")
        .key("frames")
        .value(std::to_string(frames))
        .expected("at least 4 (and enough for the resolution 2π/(T·Δt) you need)")
        .fix("dump more frames (LAMMPS dump every N steps over a longer run)");
  if (sites < 2)
    throw InputError("too few lattice sites for a wavenumber spectrum")
        .key("sites")
        .value(std::to_string(sites))
        .expected("at least 2");
  if (u.size() != frames * sites)
    throw InputError("displacement array does not match frames × sites")
        .value(std::to_string(u.size()))
        .expected(std::to_string(frames * sites));
  if (!(spacing > 0) || !(dt > 0))
    throw InputError("spacing and time step must be positive")
        .value(fmt::format("spacing {}, dt {}", spacing, dt));
  const double two_pi = 2.0 * std::numbers::pi;
  const double resolution = two_pi / (static_cast<double>(frames) * dt);
  if (min_resolution > 0 && resolution > min_resolution) {
    const auto needed = static_cast<std::size_t>(std::ceil(two_pi / (min_resolution * dt)));
    throw InputError("trajectory too short for the requested frequency resolution")
        .key("frames")
        .value(fmt::format("{} frames × Δt {} gives Δω = {:.4g}", frames, dt, resolution))
        .expected(fmt::format("Δω ≤ {:.4g}, i.e. at least {} frames", min_resolution, needed))
        .fix("run longer or dump more often");
  }

  // Remove each site's time mean; apply the window.
  const std::size_t T = frames, N = sites, Nh = N / 2 + 1;
  std::unique_ptr<double, FftwFree> in(static_cast<double*>(fftw_malloc(sizeof(double) * T * N)));
  std::unique_ptr<fftw_complex, FftwFree> out(
      static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * T * Nh)));
  for (std::size_t n = 0; n < N; ++n) {
    double mean = 0.0;
    for (std::size_t t = 0; t < T; ++t) mean += u[t * N + n];
    mean /= static_cast<double>(T);
    for (std::size_t t = 0; t < T; ++t) {
      const double w = window == Window::hann
                           ? 0.5 * (1.0 - std::cos(two_pi * static_cast<double>(t) / static_cast<double>(T - 1)))
                           : 1.0;
      in.get()[t * N + n] = w * (u[t * N + n] - mean);
    }
  }
  fftw_plan plan;
  {
    std::lock_guard<std::mutex> lock(g_fftw_planner);
    plan = fftw_plan_dft_r2c_2d(static_cast<int>(T), static_cast<int>(N), in.get(), out.get(),
                                FFTW_ESTIMATE);
  }
  fftw_execute(plan);
  {
    std::lock_guard<std::mutex> lock(g_fftw_planner);
    fftw_destroy_plan(plan);
  }

  Spectrum s;
  s.nk = Nh;
  s.nw = T / 2 + 1;
  s.resolution = resolution;
  s.kappa.resize(s.nk);
  s.omega.resize(s.nw);
  for (std::size_t m = 0; m < s.nk; ++m)
    s.kappa[m] = two_pi * static_cast<double>(m) / (static_cast<double>(N) * spacing);
  for (std::size_t l = 0; l < s.nw; ++l) s.omega[l] = resolution * static_cast<double>(l);
  s.power.assign(s.nk * s.nw, 0.0);
  auto p2 = [&](std::size_t l, std::size_t m) {
    const fftw_complex& c = out.get()[l * Nh + m];
    return c[0] * c[0] + c[1] * c[1];
  };
  for (std::size_t m = 0; m < s.nk; ++m)
    for (std::size_t l = 0; l < s.nw; ++l) {
      double p = p2(l, m);
      const std::size_t neg = (T - l) % T;  // −ω_l
      if (neg != l) p += p2(neg, m);
      s.power[m * s.nw + l] = p;
    }
  return s;
}

std::vector<RidgePoint> ridge(const Spectrum& s) {
  std::vector<RidgePoint> r;
  for (std::size_t m = 1; m < s.nk; ++m) {
    std::size_t best = 1;
    for (std::size_t l = 1; l < s.nw; ++l)
      if (s.power[m * s.nw + l] > s.power[m * s.nw + best]) best = l;
    r.push_back({s.kappa[m], s.omega[best], s.power[m * s.nw + best], s.resolution});
  }
  return r;
}

}  // namespace pdcg::dispersion
