/// \file
/// Model dispersion on the full κ-grid of a periodic body at once (FFTW; docs/theory.md §5).
///
/// At a point of a Bravais-lattice body (model.hpp) the dynamical matrix is
///   D(κ) = Σ_k w_k Σ_bc K_bc [e^{iκ·(ξ_c−ξ_b)} − e^{−iκ·ξ_b} − e^{iκ·ξ_c} + 1] = Σ_R Φ(R)
///   e^{iκ·R},
/// i.e. the force constants Φ(R) collect w_k K_bc at R ∈ {ξ_c − ξ_b, 0} and −w_k K_bc at
/// R ∈ {−ξ_b, ξ_c}. With s = H⁻¹R the fractional coordinates of R in the box (H: edge vectors
/// as columns), every R lies on a grid s_i = j_i/G_i (G_i: the finest such grid along periodic
/// direction i, found from the bonds; G_i = 1 along free directions), and for
///   κ_m = 2π H⁻ᵀ m,   m_i = 0 … G_i − 1   (all wavevectors commensurate with the box)
/// D(κ_m) = Σ_j Φ_j e^{2πi m·j/G} is one 3D FFT of the nine components of Φ (FFTW backward
/// transform). ω² = eig(D/(M·mvv2e)), signed square roots as in point_omega; at κ = 0 (rigid
/// translation, Σ_R Φ(R) = 0 exactly) ω = 0 is written instead of the FFT's round-off. Points whose
/// κ differ by a reciprocal lattice vector of the crystal are equivalent (the grid may hold each
/// physical κ more than once when the bonds' grid is finer than the lattice).
#pragma once

#include <Eigen/Core>
#include <array>
#include <span>
#include <utility>
#include <vector>

#include "pdcg/atomistic/box.hpp"
#include "pdcg/dispersion/model.hpp"

namespace pdcg::dispersion {

struct KappaGrid {
  std::array<int, 3> size{1, 1, 1};    ///< G_1, G_2, G_3
  std::vector<Eigen::Vector3d> kappa;  ///< κ_m, m_i folded into [−G_i/2, G_i/2), m_3 fastest
  std::vector<Eigen::Vector3d> omega;  ///< 3 branches per κ, ascending
};

/// ω on every κ of the grid above, for one point (weighted atoms) of a body in `box`.
/// Throws InputError when the box has no periodic direction, or when the bonds do not lie on
/// a grid of at most max_grid divisions along a periodic direction (not a lattice).
KappaGrid point_omega_grid(const LinearisedFamilies& lin,
                           std::span<const std::pair<std::int32_t, double>> atoms,
                           std::span<const double> mass, const atomistic::Box& box,
                           double mvv2e = 1.0, int max_grid = 256);

}  // namespace pdcg::dispersion
