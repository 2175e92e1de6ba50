#include "pdcg/solver/newton.hpp"

#include <fmt/format.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <set>
#include <type_traits>

#include "linear_solver.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/solver/krylov.hpp"

namespace pdcg::solver {

std::vector<double> traction_face_areas(const Discretization& body,
                                        const std::vector<int>& points) {
  const auto& surf = body.surface();
  Vec3 nsum = Vec3::Zero();
  for (int p : points) nsum += surf[p];
  const Vec3 nh = nsum.norm() > 0 ? Vec3(nsum.normalized()) : Vec3::Zero();
  std::vector<double> area;
  area.reserve(points.size());
  for (int p : points) area.push_back(std::max(0.0, surf[p].dot(nh)));
  return area;
}

LinearSolver parse_linear_solver(const std::string& name) {
  if (name == "cholmod") return LinearSolver::cholmod;
  if (name == "umfpack") return LinearSolver::umfpack;
  if (name == "lu" || name == "sparse_lu") return LinearSolver::sparse_lu;
  if (name == "bicgstab" || name == "iterative") return LinearSolver::bicgstab;
  if (name == "gmres") return LinearSolver::gmres;
  if (name == "mumps") return LinearSolver::mumps;
  if (name == "gamg") return LinearSolver::gamg;
  if (name == "hypre") return LinearSolver::hypre;
  throw InputError("unknown linear solver")
      .key("solver.linear")
      .value(name)
      .expected("one of cholmod, umfpack, lu, bicgstab, gmres, mumps, gamg, hypre");
}

const char* to_string(LinearSolver s) {
  switch (s) {
    case LinearSolver::cholmod:
      return "cholmod";
    case LinearSolver::umfpack:
      return "umfpack";
    case LinearSolver::sparse_lu:
      return "lu";
    case LinearSolver::bicgstab:
      return "bicgstab";
    case LinearSolver::gmres:
      return "gmres";
    case LinearSolver::mumps:
      return "mumps";
    case LinearSolver::gamg:
      return "gamg";
    case LinearSolver::hypre:
      return "hypre";
  }
  return "?";
}

struct StaticSolver::Solvers {
  DirectFactors factors;  // shared by the direct solvers and pseudo_transient
  // The linear solver of the Newton systems (linear_solver.hpp); replaced by fallback_of's
  // solver after a failed solve.
  std::unique_ptr<LinearSystemSolver> linear;
  Eigen::VectorXd yfull;  // matrix-free: the full product K Δu_c
  // Reduced tangent K_ff in the column-major storage the factorisations read, filled
  // in place from the full row-major K through red_map_ (no per-iteration copy).
  SparseCol Kff;
};

namespace {
// Distributed: a J ≤ 0 on any process is one on all (every process takes the same branch).
bool distributed_ok(Distribution& dist, bool ok) {
  Eigen::VectorXd flag(1);
  flag[0] = ok ? 0.0 : 1.0;
  dist.sum_scalars(flag);
  return flag[0] == 0.0;
}

}  // namespace

StaticSolver::StaticSolver(const Model& model, std::vector<DisplacementSet> displacement,
                           std::vector<TractionSet> traction, NewtonOptions options)
    : model_(&model), dsets_(std::move(displacement)), tsets_(std::move(traction)), opt_(options) {
  const int d = model.dimension();
  const std::size_t n = model.dofs();
  if (opt_.matrix_free && opt_.linear != LinearSolver::gmres)
    throw InputError("matrix-free products need the GMRES linear solver")
        .key("solver.matrix_free")
        .value("true")
        .expected("linear: gmres with matrix_free: true")
        .fix("set solver.linear: gmres, or drop matrix_free");
  if (is_petsc_solver(opt_.linear) != static_cast<bool>(opt_.distribution))
    throw InputError(opt_.distribution
                         ? "a distributed run (several MPI processes) solves with PETSc"
                         : "this linear solver is PETSc's")
        .key("solver.linear")
        .value(to_string(opt_.linear))
        .expected(opt_.distribution ? "mumps, gamg or hypre"
                                    : "cholmod, umfpack, lu, bicgstab or gmres")
        .fix(opt_.distribution ? "set solver.linear: mumps (direct), gamg or hypre"
                               : "PETSc's solvers run through `pdcg run` of a build with PETSc "
                                 "(PDCG_ENABLE_PETSC, docs/scale-out.md); otherwise set "
                                 "solver.linear: umfpack");
  if (opt_.distribution && (opt_.matrix_free || opt_.check_stability))
    throw InputError("not implemented on PETSc (docs/scale-out.md)")
        .key(opt_.matrix_free ? "solver.matrix_free" : "solver.check_stability")
        .value("true")
        .fix("drop it, or run on one process with solver.linear: umfpack or gmres");
  prescribed_by_.assign(n, -1);
  for (std::size_t s = 0; s < dsets_.size(); ++s)
    for (int p : dsets_[s].points)
      for (int a = 0; a < d; ++a)
        if (dsets_[s].component[a]) prescribed_by_[d * p + a] = static_cast<int>(s << 2) | a;
  // Rigid motions must be removed (static run).
  const char* axis = "xyz";
  std::set<int> constrained_points;
  for (int a = 0; a < d; ++a) {
    bool any = false;
    for (std::size_t k = 0; k < model.body().size(); ++k)
      if (prescribed_by_[d * k + a] >= 0) {
        any = true;
        constrained_points.insert(static_cast<int>(k));
      }
    if (!any)
      throw InputError(fmt::format("no displacement constraint in {}: the static problem is "
                                   "singular (the body can translate freely in {})",
                                   axis[a], axis[a]))
          .key("boundary")
          .expected(fmt::format("at least one displacement set fixing {}", axis[a]))
          .fix(fmt::format(
              "add e.g. {{name: pin, region: {{point: [...]}}, displacement: {{{}: 0.0}}}}",
              axis[a]));
  }
  if (constrained_points.size() < 2)
    throw InputError("all displacement constraints act on one point: the body can rotate freely")
        .key("boundary")
        .fix("constrain a second point or an edge");
  // Surface grips (docs/solver.md §4, "Grips on the surface"): prescribed components of
  // points with an offset stay unknowns, with the constraint row u_k + (F̄_k − I) o_k = ū.
  grip_of_dof_.assign(n, -1);
  for (std::size_t s = 0; s < dsets_.size(); ++s) {
    const auto& ds = dsets_[s];
    if (ds.surface_offset.empty()) continue;
    if (ds.surface_offset.size() != ds.points.size())
      throw Error("internal error: surface offsets of displacement set '" + ds.name +
                  "' do not match its points");
    for (std::size_t i = 0; i < ds.points.size(); ++i) {
      const Vec3& o = ds.surface_offset[i];
      if (!(o.squaredNorm() > 0)) continue;
      for (int a = 0; a < d; ++a) {
        const int dof = d * ds.points[i] + a;
        if (!ds.component[a] || prescribed_by_[dof] != (static_cast<int>(s << 2) | a) ||
            grip_of_dof_[dof] >= 0)
          continue;
        grip_of_dof_[dof] = static_cast<int>(grip_dof_.size());
        grip_dof_.push_back(dof);
        grip_offset_.push_back(o);
      }
    }
  }
  if (grip_dof_.empty()) {
    grip_of_dof_.clear();
  } else {
    if (opt_.check_stability)
      throw InputError(
          "the stability check counts the inertia of the stiffness, which the constraint rows "
          "of grips on the surface replace")
          .key("solver.check_stability")
          .value("true")
          .fix("grip the point columns (boundary grip: points), or drop check_stability");
    // κ: a point stiffness, A₁₁₁₁(I) Δx^(d−2), so that the constraint rows are commensurate
    // with the force rows (the Newton residual mixes them).
    Mat3 P;
    Tangent A;
    model.material().evaluate(Mat3::Identity(), nullptr, &P, &A);
    grip_scale_ = std::abs(A(flat(0, 0), flat(0, 0))) *
                  std::pow(model.body().spacing(), static_cast<double>(d - 2));
    if (!(grip_scale_ > 0)) grip_scale_ = 1.0;
  }
  free_index_.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i)
    if (prescribed_by_[i] < 0 || (!grip_of_dof_.empty() && grip_of_dof_[i] >= 0)) {
      free_index_[i] = static_cast<int>(free_dofs_.size());
      free_dofs_.push_back(static_cast<int>(i));
    }
  // Traction face areas.
  for (const auto& ts : tsets_)
    traction_area_.push_back(traction_face_areas(model.body(), ts.points));
  u_.setZero(n);
  f_.setZero(n);
  Eigen::VectorXd f;
  // (matrix-free: no K, and its pattern is never built)
  if (!(opt_.matrix_free ? model.internal_force(u_, f)
                         : model.internal_force_and_tangent(u_, f, K_)))
    throw NumericalError("the reference configuration is inadmissible for the material");
  solvers_ = std::make_shared<Solvers>();
  solvers_->linear =
      make_linear(linear_solver_for(opt_.linear, model.symmetric(), !grip_dof_.empty()));
  if (opt_.distribution) {
    if (!grip_dof_.empty()) apply_grip_rows(K_);
    opt_.distribution->setup(free_index_, K_);
    return;
  }
  // The Krylov path multiplies by the free rows of K_ directly: no reduced copy (its
  // memory is what large 3D runs cannot afford).
  if (solvers_->linear->needs_reduced()) build_reduced();
}

