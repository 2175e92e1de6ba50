// Matrix-free tangent (Model::internal_force_and_operator / apply_tangent; docs/solver.md §4):
// the product from the per-stencil tangents against the assembled K·v (whose entries are
// checked against finite differences of the residual in test_model.cpp), for the BA weak and
// energy forms and the classical model, 2D and 3D, with eliminated Dirichlet dofs and
// anchors; and a Newton solve with matrix-free GMRES against the direct solve.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "pdcg/core/error.hpp"
#include "pdcg/solver/newton.hpp"
#include "pdcg_test.hpp"
#include "reduced_condition.hpp"

using namespace pdcg::solver;

namespace {

Discretization holed(int dim) {
  GridSpec g;
  g.dimension = dim;
  g.spacing = dim == 2 ? 1.0 / 14 : 1.0 / 6;
  g.holes.push_back({Vec3(0.5, 0.5, 0.5), dim == 2 ? 0.2 : 0.25});
  return Discretization::grid(g);
}

// A random large deformation: 30 % stretch in x, 9 % contraction in the others, noise.
Eigen::VectorXd deformation(const Discretization& D, unsigned seed) {
  const int dim = D.dimension();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd u(dim * D.size());
  for (std::size_t i = 0; i < D.size(); ++i)
    for (int a = 0; a < dim; ++a)
      u[dim * i + a] =
          0.3 * D.positions()[i](a) * (a == 0 ? 1 : -0.3) + 0.05 * D.spacing() * U(rng);
  return u;
}

// ‖K v − J v‖ / ‖K v‖ for a random v (entries of prescribed dofs zeroed, their rows not
// compared: the Dirichlet elimination of the Newton solver).
double product_error(const Model& M, const Eigen::VectorXd& u, const std::vector<char>& fixed,
                     unsigned seed) {
  Eigen::VectorXd f, fm, Kv, Jv;
  SparseRow K;
  EXPECT_TRUE(M.internal_force_and_tangent(u, f, K));
  EXPECT_TRUE(M.internal_force_and_operator(u, fm));
  // the two force evaluations sum the same terms in different orders
  EXPECT_LT((f - fm).norm(), 1e-13 * f.norm());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd v(M.dofs());
  for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = fixed.empty() || !fixed[i] ? U(rng) : 0.0;
  Kv = K * v;
  M.apply_tangent(v, Jv);
  if (!fixed.empty())
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (fixed[i]) Kv[i] = Jv[i] = 0.0;
  EXPECT_GT(Kv.norm(), 0.0);
  return (Kv - Jv).norm() / Kv.norm();
}

// Round-off of sums of O(|A| |G|² |v|) terms (≈ 60–5 500 per row) in different orders, and
// the symmetrised packing (A_ij + A_ji)/2 of tangents symmetric to ≈ 1e-16: ≲ 1e-14.
constexpr double kProductTol = 1e-13;

void check(int dim, Kinematics kin, ModelOptions mo) {
  const auto D = holed(dim);
  const auto mat = make_neo_hookean({1.0, 10.0}, kin);
  const Model M(D, *mat, mo);
  EXPECT_LT(product_error(M, deformation(D, 3), {}, 11), kProductTol);
  // a second state: the operator follows u
  EXPECT_LT(product_error(M, deformation(D, 4), {}, 12), kProductTol);
  EXPECT_GT(M.operator_bytes(), 0u);
}

}  // namespace

TEST(MatrixFree, ProductPlaneStrainWeak) { check(2, Kinematics::plane_strain, {}); }
TEST(MatrixFree, ProductPlaneStressWeak) { check(2, Kinematics::plane_stress, {}); }
TEST(MatrixFree, ProductPlaneStrainEnergy) {
  check(2, Kinematics::plane_strain, {Correspondence::bond_associated, BoundaryForm::energy});
}
TEST(MatrixFree, ProductClassicalWeak) {
  check(2, Kinematics::plane_strain, {Correspondence::classical, BoundaryForm::weak});
}
TEST(MatrixFree, Product3DWeak) { check(3, Kinematics::three_d, {}); }
TEST(MatrixFree, Product3DEnergy) {
  check(3, Kinematics::three_d, {Correspondence::bond_associated, BoundaryForm::energy});
}
TEST(MatrixFree, Product3DClassicalEnergy) {
  check(3, Kinematics::three_d, {Correspondence::classical, BoundaryForm::energy});
}

