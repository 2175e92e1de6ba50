/// \file
/// Randomly perturbed grids (hard cases, docs/validation.md §2): a regular grid body whose point
/// positions are jittered, to check that the BA solver has no spurious zero-energy
/// modes and no displacement oscillations on irregular point clouds.
///
/// Each point x_i of `Discretization::grid(spec)` is moved to x_i + a Δx r_i with r_i
/// uniform in [−1, 1]^d (in-plane only in 2D), i.e. ±a of the spacing per coordinate.
/// Volumes V_i = Δx^d and boundary face vectors s_i are those of the unperturbed grid
/// cell the point belongs to (the point stays a quadrature point of its cell, so
/// Σ V_i = |Ω| and Σ s_i = 0 are kept); families, stencils and BA weights are rebuilt
/// from the jittered positions by `Discretization::from_points`. Deterministic for a
/// given seed (std::mt19937_64).
#pragma once

#include <cstdint>

#include "pdcg/solver/discretization.hpp"

namespace pdcg::solver {

/// The grid of `spec` with every coordinate jittered by up to ±amplitude·spacing
/// (amplitude in [0, 0.5)). Throws InputError for an amplitude outside that range.
Discretization perturbed_grid(const GridSpec& spec, double amplitude, std::uint64_t seed,
                              const DiscretizationOptions& opt = {});

}  // namespace pdcg::solver