std::unique_ptr<LinearSystemSolver> StaticSolver::make_linear(LinearSolver kind) const {
  LinearSolverSetup setup;
  setup.options = opt_;
  setup.factors = &solvers_->factors;
  // GMRES: the lattice stiffness of the body at the first solve (rupture may have changed it)
  if (kind == LinearSolver::gmres)
    setup.preconditioner = [model = model_, free_index = free_index_,
                            nf = static_cast<int>(free_dofs_.size())] {
      return lattice_stiffness(model->body(), model->material(), free_index, nf);
    };
  return make_linear_solver(kind, setup);
}

void StaticSolver::build_reduced() {
  if (!red_map_.empty()) return;
  // Reduced pattern and gather map from the full pattern.
  // Reduced pattern (column-major) and the map from its value array into K's:
  // build K_ff with each entry's value = its position in K, then read the map off.
  std::vector<Eigen::Triplet<double, SolverIndex>> trip;
  for (int r = 0; r < K_.outerSize(); ++r) {
    if (free_index_[r] < 0) continue;
    for (auto q = K_.outerIndexPtr()[r]; q < K_.outerIndexPtr()[r + 1]; ++q) {
      const int c = K_.innerIndexPtr()[q];
      if (free_index_[c] >= 0)
        trip.emplace_back(free_index_[r], free_index_[c], static_cast<double>(q));
    }
  }
  const int nf = static_cast<int>(free_dofs_.size());
  SparseCol& Kff = solvers_->Kff;
  Kff.resize(nf, nf);
  Kff.setFromTriplets(trip.begin(), trip.end());  // no duplicates: one entry per (r, c)
  Kff.makeCompressed();
  trip = {};
  red_map_.resize(Kff.nonZeros());
  for (Eigen::Index q = 0; q < Kff.nonZeros(); ++q)
    red_map_[q] = static_cast<std::int64_t>(Kff.valuePtr()[q]);
}

template <class Fn>
void StaticSolver::grip_row(std::size_t g, Fn&& fn) const {
  const int d = model_->dimension();
  const int dof = grip_dof_[g], k = dof / d, a = dof % d;
  const Stencils& P = model_->body().point_stencils();
  const Vec3& o = grip_offset_[g];
  fn(dof, grip_scale_);
  for (auto r = P.offsets[k]; r < P.offsets[k + 1]; ++r) {
    const double* gm = P.grad.data() + r * d;
    double c = 0;
    for (int J = 0; J < d; ++J) c += o(J) * gm[J];
    fn(d * P.index[r] + a, grip_scale_ * c);
  }
}

void StaticSolver::reduced_residual(const Eigen::VectorXd& u, const Eigen::VectorXd& f,
                                    const Eigen::VectorXd& fext, double t,
                                    Eigen::VectorXd& R) const {
  const int nf = static_cast<int>(free_dofs_.size());
  R.resize(nf);
  for (int i = 0; i < nf; ++i) R[i] = f[free_dofs_[i]] - fext[free_dofs_[i]];
  for (std::size_t g = 0; g < grip_dof_.size(); ++g) {
    double cu = 0;
    grip_row(g, [&](int col, double c) { cu += c * u[col]; });
    const int dof = grip_dof_[g];
    const auto& set = dsets_[prescribed_by_[dof] >> 2];
    R[free_index_[dof]] = cu - grip_scale_ * set.component[prescribed_by_[dof] & 3](t);
  }
}

