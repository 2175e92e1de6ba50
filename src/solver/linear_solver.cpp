#include "linear_solver.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/IterativeLinearSolvers>
#include <algorithm>
#include <chrono>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"

namespace pdcg::solver {

LinearSolver linear_solver_for(LinearSolver requested, bool symmetric_tangent, bool surface_grips) {
  if (requested != LinearSolver::cholmod) return requested;
  if (!symmetric_tangent) {
    log::info("weak-form tangent is unsymmetric: using UMFPACK instead of CHOLMOD");
    return LinearSolver::umfpack;
  }
  if (surface_grips) {
    log::info("grips on the surface make the system unsymmetric: using UMFPACK");
    return LinearSolver::umfpack;
  }
  return requested;
}

std::optional<Fallback> fallback_of(LinearSolver failed) {
  if (failed == LinearSolver::cholmod)
    return Fallback{LinearSolver::umfpack,
                    "CHOLMOD failed (tangent not positive definite); falling back to UMFPACK"};
  if (failed == LinearSolver::bicgstab)
    return Fallback{LinearSolver::umfpack, "BiCGSTAB did not converge; falling back to UMFPACK"};
  return std::nullopt;
}

namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Forcing term (inexact Newton, Eisenstat & Walker 1996): ‖R‖² keeps the quadratic
// convergence of the direct solve (each Newton iteration costs an assembly, the
// dominant cost in 3D, so Krylov digits are cheaper than Newton iterations), capped
// at 1e-4, and no tighter than the next residual needs to meet the tolerance.
double forcing_term(double rnorm, double tolerance) {
  return std::min(1e-4, std::max(rnorm * rnorm, 0.1 * tolerance / std::max(rnorm, 1e-300)));
}

/// CHOLMOD supernodal LLᵀ; the pattern analysed once.
class CholmodSolver final : public LinearSystemSolver {
 public:
  explicit CholmodSolver(DirectFactors& f) : f_(f) {}
  LinearSolver kind() const override { return LinearSolver::cholmod; }
  bool solve(const LinearSystem& sys, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx,
             StepReport&) override {
    const SerialBlas serial;
    if (!analysed_) f_.cholmod.analyzePattern(sys.Kff);
    analysed_ = true;
    f_.cholmod.factorize(sys.Kff);
    sys.mark();
    const bool ok = f_.cholmod.info() == Eigen::Success;
    if (ok) dx = f_.cholmod.solve(rhs);
    return ok;
  }
  bool needs_analysis() const override { return !analysed_; }
  void analyse(const SparseCol& Kff) override {
    f_.cholmod.analyzePattern(Kff);
    analysed_ = true;
  }

 private:
  DirectFactors& f_;
  bool analysed_ = false;
};

/// UMFPACK LU (METIS ordering, no iterative refinement: the Newton iteration is the
/// refinement); with factor reuse, GMRES preconditioned by the last factor first.
class UmfpackSolver final : public LinearSystemSolver {
 public:
  UmfpackSolver(DirectFactors& f, const NewtonOptions& o)
      : f_(f), tolerance_(o.tolerance), gmres_(o.gmres_restart) {}
  LinearSolver kind() const override { return LinearSolver::umfpack; }
  bool solve(const LinearSystem& sys, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx,
             StepReport& rep) override {
    const SerialBlas serial;
    const SparseCol& A = sys.Kff;
    if (sys.factor_reuse > 0 && factored_ && analysed_) {
      // Factor reuse (rupture passes, docs/effects.md §2): GMRES on K_ff preconditioned
      // by the last factor, a tangent a few broken bonds or a load increment away; a new
      // factorisation only if it does not reach the forcing term of the direct solve's
      // gmres path within factor_reuse products.
      const double eta = forcing_term(sys.residual, tolerance_);
      const Gmres::Operator apply_K = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
        out.noalias() = A * in;
        ++rep.operator_products;
      };
      const Gmres::Operator apply_M = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
        out = f_.umfpack.solve(in);
      };
      const GmresReport g = gmres_.solve(apply_K, apply_M, rhs, dx, eta, sys.factor_reuse);
      rep.krylov_iterations += g.iterations;
      if (g.converged && dx.allFinite()) {
        // an aged factor (more than a third of the budget spent, > 10 of the rupture
        // passes' 30): factorise at the next iteration rather than pay more Krylov
        // iterations on every later system
        if (3 * g.iterations > sys.factor_reuse) factored_ = false;
        sys.mark();
        return true;
      }
      log::debug(
          "  factor reuse: GMRES at {:.2e} after {} iterations (forcing {:.1e}); "
          "new factorisation",
          g.relative_residual, g.iterations, eta);
    }
    if (!analysed_) f_.umfpack.analyzePattern(A);
    analysed_ = true;
    f_.umfpack.factorize(A);
    ++rep.factorisations;
    sys.mark();
    const bool ok = f_.umfpack.info() == Eigen::Success;
    factored_ = ok;
    // e.g. −1 = out of memory (the int version addresses at most 2³¹ 8-byte units)
    if (!ok)
      log::warn("UMFPACK factorisation failed (status {}, matrix {} × {}, {} nonzeros)",
                f_.umfpack.umfpackFactorizeReturncode(), A.rows(), A.cols(), A.nonZeros());
    if (ok) dx = f_.umfpack.solve(rhs);
    return ok;
  }
  bool needs_analysis() const override { return !analysed_; }
  void analyse(const SparseCol& Kff) override {
    f_.umfpack.analyzePattern(Kff);
    analysed_ = true;
  }

 private:
  DirectFactors& f_;
  double tolerance_;
  Gmres gmres_;
  bool analysed_ = false;
  bool factored_ = false;  // f_.umfpack holds a numeric factor (of some earlier K_ff)
};

