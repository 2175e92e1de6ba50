/// \file
/// Static equilibrium of a Model under prescribed displacements and tractions:
/// Newton–Raphson with load stepping, a backtracking line search, automatic
/// step cutback, and convergence on both the residual and the increment.
///
/// Unknowns: u (d·N). Prescribed components u_c = ū(t) are eliminated; the free
/// components solve R_f(u) = f_int,f(u) − f_ext,f(t) = 0 with, per iteration,
///   K_ff Δu_f = −R_f(u) − K_fc (ū(t) − u_c),   u ← u + α Δu,
/// (the second term is the consistent predictor of a new load step). α halves
/// until ‖R‖ decreases (Armijo, 1e-4). Converged when
///   ‖R_f‖₂ ≤ tol · max(‖f_int‖₂, ‖f_ext‖₂)  and  ‖Δu_f‖₂ ≤ tol · max(‖u‖₂, Δx).
/// A step that does not converge in max_iterations (or meets an inadmissible
/// F, J ≤ 0) is restored and retried with half the load increment; the log
/// says so. Linear solves: CHOLMOD (symmetric tangent, energy boundary form),
/// UMFPACK (default for the unsymmetric weak form), Eigen SparseLU, or
/// BiCGSTAB with an incomplete-LU preconditioner, or restarted GMRES preconditioned by a
/// CHOLMOD factor of a lattice (Q1 finite-element) stiffness on the same points, for
/// systems whose LU does not fit in memory (krylov.hpp) — with an assembled K_ff or
/// matrix-free (NewtonOptions::matrix_free: products from the per-stencil tangents).
/// Newton calls them through one interface, LinearSystemSolver (src/solver/linear_solver.hpp;
/// docs/architecture.md, "Linear solvers"), which also holds the rule of which solver replaces
/// which.
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pdcg/solver/model.hpp"