void StaticSolver::apply_grip_rows(SparseRow& K) const {
  double* vals = K.valuePtr();
  const int* inner = K.innerIndexPtr();
  const bool partial = static_cast<bool>(opt_.distribution);
  for (std::size_t g = 0; g < grip_dof_.size(); ++g) {
    const int row = grip_dof_[g];
    const auto b = K.outerIndexPtr()[row], e = K.outerIndexPtr()[row + 1];
    std::fill(vals + b, vals + e, 0.0);
    // Distributed: the partial tangents are summed, so the constraint row is written by the
    // process whose stencils include the point's own (the point family's columns), the
    // others leave their partial row at zero.
    if (partial && !owns_row(K, row)) continue;
    grip_row(g, [&](int col, double c) {
      const int* at = std::lower_bound(inner + b, inner + e, col);
      if (at == inner + e || *at != col)
        throw Error("internal error: a grip constraint column is not in the tangent's pattern");
      vals[at - inner] += c;
    });
  }
}

bool StaticSolver::owns_row(const SparseRow&, int row) const {
  return opt_.distribution->owns_point(row / model_->dimension());
}

void StaticSolver::apply_grip_product(const Eigen::VectorXd& x, Eigen::VectorXd& out) const {
  for (std::size_t g = 0; g < grip_dof_.size(); ++g) {
    double v = 0;
    grip_row(g, [&](int col, double c) { v += c * x[col]; });
    out[grip_dof_[g]] = v;
  }
}

void StaticSolver::external_force(double t, Eigen::VectorXd& fext) const {
  const int d = model_->dimension();
  fext.setZero(model_->dofs());
  for (std::size_t s = 0; s < tsets_.size(); ++s) {
    const Vec3 tr = tsets_[s].traction(t);
    for (std::size_t i = 0; i < tsets_[s].points.size(); ++i)
      for (int a = 0; a < d; ++a) fext[d * tsets_[s].points[i] + a] += tr(a) * traction_area_[s][i];
  }
}

Vec3 StaticSolver::reaction(std::size_t set) const {
  const int d = model_->dimension();
  Eigen::VectorXd fext;
  external_force(t_, fext);
  Vec3 r = Vec3::Zero();
  for (int p : dsets_.at(set).points)
    for (int a = 0; a < d; ++a) r(a) += f_[d * p + a] - fext[d * p + a];
  return r;
}

double StaticSolver::force_balance(Vec3* sum, double* load) const {
  // Σ (f_int − f_ext) over the prescribed components (the constraint forces on the body) plus
  // Σ f_ext (the applied tractions): zero for a body in equilibrium. The free components add
  // their Newton residual, so the value is the discrete balance plus the solve's tolerance.
  const int d = model_->dimension();
  Eigen::VectorXd fext;
  external_force(t_, fext);
  Vec3 b = Vec3::Zero();
  for (std::size_t i = 0; i < model_->dofs(); ++i) {
    b(static_cast<int>(i % d)) += fext[i];
    if (prescribed_by_[i] >= 0) b(static_cast<int>(i % d)) += f_[i] - fext[i];
  }
  double scale = 0.0;  // the load: the largest set force
  for (std::size_t s = 0; s < dsets_.size(); ++s) scale = std::max(scale, reaction(s).norm());
  for (std::size_t s = 0; s < tsets_.size(); ++s) {
    Vec3 t = Vec3::Zero();
    for (std::size_t i = 0; i < tsets_[s].points.size(); ++i)
      for (int a = 0; a < d; ++a) t(a) += fext[d * tsets_[s].points[i] + a];
    scale = std::max(scale, t.norm());
  }
  if (sum) *sum = b;
  if (load) *load = scale;
  peak_load_ = std::max(peak_load_, scale);
  return peak_load_ > 0 ? b.norm() / peak_load_ : b.norm();
}