/// Eigen's SparseLU (COLAMD).
class SparseLuSolver final : public LinearSystemSolver {
 public:
  explicit SparseLuSolver(DirectFactors& f) : f_(f) {}
  LinearSolver kind() const override { return LinearSolver::sparse_lu; }
  bool solve(const LinearSystem& sys, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx,
             StepReport&) override {
    if (!analysed_) f_.lu.analyzePattern(sys.Kff);
    analysed_ = true;
    f_.lu.factorize(sys.Kff);
    sys.mark();
    const bool ok = f_.lu.info() == Eigen::Success;
    if (ok) dx = f_.lu.solve(rhs);
    return ok;
  }
  bool needs_analysis() const override { return !analysed_; }
  void analyse(const SparseCol& Kff) override {
    f_.lu.analyzePattern(Kff);
    analysed_ = true;
  }

 private:
  DirectFactors& f_;
  bool analysed_ = false;
};

/// BiCGSTAB with an incomplete-LU (ILUT) preconditioner, to min(1e-3 tol, 1e-10).
class BicgstabSolver final : public LinearSystemSolver {
 public:
  explicit BicgstabSolver(double tolerance) : tolerance_(tolerance) {}
  LinearSolver kind() const override { return LinearSolver::bicgstab; }
  bool solve(const LinearSystem& sys, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx,
             StepReport& rep) override {
    bicg_.setTolerance(std::min(1e-3 * tolerance_, 1e-10));
    bicg_.setMaxIterations(5000);
    bicg_.compute(sys.Kff);  // ILUT: the "factorisation"
    sys.mark();
    dx = bicg_.solve(rhs);
    rep.krylov_iterations += static_cast<int>(bicg_.iterations());
    return bicg_.info() == Eigen::Success;
  }

 private:
  double tolerance_;
  Eigen::BiCGSTAB<SparseCol, Eigen::IncompleteLUT<double, SolverIndex>> bicg_;
};

