#include "pdcg/solver/explicit.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"

namespace pdcg::solver {

ExplicitSolver::ExplicitSolver(const Model& model, std::vector<DisplacementSet> displacement,
                               ExplicitOptions options)
    : ExplicitSolver(model, std::move(displacement), {}, options) {}

ExplicitSolver::ExplicitSolver(const Model& model, std::vector<DisplacementSet> displacement,
                               std::vector<TractionSet> traction, ExplicitOptions options)
    : model_(&model), dsets_(std::move(displacement)), opt_(options), tsets_(std::move(traction)) {
  const int d = model.dimension();
  const std::size_t n = model.dofs();
  if (!(opt_.density > 0)) throw InputError("density must be positive").key("material.density");
  m_.resize(n);
  for (std::size_t k = 0; k < model.body().size(); ++k)
    for (int a = 0; a < d; ++a) m_[d * k + a] = opt_.density * model.body().volumes()[k];
  prescribed_.assign(n, -1);
  for (std::size_t s = 0; s < dsets_.size(); ++s)
    for (int p : dsets_[s].points)
      for (int a = 0; a < d; ++a)
        if (dsets_[s].component[a]) prescribed_[d * p + a] = static_cast<int>(s << 2 | a);
  // traction face areas, as StaticSolver (traction_face_areas)
  for (const auto& ts : tsets_)
    traction_area_.push_back(traction_face_areas(model.body(), ts.points));
  u_ = Eigen::VectorXd::Zero(n);
  v_ = Eigen::VectorXd::Zero(n);
  const double crit = critical_time_step(u_);
  crit_ = crit;
  if (opt_.time_step > 0) {
    if (opt_.time_step > crit && !opt_.allow_unstable)
      throw InputError("time step above the stable limit of the explicit integrator")
          .key("inertia.time_step")
          .value(fmt::format("{}", opt_.time_step))
          .expected(fmt::format("at most {:.6g} (Gershgorin bound 2/√(max_k Σ|K_kn|/M_k))", crit))
          .fix(
              "use time_step: auto (with safety < 1), or inertia.allow_unstable: true to run it "
              "anyway (it will blow up)");
    if (opt_.time_step > crit)
      log::warn(
          "time step {:.6g} is {:.4g}× the stable limit {:.6g}: running anyway "
          "(allow_unstable); expect the energy to grow without bound",
          opt_.time_step, opt_.time_step / crit, crit);
    dt_ = opt_.time_step;
  } else {
    if (!(opt_.safety > 0 && opt_.safety <= 1))
      throw InputError("safety factor outside (0, 1]")
          .key("inertia.safety")
          .value(fmt::format("{}", opt_.safety))
          .expected("0 < safety ≤ 1, e.g. 0.8");
    dt_ = opt_.safety * crit;
  }
  dt_nominal_ = dt_;
  if (opt_.damping_type == ExplicitDamping::none && opt_.damping > 0)
    opt_.damping_type = ExplicitDamping::viscous;
  if (opt_.damping_type == ExplicitDamping::viscous) c_ = opt_.damping;
  log::info("explicit dynamics: Δt = {:.4g} (stable limit {:.4g} from the Gershgorin bound)", dt_,
            crit);
  compute_acceleration(0.0);
  if (opt_.damping_type == ExplicitDamping::adaptive) f_prev_ = f_;
}

void ExplicitSolver::restore(const State& s) {
  if (s.dt > 0) dt_ = s.dt;
  if (s.crit > 0) crit_ = s.crit;
  n_steps_ = s.steps;
  u_ = s.u;
  v_ = s.v;
  a_ = s.a;
  f_ = s.f;
  f_prev_ = s.f_prev;
  t_ = s.t;
  c_ = s.c;
}

Vec3 ExplicitSolver::reaction(std::size_t set) const {
  const int d = model_->dimension();
  Vec3 r = Vec3::Zero();
  for (int p : dsets_.at(set).points)
    for (int a = 0; a < d; ++a) r(a) += f_[d * p + a];
  return r;
}

void ExplicitSolver::update_adaptive_damping() {
  // Underwood (1983): ¹K_ii = −(r_i^n − r_i^{n−1})/(Δt v_i^{n−½}) with r = −f (free dofs with
  // v ≠ 0), c = 2√(uᵀ¹K u / uᵀMu) when positive, else 0 (the split exponential damping is
  // stable for every c).
  double num = 0.0, den = 0.0;
  for (Eigen::Index i = 0; i < u_.size(); ++i) {
    if (prescribed_[i] >= 0) continue;
    den += u_[i] * m_[i] * u_[i];
    if (v_[i] == 0.0) continue;
    const double k = (f_[i] - f_prev_[i]) / (dt_ * v_[i]);
    num += u_[i] * k * u_[i];
  }
  c_ = (num > 0 && den > 0) ? 2.0 * std::sqrt(num / den) : 0.0;
}

double ExplicitSolver::critical_time_step(const Eigen::VectorXd& u) const {
  Eigen::VectorXd f;
  SparseRow K;
  if (!model_->internal_force_and_tangent(u, f, K))
    throw NumericalError("inadmissible deformation while estimating the stable time step");
  double wmax2 = 0.0;
  for (int r = 0; r < K.outerSize(); ++r) {
    if (prescribed_[r] >= 0) continue;
    double s = 0;
    for (auto q = K.outerIndexPtr()[r]; q < K.outerIndexPtr()[r + 1]; ++q)
      if (prescribed_[K.innerIndexPtr()[q]] < 0) s += std::abs(K.valuePtr()[q]);
    wmax2 = std::max(wmax2, s / m_[r]);
  }
  return 2.0 / std::sqrt(wmax2);
}

double ExplicitSolver::critical_time_step_local(const Eigen::VectorXd& u,
                                                const std::vector<int>& points) const {
  std::vector<double> sums;
  if (!model_->tangent_row_abs_sums(u, points, skip_col_, sums))
    throw NumericalError(
        "inadmissible deformation (J ≤ 0) while re-estimating the stable time step after "
        "bonds broke");
  const int d = model_->dimension();
  double wmax2 = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int a = 0; a < d; ++a) {
      const std::size_t dof = static_cast<std::size_t>(d) * points[i] + a;
      if (prescribed_[dof] >= 0) continue;
      wmax2 = std::max(wmax2, sums[d * i + a] / m_[dof]);
    }
  return wmax2 > 0 ? 2.0 / std::sqrt(wmax2) : std::numeric_limits<double>::infinity();
}