bool StaticSolver::newton(double t_target, StepReport& rep) {
  const std::size_t n = model_->dofs();
  const int nf = static_cast<int>(free_dofs_.size());
  Eigen::VectorXd fext, f, du_c = Eigen::VectorXd::Zero(n);
  external_force(t_target, fext);
  for (std::size_t i = 0; i < n; ++i)
    if (prescribed_by_[i] >= 0 && free_index_[i] < 0) {
      const auto& set = dsets_[prescribed_by_[i] >> 2];
      du_c[i] = set.component[prescribed_by_[i] & 3](t_target) - u_[i];
    }
  Eigen::VectorXd u = u_;
  Eigen::VectorXd Rf(nf), dx(nf), rhs(nf), Rtrial(nf);
  bool grip_load_step = false;
  const double dx_scale = model_->body().spacing();
  rep.residual_history.clear();
  double last_inc = INFINITY;
  const bool mf = opt_.matrix_free;
  auto& S = *solvers_;
  // matrix-free: f and the per-stencil tangents (the operator); else f and the assembled K
  Distribution* dist = opt_.distribution.get();
  const auto evaluate = [&] {
    const bool ok = mf ? model_->internal_force_and_operator(u, f)
                       : model_->internal_force_and_tangent(u, f, K_);
    if (dist) return distributed_ok(*dist, ok) && (dist->sum(f), true);
    return ok;
  };
  // The converged state: u, f and (check_stability) the inertia of K at u.
  const auto accept = [&](int it, double rnorm) {
    rep.iterations = it;
    rep.residual = rnorm;
    u_ = u;
    f_ = f;
    if (opt_.check_stability) {
      Eigen::VectorXd ftmp;  // matrix-free: K assembled for the inertia only
      if (mf && !model_->internal_force_and_tangent(u, ftmp, K_)) return false;
      rep.negative_eigenvalues = tangent_inertia();  // K_ is at u
    }
    return true;
  };
  // The increments of the last 8 iterations (the window of the stagnation rule), ring.
  std::array<double, 8> increments;
  increments.fill(INFINITY);
  for (int it = 0; it < opt_.max_iterations; ++it) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!evaluate() && !(inadmissible_ && inadmissible_(u) && evaluate())) return false;
    if (!grip_dof_.empty() && !mf) apply_grip_rows(K_);
    const auto t1 = std::chrono::steady_clock::now();
    reduced_residual(u, f, fext, t_target, Rf);
    const double scale = std::max({f.norm(), fext.norm(), force_floor_, 1e-300});
    // Surface grips: in the first iteration their rows hold the load increment κ (ū(t) − C u),
    // the counterpart of Δu_c of the eliminated components, which is no residual either:
    // left out of the norm, and (as Δu_c ≠ 0) the full step is taken.
    double grip2 = 0;
    for (int dof : grip_dof_) grip2 += Rf[free_index_[dof]] * Rf[free_index_[dof]];
    if (it == 0) grip_load_step = std::sqrt(grip2) > 1e-10 * grip_scale_ * dx_scale;
    const double rnorm =
        (it == 0 ? std::sqrt(std::max(0.0, Rf.squaredNorm() - grip2)) : Rf.norm()) / scale;
    rep.residual_history.push_back(rnorm);
    // Stagnation or divergence: Newton near a solution gains orders of magnitude
    // within a few iterations; give the step back for a cutback early.
    if (it >= 10 && !(rnorm < 0.5 * rep.residual_history[it - 8])) {
      // Round-off floor (docs/solver.md §4, "Round-off floor"): the residual can fall no
      // further when the state no longer moves — every increment of the last 8 iterations
      // below the increment tolerance — and the residual is within kRoundoffResidualFactor
      // of the tolerance: it is the summation noise of the forces (a separated body's, whose
      // forces are round-off), not a distance to equilibrium.
      const double inc_tol = opt_.tolerance * std::max(u.norm(), dx_scale);
      const double recent_inc = *std::max_element(increments.begin(), increments.end());
      if (recent_inc <= inc_tol && rnorm <= kRoundoffResidualFactor * opt_.tolerance) {
        log::debug(
            "Newton: residual {:.3e} at its round-off floor after {} iterations "
            "(tolerance {:.1e}; increments ≤ {:.2e}, tolerance {:.2e}): accepted",
            rnorm, it, opt_.tolerance, recent_inc, inc_tol);
        rep.roundoff_floor = true;
        return accept(it, rnorm);
      }
      log::debug("Newton stagnates (residual {:.3e} after {} iterations)", rnorm, it);
      return false;
    }
    // rhs = −R_f − K_fc Δu_c (Δu_c ≠ 0 only in the first iteration of a step).
    rhs = -Rf;
    if (du_c.squaredNorm() > 0 && mf) {
      const auto tp = std::chrono::steady_clock::now();
      model_->apply_tangent(du_c, S.yfull);
      apply_grip_product(du_c, S.yfull);
      rep.product_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - tp).count();
      ++rep.operator_products;
      for (int i = 0; i < nf; ++i) rhs[i] -= S.yfull[free_dofs_[i]];
    } else if (du_c.squaredNorm() > 0 && dist) {
      // this process's partial rows of K Δu_c, summed over the processes
      Eigen::VectorXd kdu = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
      for (int r = 0; r < K_.outerSize(); ++r) {
        if (free_index_[r] < 0) continue;
        double s = 0;
        for (auto q = K_.outerIndexPtr()[r]; q < K_.outerIndexPtr()[r + 1]; ++q)
          s += K_.valuePtr()[q] * du_c[K_.innerIndexPtr()[q]];
        kdu[r] = s;
      }
      dist->sum(kdu);
      for (int i = 0; i < nf; ++i) rhs[i] -= kdu[free_dofs_[i]];
    } else if (du_c.squaredNorm() > 0) {
      for (int r = 0; r < K_.outerSize(); ++r) {
        const int fr = free_index_[r];
        if (fr < 0) continue;
        double s = 0;
        for (auto q = K_.outerIndexPtr()[r]; q < K_.outerIndexPtr()[r + 1]; ++q)
          s += K_.valuePtr()[q] * du_c[K_.innerIndexPtr()[q]];
        rhs[fr] -= s;
      }
    } else if (it > 0 && rnorm <= opt_.tolerance &&
               last_inc <= opt_.tolerance * std::max(u.norm(), dx_scale)) {
      return accept(it, rnorm);  // converged on the residual and on the last increment
    }
    // Linear solve, through the seam (linear_solver.hpp).
    LinearSystemSolver& linear = *S.linear;
    if (linear.needs_reduced()) {
      double* kv = S.Kff.valuePtr();
      const double* fv = K_.valuePtr();
      const auto nnz = static_cast<std::int64_t>(red_map_.size());
#pragma omp parallel for schedule(static)
      for (std::int64_t q = 0; q < nnz; ++q) kv[q] = fv[red_map_[q]];
    }
    const auto t_fact = std::chrono::steady_clock::now();
    double t_solve_start = 0;
    const LinearSystem sys{
        .K = K_,
        .Kff = S.Kff,
        .free_dofs = free_dofs_,
        .dofs = static_cast<Eigen::Index>(n),
        .apply_full = mf ? std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)>(
                               [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
                                 model_->apply_tangent(x, out);
                                 apply_grip_product(x, out);
                               })
                         : nullptr,
        .residual = rnorm,
        .load_factor = t_target,
        .iteration = it,
        .factor_reuse = factor_reuse_,
        .mark =
            [&] {
              t_solve_start =
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t_fact).count();
            },
    };
    const bool ok = linear.solve(sys, rhs, dx, rep);
    const auto t2 = std::chrono::steady_clock::now();
    rep.assembly_seconds += std::chrono::duration<double>(t1 - t0).count();
    rep.solve_seconds += std::chrono::duration<double>(t2 - t1).count();
    rep.factor_seconds += t_solve_start;
    if (!ok || !dx.allFinite()) {
      // The fallback rule (fallback_of): retry this iteration with the other solver, which
      // stays for the rest of the run.
      const auto fallback = fallback_of(linear.kind());
      if (!fallback) return false;
      log::warn("{}", fallback->reason);
      S.linear = make_linear(fallback->to);
      --it;
      continue;
    }
    // Line search on ‖R_f‖ (backtracking, Armijo 1e-4).
    const Eigen::VectorXd u0 = u;
    double alpha = 1.0;
    Eigen::VectorXd ftrial;
    for (int ls = 0; ls < (opt_.line_search ? 8 : 1); ++ls) {
      u = u0 + du_c;
      for (int i = 0; i < nf; ++i) u[free_dofs_[i]] += alpha * dx[i];
      if (!opt_.line_search) break;
      bool admissible = model_->internal_force(u, ftrial);
      if (dist) {
        admissible = distributed_ok(*dist, admissible);
        if (admissible) dist->sum(ftrial);
      }
      if (admissible) {
        reduced_residual(u, ftrial, fext, t_target, Rtrial);
        const double r2 = Rtrial.squaredNorm();
        const double sc = std::max({ftrial.norm(), fext.norm(), force_floor_, 1e-300});
        // Non-monotone acceptance (after Grippo, Lampariello & Lucidi 1986): the
        // full Newton step is taken unless the residual grows more than tenfold
        // over the recent maximum (far from the solution ‖R‖ may rise before the
        // quadratic phase); shorter steps must meet Armijo against that maximum.
        // The first iteration of a step changes the load: its full step is taken.
        double recent = rnorm;
        for (std::size_t h = rep.residual_history.size() > 4 ? rep.residual_history.size() - 4 : 1;
             h < rep.residual_history.size(); ++h)
          recent = std::max(recent, rep.residual_history[h]);
        const double rt = std::sqrt(r2) / sc;
        if (du_c.squaredNorm() > 0 || (it == 0 && grip_load_step) || rt <= opt_.tolerance ||
            (alpha == 1.0 ? rt <= 10.0 * recent : rt <= (1 - 1e-4 * alpha) * recent))
          break;
      }
      alpha *= 0.5;
      if (ls == 7) log::debug("line search did not reduce the residual; taking α = {}", alpha);
    }
    du_c.setZero();
    const double inc = alpha * dx.norm();
    log::debug("  iteration {}: residual {:.3e}, increment {:.3e}, alpha {}", it, rnorm, inc,
               alpha);
    last_inc = inc;
    increments[static_cast<std::size_t>(it) % increments.size()] = inc;
  }
  return false;
}

