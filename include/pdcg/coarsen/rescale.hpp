/// \file
/// Rescaling the horizon (docs/theory.md §4): ε = δ'/δ,
///   W_ε(Y) = W(E(Y)),  (E(Y))⟨ξ⟩ = ε⁻¹ Y⟨εξ⟩,
/// so a homogeneous deformation keeps its energy density, W_ε(F) = W(F). Bonds become εξ,
/// the density is unchanged (point masses ×ε^d as each point now stands for ε^d times the
/// volume), and the force state scales as T_ε⟨ξ'⟩ = ε^−(d+1) T⟨ξ'/ε⟩. A rescaled lattice body
/// sits on a lattice of spacing εh: ε^d fewer points per volume.
#pragma once

#include "pdcg/body/body.hpp"

namespace pdcg::coarsen {

/// Rescales every layer of the body by ε (positions, box, bonds, masses ×ε^d, statistical
/// widths, homogenisation points and volumes). ε ≤ 0 (or not finite) → InputError.
body::Body rescale(const body::Body& body, double epsilon);

/// ε for a target horizon δ': δ'/δ with δ the body's current horizon (the potential cutoff).
double epsilon_for_horizon(const body::Body& body, double horizon);

}  // namespace pdcg::coarsen
