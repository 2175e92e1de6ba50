/// \file
/// Molecular statics of a delta body: relax the atom positions at a fixed box to a force
/// tolerance (docs/fracture.md §2).
///
/// The energy is U(y) = Σ_k ψ_k(Y) of the body's potential (the Evaluator), the force −∂U/∂y.
/// Two minimisers:
///  - cg:   nonlinear conjugate gradients (Polak–Ribière+, restarted on loss of descent) with a
///          line search on the directional derivative (secant steps inside a bracket), so it
///          converges below the round-off floor of the energy (as LAMMPS's `min_style cg`
///          with its force-based `quadratic` line search);
///  - fire: FIRE (Bitzek, Koskinen, Gähler, Moseler & Gumbsch, PRL 97 (2006) 170201), unit
///          masses, semi-implicit Euler, the published parameters.
///
/// Families. The relaxation works on its own copy of the body whose families have the radius
/// r_f = r_c + skin (r_c: the potential's cutoff, or the body's horizon if larger). They are
/// exact for every configuration in which no atom moved more than skin/2 from the positions
/// the families were built at (two atoms then approach by at most skin). Before every
/// evaluation the largest displacement since the last build is checked; beyond skin/2 the
/// families are rebuilt at the current positions (counted in StaticsResult::rebuilds). Stale
/// families are never used.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pdcg/body/body.hpp"

namespace pdcg::body {

enum class MinStyle { cg, fire };
/// "cg" | "fire"; InputError otherwise.
MinStyle parse_min_style(std::string_view name, std::string_view where = {});

struct StaticsOptions {
  MinStyle style = MinStyle::cg;
  /// Stop when the 2-norm of the global 3N force vector is at most this (LAMMPS's ftol), in
  /// the body's force units (energy/length).
  double force_tolerance = 1e-10;
  std::int64_t max_iterations = 100000;
  /// Largest displacement of any atom in one line-search step or FIRE step (LAMMPS dmax),
  /// length units. 0: 0.1 × the shortest bond of the body.
  double max_step = 0.0;
  /// Family margin (skin), length units. < 0: 0.1 × r_c.
  double skin = -1.0;
};

struct StaticsResult {
  double energy = 0.0;      ///< U at the returned positions
  double energy0 = 0.0;     ///< U at the start
  double force_norm = 0.0;  ///< 2-norm of the 3N forces at the returned positions
  double force_max = 0.0;   ///< largest |f_k| (per atom)
  std::int64_t iterations = 0;
  std::int64_t evaluations = 0;
  int rebuilds = 0;  ///< family rebuilds (atoms moved beyond skin/2)
  double family_radius = 0.0;
  bool converged = false;
  std::string stop;  ///< why it stopped
};

/// Relaxes y (3N positions, same order and conventions as body.x, box fixed at body.box) in
/// place. Throws InputError for a body that is not a delta body, has molecular bonds or
/// special_bonds factors (families cannot be rebuilt from positions alone), or for bad options;
/// NumericalError for non-finite energies. Not converging within max_iterations is reported in
/// the result (converged = false), not thrown.
StaticsResult relax(const Body& body, std::vector<double>& y, const StaticsOptions& options = {});

}  // namespace pdcg::body