void StaticSolver::advance_to(double t_end, const std::function<void(const StepReport&)>& on_step) {
  const double nominal = (t_end - t_) > 0 ? (t_end - t_) : 1.0;
  double dt = nominal;
  int cutbacks = 0;
  while (t_ < t_end - 1e-14 * std::max(1.0, std::abs(t_end))) {
    const double t_new = std::min(t_ + dt, t_end);
    StepReport rep;
    const Eigen::VectorXd u_save = u_, f_save = f_;
    if (!newton(t_new, rep)) {
      u_ = u_save;
      f_ = f_save;
      ++cutbacks;
      if (cutbacks > opt_.max_cutbacks) {
        // Diagnosis: inertia of the tangent at the last converged state.
        std::string why = "the tangent at the last converged state could not be evaluated";
        Eigen::VectorXd ftmp;
        if (opt_.matrix_free)
          why = "the tangent's inertia was not evaluated (matrix-free: K is not assembled)";
        else if (opt_.distribution)
          why = "the tangent's inertia was not evaluated (not implemented on PETSc)";
        else if (model_->internal_force_and_tangent(u_, ftmp, K_)) {
          const int neg = tangent_inertia();
          why = neg == 0 ? fmt::format(
                               "the tangent at the last converged load factor {:.6g} is "
                               "positive definite (no loss of stability detected)",
                               t_)
                : neg > 0 ? fmt::format(
                                "LOSS OF STABILITY: the tangent at the last converged load "
                                "factor {:.6g} has {} negative eigenvalue(s) (buckling or "
                                "a limit point)",
                                t_, neg)
                          : fmt::format(
                                "LOSS OF STABILITY: the tangent at the last converged load "
                                "factor {:.6g} is singular (a bifurcation or limit point)",
                                t_);
        }
        throw NumericalError(fmt::format(
            "Newton failed at load factor {:.6g} after {} step cutbacks (last residual history: "
            "{}); {}. The load may exceed a limit point, or the deformation inverts an element "
            "(J ≤ 0). Try more load steps, a larger horizon, or check the boundary conditions",
            t_new, opt_.max_cutbacks, fmt::join(rep.residual_history, " "), why));
      }
      dt *= 0.5;
      log::warn(
          "step to t = {:.6g} did not converge ({} iterations, residual {:.3e}): cutting back to "
          "dt = {:.4g}",
          t_new, rep.residual_history.size(),
          rep.residual_history.empty() ? NAN : rep.residual_history.back(), dt);
      continue;
    }
    if (opt_.check_stability && rep.negative_eigenvalues != 0) {
      const double t_stable = t_;
      u_ = u_save;
      f_ = f_save;
      throw NumericalError(fmt::format(
          "loss of stability at load factor {:.6g}: the converged tangent stiffness{} {} "
          "(LDLᵀ inertia), so this equilibrium is unstable (buckling or a limit point between "
          "load factors {:.6g} and {:.6g}); the state at {:.6g} is kept. To follow a buckled "
          "path, add an imperfection (a small transverse load or a perturbed geometry) and "
          "use smaller load steps",
          t_new, model_->symmetric() ? "" : " (symmetric part)",
          rep.negative_eigenvalues > 0
              ? fmt::format("has {} negative eigenvalue(s)", rep.negative_eigenvalues)
              : std::string("is singular (zero pivot)"),
          t_stable, t_new, t_stable));
    }
    t_ = t_new;
    rep.t = t_;
    rep.step = ++step_;
    rep.cutbacks = cutbacks;
    rep.balance = force_balance();
    log::info(
        "step {} t = {:.6g}: {} Newton iterations, residual {:.3e}{} (history {:.2e}); "
        "force balance {:.2e} of the load; assembly {:.2f} s, linear solve {:.2f} s",
        rep.step, t_, rep.iterations, rep.residual,
        rep.roundoff_floor ? " (at its round-off floor)" : "", fmt::join(rep.residual_history, " "),
        rep.balance, rep.assembly_seconds, rep.solve_seconds);
    if (on_step) on_step(rep);
    if (dt < nominal) dt = std::min(nominal, 2 * dt);  // recover after a successful step
  }
}

int StaticSolver::tangent_inertia() {
  build_reduced();
  SparseCol& Kff = solvers_->Kff;
  for (std::size_t q = 0; q < red_map_.size(); ++q) Kff.valuePtr()[q] = K_.valuePtr()[red_map_[q]];
  const SparseCol& A = Kff;
  const SparseCol At = A.transpose();
  const SparseCol S = 0.5 * (A + At);
  // Sylvester: P S Pᵀ = L D Lᵀ has as many negative entries of D as S has negative
  // eigenvalues (no pivoting needed unless a pivot is exactly zero: reported as −2).
  Eigen::SimplicialLDLT<SparseCol, Eigen::Lower, Eigen::AMDOrdering<SolverIndex>> ldlt(S);
  if (ldlt.info() != Eigen::Success) return -2;
  int neg = 0;
  for (double dk : ldlt.vectorD()) {
    if (!(dk != 0.0) || !std::isfinite(dk)) return -2;
    if (dk < 0) ++neg;
  }
  return neg;
}

bool StaticSolver::reequilibrate(StepReport& rep) {
  const Eigen::VectorXd u_save = u_, f_save = f_;
  if (!newton(t_, rep)) {
    u_ = u_save;
    f_ = f_save;
    return false;
  }
  rep.t = t_;
  rep.step = step_;
  rep.balance = force_balance();
  return true;
}

