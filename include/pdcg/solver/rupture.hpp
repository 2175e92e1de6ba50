/// \file
/// Rupture for the BA correspondence solver (docs/theory.md §9; docs/effects.md).
///
/// A bond (i, j) breaks when the chosen criterion exceeds `critical`:
///  - bond_stretch:       s_ij = |y_j − y_i| / |x_j − x_i|;
///  - principal_stretch:  λ_max(F_ij) = √(largest eigenvalue of C_ij = F_ijᵀF_ij), of the full
///                        3×3 F of the material (plane stress: with the thickness stretch),
///                        the larger of the two directions (i, j) and (j, i);
///  - energy_density:     Ψ(F_ij), the larger of the two directions.
/// Broken bonds leave every family that holds them and the affected PDDO stencils are
/// rebuilt locally (Discretization::rebuild_broken). Quasi-static runs are staggered: after
/// a converged load step, bonds past the criterion break, equilibrium is re-solved at the
/// same load, and this repeats until no bond breaks (one log line per pass).
///
/// Structure ("only what a scene asks for"): the model kernels are the same with and
/// without rupture — a broken bond is a stencil of weight 0 and a departed member a G of
/// 0, i.e. data, not a branch. The broken flags exist only after Rupture is constructed.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "pdcg/solver/discretization.hpp"
#include "pdcg/solver/model.hpp"
#include "pdcg/solver/newton.hpp"

namespace pdcg::solver {

enum class RuptureCriterion { bond_stretch, principal_stretch, energy_density };
RuptureCriterion parse_rupture_criterion(const std::string& name);  // throws InputError
std::string to_string(RuptureCriterion c);

struct RuptureOptions {
  RuptureCriterion criterion = RuptureCriterion::bond_stretch;
  double critical = 2.5;
  int max_passes = 200;  ///< staggered passes per load step before giving up
  /// Adaptive dynamic relaxation fallback (when Newton fails at fixed load): relative
  /// residual at which it hands back to Newton, and its iteration limit.
  double relaxation_tolerance = 1e-4;
  /// A rebuilt (one-sided, thinned) stencil must have a scaled moment matrix with at least
  /// this reciprocal condition, or it is switched off: nearly singular stencils have huge G
  /// and turn tiny displacements into J ≤ 0 (measured on the pre-cracked sheet).
  double min_reciprocal_condition = 1e-3;
  int relaxation_iterations = 50000;
  /// Quasi-static runs park points that no stencil couples any more with a spring (else
  /// K has zero rows); explicit dynamics does not: a detached point carries no force and
  /// moves on with its velocity (a fragment), so no anchors (false).
  bool anchor_detached = true;
  /// Explicit dynamics: evaluate the criterion every check_every time steps (1 = each).
  int check_every = 1;
};

struct RupturePass {
  std::size_t broken = 0;    ///< bonds broken in this pass
  double max_value = 0.0;    ///< largest criterion value over the intact bonds
  std::size_t rebuilt = 0;   ///< stencils rebuilt
  std::size_t anchored = 0;  ///< points no stencil couples any more
  std::size_t inverted = 0;  ///< of `broken`: bonds whose rebuilt stencil was inverted (J ≤ 0)
  /// weak-form point stencils switched off because F̄_k was inverted (J ≤ 0)
  std::size_t point_stencils_off = 0;
};

class Rupture {
 public:
  /// Enables rupture on the body (allocates the broken flags). The model must be
  /// built on this body.
  Rupture(Discretization& body, Model& model, RuptureOptions options);

  /// Criterion value of every intact bond (CSR order; both directions hold the
  /// same value; broken bonds −∞).
  std::vector<double> criterion_values(const Eigen::VectorXd& u) const;
  /// Breaks every intact bond whose criterion exceeds the critical value, rebuilds
  /// the stencils, and parks points that nothing couples any more (Model::set_anchors,
  /// when options().anchor_detached). The criterion goes into a scratch array allocated
  /// at the first call (one double per directed bond): a check that breaks nothing
  /// allocates nothing (the per-step check of explicit dynamics).
  RupturePass break_exceeding(const Eigen::VectorXd& u);
  /// Centres of the stencils the last break_exceeding rebuilt (sorted; empty if it broke
  /// nothing).
  const std::vector<int>& rebuilt_centres() const { return all_rebuilt_; }
  /// Breaks every intact bond whose BA stencil is inadmissible (J ≤ 0) at u, rebuilds, and
  /// repeats until every intact stencil is admissible (the material cannot be evaluated
  /// there: the bond counts as past every criterion). For solvers that meet J ≤ 0 during
  /// a step or an iteration (explicit dynamics, ADR). Returns the pass (broken = inverted).
  RupturePass break_inadmissible(const Eigen::VectorXd& u);
  /// Staggered re-equilibration at the current load: break, re-solve, repeat until no
  /// bond breaks. Returns the number of bonds broken. Throws NumericalError if the
  /// re-solve fails (unstable crack growth) or max_passes is exceeded.
  std::size_t stagger(StaticSolver& solver);
  /// After Discretization::break_bond calls: rebuilds the touched stencils and parks
  /// the points nothing couples any more at their displacement u. Returns stencils rebuilt.
  std::size_t commit(const Eigen::VectorXd& u);

  const RuptureOptions& options() const { return opt_; }
  /// Broken bonds as pairs (i < j), flattened [i0, j0, i1, j1, …] (checkpoints).
  std::vector<std::int64_t> broken_pairs() const;
  /// Checkpoint restart: breaks the given pairs on the intact body, rebuilds every touched
  /// stencil (a pure function of the broken set) and sets the anchors as they were saved.
  void restore(const std::vector<std::int64_t>& pairs, std::vector<int> anchor_points,
               std::vector<double> anchor_targets,
               const std::vector<std::int64_t>& point_stencils_off = {});
  std::vector<double> damage() const { return body_->damage(); }

 private:
  void update_anchors(const Eigen::VectorXd& u);
  /// Breaks every intact bond whose (rebuilt) BA stencil gives an inadmissible F (J ≤ 0)
  /// at u; returns how many. Weak-form point stencils (points with a boundary defect
  /// e_k ≠ 0) whose F̄_k is inadmissible are switched off (counted in *points_off).
  /// centres non-null: only the stencils centred there (after a rebuild, the only ones
  /// that can have become inadmissible at a u where all others were admissible).
  std::size_t break_inverted(const Eigen::VectorXd& u, std::size_t* points_off = nullptr,
                             const std::vector<int>* centres = nullptr);
  /// Directed criterion values into dir_ (−∞ for broken bonds); returns their maximum.
  double evaluate_directed(const Eigen::VectorXd& u) const;
  Discretization* body_;
  mutable std::vector<double> dir_;  // scratch: criterion per directed bond
  std::vector<int> all_rebuilt_;
  Model* model_;
  RuptureOptions opt_;
  double anchor_stiffness_ = 0.0;
};

}  // namespace pdcg::solver