namespace pdcg::solver {

/// mumps, gamg, hypre: PETSc's KSP (MUMPS LU; CG/GMRES with smoothed-aggregation AMG and the
/// rigid-body near-null space; GMRES with hypre BoomerAMG), on one or several MPI processes
/// through a Distribution (pdcg::parallel, docs/scale-out.md).
enum class LinearSolver { cholmod, umfpack, sparse_lu, bicgstab, gmres, mumps, gamg, hypre };
LinearSolver parse_linear_solver(const std::string& name);  // throws InputError
/// True for the solvers of PETSc (they need a Distribution).
inline bool is_petsc_solver(LinearSolver s) {
  return s == LinearSolver::mumps || s == LinearSolver::gamg || s == LinearSolver::hypre;
}
const char* to_string(LinearSolver s);

struct StepReport;
class LinearSystemSolver;  // the seam of the Newton linear solves (src/solver/linear_solver.hpp)

/// The hooks by which StaticSolver runs its Newton iteration on several processes
/// (docs/scale-out.md). pdcg::parallel implements them on PETSc and MPI; this library has no
/// MPI dependency. Every process runs the same Newton logic on replicated vectors (u, f, the
/// reduced residual, the increment: the same values on every process, so every decision is
/// the same); the Model evaluates only this process's stencils (Model::restrict_evaluation),
/// sum() adds the partial forces, and solve() assembles the partial tangents into one
/// distributed matrix and solves with it.
class Distribution {
 public:
  virtual ~Distribution() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  /// True if this process owns point k (evaluates the stencils centred at k and its row).
  virtual bool owns_point(int k) const = 0;
  /// v (length d·N, this process's partial sums) ← the sum over all processes; bitwise the
  /// same on every process.
  virtual void sum(Eigen::VectorXd& v) = 0;
  /// A few scalars summed over the processes (MPI_Allreduce).
  virtual void sum_scalars(Eigen::VectorXd& v) = 0;
  /// Called once by StaticSolver with its free-dof numbering (dof → free index or −1) and the
  /// tangent at u = 0 (this process's partial K, grip rows applied).
  virtual void setup(const std::vector<int>& free_index, const SparseRow& K) = 0;
  /// dx = K_ff⁻¹ rhs with K_ff the free block of the sum of the processes' partial tangents K;
  /// rhs and dx are the reduced (free) vectors, replicated. False if the solve failed.
  virtual bool solve(const SparseRow& K, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx,
                     StepReport& rep) = 0;
};

/// Prescribed displacement on a point set: component c (0..d−1) gets value(t)
/// for each component that has a function.
struct DisplacementSet {
  std::string name;
  std::vector<int> points;
  std::array<std::function<double(double)>, 3> component;  ///< empty = free
  /// Grip on the body surface (docs/solver.md §4, "Grips on the surface"): per point of
  /// `points`, the vector o_k from the point to the surface point it stands for (empty, or
  /// o_k = 0: the point itself is prescribed). A point with o_k ≠ 0 gets, on its prescribed
  /// components, the constraint
  ///   u_k + (F̄_k − I) o_k = ū(t)      (first-order PDDO extrapolation to x_k + o_k)
  /// in place of u_k = ū(t): on a cell-centred grid o_k = (Δx/2) n puts the grip on the face.
  std::vector<Vec3> surface_offset = {};
};

/// Nominal (reference-configuration) traction t*(t) on a point set, applied as
/// f_ext,k = t* dS_k, dS_k = max(0, s_k · n̂) with n̂ the mean outward normal of
/// the set (faces of the set's cells on the surface facing n̂).
struct TractionSet {
  std::string name;
  std::vector<int> points;
  std::function<Vec3(double)> traction;
};

/// Face areas of a traction set's points: dS_k = max(0, s_k · n̂), s_k the surface vectors of
/// the body and n̂ the set's mean normal (Σ s_k normalised; zero areas when it vanishes). The
/// applied force on point k is t*(t) dS_k (static and explicit solvers alike).
std::vector<double> traction_face_areas(const Discretization& body, const std::vector<int>& points);

struct NewtonOptions {
  int steps = 20;           ///< nominal load steps, t = 0 … 1
  double tolerance = 1e-8;  ///< relative, for residual and increment
  int max_iterations = 30;  ///< per load step
  int max_cutbacks = 10;    ///< halvings of the nominal step
  bool line_search = true;
  LinearSolver linear = LinearSolver::umfpack;
  /// After every converged step, count the negative eigenvalues of the free-dof tangent
  /// (of its symmetric part for the unsymmetric weak form) by the inertia of a sparse
  /// LDLᵀ (Sylvester); a negative one means the equilibrium just found is unstable
  /// (buckling, limit point): the step is undone and NumericalError thrown with that
  /// diagnosis. Off by default (one extra factorisation per step). Independently of this
  /// option, a run that fails after all cutbacks reports the inertia of the tangent at
  /// the last converged state in its error message.
  bool check_stability = false;
  /// GMRES (linear = gmres): restart length and the maximum number of Krylov iterations
  /// per linear solve; not reaching the forcing tolerance throws NumericalError.
  int gmres_restart = 50;
  int krylov_max_iterations = 2000;
  /// GMRES only (linear = gmres): products K v from the per-stencil tangents
  /// (Model::apply_tangent) instead of an assembled K — no K, no reverse index, the stencil
  /// tangents packed by major symmetry (docs/solver.md §4, "Matrix-free GMRES"). K is then
  /// assembled only on request (check_stability; relax).
  bool matrix_free = false;
  /// Several processes (or PETSc's solvers on one): see Distribution. Empty: the serial run.
  std::shared_ptr<Distribution> distribution = {};
};

/// Newton's round-off floor (StaticSolver::newton; docs/solver.md §4, "Round-off floor"): a
/// Newton solve whose residual stagnates within this factor of the tolerance while the state no
/// longer moves (every increment of the last 8 iterations below the increment tolerance) is
/// accepted. Reason for 10: a separated sheet's forces are round-off, and its residual
/// measured 0.95–1.1e-8 (1e-4 force floor, tolerance 1e-8) at increments of 2e-12 of ‖u‖.
inline constexpr double kRoundoffResidualFactor = 10.0;

struct StepReport {
  int step = 0;    ///< converged step number (1, 2, …)
  double t = 0.0;  ///< load factor
  int iterations = 0;
  double residual = 0.0;  ///< final relative residual
  std::vector<double> residual_history;
  int cutbacks = 0;               ///< cutbacks spent on this step
  bool stalled = false;           ///< pseudo_transient: stopped by its stall rule
  /// Newton: accepted at the round-off floor of the residual (StaticSolver::newton, "Round-off
  /// floor"): it stagnated within kRoundoffResidualFactor of the tolerance while every
  /// increment of the last 8 iterations was below the increment tolerance.
  bool roundoff_floor = false;
  double assembly_seconds = 0.0;  ///< residual + tangent assembly, summed over iterations
  double solve_seconds = 0.0;     ///< reduction + linear solve, summed over iterations
  double factor_seconds = 0.0;    ///< of which: (symbolic +) numeric factorisation
                                  ///< (gmres: building and factorising the preconditioner)
  int krylov_iterations = 0;      ///< gmres / bicgstab: Krylov iterations, summed
  int factorisations = 0;         ///< umfpack: numeric factorisations of K_ff
  int operator_products = 0;      ///< gmres: products by the tangent (Krylov + restarts + rhs)
  double product_seconds = 0.0;   ///< gmres: time in those products, summed
  /// Negative eigenvalues of the converged free-dof tangent (check_stability), −1 if
  /// not checked, −2 if the LDLᵀ met a zero pivot (singular tangent).
  int negative_eigenvalues = -1;
  /// Global force balance after the step: |Σ reactions + Σ applied tractions| relative to the
  /// load (StaticSolver::force_balance).
  double balance = 0.0;
};

class StaticSolver {
 public:
  StaticSolver(const Model& model, std::vector<DisplacementSet> displacement,
               std::vector<TractionSet> traction, NewtonOptions options);