bool StaticSolver::relax(double tol, int max_iterations, StepReport& rep) {
  if (opt_.distribution)
    throw Error("internal error: adaptive dynamic relaxation is not implemented on PETSc");
  const std::size_t n = model_->dofs();
  const int nf = static_cast<int>(free_dofs_.size());
  Eigen::VectorXd fext, f, u = u_;
  external_force(t_, fext);
  for (std::size_t i = 0; i < n; ++i)
    if (prescribed_by_[i] >= 0 && free_index_[i] < 0) {
      const auto& set = dsets_[prescribed_by_[i] >> 2];
      u[i] = set.component[prescribed_by_[i] & 3](t_);
    }
  // Surface grips: not moved by the relaxation; after every update their constraint rows are
  // solved for their own unknowns (Gauss–Seidel sweeps: the rows couple a grip column).
  auto project_grips = [&] {
    for (int sweep = 0; sweep < 4; ++sweep)
      for (std::size_t g = 0; g < grip_dof_.size(); ++g) {
        const int dof = grip_dof_[g];
        double rest = 0, self = 0;
        grip_row(g, [&](int col, double c) {
          if (col == dof)
            self += c;
          else
            rest += c * u[col];
        });
        const auto& set = dsets_[prescribed_by_[dof] >> 2];
        if (self != 0)
          u[dof] = (grip_scale_ * set.component[prescribed_by_[dof] & 3](t_) - rest) / self;
      }
  };
  project_grips();
  if (!model_->internal_force_and_tangent(u, f, K_)) {
    log::warn("adaptive dynamic relaxation: inadmissible deformation (J ≤ 0) at the start state");
    return false;
  }
  // fictitious masses from the Gershgorin row sums of the tangent (Δt = 1)
  Eigen::VectorXd lam = Eigen::VectorXd::Zero(nf);
  for (int r = 0; r < nf; ++r) {
    const int row = free_dofs_[r];
    double s = 0;
    for (auto q = K_.outerIndexPtr()[row]; q < K_.outerIndexPtr()[row + 1]; ++q)
      s += std::abs(K_.valuePtr()[q]);
    lam[r] = std::max(0.25 * s, 1e-300);
  }
  Eigen::VectorXd r_now(nf), r_old(nf), v(nf);
  auto residual = [&](double& rel) {
    for (int i = 0; i < nf; ++i) r_now[i] = fext[free_dofs_[i]] - f[free_dofs_[i]];
    for (int dof : grip_dof_) r_now[free_index_[dof]] = 0.0;  // not moved: no velocity
    rel = r_now.norm() / std::max({f.norm(), fext.norm(), force_floor_, 1e-300});
  };
  double rel = 0;
  residual(rel);
  rep.residual_history.assign(1, rel);
  v = 0.5 * r_now.cwiseQuotient(lam);
  int c_zero = 0;    // iterations with c = 0 (¹K's Rayleigh quotient ≤ 0: undamped)
  int rejected = 0;  // steps rejected by the guard (J ≤ 0 far from equilibrium)
  int last_reject = -2, streak = 0;  // streak: consecutive rejections from rest
  Eigen::VectorXd lam_streak;
  const double lam0_max = lam.maxCoeff();
  int it = 0;
  for (; it < max_iterations && rel > tol; ++it) {
    for (int i = 0; i < nf; ++i) u[free_dofs_[i]] += v[i];
    if (!grip_dof_.empty()) project_grips();
    r_old = r_now;
    bool admissible = model_->internal_force(u, f);
    // five rejections in a row, each within 3 iterations of the last (the masses up to 4⁵×
    // heavier): the forces drive the stencil through J = 0 (not an overshoot), and it breaks
    // as a near-equilibrium one would
    const bool driven = streak >= 5;
    if (!admissible && inadmissible_ && !(rel <= relax_break_residual_) && !driven) {
      // Guard (docs/effects.md §2, "No breaking far from equilibrium"): an iterate far from
      // equilibrium that inverts a stencil is a step rejection, not a failure of the
      // material. A step with momentum overshot: back, and restart from rest (kinetic
      // damping); the step right after a restart inverts: back, fictitious masses 4× heavier.
      // (Heavier masses only at the inverted stencils' points, tried first, left ADR's
      // damping estimate c_n at 4 and the cut sheet of the test unrelaxed after 50 000
      // iterations.)
      for (int i = 0; i < nf; ++i) u[free_dofs_[i]] -= v[i];
      if (!grip_dof_.empty()) project_grips();
      if (!model_->internal_force(u, f)) return false;  // the state before: admissible
      residual(rel);
      // from rest: the step right after a restart inverted; a streak: rejections at most
      // 3 iterations apart (the forces bring the stencil back to J = 0 within a few steps)
      const int gap = it - last_reject;
      const bool from_rest = gap == 1;
      last_reject = it;
      ++rejected;
      if (gap > 3) {
        lam_streak = lam;
        streak = 0;
      } else {
        ++streak;
        if (from_rest) lam *= 4.0;
      }
      v = 0.5 * r_now.cwiseQuotient(lam);
      if (rejected % 100 == 0 || rejected <= 10)
        log::debug(
            "adaptive dynamic relaxation: J ≤ 0 at iteration {} (residual {:.3e} > {:.1e}): "
            "step rejected, restart from rest{} ({} rejections)",
            it, rel, relax_break_residual_, from_rest ? ", fictitious masses ×4" : "", rejected);
      if (lam.maxCoeff() > 1e12 * lam0_max) {
        rep.iterations = it;
        rep.residual = rel;
        rep.cutbacks = rejected;
        return false;
      }
      continue;
    }
    if (!admissible && driven) {
      lam = lam_streak;  // the masses before the rejections
      streak = 0;
    }
    if (admissible) streak = 0;
    if (!admissible && inadmissible_ && inadmissible_(u)) {
      // the handler changed the model at u (rupture: inverted stencils broke): go on from
      // u with fictitious masses from the new tangent (stiffer rebuilt stencils). A tangent
      // that cannot be assembled there (a nearly degenerate stencil's material tangent
      // failing the major-symmetry check by round-off: the 30 × 30 sheet's burst at t = 0.54,
      // docs/effects.md §2) leaves the masses as they are; a step to J ≤ 0 makes them heavier.
      bool tangent = false;
      try {
        tangent = model_->internal_force_and_tangent(u, f, K_);
      } catch (const NumericalError& e) {
        log::debug("adaptive dynamic relaxation: no tangent after the handler ({}); masses kept",
                   e.what());
      }
      if (tangent) {
        for (int r = 0; r < nf; ++r) {
          const int row = free_dofs_[r];
          double sum = 0;
          for (auto q = K_.outerIndexPtr()[row]; q < K_.outerIndexPtr()[row + 1]; ++q)
            sum += std::abs(K_.valuePtr()[q]);
          lam[r] = std::max(lam[r], 0.25 * sum);
        }
        residual(rel);
        v = 0.5 * r_now.cwiseQuotient(lam);
        continue;
      }
      admissible = model_->internal_force(u, f);
    }
    if (!admissible) {
      // inadmissible F (J ≤ 0): step back, make the fictitious masses 4× heavier, stop the motion
      for (int i = 0; i < nf; ++i) u[free_dofs_[i]] -= v[i];
      rep.iterations = it;
      rep.residual = rel;
      if (!model_->internal_force(u, f)) return false;
      residual(rel);
      lam *= 4.0;
      log::debug("adaptive dynamic relaxation: J ≤ 0 at iteration {}, fictitious masses ×4", it);
      v = 0.5 * r_now.cwiseQuotient(lam);
      if (lam.maxCoeff() > 1e12 * std::max(1.0, f.norm())) return false;
      continue;
    }
    residual(rel);
    // Kilic & Madenci's local diagonal stiffness and the damping coefficient
    // Only dofs that move: a velocity below 1e-8 of the largest comes from a residual at
    // round-off (the body in equilibrium away from the broken bonds), where k divides
    // round-off by round-off (the cut sheet: terms of ±1e13 against a sum of −179 from the
    // rest, their sign set by the thread count; docs/effects.md §2, "Thread count").
    double num = 0, den = 0;
    const double v_min = 1e-8 * v.cwiseAbs().maxCoeff();
    for (int i = 0; i < nf; ++i) {
      const double ui = u[free_dofs_[i]];
      if (std::abs(v[i]) > v_min) {
        const double k = -(r_now[i] - r_old[i]) / (lam[i] * v[i]);
        num += ui * k * ui;
      }
      den += ui * ui;
    }
    const double c = (num > 0 && den > 0) ? 2.0 * std::sqrt(num / den) : 0.0;
    if (c == 0.0) ++c_zero;
    // c_n at the Gershgorin bound (ω = 2 with Δt = 1): the masses from the start tangent are
    // too light for this state, and the iterates lock into a period-2 oscillation
    // (docs/effects.md §2, "Thread count"): masses 4× heavier, restart from rest.
    if (c >= 4.0 * (1 - 1e-6)) {
      lam *= 4.0;
      v = 0.5 * r_now.cwiseQuotient(lam);
      log::debug("adaptive dynamic relaxation: c = {:.6f} at iteration {}: fictitious masses ×4", c,
                 it);
      if (lam.maxCoeff() > 1e12 * lam0_max) break;
      continue;
    }
    v = ((2.0 - c) * v + 2.0 * r_now.cwiseQuotient(lam)) / (2.0 + c);
    if (it % 500 == 0) rep.residual_history.push_back(rel);
    if (it % 2000 == 0)
      log::debug(
          "adaptive dynamic relaxation: iteration {}, residual {:.3e}, c = {:.3e} ({} with c = 0)",
          it, rel, c, c_zero);
  }
  rep.residual_history.push_back(rel);
  rep.iterations = it;
  rep.residual = rel;
  rep.cutbacks = rejected;
  if (rel > tol) return false;
  u_ = u;
  f_ = f;
  return true;
}

