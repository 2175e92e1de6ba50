/// \file
/// Rupture for the BA correspondence solver (docs/theory.md §9; docs/effects.md).
///
/// A bond (i, j) breaks when the chosen criterion exceeds `critical`:
///  - bond_stretch:       s_ij = |y_j − y_i| / |x_j − x_i|;
///  - principal_stretch:  λ_max(F_ij) = √(largest eigenvalue of C_ij = F_ijᵀF_ij), of the full
///                        3×3 F of the material (plane stress: with the thickness stretch),
///                        the larger of the two directions (i, j) and (j, i);
///  - energy_density:     Ψ(F_ij), the larger of the two directions;
///  - fracture_energy:    the work done on the pair, W_ij = ∫ V_iφ̂_ijV_j P(F_ij):dF_ij +
///                        (j, i), accumulated per bond over the run, against its critical
///                        value W_c,ij = ψ_c (V_iφ̂⁰_ijV_j + V_jφ̂⁰_jiV_i) (φ̂⁰ of the intact
///                        body), ψ_c = G_c / (β_d δ) so that a straight crack through a
///                        homogeneous body dissipates G_c per unit area (docs/fracture.md §5,
///                        theory.md §12). The criterion value is W_ij / W_c,ij (critical 1).
///   With softening (fracture_energy only, docs/fracture.md §6): each pair carries an
///   irreversible damage d ∈ [0, 1] that scales the weight of both its stencils by (1 − d);
///   d follows the history κ = max over time of the pair's energy density
///   Y = (w_ijΨ(F_ij) + w_jiΨ(F_ji)) / (w_ij + w_ji) (w the undamaged weights) through a
///   linear-softening law in the equivalent strain e = √κ, from 0 at e₀ = √(ρψ_c) to 1 at
///   e_f = √(ψ_c/ρ) (ρ = options.elastic_limit), so that a pair dissipates
///   ψ_c (w_ij + w_ji) from intact to separated, the same G_c per unit crack area as the
///   brittle rule; at d = 1 the pair breaks. The member j of the lenses of i's stencils
///   (and i of j's) counts with the share 1 − d (Discretization::set_bond_stiffness_factor),
///   so a softening pair leaves the lenses continuously. Staggered: d is frozen in each
///   solve (secant stiffness) and updated between solves until it stops growing. The
///   criterion value is √κ / e_f.
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

enum class RuptureCriterion { bond_stretch, principal_stretch, energy_density, fracture_energy };
RuptureCriterion parse_rupture_criterion(const std::string& name);  // throws InputError
std::string to_string(RuptureCriterion c);
/// Failure law of the fracture_energy criterion: elastic-brittle (none: the pair breaks when
/// its work reaches W_c) or a damage that softens the pair linearly in the equivalent strain
/// (linear; docs/fracture.md §6).
enum class RuptureSoftening { none, linear };
RuptureSoftening parse_rupture_softening(const std::string& name);  // throws InputError
std::string to_string(RuptureSoftening s);

/// Damage of the linear softening law at the history κ (an energy density) for the
/// critical energy density ψ_c and the elastic limit ρ = e₀/e_f ∈ (0, 1]: with e = √κ,
/// e₀ = √(ρψ_c), e_f = √(ψ_c/ρ): d = 0 for e ≤ e₀, 1 for e ≥ e_f, and otherwise
/// d = 1 − (e₀/e)(e_f − e)/(e_f − e₀) (the 1-D stress (1 − d)E ε falls linearly from E ε₀ to
/// 0; ∫₀^∞ (1 − d) dκ = e₀e_f = ψ_c: the energy a pair dissipates per unit weight).
double linear_softening_damage(double kappa, double psi_c, double elastic_limit);

/// β_d = ⟨|ξ·n|⟩_φ̂ / δ: the mean projected bond length, over δ, of an interior BA family
/// weighted by the continuum φ̂ (docs/fracture.md §5, closed forms):
///   2D: 8 (128 + 20π − 81√3) / (45π (4π − 3√3)) = 0.388013,   3D: 61/175 = 0.348571.
/// G_c = ψ_c β_d δ relates the critical energy density ψ_c of the fracture_energy rule to
/// the energy release rate. Throws pdcg::Error for d ∉ {2, 3}.
double fracture_energy_shape_factor(int dimension);