  /// Runs t = 0 → 1. on_step is called after every converged step. Throws
  /// NumericalError if the step had to be cut back past max_cutbacks, and
  /// InputError if no displacement constraint removes the rigid motions.
  void run(const std::function<void(const StepReport&)>& on_step = {});
  /// Solves one load factor t from the current state (single Newton solve,
  /// with cutbacks between the current and the target t).
  void advance_to(double t, const std::function<void(const StepReport&)>& on_step = {});

  /// Re-solves equilibrium at the current load factor (after the model changed,
  /// e.g. bonds broke). On failure the state is restored and false returned.
  bool reequilibrate(StepReport& rep);
  /// Adaptive dynamic relaxation at the current load (Underwood 1983; local stiffness
  /// estimate and damping of Kilic & Madenci, Theor. Appl. Fract. Mech. 53 (2010) 194–204):
  /// fictitious masses λ_ii = ¼ Σ_j |K_ij| (Δt = 1, Gershgorin: stable), damping
  ///   c_n = 2 √(uᵀ ¹K u / uᵀu),  ¹K_ii = −(r_i^n − r_i^{n−1}) / (λ_ii u̇_i^{n−½}),
  ///   u̇^{n+½} = ((2 − c_n) u̇^{n−½} + 2 r^n/λ) / (2 + c_n),  u^{n+1} = u^n + u̇^{n+½}.
  /// The quasi-static fallback when Newton cannot follow (unstable crack growth): it
  /// converges from far away where Newton does not. Stops when ‖r_f‖ ≤ tol·‖f‖ (then
  /// Newton polishes). Returns false (state restored) after max_iterations.
  bool relax(double tol, int max_iterations, StepReport& rep);
  /// Pseudo-transient continuation at the current load (Kelley & Keyes, SIAM J. Numer. Anal.
  /// 35 (1998) 508–523; switched evolution relaxation of Mulder & van Leer, J. Comput. Phys.
  /// 59 (1985) 232–246): implicit (backward-Euler) steps of the gradient flow D u̇ = −R(u),
  ///   (K_ff + σ_n D) Δu = −R_f(u_n),   u_{n+1} = u_n + Δu,
  /// with D = diag(Σ_j |K_ij|) of the start state (the Gershgorin row sums: at σ = 1 the
  /// shifted matrix is diagonally dominant, a short, safe step; ADR uses ¼ of them as its
  /// masses), σ_0 = 1 and σ_{n+1} = σ_n min(½, ‖R_{n+1}‖ / ‖R_n‖) (SER: the pseudo-time
  /// step grows as the residual falls, here at least twofold per accepted step; σ → 0 is
  /// Newton). A step with σ ≥ 0.1 to an inadmissible state (J ≤ 0) that the inadmissible
  /// handler resolves (rupture: the inverted stencils break, as in relax) is taken as it
  /// stands; a step to
  /// another inadmissible state, or one that more than doubles ‖R‖, is rejected and σ multiplied by
  /// 10 (the tangent is kept: one more factorisation). Stops when ‖R_f‖ ≤ tol·max(‖f‖, ‖f_ext‖)
  /// (then Newton polishes, as after relax). Returns false (state restored, unless the handler
  /// changed the model: then the last admissible state is kept) after max_iterations
  /// factorisations, when the residual stalls (the smallest ‖R‖ of the last 20
  /// factorisations not below ½ of the smallest before them, or since the handler last
  /// changed the model; rep.stalled), when σ exceeds 10⁸, or with an iterative linear solver (not
  /// supported: the caller falls back to relax). The quasi-static rupture fallback (docs/effects.md
  /// §2).
  bool pseudo_transient(double tol, int max_iterations, StepReport& rep);