bool StaticSolver::pseudo_transient(double tol, int max_iterations, StepReport& rep) {
  rep.residual_history.clear();
  rep.iterations = 0;
  rep.stalled = false;
  LinearSolver linear = solvers_->linear->kind();  // (after any fallback of the Newton solves)
  if (opt_.matrix_free || linear == LinearSolver::gmres || linear == LinearSolver::bicgstab)
    return false;  // needs a factorisation of the shifted tangent
  const int nf = static_cast<int>(free_dofs_.size());
  auto& S = solvers_->factors;
  build_reduced();
  SparseCol& Kff = solvers_->Kff;
  std::vector<std::int64_t> diag(nf, -1);  // position of (c, c) in K_ff's values
  for (int c = 0; c < nf; ++c)
    for (auto q = Kff.outerIndexPtr()[c]; q < Kff.outerIndexPtr()[c + 1]; ++q)
      if (Kff.innerIndexPtr()[q] == c) diag[c] = q;
  Eigen::VectorXd fext, f, ft, u = u_, ut, Rf(nf), Rt(nf), dx(nf), D(nf), rhs(nf);
  external_force(t_, fext);
  const auto t0 = std::chrono::steady_clock::now();
  auto eval = [&](const Eigen::VectorXd& x, Eigen::VectorXd& fx) {
    if (!model_->internal_force_and_tangent(x, fx, K_)) return false;
    if (!grip_dof_.empty()) apply_grip_rows(K_);
    return true;
  };
  auto relative = [&](const Eigen::VectorXd& R, const Eigen::VectorXd& fx) {
    return R.norm() / std::max({fx.norm(), fext.norm(), force_floor_, 1e-300});
  };
  if (!eval(u, f) && !(inadmissible_ && inadmissible_(u) && eval(u, f))) {
    log::warn("pseudo-transient continuation: inadmissible deformation (J ≤ 0) at the start");
    return false;
  }
  reduced_residual(u, f, fext, t_, Rf);
  double rnorm = relative(Rf, f);
  rep.residual_history.push_back(rnorm);
  // D: Gershgorin row sums of the start tangent (grip rows are constraints: no shift)
  for (int r = 0; r < nf; ++r) {
    const int row = free_dofs_[r];
    double sum = 0;
    for (auto q = K_.outerIndexPtr()[row]; q < K_.outerIndexPtr()[row + 1]; ++q)
      sum += std::abs(K_.valuePtr()[q]);
    D[r] = sum;
  }
  for (int dof : grip_dof_) D[free_index_[dof]] = 0.0;
  bool umf_analysed = linear == LinearSolver::umfpack;
  double sigma = 1.0;
  int rejected = 0;
  bool model_changed = false;
  auto done = [&](bool ok) {
    rep.residual = rnorm;
    rep.cutbacks = rejected;
    rep.assembly_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() -
        rep.solve_seconds;
    // Once the handler changed the model (stencils broke), the start state may be
    // inadmissible for it: keep the last admissible state even on failure (for relax).
    if (ok || model_changed) {
      u_ = u;
      f_ = f;
    }
    return ok;
  };
  // Stall rule: stop when the smallest residual of the last stall_window factorisations is
  // not below stall_factor of the smallest before them (or since the model last changed).
  // The 50 × 50 sheet's burst pass oscillated between 0.67 and 1.0 of the load for 100
  // factorisations; the passes the continuation resolves took ≤ 18 factorisations.
  constexpr int stall_window = 20;
  constexpr double stall_factor = 0.5;
  std::vector<double> best_after;  // smallest residual after each factorisation
  best_after.reserve(static_cast<std::size_t>(std::max(0, max_iterations)) + 1);
  best_after.push_back(rnorm);
  auto stalled = [&] {
    const std::size_t n = best_after.size();
    return n > static_cast<std::size_t>(stall_window) &&
           best_after.back() > stall_factor * best_after[n - 1 - stall_window];
  };
  while (rnorm > tol) {
    if (stalled()) {
      rep.stalled = true;
      log::debug(
          "pseudo-transient continuation: stalled (smallest residual {:.3e} after {} "
          "factorisations, {:.3e} {} factorisations before)",
          best_after.back(), rep.iterations, best_after[best_after.size() - 1 - stall_window],
          stall_window);
    }
    if (rep.iterations >= max_iterations || sigma > 1e8 || rep.stalled) {
      if (log::level() <= log::Level::debug) {  // where the residual sits
        const int d = model_->dimension();
        std::vector<std::pair<double, int>> big;
        for (int i = 0; i < nf; ++i) big.emplace_back(std::abs(Rf[i]), free_dofs_[i]);
        std::partial_sort(big.begin(), big.begin() + std::min<int>(5, nf), big.end(),
                          std::greater<>());
        for (int k = 0; k < std::min<int>(5, nf); ++k) {
          const int p = big[k].second / d;
          const Vec3& x = model_->body().positions()[p];
          log::debug(
              "  pseudo-transient: |R| {:.3e} ({:.2f} of ‖R‖) at point {} ({:.3f}, {:.3f}), "
              "u = ({:.3f}, {:.3f})",
              big[k].first, big[k].first / Rf.norm(), p, x.x(), x.y(), u[d * p], u[d * p + 1]);
        }
      }
      return done(false);
    }
    double* kv = Kff.valuePtr();
    const double* fv = K_.valuePtr();
    const auto nnz = static_cast<std::int64_t>(red_map_.size());
#pragma omp parallel for schedule(static)
    for (std::int64_t q = 0; q < nnz; ++q) kv[q] = fv[red_map_[q]];
    for (int c = 0; c < nf; ++c) kv[diag[c]] += sigma * D[c];
    const auto ts = std::chrono::steady_clock::now();
    bool ok = false;
    rhs = -Rf;
    {
      const SerialBlas serial;
      if (linear == LinearSolver::cholmod) {
        S.cholmod.factorize(Kff);
        ok = S.cholmod.info() == Eigen::Success;
        if (ok) dx = S.cholmod.solve(rhs);
        if (!ok || !dx.allFinite()) {  // shifted tangent not positive definite: LU from now on
          linear = LinearSolver::umfpack;
          ok = false;
        }
      }
      if (linear == LinearSolver::umfpack) {
        if (!umf_analysed) S.umfpack.analyzePattern(Kff);
        umf_analysed = true;
        S.umfpack.factorize(Kff);
        ok = S.umfpack.info() == Eigen::Success;
        if (ok) dx = S.umfpack.solve(rhs);
      } else if (linear == LinearSolver::sparse_lu) {
        S.lu.factorize(Kff);
        ok = S.lu.info() == Eigen::Success;
        if (ok) dx = S.lu.solve(rhs);
      }
    }
    rep.solve_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - ts).count();
    ++rep.iterations;
    ut = u;
    if (ok && dx.allFinite())
      for (int i = 0; i < nf; ++i) ut[free_dofs_[i]] += dx[i];
    double rt = INFINITY;
    bool changed = false;  // the handler changed the model at ut (inverted stencils broke)
    if (ok && dx.allFinite()) {
      bool admissible = eval(ut, ft);
      // As in ADR: stencils that invert on the way break there (rupture), and the
      // continuation goes on from that state with the changed model.
      // Only on short (gradient-flow-like) steps, σ ≥ 0.1: a near-Newton trial step can be
      // wild, and breaking what it inverts is spurious (measured: 227 bonds at σ = 1.2e-4 on
      // the 50 × 50 sheet; the 20 × 20 sheet's burst needed it at σ = 0.125).
      if (!admissible && sigma >= 0.1 && inadmissible_ && inadmissible_(ut)) {
        model_changed = true;
        admissible = changed = eval(ut, ft);
      }
      if (admissible) {
        reduced_residual(ut, ft, fext, t_, Rt);
        rt = relative(Rt, ft);
      }
    }
    log::debug("  pseudo-transient {}: residual {:.3e} -> {:.3e}, sigma {:.3e}{}", rep.iterations,
               rnorm, rt, sigma, changed ? " (inverted stencils broke)" : "");
    if (changed)  // another model: the residuals before do not compare
      best_after.assign(1, rt);
    else
      best_after.push_back(std::min(best_after.back(), rt));
    if (!changed && !(rt <= 2.0 * rnorm)) {
      // inadmissible, singular or growing: a shorter pseudo-time step from the same state
      ++rejected;
      sigma = std::max(10.0 * sigma, 1e-6);
      if (!eval(u, f)) return done(false);  // K_ back at u
      continue;
    }
    u.swap(ut);
    f.swap(ft);
    Rf.swap(Rt);
    // SER: the pseudo-time step grows as the residual falls, at least twofold per accepted
    // step (plain SER, σ ∝ ‖R‖, needed 33 factorisations on the 50 × 50 sheet's first
    // unstable pass, the residual falling by ≈ 0.82 per step); σ ≪ 1 is Newton
    if (!changed) sigma *= std::min(0.5, rt / rnorm);
    if (sigma < 1e-12) sigma = 0.0;
    rnorm = rt;
    rep.residual_history.push_back(rnorm);
  }
  return done(true);
}