void ExplicitSolver::attach_rupture(Rupture* r) {
  if (r && r->options().anchor_detached)
    throw Error("internal error: dynamic fracture needs RuptureOptions::anchor_detached = false");
  if (r && r->options().check_every < 1)
    throw InputError("rupture.check_every must be at least 1").key("rupture.check_every");
  rupture_ = r;
  if (r) {
    skip_col_.resize(prescribed_.size());
    for (std::size_t i = 0; i < prescribed_.size(); ++i) skip_col_[i] = prescribed_[i] >= 0;
    row_mark_.assign(model_->body().size(), 0);
  }
}

void ExplicitSolver::rupture_check() {
  const RupturePass p = rupture_->break_exceeding(u_);
  last_pass_.max_value = p.max_value;
  if (p.broken == 0) return;
  notify_rebuilt();
  last_pass_.broken += p.broken;
  last_pass_.inverted += p.inverted;
  last_pass_.rebuilt += p.rebuilt;
  // the force at u_{n+1} with the rebuilt stencils (v_{n+1} stays)
  compute_acceleration(t_);
  after_break();
}

void ExplicitSolver::after_break() {
  // Stable step: rows touched by the rebuilt stencils = members of the point stencils of
  // the rebuilt centres (every rebuilt stencil lies within δ of its centre).
  const Discretization& B = model_->body();
  const Stencils& P = B.point_stencils();
  std::vector<int> rows;
  for (int c : rupture_->rebuilt_centres())
    for (auto r = P.offsets[c]; r < P.offsets[c + 1]; ++r)
      if (!row_mark_[P.index[r]]) {
        row_mark_[P.index[r]] = 1;
        rows.push_back(P.index[r]);
      }
  for (int k : rows) row_mark_[k] = 0;
  if (opt_.allow_unstable) return;  // the user's step, whatever the limit
  const double local = critical_time_step_local(u_, rows);
  // Shrink: the rebuilt rows need a smaller step. Grow back: a step shrunk earlier may
  // have been set by a transient (a stencil stretched hard just before its bond broke).
  // Either way the whole tangent decides (one assembly, only in these cases): the step
  // is safety × the Gershgorin bound of all rows at u_{n+1}, never above the nominal step.
  if (!(dt_ > opt_.safety * local) && !(dt_ < dt_nominal_)) return;
  const double full = critical_time_step(u_);
  crit_ = full;
  const double old = dt_;
  dt_ = std::min(dt_nominal_, opt_.safety * full);
  if (dt_ < old)
    log::debug(
        "t = {:.6g}: the stencils rebuilt after {} bonds broke lower the stable limit to {:.6g} "
        "(Gershgorin bound of the tangent at this state): time step {:.6g} → {:.6g} (safety {})",
        t_, last_pass_.broken, full, old, dt_, opt_.safety);
  else if (dt_ > old)
    log::debug("t = {:.6g}: stable limit {:.6g} at this state: time step {:.6g} → {:.6g}", t_, full,
               old, dt_);
}