struct RuptureOptions {
  RuptureCriterion criterion = RuptureCriterion::bond_stretch;
  double critical = 2.5;  ///< fracture_energy: ignored (the value is W/W_c, breaks past 1)
  int max_passes = 200;   ///< staggered passes per load step before giving up
  /// Adaptive dynamic relaxation fallback (when Newton fails at fixed load): relative
  /// residual at which it hands back to Newton, and its iteration limit.
  double relaxation_tolerance = 1e-4;
  /// A rebuilt (one-sided, thinned) stencil must have a scaled moment matrix with at least
  /// this reciprocal condition, or it is switched off: nearly singular stencils have huge G
  /// and turn tiny displacements into J ≤ 0 (measured on the pre-cracked sheet).
  double min_reciprocal_condition = 1e-3;
  int relaxation_iterations = 50000;
  /// ADR guard (docs/effects.md §2, "No breaking far from equilibrium"): a stencil that an
  /// ADR iterate inverts (J ≤ 0) breaks only if the relative residual of the iterate before
  /// it is at most this; above it the step is rejected (StaticSolver::relax: back, restart
  /// from rest, masses 4× heavier if that inverts again). +∞: every inversion breaks (the
  /// scheme before).
  double relaxation_break_residual = 1e-2;
  /// Quasi-static runs park points that no stencil couples any more with a spring (else
  /// K has zero rows); explicit dynamics does not: a detached point carries no force and
  /// moves on with its velocity (a fragment), so no anchors (false).
  bool anchor_detached = true;
  /// Quasi-static runs (with anchor_detached): also park every point of a free fragment —
  /// a set of points that the intact stencils couple to each other but to no point with a
  /// prescribed displacement (Rupture::set_held_dofs) — each at its displacement when it
  /// was cut loose. Such a fragment carries no load and its rigid motions make K singular
  /// (docs/effects.md §2, "Free fragments"). false (default, the scheme before): only
  /// single uncoupled points. Off by default: on the 50 × 50 sheet the ADR of the burst pass
  /// did not converge with a parked fragment (docs/effects.md §2; cause not established).
  bool anchor_fragments = false;
  /// Quasi-static runs (with anchor_detached): a piece held in some directions only (no
  /// point of it prescribed along a) has a free translation along a; its lowest-numbered
  /// point is pinned along those directions by the anchor spring, which carries no force at
  /// equilibrium (no external force acts on the piece along a). Rotations left free by the
  /// grips are not detected (docs/effects.md §2, "Free fragments").
  bool pin_partly_held = true;
  /// Explicit dynamics: evaluate the criterion every check_every time steps (1 = each).
  int check_every = 1;
  /// fracture_energy: the critical energy release rate G_c (energy per unit crack area;
  /// energy per unit length in 2D), > 0.
  double fracture_energy = 0.0;
  /// fracture_energy: the failure law (none: elastic-brittle).
  RuptureSoftening softening = RuptureSoftening::none;
  /// softening: ρ = e₀/e_f, the equivalent strain at which softening starts over the one at
  /// full separation, in (0, 1] (ρ = 1: the pair drops from e₀ = √ψ_c to 0 at once).
  double elastic_limit = 0.1;
  /// softening: the staggered passes stop when no pair's damage grew by more than this in
  /// the last pass (and no pair broke).
  double damage_tolerance = 1e-3;
  /// softening: the largest damage increment of a pair in one pass (the rest follows in the
  /// next passes), in (0, 1]; smaller values follow the continuous softening path more
  /// closely (docs/fracture.md §6.2).
  double max_damage_increment = 1.0;
  /// Quasi-static re-equilibrium when Newton fails at fixed load (docs/effects.md §2):
  /// pseudo-transient continuation (StaticSolver::pseudo_transient) first, with at most
  /// continuation_iterations factorisations, then adaptive dynamic relaxation; false: ADR
  /// only (the scheme before pseudo-transient continuation, kept for comparisons).
  bool pseudo_transient = true;
  int continuation_iterations = 100;
  /// Staggered passes with linear: umfpack: > 0 reuses the last factorisation as the GMRES
  /// preconditioner of the Newton systems, at most this many products before a new
  /// factorisation (StaticSolver::set_factor_reuse); 0: a factorisation per iteration.
  int factor_reuse = 0;
  /// the products per reuse that the scene key rupture.factorisations: reuse sets
  int reuse_products = 30;
};

