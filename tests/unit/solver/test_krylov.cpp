// Iterative linear path (krylov.hpp): restarted GMRES against a dense LU, the lattice (Q1)
// preconditioner against closed forms of linear elasticity, and the Newton solution with
// linear = gmres against the direct (UMFPACK) one on a small 3D body.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "pdcg/core/error.hpp"
#include "pdcg/solver/krylov.hpp"
#include "pdcg/solver/newton.hpp"
#include "pdcg_test.hpp"
#include "reduced_condition.hpp"

using namespace pdcg::solver;

namespace {

// Small-strain energy density ½ H:A:H of the displacement gradient H.
double strain_energy_density(const Tangent& A, const Eigen::Matrix3d& H, int d) {
  double e = 0;
  for (int a = 0; a < d; ++a)
    for (int J = 0; J < d; ++J)
      for (int b = 0; b < d; ++b)
        for (int L = 0; L < d; ++L) e += 0.5 * H(a, J) * A(flat(a, J), flat(b, L)) * H(b, L);
  return e;
}

struct Setup3 {
  Discretization body;
  std::vector<DisplacementSet> sets;
};

Setup3 cube(int n, double stretch) {
  GridSpec g;
  g.dimension = 3;
  g.spacing = 1.0 / n;
  Setup3 s{Discretization::grid(g), {}};
  const double dx = g.spacing;
  DisplacementSet left{"left", {}, {}}, pin{"pin", {}, {}}, pin2{"pin2", {}, {}},
      right{"right", {}, {}};
  left.component[0] = [](double) { return 0.0; };
  pin.component[1] = [](double) { return 0.0; };
  pin.component[2] = [](double) { return 0.0; };
  pin2.component[1] = [](double) { return 0.0; };
  right.component[0] = [=](double t) { return (stretch - 1) * (1 - dx) * t; };
  for (std::size_t i = 0; i < s.body.size(); ++i) {
    const Vec3& x = s.body.positions()[i];
    if (x.x() < dx) left.points.push_back(i);
    if (x.x() > 1 - dx) right.points.push_back(i);
    if (x.x() < dx && x.y() < dx && x.z() < dx) pin.points.push_back(i);
    if (x.x() < dx && x.y() < dx && x.z() > 1 - dx) pin2.points.push_back(i);
  }
  s.sets = {left, pin, right, pin2};
  return s;
}

}  // namespace

TEST(Gmres, MatchesDenseLuWithRestarts) {
  // Nonsymmetric, diagonally dominant 300×300 system (condition number ≈ 3, printed),
  // restart 10 so that several restart cycles run, a Jacobi preconditioner.
  const int n = 300;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = U(rng) / std::sqrt(static_cast<double>(n));
  A.diagonal().array() += 2.0 + Eigen::ArrayXd::LinSpaced(n, 0.0, 1.0);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b(i) = U(rng);
  const Eigen::VectorXd x_ref = A.partialPivLu().solve(b);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
  const double cond = svd.singularValues()(0) / svd.singularValues()(n - 1);
  Gmres gm(10);
  Eigen::VectorXd x;
  const GmresReport r = gm.solve(
      [&](const Eigen::VectorXd& v, Eigen::VectorXd& o) { o = A * v; },
      [&](const Eigen::VectorXd& v, Eigen::VectorXd& o) { o = v.cwiseQuotient(A.diagonal()); }, b,
      x, 1e-12, 500);
  ASSERT_TRUE(r.converged);
  EXPECT_GT(r.restart_residuals.size(), 2u) << "restarts should have happened";
  EXPECT_LE(r.relative_residual, 1e-12);
  // forward error ≤ cond × backward error (1e-12), with a factor 10 for round-off
  EXPECT_LT((x - x_ref).norm(), 10 * cond * 1e-12 * x_ref.norm()) << "cond " << cond;
  // Not enough iterations: reported as not converged, with its residual.
  const GmresReport r2 =
      gm.solve([&](const Eigen::VectorXd& v, Eigen::VectorXd& o) { o = A * v; },
               [&](const Eigen::VectorXd& v, Eigen::VectorXd& o) { o = v; }, b, x, 1e-12, 3);
  EXPECT_FALSE(r2.converged);
  EXPECT_EQ(r2.iterations, 3);
  EXPECT_GT(r2.relative_residual, 1e-12);
}

TEST(LatticeStiffness, ElementIsExactForLinearFields) {
  // Q1 element of side h: a homogeneous displacement gradient H stores exactly the
  // small-strain energy ½ H:A:H h^d (bilinear/trilinear shape functions reproduce linear
  // fields, the 2-point Gauss rule integrates the constant integrand exactly); a
  // translation has zero force. Closed forms of linear elasticity.
  for (int d : {2, 3}) {
    const auto mat =
        make_neo_hookean({1.3, 7.0}, d == 3 ? Kinematics::three_d : Kinematics::plane_strain);
    Tangent A;
    ASSERT_TRUE(mat->evaluate(Eigen::Matrix3d::Identity(), nullptr, nullptr, &A));
    const double h = 0.1;
    const Eigen::MatrixXd Ke = lattice_element_stiffness(d, h, A);
    Eigen::Matrix3d H;
    H << 0.01, 0.02, -0.005, 0.004, -0.01, 0.003, 0.002, 0.006, 0.008;
    const int nc = 1 << d;
    Eigen::VectorXd u(nc * d), t(nc * d);
    for (int c = 0; c < nc; ++c) {
      Eigen::Vector3d X = Eigen::Vector3d::Zero();
      for (int a = 0; a < d; ++a) X(a) = ((c >> a) & 1) * h;
      for (int a = 0; a < d; ++a) {
        u(c * d + a) = (H * X)(a);
        t(c * d + a) = 1.0 + a;
      }
    }
    const double expect = strain_energy_density(A, H, d) * std::pow(h, d);
    EXPECT_NEAR(0.5 * u.dot(Ke * u), expect, 1e-13 * std::abs(expect));  // round-off
    EXPECT_LT((Ke * t).norm(), 1e-13 * Ke.norm());                       // round-off
    EXPECT_LT((Ke - Ke.transpose()).norm(), 1e-14 * Ke.norm());          // symmetric
  }
}