void ExplicitSolver::set_displacement(const Eigen::VectorXd& u) {
  u_ = u;
  compute_acceleration(t_);
}

void ExplicitSolver::compute_force(double t) {
  if (evaluate_force()) return;
  if (rupture_) {
    // Dynamic fracture: a stencil inverted (J ≤ 0) during the step; its material cannot be
    // evaluated — the bond counts as past every criterion and breaks (then the stable
    // step is re-estimated on the rebuilt rows like after a criterion check).
    const RupturePass p = rupture_->break_inadmissible(u_);
    last_pass_.broken += p.broken;
    last_pass_.inverted += p.inverted;
    last_pass_.rebuilt += p.rebuilt;
    if (p.broken > 0 || p.point_stencils_off > 0) notify_rebuilt();
    if ((p.broken > 0 || p.point_stencils_off > 0) && evaluate_force()) {
      after_break();
      return;
    }
  }
  throw NumericalError(
      fmt::format("inadmissible deformation (J ≤ 0) at time {:.6g}: the time step may be too "
                  "large or the motion too violent",
                  t));
}

void ExplicitSolver::compute_acceleration(double t) {
  compute_force(t);
  acceleration_from_force();
  if (!tsets_.empty()) add_external_force(t);
}

void ExplicitSolver::add_external_force(double t) {
  const int d = model_->dimension();
  for (std::size_t s = 0; s < tsets_.size(); ++s) {
    const Vec3 tr = tsets_[s].traction(t);
    for (std::size_t i = 0; i < tsets_[s].points.size(); ++i)
      for (int a = 0; a < d; ++a) {
        const std::size_t dof = static_cast<std::size_t>(d) * tsets_[s].points[i] + a;
        if (prescribed_[dof] < 0) a_[dof] += tr(a) * traction_area_[s][i] / m_[dof];
      }
  }
}

Vec3 ExplicitSolver::traction_force(std::size_t set) const {
  const Vec3 tr = tsets_.at(set).traction(t_);
  double area = 0;
  for (double a : traction_area_[set]) area += a;
  return tr * area;
}

void ExplicitSolver::acceleration_from_force() {
  a_ = -f_.cwiseQuotient(m_);
  for (std::size_t i = 0; i < prescribed_.size(); ++i)
    if (prescribed_[i] >= 0) a_[i] = 0.0;
}

void ExplicitSolver::step() {
  const double h = dt_, t1 = t_ + h;
  if (rupture_) last_pass_ = {};
  // Damping by Strang splitting: v ← e^{−c h/2} v before and after the Verlet step (exact
  // for the damping part, stable for every c ≥ 0; the prescribed components are reset below).
  if (c_ > 0) v_ *= std::exp(-0.5 * c_ * h);
  v_ += 0.5 * h * a_;
  u_ += h * v_;
  for (std::size_t i = 0; i < prescribed_.size(); ++i) {
    const int p = prescribed_[i];
    if (p < 0) continue;
    const auto& fn = dsets_[p >> 2].component[p & 3];
    u_[i] = fn(t1);
    v_[i] = (fn(t1 + 0.5 * h) - fn(t1 - 0.5 * h)) / h;
  }
  t_ = t1;
  if (opt_.damping_type == ExplicitDamping::adaptive) f_prev_.swap(f_);
  compute_force(t_);
  if (opt_.damping_type == ExplicitDamping::adaptive) update_adaptive_damping();
  acceleration_from_force();
  if (!tsets_.empty()) add_external_force(t_);
  v_ += 0.5 * h * a_;
  if (c_ > 0) v_ *= std::exp(-0.5 * c_ * h);
  for (std::size_t i = 0; i < prescribed_.size(); ++i) {
    const int p = prescribed_[i];
    if (p < 0) continue;
    const auto& fn = dsets_[p >> 2].component[p & 3];
    v_[i] = (fn(t1 + 0.5 * h) - fn(t1 - 0.5 * h)) / h;
  }
  ++n_steps_;
  // only with dynamic fracture: one test per step, nothing per bond
  if (rupture_ && n_steps_ % rupture_->options().check_every == 0) rupture_check();
}

double ExplicitSolver::kinetic_energy() const { return 0.5 * v_.dot(m_.cwiseProduct(v_)); }

double ExplicitSolver::modified_kinetic_energy() const {
  return kinetic_energy() - dt_ * dt_ / 8.0 * a_.dot(m_.cwiseProduct(a_));
}

}  // namespace pdcg::solver
