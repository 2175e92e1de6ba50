/// \file
/// Explicit dynamics of the BA solver (effect `inertia`; docs/effects.md).
///
/// Lumped mass M_k = ρ V_k, equations of motion M ü = f_ext(t) − f(u) − c M u̇ with f the
/// internal force of the Model (weak or energy form) and c an optional viscous damping
/// coefficient. Velocity Verlet (Swope et al. 1982):
///   v_{n+½} = v_n + ½Δt a_n,   u_{n+1} = u_n + Δt v_{n+½},
///   a_{n+1} = M⁻¹(f_ext − f(u_{n+1})),   v_{n+1} = v_{n+½} + ½Δt a_{n+1}
/// (c = 0: the symplectic, time-reversible scheme whose energy error stays bounded). Damping
/// by Strang splitting: v ← e^{−cΔt/2} v before and after each Verlet step (the damping
/// part solved exactly: stable for every c ≥ 0, energy decays as e^{−ct} for light damping).
/// Prescribed components follow ū(t) (velocity by central difference of ū).
///
/// Stable step: for the linearised system the scheme is stable iff Δt ω_max ≤ 2, ω_max² the
/// largest eigenvalue of M⁻¹K. By Gershgorin's theorem (applied to M^{-1/2} K M^{-1/2}, whose
/// rows sums are bounded by max_k Σ_n |K_kn| / min(M_k, M_n) = max_k Σ_n |K_kn| / M for the
/// uniform lumped mass), ω_max² ≤ max_k Σ_n |K_kn| / M_k, so
///   Δt_crit = 2 / √(max_k Σ_n |K_kn| / M_k)
/// is a safe (conservative) bound; Δt = safety · Δt_crit. K is the consistent tangent at the
/// current state (at u = 0 unless re-estimated).
///
/// Dynamic fracture (attach_rupture, docs/effects.md §3c): after every check_every-th step
/// the rupture criterion is evaluated on the intact bonds at u_{n+1}; bonds past it break,
/// the touched stencils are rebuilt locally (Rupture::break_exceeding), and f, a are
/// recomputed at u_{n+1} with the new stencils (v_{n+1} is kept: breaking changes forces,
/// not positions or velocities). The stable step is re-estimated on the rows the rebuilt
/// stencils touch (Gershgorin at u_{n+1}); if safety·Δt_crit,local < Δt, or the step was
/// shrunk before, the Gershgorin bound of the whole tangent at u_{n+1} sets the step:
/// Δt = min(Δt_nominal, safety·Δt_crit) (it shrinks, and grows back when a transient that
/// shrank it is gone).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "pdcg/solver/model.hpp"
#include "pdcg/solver/newton.hpp"
#include "pdcg/solver/rupture.hpp"

namespace pdcg::solver {

enum class ExplicitDamping {
  none,
  viscous,  ///< c fixed (`damping`)
  /// Adaptive dynamic relaxation (Underwood 1983) on the physical masses: c_n =
  /// 2√(uᵀ ¹K u / uᵀMu) with the local diagonal stiffness estimate
  /// ¹K_ii = −(r_i^n − r_i^{n−1}) / (Δt v_i^{n−½}), r = −f: critical damping of the lowest mode,
  /// so the motion relaxes to static equilibrium (the quasi-static use of damping).
  adaptive
};

/// Explicit dynamics on several processes (docs/scale-out.md §6): the hook through which
/// ExplicitSolver gets its internal force when the force is evaluated by parts. pdcg::parallel
/// implements it on PETSc and MPI (each process evaluates the stencils centred at its points,
/// the partial forces are summed); this library has no MPI dependency. Every process steps the
/// same replicated u, v with the same summed f, so every decision (time step, broken bonds)
/// is the same on every process.
class ForceExchange {
 public:
  virtual ~ForceExchange() = default;
  /// f (all d·N components) ← the internal force at u, summed over the processes; bitwise
  /// the same on every process. False (on every process) if F is inadmissible (J ≤ 0) on
  /// any process.
  virtual bool internal_force(const Eigen::VectorXd& u, Eigen::VectorXd& f) = 0;
  /// The body's stencils were rebuilt (bonds broke): later forces must use them.
  virtual void stencils_rebuilt() = 0;
  /// Π(u) summed over the processes (each its own stencils'), the same on every process.
  virtual double energy(const Eigen::VectorXd& u) = 0;
};

struct ExplicitOptions {
  double density = 1.0;
  double time_step = 0.0;  ///< 0 = auto (safety · Δt_crit)
  double safety = 0.8;
  double damping = 0.0;                                  ///< viscous coefficient c (1/time)
  ExplicitDamping damping_type = ExplicitDamping::none;  ///< none = viscous if damping > 0
  /// Accept a time_step above the stable limit (warning instead of an InputError):
  /// for demonstrating the instability only.
  bool allow_unstable = false;
};

class ExplicitSolver {
 public:
  /// Throws InputError if time_step exceeds the stable limit (naming both).
  ExplicitSolver(const Model& model, std::vector<DisplacementSet> displacement,
                 ExplicitOptions options);
  /// With nominal tractions t*(t) on point sets, t the time: the external force
  /// f_ext,k = t*(t) dS_k, dS_k = max(0, s_k · n̂) (n̂ the mean outward normal of the set;
  /// the same face areas as the static solver) enters M a = f_ext(t) − f(u). No traction
  /// set: nothing is allocated or evaluated for them.
  ExplicitSolver(const Model& model, std::vector<DisplacementSet> displacement,
                 std::vector<TractionSet> traction, ExplicitOptions options);