TEST(LatticeStiffness, GridPatchTestAndSpd) {
  // All points free: for u = H X the interior rows of P u vanish (equilibrium of a
  // homogeneous state), and uᵀPu/2 = ½ H:A:H × the volume the elements cover,
  // ((n − 1) h)² for an n × n grid of cell centres.
  GridSpec g;
  g.spacing = 0.1;
  const auto body = Discretization::grid(g);
  const NeoHookeanPlaneStrain mat({1.0, 10.0});
  const int nd = static_cast<int>(2 * body.size());
  std::vector<int> free_index(nd);
  for (int i = 0; i < nd; ++i) free_index[i] = i;
  const SparseColLong P = lattice_stiffness(body, mat, free_index, nd);
  Tangent A;
  ASSERT_TRUE(mat.evaluate(Eigen::Matrix3d::Identity(), nullptr, nullptr, &A));
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  H.topLeftCorner<2, 2>() << 0.01, 0.003, -0.002, 0.02;
  Eigen::VectorXd u(nd);
  for (std::size_t k = 0; k < body.size(); ++k)
    for (int a = 0; a < 2; ++a) u(2 * k + a) = (H * body.positions()[k])(a);
  const Eigen::VectorXd f = P * u;
  double fmax_interior = 0, fmax = 0;
  for (std::size_t k = 0; k < body.size(); ++k) {
    const Vec3& x = body.positions()[k];
    const bool edge = x.x() < 0.1 || x.x() > 0.9 || x.y() < 0.1 || x.y() > 0.9;
    for (int a = 0; a < 2; ++a) {
      fmax = std::max(fmax, std::abs(f(2 * k + a)));
      if (!edge) fmax_interior = std::max(fmax_interior, std::abs(f(2 * k + a)));
    }
  }
  EXPECT_LT(fmax_interior, 1e-13 * fmax);  // round-off of sums of O(fmax) terms
  const double expect = strain_energy_density(A, H, 2) * 0.81;  // (9 × 0.1)²
  EXPECT_NEAR(0.5 * u.dot(P * u), expect, 1e-12 * expect);      // round-off
  // Fix two corners' worth of rigid motion: then the Cholesky factor exists.
  std::vector<int> fi(nd);
  int nf = 0;
  for (int i = 0; i < nd; ++i) fi[i] = (i == 0 || i == 1 || i == 3) ? -1 : nf++;
  const SparseColLong Pff = lattice_stiffness(body, mat, fi, nf);
  const Eigen::MatrixXd D(Pff);
  const Eigen::LLT<Eigen::MatrixXd> llt(D);
  EXPECT_EQ(llt.info(), Eigen::Success);
}

TEST(NewtonGmres, SameSolutionAsDirectIn3D) {
  // 6³ points, weak form (unsymmetric tangent), stretch 1.1 in one load step: GMRES
  // preconditioned by the lattice stiffness reaches the same equilibrium as UMFPACK.
  auto s = cube(6, 1.1);
  NeoHookean3D mat({1.0, 10.0});
  Model M(s.body, mat);
  const double tol = 1e-10;
  std::vector<Eigen::VectorXd> u;
  int krylov = 0;
  for (auto ls : {LinearSolver::umfpack, LinearSolver::gmres}) {
    NewtonOptions o;
    o.steps = 1;
    o.tolerance = tol;
    o.linear = ls;
    StaticSolver solver(M, s.sets, {}, o);
    solver.run([&](const StepReport& r) { krylov += r.krylov_iterations; });
    u.push_back(solver.displacement());
  }
  EXPECT_GT(krylov, 0);
  // Both satisfy ‖R_f‖ ≤ tol ‖f‖; their difference is bounded by κ(K_ff) · tol · ‖u‖.
  // κ of the reduced tangent at the solution, from a dense SVD:
  const double cond = test_support::reduced_condition_number(M, s.sets, u[0]);
  EXPECT_LT((u[1] - u[0]).norm(), 10 * cond * tol * u[0].norm()) << "condition number " << cond;
  EXPECT_GT((u[0]).norm(), 0.01);
}

TEST(NewtonGmres, NonConvergenceIsANumericalError) {
  auto s = cube(6, 1.1);
  NeoHookean3D mat({1.0, 10.0});
  Model M(s.body, mat);
  NewtonOptions o;
  o.steps = 1;
  o.linear = LinearSolver::gmres;
  o.krylov_max_iterations = 2;  // far too few for the forcing tolerance
  StaticSolver solver(M, s.sets, {}, o);
  try {
    solver.run();
    FAIL() << "expected NumericalError";
  } catch (const pdcg::NumericalError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("GMRES(50) did not converge"), std::string::npos) << what;
    EXPECT_NE(what.find("after 2 iterations"), std::string::npos) << what;
    EXPECT_NE(what.find("preconditioner"), std::string::npos) << what;
  }
}

TEST(NewtonGmres, UnknownLinearSolverListsGmres) {
  try {
    parse_linear_solver("cg");
    FAIL() << "expected InputError";
  } catch (const pdcg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gmres"), std::string::npos) << e.what();
  }
  EXPECT_EQ(parse_linear_solver("gmres"), LinearSolver::gmres);
}