TEST(MatrixFree, ProductWithDirichletEliminationAndAnchors) {
  for (int dim : {2, 3}) {
    const auto D = holed(dim);
    const auto mat =
        make_neo_hookean({1.0, 10.0}, dim == 2 ? Kinematics::plane_strain : Kinematics::three_d);
    Model M(D, *mat, {});
    const Eigen::VectorXd u = deformation(D, 5);
    // anchors on three points (spring κ on the diagonal)
    std::vector<int> pts{0, static_cast<int>(D.size() / 2), static_cast<int>(D.size() - 1)};
    std::vector<double> targets(pts.size() * dim, 0.01);
    M.set_anchors(pts, targets, 7.5);
    // left face prescribed in all components
    std::vector<char> fixed(M.dofs(), 0);
    for (std::size_t i = 0; i < D.size(); ++i)
      if (D.positions()[i].x() < D.spacing())
        for (int a = 0; a < dim; ++a) fixed[dim * i + a] = 1;
    EXPECT_LT(product_error(M, u, fixed, 21), kProductTol) << dim << "D";
    EXPECT_LT(product_error(M, u, {}, 22), kProductTol) << dim << "D";
  }
}

namespace {
struct Case {
  Discretization body;
  std::vector<DisplacementSet> sets;
};
// Unit square with a hole / unit cube: left face x-fixed, pins, right face displaced.
Case stretched(int dim, int n, double stretch) {
  GridSpec g;
  g.dimension = dim;
  g.spacing = 1.0 / n;
  if (dim == 2) g.holes.push_back({Vec3(0.5, 0.5, 0), 0.2});  // (3D 6³: a hole buckles)
  Case c{Discretization::grid(g), {}};
  const double dx = g.spacing;
  DisplacementSet left{"left", {}, {}}, pin{"pin", {}, {}}, pin2{"pin2", {}, {}},
      right{"right", {}, {}};
  left.component[0] = [](double) { return 0.0; };
  pin.component[1] = [](double) { return 0.0; };
  if (dim == 3) pin.component[2] = [](double) { return 0.0; };
  pin2.component[1] = [](double) { return 0.0; };
  right.component[0] = [=](double t) { return (stretch - 1) * (1 - dx) * t; };
  for (std::size_t i = 0; i < c.body.size(); ++i) {
    const Vec3& x = c.body.positions()[i];
    if (x.x() < dx) left.points.push_back(i);
    if (x.x() > 1 - dx) right.points.push_back(i);
    if (x.x() < dx && x.y() < dx && (dim == 2 || x.z() < dx)) pin.points.push_back(i);
    if (dim == 3 && x.x() < dx && x.y() < dx && x.z() > 1 - dx) pin2.points.push_back(i);
  }
  c.sets = {left, pin, right};
  if (dim == 3) c.sets.push_back(pin2);
  return c;
}
}  // namespace

TEST(MatrixFree, NewtonGmresSameSolutionAsDirect) {
  // Weak form (unsymmetric tangent), 2D plane strain 14² with a hole (stretch 1.2, two load
  // steps) and a 3D 6³ cube (stretch 1.1, one step): matrix-free GMRES reaches the UMFPACK
  // equilibrium.
  for (int dim : {2, 3}) {
    auto c = stretched(dim, dim == 2 ? 14 : 6, dim == 2 ? 1.2 : 1.1);
    const auto mat =
        make_neo_hookean({1.0, 10.0}, dim == 2 ? Kinematics::plane_strain : Kinematics::three_d);
    Model M(c.body, *mat);
    const double tol = 1e-10;
    std::vector<Eigen::VectorXd> u;
    int products = 0, krylov = 0;
    for (bool mf : {false, true}) {
      NewtonOptions o;
      o.steps = dim == 2 ? 2 : 1;
      o.tolerance = tol;
      o.linear = mf ? LinearSolver::gmres : LinearSolver::umfpack;
      o.matrix_free = mf;
      StaticSolver solver(M, c.sets, {}, o);
      solver.run([&](const StepReport& r) {
        if (mf) {
          products += r.operator_products;
          krylov += r.krylov_iterations;
        }
      });
      u.push_back(solver.displacement());
    }
    EXPECT_GT(krylov, 0);
    EXPECT_GE(products, krylov);  // + one product per restart and per step's predictor
    // Both satisfy ‖R_f‖ ≤ tol ‖f‖: their difference is bounded by κ(K_ff) · tol · ‖u‖
    // (κ from a dense SVD of the reduced tangent at the solution).
    const double cond = test_support::reduced_condition_number(M, c.sets, u[0]);
    EXPECT_LT((u[1] - u[0]).norm(), 10 * cond * tol * u[0].norm())
        << dim << "D, condition number " << cond;
    EXPECT_GT(u[0].norm(), 0.05);
  }
}

TEST(MatrixFree, NeedsGmres) {
  auto c = stretched(2, 8, 1.1);
  const auto mat = make_neo_hookean({1.0, 10.0}, Kinematics::plane_strain);
  Model M(c.body, *mat);
  NewtonOptions o;
  o.linear = LinearSolver::umfpack;
  o.matrix_free = true;
  try {
    StaticSolver solver(M, c.sets, {}, o);
    FAIL() << "expected InputError";
  } catch (const pdcg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gmres"), std::string::npos) << e.what();
  }
}