struct RupturePass {
  std::size_t broken = 0;     ///< bonds broken in this pass
  double max_value = 0.0;     ///< largest criterion value over the intact bonds
  std::size_t rebuilt = 0;    ///< stencils rebuilt
  std::size_t anchored = 0;   ///< points no stencil couples any more, and free fragments
  std::size_t fragments = 0;  ///< free fragments parked (anchor_fragments), all passes so far
  std::size_t inverted = 0;   ///< of `broken`: bonds whose rebuilt stencil was inverted (J ≤ 0)
  /// weak-form point stencils switched off because F̄_k was inverted (J ≤ 0)
  std::size_t point_stencils_off = 0;
  /// softening: pairs whose damage grew by more than options.damage_tolerance, and the
  /// largest damage increment of the pass
  std::size_t damaged = 0;
  double max_damage_increment = 0.0;
};

/// Work of the staggered re-equilibration at one load (Rupture::stagger), for the log and
/// the benchmarks: Newton iterations (converged and failed solves), factorisations of the
/// pseudo-transient continuation, ADR iterations, passes that needed a fallback, wall time.
struct StaggerCost {
  int passes = 0;
  int newton_iterations = 0;
  int failed_newton_iterations = 0;  ///< of newton_iterations: in solves that failed
  int continuation_iterations = 0;
  int relaxation_iterations = 0;
  int continuation_passes = 0;  ///< passes that Newton failed and the continuation resolved
  int relaxation_passes = 0;    ///< passes that needed ADR
  double seconds = 0.0;
  /// of seconds: Newton and continuation assembly (residual + tangent) and linear solves
  /// (reduction, factorisation, substitution), as the solvers' step reports count them
  double assembly_seconds = 0.0;
  double solve_seconds = 0.0;
  int factorisations = 0;     ///< Newton's (umfpack), not the continuation's
  int krylov_iterations = 0;  ///< factor reuse: GMRES iterations
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
  /// Work of the last stagger call, and summed over all calls.
  const StaggerCost& last_stagger_cost() const { return last_cost_; }
  const StaggerCost& total_stagger_cost() const { return total_cost_; }
  /// After Discretization::break_bond calls: rebuilds the touched stencils and parks
  /// the points nothing couples any more at their displacement u. Returns stencils rebuilt.
  std::size_t commit(const Eigen::VectorXd& u);
  /// Degrees of freedom held by a prescribed displacement (length d·N, 1 = prescribed),
  /// for anchor_fragments; stagger sets it from the solver's displacement sets. Empty (the
  /// default): every coupled point counts as held (no fragment is parked).
  void set_held_dofs(std::vector<char> held) { held_ = std::move(held); }
  /// Points parked because their fragment is free (of Model::anchors()).
  std::size_t fragment_points() const { return fragment_points_; }
  std::size_t free_fragments() const { return free_fragments_; }
  /// pieces held in some directions only, pinned by one point (RuptureOptions::pin_partly_held)
  std::size_t pinned_pieces() const { return pinned_pieces_; }

  const RuptureOptions& options() const { return opt_; }
  /// Broken bonds as pairs (i < j), flattened [i0, j0, i1, j1, …] (checkpoints).
  std::vector<std::int64_t> broken_pairs() const;
  /// Checkpoint restart: breaks the given pairs on the intact body, rebuilds every touched
  /// stencil (a pure function of the broken set) and sets the anchors as they were saved.
  void restore(const std::vector<std::int64_t>& pairs, std::vector<int> anchor_points,
               std::vector<double> anchor_targets,
               const std::vector<std::int64_t>& point_stencils_off = {});
  std::vector<double> damage() const { return body_->damage(); }
  /// Largest ‖f_int‖ of a converged state seen by stagger: 1e-4 of it is the floor of the
  /// residual scale once the body has separated (docs/effects.md §2, "Residual scale after
  /// separation"). In the checkpoint: a restart re-deriving it from the restored state got a
  /// lower floor after the peak load and failed a pass the uninterrupted run converged.
  double peak_force() const { return peak_force_; }
  void restore_peak_force(double peak) { peak_force_ = peak; }

