/// \file
/// The linear-solver seam of StaticSolver (docs/architecture.md, "Linear solvers"): one
/// Newton system K_ff Δx = rhs on the free dofs is solved through LinearSystemSolver, whose
/// implementations (CHOLMOD, UMFPACK with optional factor reuse, Eigen SparseLU, BiCGSTAB +
/// ILUT, GMRES with the lattice preconditioner on an assembled or a matrix-free tangent,
/// PETSc through a Distribution) are created by make_linear_solver from the solver options.
/// Which solver replaces which is a rule in two functions here: linear_solver_for (before
/// the first solve) and fallback_of (after a failed solve). Internal to the solver module
/// (it names SuiteSparse's index type).
#pragma once

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <Eigen/UmfPackSupport>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "pdcg/solver/krylov.hpp"
#include "pdcg/solver/newton.hpp"

namespace pdcg::solver {

// The reduced tangent uses 64-bit indices, so that UMFPACK runs as umfpack_dl_* and CHOLMOD
// through its cholmod_l_* interface: the int versions address their workspace with int
// (at most 2³¹ units) and fail with "out of memory" on the LU of the 2D 1.6·10⁵-point plate
// (docs/performance.md). Cost at small sizes: 4 more bytes per nonzero of K_ff (measured
// in docs/performance.md, "Long indices").
using SolverIndex = SuiteSparse_long;
using SparseCol = Eigen::SparseMatrix<double, Eigen::ColMajor, SolverIndex>;
static_assert(std::is_same_v<SparseCol, SparseColLong>, "SuiteSparse_long is not std::int64_t");

// The sparse direct factorisations spend their time in many small dense BLAS calls
// (supernodes / frontal matrices). A threaded BLAS (OpenBLAS built with OpenMP) then
// meets an OpenMP barrier per call; on a loaded or oversubscribed machine a barrier
// costs a scheduler time slice, and the factorisation was measured 20× slower with
// 2 threads than with 1 (docs/performance.md). The factorisation and the triangular
// solves therefore run on one thread; the assembly keeps all threads.
class SerialBlas {
 public:
  SerialBlas() {
#ifdef _OPENMP
    saved_ = omp_get_max_threads();
    omp_set_num_threads(1);
#endif
  }
  ~SerialBlas() {
#ifdef _OPENMP
    omp_set_num_threads(saved_);
#endif
  }
  SerialBlas(const SerialBlas&) = delete;
  SerialBlas& operator=(const SerialBlas&) = delete;

 private:
  int saved_ = 1;
};

/// The direct factorisations, shared by the Newton solvers made by make_linear_solver and by
/// StaticSolver::pseudo_transient (which factorises the shifted tangent with the same objects,
/// so that UMFPACK's symbolic analysis is done once per run).
struct DirectFactors {
  DirectFactors() {
    // METIS nested dissection for the (structurally symmetric) nonlocal pattern; the
    // strategy stays automatic (UMFPACK picks its symmetric strategy for this pattern).
    umfpack.umfpackControl()(UMFPACK_ORDERING) = UMFPACK_ORDERING_METIS;
    // No iterative refinement inside UMFPACK: the Newton iteration is the refinement.
    umfpack.umfpackControl()(UMFPACK_IRSTEP) = 0;
  }
  Eigen::CholmodSupernodalLLT<SparseCol> cholmod;
  Eigen::UmfPackLU<SparseCol> umfpack;
  Eigen::SparseLU<SparseCol> lu;
};

/// What a Newton iteration hands its linear solver. The reduced tangent Kff is filled from K
/// by the caller when the solver's needs_reduced() is true.
struct LinearSystem {
  const SparseRow& K;  ///< the full tangent (row-major, all dofs; grip rows applied)
  const SparseCol& Kff;
  const std::vector<int>& free_dofs;
  Eigen::Index dofs = 0;  ///< all dofs (d·N)
  /// Matrix-free: out = K x on all dofs (x zero on the eliminated ones).
  std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd& out)> apply_full;
  double residual = 0.0;  ///< relative Newton residual (the forcing term of the Krylov solves)
  double load_factor = 0.0;
  int iteration = 0;
  int factor_reuse = 0;        ///< UMFPACK: StaticSolver::set_factor_reuse
  std::function<void()> mark;  ///< call at the end of the factorisation (timing)
};

/// One way of solving K_ff Δx = rhs (MFEM's Solver, PETSc's KSP + PC). solve() returns false
/// (or a non-finite dx) when the solve failed; StaticSolver then applies fallback_of.
class LinearSystemSolver {
 public:
  virtual ~LinearSystemSolver() = default;
  virtual LinearSolver kind() const = 0;
  /// True if solve() reads LinearSystem::Kff (the caller gathers it from K).
  virtual bool needs_reduced() const { return true; }
  virtual bool solve(const LinearSystem& sys, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx,
                     StepReport& rep) = 0;
  /// Direct solvers: true until the symbolic analysis of Kff's pattern is done; analyse()
  /// does it (a restarted run, with the tangent at u = 0, as the first Newton iteration of a
  /// fresh run would: UMFPACK's analysis looks at the values).
  virtual bool needs_analysis() const { return false; }
  virtual void analyse(const SparseCol& /*Kff*/) {}
};

/// Everything make_linear_solver needs besides the kind.
struct LinearSolverSetup {
  NewtonOptions options;  ///< tolerance, gmres_restart, krylov_max_iterations, distribution
  DirectFactors* factors = nullptr;
  /// GMRES: builds the preconditioner matrix (the lattice stiffness on the free dofs); called
  /// at the first solve.
  std::function<SparseCol()> preconditioner;
};

/// The rule before the first solve: CHOLMOD needs a symmetric system; the weak-form tangent
/// and the constraint rows of grips on the surface are not, so it is replaced by UMFPACK
/// (with a log line). Every other request stands.
LinearSolver linear_solver_for(LinearSolver requested, bool symmetric_tangent, bool surface_grips);

/// The rule after a failed solve: the solver that retries the same Newton iteration and takes
/// over for the rest of the run, with the reason for the log; none (the Newton step fails and
/// is cut back) otherwise. CHOLMOD (tangent not positive definite) and BiCGSTAB (not
/// converged) fall back to UMFPACK; UMFPACK, SparseLU and PETSc's solvers have no fallback;
/// GMRES throws NumericalError itself (its message says what to change).
struct Fallback {
  LinearSolver to;
  const char* reason;
};
std::optional<Fallback> fallback_of(LinearSolver failed);

/// The factory: the implementation of `kind` (a PETSc kind needs setup.options.distribution).
std::unique_ptr<LinearSystemSolver> make_linear_solver(LinearSolver kind,
                                                       const LinearSolverSetup& setup);

}  // namespace pdcg::solver
