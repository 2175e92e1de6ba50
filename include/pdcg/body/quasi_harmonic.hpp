/// \file
/// Quasi-harmonic free energy of a periodic delta body (docs/temperature.md §3): the classical
/// harmonic free energy of the body's vibrations about its deformed lattice,
///   W_T(F) = [ U(F) + k_B T Σ_i ln(ω_i(F) / (k_B T)) ] / V₀,
/// ω_i² the eigenvalues of the mass-weighted Hessian M^(−½) ∂²U/∂y∂y M^(−½) at y = F x (the
/// force-state tangents K_bc of every family, theory.md (1.7)), the three translations left out.
/// ħ is set to 1 in the body's units: W_T is defined up to the constant (3N − 3) k_B T ln ħ / V₀,
/// which no derivative with respect to F sees (stress and elastic constants are exact).
/// The Hessian is dense (3N)²: bodies of up to 3000 atoms (a supercell of the crystal).
///
/// Coarse models (docs/theory.md §2, (2.8)): the free energy is that of the atoms the model stands
/// for, so that W_T is invariant under homogenisation and rescaling as W is ((4.2)). A
/// homogenised body's atomic layer is the crystal cell (every atom of weight Σ_p w_kp = 1,
/// refused otherwise); a body rescaled by ε has point frequencies ω/ε, point masses ε^d M and
/// volume ε^d V₀, and its vibrations are taken back to the atoms' (ω = ε ω', V₀ = V₀'/ε^d). The
/// literal classical free energy of the rescaled points would carry ε^(−d) times the atoms'
/// thermal part (ε^d fewer degrees of freedom per volume, the same Grüneisen parameters).
///
/// As a material (QuasiHarmonicCauchyBorn): W_T(F), P_T = ∂W_T/∂F and A_T = ∂P_T/∂F. The static
/// part W(F) = U/V₀ and its derivatives are the analytic Cauchy–Born ones (cauchy_born.hpp,
/// clamped ion); the vibrational part (k_B T/V₀) S(F), S = Σ_i ln ω_i, is differentiated by
/// central differences. S depends on F through C = FᵀF only (the eigenvalues of a rotated
/// lattice are those of the lattice), so the differences are taken in the Green–Lagrange strain
/// E = ½(C − I), at F(E) = (I + 2E)^½: ∂S/∂E from 12 evaluations, ∂²S/∂E∂E from 60 more
/// (73 dense eigenvalue problems for W, P and A; 13 without A), then
///   P_th = (k_B T/V₀) F ∂S/∂E,  A_th,iJkL = (k_B T/V₀) [δ_ik ∂S/∂E_JL + F_iM F_kN ∂²S/∂E_MJ∂E_NL].
#pragma once

#include <Eigen/Core>
#include <memory>

#include "pdcg/body/body.hpp"
#include "pdcg/body/cauchy_born.hpp"

namespace pdcg::body {

struct QuasiHarmonic {
  double free_energy_density = 0.0;  ///< W_T(F)
  double energy_density = 0.0;       ///< W(F) = U/V₀ (static lattice)
  double sum_ln_omega = 0.0;         ///< Σ_i ln ω_i over the 3N − 3 vibrations
  double smallest_omega2 = 0.0;      ///< smallest vibrational eigenvalue ω² (stability)
};

/// Throws InputError for a body that is not periodic along x, y and z in 3D, a statistical
/// body, a homogenised body whose atoms do not each count once, more than 3000 atoms, T < 0 or
/// not finite; NumericalError when the lattice at F is unstable (a vibrational ω² ≤ 0: the
/// free energy does not exist there). Values are the atoms' (header comment).
QuasiHarmonic quasi_harmonic(const Body& body, const Eigen::Matrix3d& F, double temperature);

/// Range of the central-difference strain step h of the vibrational part. Below 1e-6 the
/// round-off of the second difference, ≈ 1e-16 |S|/h², exceeds 1e-4 relative; above 1e-2 the
/// truncation O(h²) of a smooth S reaches 1e-4 and the step leaves the small-strain range.
inline constexpr double kQuasiHarmonicStepMin = 1e-6, kQuasiHarmonicStepMax = 1e-2;
inline constexpr double kQuasiHarmonicStepDefault = 1e-4;

/// The smallest strain step h whose differences span the knots of a tabulated potential:
/// h = 2 dr / r_nn, dr the r spacing of a native EAM potential's tables, r_nn the
/// nearest-neighbour distance. A step h changes a nearest-neighbour bond by up to h·r_nn (a
/// shear along the bond) and by h·r_nn/2 at 45° to a stretched axis (fcc under E_xx), so at
/// this h every difference moves the nearest shell by at least one table interval. With a
/// shorter step the tangent is the curvature of one C¹ spline piece (docs/temperature.md §3.1:
/// Cu_u3.eam at 600 K, thermal C11 −12 GPa with h ≤ 1e-3, −3 GPa with 1e-2). An EAM style
/// evaluated through LAMMPS (tables not visible): 5e-3. 0 for analytic potentials (no knots)
/// and for bodies without a nearest-neighbour distance.
double quasi_harmonic_knot_step(const Body& body);

/// The quasi-harmonic Cauchy–Born material at temperature T (header comment): W_T, P_T and
/// (if asked) A_T at F. `strain_step` is the central-difference step h in E of the
/// vibrational part (default 1e-4: truncation O(h²) ≈ 1e-8 relative, round-off ≈ 1e-16 |S|/h²
/// ≈ 1e-8 relative of ∂²S for cells of a few hundred atoms; docs/temperature.md §3.1; a
/// tabulated EAM needs h ≥ quasi_harmonic_knot_step(), ≈ 1e-2 for Cu: a warning says so).
/// Throws InputError for what quasi_harmonic() refuses, for a crystal whose basis would relax
/// under F (the free energy is minimised over the atoms held at Fx only: Bravais lattices and
/// crystals whose every atom is a centre of inversion), and for h outside
/// [kQuasiHarmonicStepMin, kQuasiHarmonicStepMax].
class QuasiHarmonicCauchyBorn {
 public:
  QuasiHarmonicCauchyBorn(const Body& body, double temperature,
                          double strain_step = kQuasiHarmonicStepDefault);
  CauchyBornState evaluate(const Eigen::Matrix3d& F, bool tangent = true) const;
  /// S(F) = Σ_i ln ω_i(F) (NumericalError where the lattice is unstable).
  double sum_ln_omega(const Eigen::Matrix3d& F) const;
  double temperature() const { return temperature_; }
  double strain_step() const { return step_; }
  const CauchyBorn& cauchy_born() const { return cb_; }

 private:
  const Body& body_;
  CauchyBorn cb_;
  double temperature_, kT_, step_;
  double knot_step_ = 0.0;  ///< quasi_harmonic_knot_step(body)
};

}  // namespace pdcg::body