  /// Gershgorin bound Δt_crit = 2/√(max_k Σ_n |K_kn|/M_k) at displacement u.
  double critical_time_step(const Eigen::VectorXd& u) const;
  /// The stable limit: at construction (u = 0), then the last full re-estimate after bonds
  /// broke (dynamic fracture).
  double stable_limit() const { return crit_; }
  double time_step() const { return dt_; }
  /// Shortens the step (e.g. to end exactly at a given time); never above the current one.
  void shorten_time_step(double dt) {
    if (dt > 0 && dt <= dt_) dt_ = dt;
  }
  /// The step at construction (the cap when a shrunk step grows back).
  double nominal_time_step() const { return dt_nominal_; }
  double time() const { return t_; }
  void set_velocity(const Eigen::VectorXd& v) { v_ = v; }
  void set_displacement(const Eigen::VectorXd& u);
  /// One velocity-Verlet step. Throws NumericalError if F becomes inadmissible.
  void step();
  const Eigen::VectorXd& displacement() const { return u_; }
  const Eigen::VectorXd& velocity() const { return v_; }
  double kinetic_energy() const;
  /// a_n (free components; prescribed ones 0).
  const Eigen::VectorXd& acceleration() const { return a_; }
  /// Verlet's modified energy ½ v_{n−½}·M v_{n+½} + Π(u_n) = E_kin(v_n) − (Δt²/8) aᵀMa + Π:
  /// exactly conserved by the scheme for a linear system, so its change measures drift
  /// without the bounded O((ωΔt)²) oscillation of E_kin + Π.
  double modified_kinetic_energy() const;
  const Eigen::VectorXd& mass() const { return m_; }
  /// Internal force f(u_n) (all components).
  const Eigen::VectorXd& internal_force() const { return f_; }
  /// Σ f_int over the points of displacement set i (the force the constraint exerts, negated).
  Vec3 reaction(std::size_t set) const;
  /// Σ f_ext over the points of traction set i at the current time (its resultant).
  Vec3 traction_force(std::size_t set) const;
  /// Current damping coefficient (viscous: fixed; adaptive: c_n of the last step).
  double damping_coefficient() const { return c_; }

  /// Dynamic fracture: check the rupture criterion after every r.options().check_every-th
  /// step (see the file comment). The rupture must be built on the model's body with
  /// anchor_detached = false. Without it, step() does no rupture work at all.
  void attach_rupture(Rupture* r);
  /// The break event of the last step (zero counts if nothing broke or not checked).
  const RupturePass& last_rupture() const { return last_pass_; }
  /// Number of steps taken (restored with the state).
  long steps_taken() const { return n_steps_; }
  /// Recomputes f and a at the current u (after the model changed, e.g. bonds broke).
  void refresh_force() { compute_acceleration(t_); }
  /// Internal forces through `x` from now on (nullptr: the model's own, the serial run); f
  /// and a are recomputed at the current u. The model given to the constructor stays the
  /// whole one: the stable step (Gershgorin) and the rupture use it.
  void set_force_exchange(ForceExchange* x) {
    exchange_ = x;
    refresh_force();
  }
  /// Gershgorin bound 2/√(max Σ_n |K_kn|/M_k) over the rows of the given points only.
  double critical_time_step_local(const Eigen::VectorXd& u, const std::vector<int>& points) const;

  /// Complete state after a step (for checkpoints): restoring it and stepping on gives
  /// bitwise the same trajectory as never stopping.
  struct State {
    Eigen::VectorXd u, v, a, f, f_prev;
    double t = 0.0, c = 0.0;
    double dt = 0.0;    ///< the current step (0: keep; shrinks after rebuilds)
    double crit = 0.0;  ///< the current stable limit (0: keep)
    long steps = 0;     ///< steps taken
  };
  State state() const { return {u_, v_, a_, f_, f_prev_, t_, c_, dt_, crit_, n_steps_}; }
  void restore(const State& s);

 private:
  void compute_acceleration(double t);
  void compute_force(double t);
  /// f_ = f(u_): the model's, or the exchange's sum over the processes
  bool evaluate_force() {
    return exchange_ ? exchange_->internal_force(u_, f_) : model_->internal_force(u_, f_);
  }
  void notify_rebuilt() {
    if (exchange_) exchange_->stencils_rebuilt();
  }
  ForceExchange* exchange_ = nullptr;
  void acceleration_from_force();
  const Model* model_;
  std::vector<DisplacementSet> dsets_;
  ExplicitOptions opt_;
  std::vector<int> prescribed_;  // dof -> (set << 2 | comp) or −1
  std::vector<TractionSet> tsets_;
  std::vector<std::vector<double>> traction_area_;
  void add_external_force(double t);  // a_ += M⁻¹ f_ext(t) on free dofs
  void update_adaptive_damping();
  Eigen::VectorXd m_, u_, v_, a_, f_, f_prev_;
  double dt_ = 0.0, t_ = 0.0, crit_ = 0.0, c_ = 0.0, dt_nominal_ = 0.0;
  void rupture_check();
  void after_break();  // force and stable-step update after last_pass_ broke bonds
  Rupture* rupture_ = nullptr;
  RupturePass last_pass_;
  long n_steps_ = 0;
  std::vector<char> skip_col_;  // prescribed dofs (Gershgorin columns skipped)
  std::vector<char> row_mark_;  // scratch for the local re-estimate
};

}  // namespace pdcg::solver