void StaticSolver::restore(const Eigen::VectorXd& u, const Eigen::VectorXd& f, double t, int step,
                           double peak_load) {
  if (u.size() != u_.size() || f.size() != u_.size())
    throw Error("internal error: restored state of another size");
  if (!(peak_load >= 0)) throw Error("internal error: restored peak load is negative or NaN");
  peak_load_ = peak_load;
  u_ = u;
  f_ = f;
  t_ = t;
  step_ = step;
}

void StaticSolver::prepare_restart() {
  if (opt_.distribution)
    throw InputError("restart is not implemented on PETSc (docs/scale-out.md)")
        .key("--restart")
        .fix("rerun from the start, or restart a run made on one process");
  auto& S = *solvers_;
  if (!S.linear->needs_analysis()) return;
  Eigen::VectorXd f;
  if (!model_->internal_force_and_tangent(Eigen::VectorXd::Zero(model_->dofs()), f, K_))
    throw NumericalError("inadmissible reference state while preparing a restart");
  if (!grip_dof_.empty()) apply_grip_rows(K_);
  for (std::size_t q = 0; q < red_map_.size(); ++q)
    S.Kff.valuePtr()[q] = K_.valuePtr()[red_map_[q]];
  S.linear->analyse(S.Kff);
}

void StaticSolver::run(const std::function<void(const StepReport&)>& on_step) {
  const int steps = std::max(1, opt_.steps);
  for (int s = 1; s <= steps; ++s) advance_to(static_cast<double>(s) / steps, on_step);
}

}  // namespace pdcg::solver