  /// Called when Newton's accepted state or an ADR iterate is inadmissible (some F with
  /// J ≤ 0): it may change the model there (rupture: break the inverted stencils) and
  /// returns true if it did, and the solve goes on from that state with the new model.
  /// Empty (default): J ≤ 0 fails the Newton solve / steps ADR back.
  using InadmissibleHandler = std::function<bool(const Eigen::VectorXd& u)>;
  void set_inadmissible_handler(InadmissibleHandler h) { inadmissible_ = std::move(h); }
  /// ADR guard (docs/effects.md §2, "No breaking far from equilibrium"): an ADR iterate
  /// with J ≤ 0 calls the handler only if the relative residual of the iterate before it
  /// is at most break_residual; otherwise the step is rejected (back to that iterate,
  /// restart from rest; fictitious masses 4× heavier if the step from rest inverts again).
  /// +∞ (default): the handler on every J ≤ 0, as before.
  void set_relaxation_break_residual(double break_residual) {
    relax_break_residual_ = break_residual;
  }

  /// Floor of the force scale of the relative residual (Newton, ADR, continuation):
  /// ‖R_f‖ ≤ tol · max(‖f‖, ‖f_ext‖, floor). 0 by default (purely relative). A body that
  /// has separated carries round-off forces only, so the purely relative residual stays
  /// O(1) at any equilibrium; the quasi-static rupture driver sets 1e-4 of the largest
  /// internal force of its converged states (docs/effects.md §2).
  void set_force_floor(double floor) { force_floor_ = floor; }
  /// linear: umfpack only: > 0 solves each Newton system by GMRES preconditioned by the last
  /// factorisation, with at most this many products, and factorises when that fails (and
  /// at the next iteration when GMRES needed more than a third of them: an aged factor)
  /// (rupture passes, docs/effects.md §2); 0 (default): a factorisation per iteration.
  void set_factor_reuse(int max_products) { factor_reuse_ = max_products; }
  int factor_reuse() const { return factor_reuse_; }
  double force_floor() const { return force_floor_; }
  const Eigen::VectorXd& displacement() const { return u_; }
  double load_factor() const { return t_; }
  int step() const { return step_; }
  /// Checkpoint restart: sets the state reached after a converged step, and the largest load
  /// met so far (peak_load() of the interrupted run: force_balance's normaliser, so that the
  /// restarted run logs the same balances). Call prepare_restart() first, while the model is
  /// still the one of the start of the run.
  void restore(const Eigen::VectorXd& u, const Eigen::VectorXd& f, double t, int step,
               double peak_load);
  /// The largest load met so far by force_balance (0 before the first call).
  double peak_load() const { return peak_load_; }
  /// Analyses the sparsity pattern with the tangent at u = 0, exactly as the first Newton
  /// iteration of a fresh run does (UMFPACK's symbolic analysis looks at the values), so
  /// that a restarted run factorises with the same ordering — bitwise the same results.
  void prepare_restart();
  /// Reaction (Σ f_int − f_ext over the set's points) of displacement set i.
  Vec3 reaction(std::size_t set) const;
  /// Global force balance of the current state: |Σ reactions + Σ applied tractions| (each
  /// prescribed component counted once, plus the Newton residual of the free ones) divided
  /// by the load, the largest force of a displacement or traction set — here or at any earlier
  /// call of this solver (after a complete separation the current reactions are round-off and
  /// would make any sum "large"; docs/solver.md §3). sum and load, if given, receive the vector
  /// sum and the current load.
  double force_balance(Vec3* sum = nullptr, double* load = nullptr) const;
  const Eigen::VectorXd& internal_force() const { return f_; }
  const std::vector<DisplacementSet>& displacement_sets() const { return dsets_; }