/// Restarted GMRES preconditioned by a CHOLMOD factor of the lattice stiffness (krylov.hpp),
/// with products by the free rows of the assembled K (no reduced copy: its memory is what
/// large 3D runs cannot afford) or matrix-free (LinearSystem::apply_full).
class GmresSolver final : public LinearSystemSolver {
 public:
  GmresSolver(const NewtonOptions& o, std::function<SparseCol()> preconditioner)
      : opt_(o), build_preconditioner_(std::move(preconditioner)), gmres_(o.gmres_restart) {}
  LinearSolver kind() const override { return LinearSolver::gmres; }
  bool needs_reduced() const override { return false; }
  bool solve(const LinearSystem& sys, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx,
             StepReport& rep) override {
    const int nf = static_cast<int>(sys.free_dofs.size());
    const bool mf = opt_.matrix_free;
    if (!ready_) {
      const SparseCol P = build_preconditioner_();
      const SerialBlas serial;
      lattice_.compute(P);
      if (lattice_.info() != Eigen::Success)
        throw NumericalError(
            "GMRES preconditioner: the Cholesky factorisation of the lattice stiffness "
            "failed (not positive definite: the displacement constraints may not remove "
            "every rigid motion of some part of the body)");
      ready_ = true;
      xfull_.setZero(sys.dofs);
      yfull_.setZero(xfull_.size());
    }
    sys.mark();
    const double eta = forcing_term(sys.residual, opt_.tolerance);
    // Threads only for large products: a GMRES iteration has two parallel regions, and
    // on a loaded machine each barrier can cost a time slice (measured 18× slower with 2
    // threads than with 1 at 216 points, load 12).
    const SparseRow& K = sys.K;
    const bool threaded = K.nonZeros() > 4'000'000;
    const Gmres::Operator apply_K = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
      const auto tp = std::chrono::steady_clock::now();
      double* xf = xfull_.data();
      const int* fd = sys.free_dofs.data();
      ++rep.operator_products;
      if (mf) {  // prescribed entries of xfull stay 0
        for (int i = 0; i < nf; ++i) xf[fd[i]] = in[i];
        sys.apply_full(xfull_, yfull_);
        for (int i = 0; i < nf; ++i) out[i] = yfull_[fd[i]];
        rep.product_seconds += seconds_since(tp);
        return;
      }
#pragma omp parallel for schedule(static) if (threaded)
      for (int i = 0; i < nf; ++i) xf[fd[i]] = in[i];
      const double* kv = K.valuePtr();
      const int* ki = K.innerIndexPtr();
      const auto* ko = K.outerIndexPtr();
#pragma omp parallel for schedule(static) if (threaded)
      for (int i = 0; i < nf; ++i) {
        const int r = fd[i];
        double s = 0;
        for (auto q = ko[r]; q < ko[r + 1]; ++q) s += kv[q] * xf[ki[q]];
        out[i] = s;
      }
      rep.product_seconds += seconds_since(tp);
    };
    const Gmres::Operator apply_M = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) {
      const SerialBlas serial;
      out = lattice_.solve(in);
    };
    const GmresReport g = gmres_.solve(apply_K, apply_M, rhs, dx, eta, opt_.krylov_max_iterations);
    rep.krylov_iterations += g.iterations;
    log::debug("  GMRES: {} iterations, relative residual {:.3e} (forcing {:.1e})", g.iterations,
               g.relative_residual, eta);
    if (!g.converged)
      throw NumericalError(fmt::format(
          "GMRES({}) did not converge at load factor {:.6g}, Newton iteration {}: relative "
          "residual {:.3e} after {} iterations, required {:.1e} (true residual at each "
          "restart: {:.2e}). The lattice (Q1) preconditioner is too far from the BA "
          "tangent here — near a loss of stability or ellipticity, with many broken bonds, "
          "or a very stiff nearly incompressible material — raise krylov_max_iterations "
          "or use linear: umfpack if its factorisation fits in memory",
          opt_.gmres_restart, sys.load_factor, sys.iteration, g.relative_residual, g.iterations,
          eta, fmt::join(g.restart_residuals, " ")));
    return true;
  }

 private:
  NewtonOptions opt_;
  std::function<SparseCol()> build_preconditioner_;
  Gmres gmres_;
  Eigen::CholmodSupernodalLLT<SparseCol> lattice_;  // factorised once, at the first solve
  bool ready_ = false;
  Eigen::VectorXd xfull_;  // free vector scattered to all dofs (prescribed = 0)
  Eigen::VectorXd yfull_;  // matrix-free: the full product K xfull
};

/// PETSc (docs/scale-out.md): assembly of the processes' partial tangents into one
/// distributed matrix, KSP solve.
class DistributedSolver final : public LinearSystemSolver {
 public:
  DistributedSolver(LinearSolver kind, Distribution& dist) : kind_(kind), dist_(dist) {}
  LinearSolver kind() const override { return kind_; }
  bool needs_reduced() const override { return false; }
  bool solve(const LinearSystem& sys, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx,
             StepReport& rep) override {
    const bool ok = dist_.solve(sys.K, rhs, dx, rep);
    sys.mark();
    return ok;
  }

 private:
  LinearSolver kind_;
  Distribution& dist_;
};

}  // namespace

std::unique_ptr<LinearSystemSolver> make_linear_solver(LinearSolver kind,
                                                       const LinearSolverSetup& setup) {
  const NewtonOptions& o = setup.options;
  if (is_petsc_solver(kind)) {
    if (!o.distribution)
      throw Error("internal error: a PETSc linear solver without a Distribution");
    return std::make_unique<DistributedSolver>(kind, *o.distribution);
  }
  if (!setup.factors) throw Error("internal error: a linear solver without its factor storage");
  DirectFactors& f = *setup.factors;
  switch (kind) {
    case LinearSolver::cholmod:
      return std::make_unique<CholmodSolver>(f);
    case LinearSolver::umfpack:
      return std::make_unique<UmfpackSolver>(f, o);
    case LinearSolver::sparse_lu:
      return std::make_unique<SparseLuSolver>(f);
    case LinearSolver::bicgstab:
      return std::make_unique<BicgstabSolver>(o.tolerance);
    case LinearSolver::gmres:
      return std::make_unique<GmresSolver>(o, setup.preconditioner);
    default:
      break;
  }
  throw Error(
      fmt::format("internal error: no implementation of linear solver {}", to_string(kind)));
}

}  // namespace pdcg::solver
