// The linear-solver seam of StaticSolver (src/solver/linear_solver.hpp, docs/architecture.md
// "Linear solvers"): the factory's solvers on a small system against a dense LU, and the
// fallback rule on a system CHOLMOD must refuse.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "../../../src/solver/linear_solver.hpp"

namespace pdcg::solver {
namespace {

// A 1D chain −u'' − s u (tridiagonal 2 −1, shifted by s) with n unknowns. Its eigenvalues are
// 2 − 2 cos(kπ/(n+1)) − s: s = 0 is positive definite; s = 0.5 has negative ones (indefinite)
// and, for n = 40, none within 0.04 of zero (k = 9: −0.043; k = 10: +0.059).
SparseCol chain(int n, double s) {
  std::vector<Eigen::Triplet<double, SolverIndex>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2.0 - s);
    if (i > 0) t.emplace_back(i, i - 1, -1.0);
    if (i + 1 < n) t.emplace_back(i, i + 1, -1.0);
  }
  SparseCol K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  K.makeCompressed();
  return K;
}

struct Seam {
  explicit Seam(const SparseCol& Kff) : Kff(Kff), K(Kff), free_dofs(Kff.rows()) {
    for (int i = 0; i < Kff.rows(); ++i) free_dofs[i] = i;
    setup.options.tolerance = 1e-10;
    setup.factors = &factors;
  }
  bool solve(LinearSystemSolver& s, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx) {
    const LinearSystem sys{.K = K,
                           .Kff = Kff,
                           .free_dofs = free_dofs,
                           .dofs = Kff.rows(),
                           .apply_full = nullptr,
                           .residual = 1.0,
                           .load_factor = 1.0,
                           .iteration = 0,
                           .factor_reuse = 0,
                           .mark = [] {}};
    StepReport rep;
    return s.solve(sys, rhs, dx, rep) && dx.allFinite();
  }
  SparseCol Kff;
  SparseRow K;
  std::vector<int> free_dofs;
  DirectFactors factors;
  LinearSolverSetup setup;
};

Eigen::VectorXd dense_solution(const SparseCol& K, const Eigen::VectorXd& rhs) {
  return Eigen::MatrixXd(K).fullPivLu().solve(rhs);
}

TEST(LinearSolverSeam, DirectAndIterativeSolversMatchDenseLu) {
  const int n = 40;
  Seam seam(chain(n, 0.0));
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  const Eigen::VectorXd ref = dense_solution(seam.Kff, rhs);
  for (LinearSolver kind : {LinearSolver::cholmod, LinearSolver::umfpack, LinearSolver::sparse_lu,
                            LinearSolver::bicgstab}) {
    const auto s = make_linear_solver(kind, seam.setup);
    ASSERT_EQ(s->kind(), kind);
    EXPECT_TRUE(s->needs_reduced());
    Eigen::VectorXd dx;
    ASSERT_TRUE(seam.solve(*s, rhs, dx)) << to_string(kind);
    // condition number of the chain ≈ 4(n+1)²/π² ≈ 700: direct solves agree to ~1e-13
    // relative; BiCGSTAB is asked for 1e-13 (min(1e-3·tol, 1e-10)) of ‖rhs‖ in residual,
    // ≤ 700 × that in the solution
    EXPECT_LT((dx - ref).norm(), 1e-9 * ref.norm()) << to_string(kind);
  }
}

TEST(LinearSolverSeam, CholmodRefusesAnIndefiniteSystemAndUmfpackTakesOver) {
  const int n = 40;
  Seam seam(chain(n, 0.5));
  const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(n);
  const Eigen::VectorXd ref = dense_solution(seam.Kff, rhs);
  const auto cholmod = make_linear_solver(LinearSolver::cholmod, seam.setup);
  Eigen::VectorXd dx;
  EXPECT_FALSE(seam.solve(*cholmod, rhs, dx));  // LLᵀ of an indefinite matrix
  const auto fallback = fallback_of(LinearSolver::cholmod);
  ASSERT_TRUE(fallback.has_value());
  EXPECT_EQ(fallback->to, LinearSolver::umfpack);
  const auto umfpack = make_linear_solver(fallback->to, seam.setup);
  ASSERT_TRUE(seam.solve(*umfpack, rhs, dx));
  // smallest |eigenvalue| 0.043, largest < 3.5: condition ≈ 80; LU agrees to ~1e-14
  EXPECT_LT((dx - ref).norm(), 1e-12 * ref.norm());
  // no fallback after a failed LU: the Newton step fails and is cut back
  EXPECT_FALSE(fallback_of(LinearSolver::umfpack).has_value());
  EXPECT_FALSE(fallback_of(LinearSolver::sparse_lu).has_value());
  EXPECT_EQ(fallback_of(LinearSolver::bicgstab)->to, LinearSolver::umfpack);
}

TEST(LinearSolverSeam, CholmodIsReplacedBeforeTheFirstSolveOnlyForUnsymmetricSystems) {
  EXPECT_EQ(linear_solver_for(LinearSolver::cholmod, true, false), LinearSolver::cholmod);
  EXPECT_EQ(linear_solver_for(LinearSolver::cholmod, false, false), LinearSolver::umfpack);
  EXPECT_EQ(linear_solver_for(LinearSolver::cholmod, true, true), LinearSolver::umfpack);
  EXPECT_EQ(linear_solver_for(LinearSolver::bicgstab, false, true), LinearSolver::bicgstab);
  EXPECT_EQ(linear_solver_for(LinearSolver::gmres, false, false), LinearSolver::gmres);
}

}  // namespace
}  // namespace pdcg::solver
