/// \file
/// Closed-form dispersion relations of the 1D references (docs/theory.md §3–5).
///
/// Spring chain with lattice spacing h, mass M per site and springs μ_n to the n-th neighbour
/// (Brillouin 1946, Wave Propagation in Periodic Structures, ch. 1; Dove 1993, §3):
///   ω²(κ) = (2/M) Σ_n μ_n (1 − cos nκh).
/// Constant-micromodulus 1D PD bar, ρ ω² = ∫_{−δ}^{δ} C (1 − cos κξ) dξ = 2C(δ − sin(κδ)/κ)
/// (Silling 2000, J. Mech. Phys. Solids 48:175, eq. for the linearised bond-based model).
/// Rescaling by ε (docs/theory.md §4): ω_ε(κ) = ω(εκ)/ε.
#pragma once

#include <span>

namespace pdcg::dispersion {

/// ω(κ) of a chain with neighbour springs μ_1, μ_2, … (spring_constants[n-1] = μ_n).
double chain_omega(double kappa, double mass, double spacing, std::span<const double> spring_constants);

/// ω(κ) of a 1D PD bar with constant micromodulus C on |ξ| < δ and density ρ.
double constant_micromodulus_omega(double kappa, double density, double micromodulus, double horizon);

/// ω_ε(κ) = ω(εκ)/ε for any ω(κ).
template <class Omega>
double rescaled_omega(const Omega& omega, double kappa, double epsilon) {
  return omega(epsilon * kappa) / epsilon;
}

/// Long-wave (local continuum) limit of the chain: ω = κ h √(Σ μ_n n² / M).
double chain_long_wave_speed(double mass, double spacing, std::span<const double> spring_constants);

}  // namespace pdcg::dispersion
