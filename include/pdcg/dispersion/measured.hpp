/// \file
/// Dispersion measured from a trajectory: the space–time Fourier transform of a displacement
/// field on a periodic 1D lattice (docs/theory.md §5).
///
/// For sites n = 0..N−1 at spacing h and frames t = 0..T−1 at interval Δt, with u_n(t) the
/// displacement (time mean removed per site) and w(t) a window,
///   Û(κ_m, ω_l) = Σ_t Σ_n w(t) u_n(t) e^{−i(κ_m n h + ω_l t Δt)},
///   κ_m = 2πm/(Nh), m = 0..N/2;  ω_l = 2πl/(TΔt), l = 0..T/2,
///   S(κ_m, ω_l) = |Û(κ_m, ω_l)|² + |Û(κ_m, −ω_l)|²   (waves in both directions).
/// The ridge is ω at peak S for each κ_m ≠ 0; its resolution is Δω = 2π/(TΔt) (one bin).
/// FFTW computes the 2D real-to-complex transform in one call.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace pdcg::dispersion {

enum class Window { none, hann };

struct Spectrum {
  std::size_t nk = 0, nw = 0;  ///< κ_m for m = 0..nk−1, ω_l for l = 0..nw−1
  std::vector<double> kappa;   ///< nk
  std::vector<double> omega;   ///< nw
  std::vector<double> power;   ///< nk × nw, row-major (power[m * nw + l])
  double resolution = 0.0;     ///< Δω
};

struct RidgePoint {
  double kappa, omega, power, resolution;
};

/// S(κ, ω) from u (frames × sites, row-major). Throws InputError when there are fewer than
/// 4 frames or 2 sites, or when min_resolution > 0 and 2π/(TΔt) is coarser than it (the
/// message says how many frames are needed).
Spectrum space_time_spectrum(std::span<const double> u, std::size_t frames, std::size_t sites,
                             double spacing, double dt, Window window = Window::hann,
                             double min_resolution = 0.0);

/// ω at the peak of S for every κ_m with m ≥ 1 (the static ω = 0 bin is excluded).
std::vector<RidgePoint> ridge(const Spectrum& spectrum);

}  // namespace pdcg::dispersion
