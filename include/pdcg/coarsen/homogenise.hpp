/// \file
/// Homogenisation (docs/theory.md §3): W̄(Y, x) = ∫ φ(q) W(Y, x + q) dq = Σ_k φ(x_k − x) ψ_k(Y),
/// ρ̄(x) = Σ_k M_k φ(x_k − x). On a discrete set of continuum points x_p the weights are
///   w_kp = φ(|x_k − x_p|) / Σ_q φ(|x_k − x_q|)     (periodic images summed),
/// so Σ_p w_kp = 1 for every atom k and the point masses m_p = Σ_k w_kp M_k and point energies
/// E_p(Y) = Σ_k w_kp ψ_k(Y) add up to the atomic mass and energy to round-off, for any grid.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pdcg/body/body.hpp"
#include "pdcg/coarsen/kernels.hpp"

namespace pdcg::coarsen {

/// Regular grid x_p = origin + A (i, j, k), i ∈ [0, counts[0]) …; columns of A are the steps.
struct Grid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  std::array<std::int64_t, 3> counts{1, 1, 1};
};

/// A grid of spacing h, with orientation `rotation` (orthonormal columns: the grid axes) and
/// offset `shift` (in units of h along the grid axes), covering the body: the periodic box for
/// periodic bodies (points with fractional coordinates in [0, 1) along periodic directions),
/// the atoms plus the kernel support along free directions. For bodies of dimension d < 3 the
/// grid spans the first d grid axes only (one layer at the atoms' mean along the others).
struct GridOptions {
  double spacing = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
};

struct HomogeniseReport {
  double lattice_spacing = 0.0;  ///< median nearest-neighbour distance of the atoms
  std::vector<std::string> warnings;
};

/// Homogenises a body on a regular grid (empty grid points — no atom within the kernel support —
/// are dropped). Point volumes: the grid cell measure (d-dimensional). Warns (log and report)
/// when the kernel's support radius is smaller than the lattice spacing: no point then averages
/// over neighbouring atoms and homogenisation does nothing. Throws InputError for a non-positive spacing,
/// an already homogenised body, or an atom that no grid point reaches.
body::Body homogenise_on_grid(const body::Body& body, const Kernel& kernel, const GridOptions& grid,
                              HomogeniseReport* report = nullptr);

/// Homogenises on given points (3P). Point volumes V_p = Σ_k w_kp V₀/N (the atoms' share of the
/// body's reference volume). Points that no atom reaches keep zero mass.
body::Body homogenise_on_points(const body::Body& body, const Kernel& kernel,
                                std::vector<double> points, HomogeniseReport* report = nullptr);

/// Median nearest-neighbour distance of the body's atoms (from its families; 0 without bonds).
double lattice_spacing(const body::Body& body);

}  // namespace pdcg::coarsen