 private:
  void external_force(double t, Eigen::VectorXd& fext) const;
  bool newton(double t_target, StepReport& rep);
  /// Negative eigenvalues of the free block of K_ (symmetric part), −2 if singular.
  int tangent_inertia();
  /// Reduced column-major pattern of K_ff and the gather map (direct solvers, inertia).
  void build_reduced();
  /// Surface grips: row g of the constraint C u = ū, C_g = κ (e_i + Σ_m (o·Ḡ_k^m) e_(m,a))
  /// from the current point stencil (rebuilt stencils after rupture included).
  template <class Fn>
  void grip_row(std::size_t g, Fn&& fn) const;
  /// R_f: f − f_ext on the free rows, κ (C u − ū(t)) on the grip rows.
  void reduced_residual(const Eigen::VectorXd& u, const Eigen::VectorXd& f,
                        const Eigen::VectorXd& fext, double t, Eigen::VectorXd& R) const;
  /// Replaces the grip rows of K by C (their columns are in the pattern: the point family).
  void apply_grip_rows(SparseRow& K) const;
  /// Distributed: this process writes row (a dof) of the summed tangent's constraint rows.
  bool owns_row(const SparseRow& K, int row) const;
  /// The grip rows of a product: out_i = (C x)_i (matrix-free GMRES).
  void apply_grip_product(const Eigen::VectorXd& x, Eigen::VectorXd& out) const;
  /// The linear solver of the Newton systems of the given kind (src/solver/linear_solver.hpp).
  std::unique_ptr<LinearSystemSolver> make_linear(LinearSolver kind) const;

  const Model* model_;
  std::vector<DisplacementSet> dsets_;
  std::vector<TractionSet> tsets_;
  std::vector<std::vector<double>> traction_area_;
  NewtonOptions opt_;
  std::vector<int> free_index_;  // dof -> free index or −1
  std::vector<int> free_dofs_;
  std::vector<int> prescribed_by_;  // dof -> (set << 2 | component) or −1
  // Surface grips: prescribed dofs that stay unknowns with a constraint row (free_index_ ≥ 0).
  std::vector<int> grip_dof_;      // dof of grip g
  std::vector<Vec3> grip_offset_;  // o_k of grip g
  std::vector<int> grip_of_dof_;   // dof -> g or −1 (empty without grips)
  double grip_scale_ = 1.0;        // κ: the constraint rows' scale (a point stiffness)
  Eigen::VectorXd u_, f_;
  double t_ = 0.0;
  int step_ = 0;
  SparseRow K_;
  // reduced pattern gather map: K_ff value q (column-major, in Solvers) = K_ value red_map_[q]
  std::vector<std::int64_t> red_map_;
  struct Solvers;
  std::shared_ptr<Solvers> solvers_;
  InadmissibleHandler inadmissible_;
  double relax_break_residual_ = INFINITY;
  double force_floor_ = 0.0;
  mutable double peak_load_ = 0.0;  // force_balance: the largest load met so far
  int factor_reuse_ = 0;
};

}  // namespace pdcg::solver