  // ---- fracture_energy (empty / zero for the other criteria) -------------------
  /// ψ_c = G_c / (β_d δ): the energy density at which a homogeneously loaded bond breaks.
  double critical_energy_density() const { return psi_c_; }
  /// Critical work W_c of every directed bond's pair (CSR order, both directions equal;
  /// energy units: ψ_c (V_iφ̂⁰_ijV_j + V_jφ̂⁰_jiV_i)).
  const std::vector<double>& critical_work() const { return work_c_; }
  /// Work done on each directed bond's stencil so far, Σ V_iφ̂_ijV_j ΔΨ(F_ij) (energy).
  const std::vector<double>& bond_work() const { return work_; }
  /// Energy dissipated so far: Σ over broken pairs of the work stored in them when they
  /// broke (W_ij, both directions).
  double dissipated_energy() const { return dissipated_; }
  /// Checkpoint state of the work integrals: work, the last Ψ per directed bond, dissipated.
  /// With softening the two arrays hold the damage state instead: bond_work() the history
  /// κ of each directed bond's pair, bond_work_last_psi() its damage d (restore_work sets
  /// the stiffness factors 1 − d again).
  const std::vector<double>& bond_work_last_psi() const { return psi_last_; }
  /// softening: damage d of each directed bond's pair (CSR order; empty otherwise).
  const std::vector<double>& bond_damage() const { return psi_last_; }
  void restore_work(std::vector<double> work, std::vector<double> last_psi, double dissipated);

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
  /// Marks (i, j) broken; with fracture_energy adds the pair's stored work to dissipated_.
  bool break_pair(int i, std::int64_t q);
  /// softening: updates every pair's history and damage from u, breaks the pairs that
  /// reach d = 1 (and inverted ones), rebuilds.
  RupturePass soften(const Eigen::VectorXd& u);
  /// After bonds broke in a pass: rebuilds, breaks the bonds whose rebuilt stencils invert
  /// at u (repeatedly), records the rebuilt centres and the anchors.
  void finish_breaks(const Eigen::VectorXd& u, RupturePass& pass, bool softened = false);
  /// Rounds of break_inverted and commit until no stencil inverts at u (at most 100): each
  /// round checks the centres the last rebuild touched (the first round every stencil if
  /// check_all_first). Adds to pass (broken = inverted, rebuilt, point stencils off) and
  /// appends the rebuilt centres to centres (unsorted, possibly repeated).
  void break_inverted_rounds(const Eigen::VectorXd& u, bool check_all_first, RupturePass& pass,
                             std::vector<int>& centres);
  /// softening: Σ over the BA stencils of w_s (Ψ(F_s) − Ψ(I)) at u (NaN if one is inverted).
  double stored_energy(const Eigen::VectorXd& u) const;
  bool softening() const { return opt_.softening != RuptureSoftening::none; }
  Discretization* body_;
  mutable std::vector<double> dir_;  // scratch: criterion per directed bond
  std::vector<int> all_rebuilt_;
  Model* model_;
  RuptureOptions opt_;
  double anchor_stiffness_ = 0.0;
  std::vector<char> held_;            // dof held by a prescribed displacement
  std::vector<int> fragment_parent_;  // scratch: union-find over points
  std::size_t fragment_points_ = 0, free_fragments_ = 0, pinned_pieces_ = 0;
  // fracture_energy: per directed bond (CSR order), allocated by the constructor only for it
  double psi_c_ = 0.0;
  std::vector<std::int64_t> reverse_;  // CSR position of (j, i)
  std::vector<double> work_c_;         // critical pair work
  mutable std::vector<double> work_;   // accumulated work (energy)
  mutable std::vector<double> psi_last_;
  double dissipated_ = 0.0;
  // softening: work_ holds the history κ, psi_last_ the damage d (both per directed bond,
  // equal in the two directions of a pair); scratch per directed bond: the undamaged
  // energy w_ijΨ(F_ij) at the last evaluation (the dissipation of a pair that breaks before
  // d = 1), the pair's energy density Y; per point Ψ(I) (a Cauchy–Born W need not vanish).
  mutable std::vector<double> energy_last_, y_pair_;
  std::vector<double> psi_ref_;
  std::vector<char> to_break_;
  StaggerCost last_cost_, total_cost_;
  double peak_force_ = 0.0;  // largest ‖f_int‖ of a converged state seen by stagger
};

}  // namespace pdcg::solver
