/// \file
/// Quasi-harmonic free energy of a periodic delta body (docs/temperature.md §3): the classical
/// harmonic free energy of the body's vibrations about its deformed lattice,
///   W_T(F) = [ U(F) + k_B T Σ_i ln(ω_i(F) / (k_B T)) ] / V₀,
/// ω_i² the eigenvalues of the mass-weighted Hessian M^(−½) ∂²U/∂y∂y M^(−½) at y = F x (the
/// force-state tangents K_bc of every family, theory.md (1.7)), the three translations left out.
/// ħ is set to 1 in the body's units: W_T is defined up to the constant (3N − 3) k_B T ln ħ / V₀,
/// which no derivative with respect to F sees (stress and elastic constants are exact).
/// The Hessian is dense (3N)²: bodies of up to 3000 atoms (a supercell of the crystal).
#pragma once

#include <Eigen/Core>

#include "pdcg/body/body.hpp"

namespace pdcg::body {

struct QuasiHarmonic {
  double free_energy_density = 0.0;  ///< W_T(F)
  double energy_density = 0.0;       ///< W(F) = U/V₀ (static lattice)
  double sum_ln_omega = 0.0;         ///< Σ_i ln ω_i over the 3N − 3 vibrations
  double smallest_omega2 = 0.0;      ///< smallest vibrational eigenvalue ω² (stability)
};

/// Throws InputError for a body that is not a delta body periodic along x, y and z in 3D, for
/// more than 3000 atoms, for T < 0 or not finite; NumericalError when the lattice at F is
/// unstable (a vibrational ω² ≤ 0: the free energy does not exist there).
QuasiHarmonic quasi_harmonic(const Body& body, const Eigen::Matrix3d& F, double temperature);

}  // namespace pdcg::body
