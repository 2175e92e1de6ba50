// Newton solver behaviour: quadratic convergence near the solution, automatic
// cutback of a step that is too large, agreement of the linear solvers, and
// the rigid-body check. Small grids (seconds).
#include <gtest/gtest.h>

#include <cmath>

#include "pdcg/core/error.hpp"
#include "pdcg/solver/newton.hpp"
#include "pdcg_test.hpp"

using namespace pdcg::solver;

namespace {

struct Setup {
  Discretization body;
  std::vector<DisplacementSet> sets;
};

Setup uniaxial(int n, double stretch) {
  GridSpec g;
  g.spacing = 1.0 / n;
  g.size = Vec3(1, 1, 1);
  Setup s{Discretization::grid(g), {}};
  const double dx = g.spacing;
  DisplacementSet left{"left", {}, {}}, pin{"pin", {}, {}}, right{"right", {}, {}};
  left.component[0] = [](double) { return 0.0; };
  pin.component[1] = [](double) { return 0.0; };
  right.component[0] = [=](double t) { return (stretch - 1) * (1 - dx) * t; };
  for (std::size_t i = 0; i < s.body.size(); ++i) {
    const Vec3& x = s.body.positions()[i];
    if (x.x() < dx) left.points.push_back(i);
    if (x.x() > 1 - dx) right.points.push_back(i);
    if (x.x() < dx && x.y() < dx) pin.points.push_back(i);
  }
  s.sets = {left, pin, right};
  return s;
}

}  // namespace

TEST(Newton, ConvergesQuadraticallyAndCutsBack) {
  // One load step to λ = 3 with K = 100 (nearly incompressible plane strain) is
  // too large for Newton from the stress-free state on this grid: the solver
  // must cut back on its own and still reach t = 1.
  auto s = uniaxial(10, 3.0);
  NeoHookeanPlaneStrain mat({1.0, 100.0});
  Model M(s.body, mat);
  NewtonOptions o;
  o.steps = 1;
  o.tolerance = 1e-10;
  StaticSolver solver(M, s.sets, {}, o);
  int total_cutbacks = 0;
  bool quadratic = false;
  solver.run([&](const StepReport& r) {
    total_cutbacks += r.cutbacks;
    // Quadratic: some iteration with r_k < 1e-2 has r_{k+1} < 10 r_k².
    const auto& h = r.residual_history;
    for (std::size_t k = 1; k + 1 < h.size(); ++k)
      if (h[k] < 1e-2 && h[k] > 1e-12 && h[k + 1] < 10 * h[k] * h[k]) quadratic = true;
  });
  EXPECT_DOUBLE_EQ(solver.load_factor(), 1.0);
  EXPECT_GT(total_cutbacks, 0) << "the single step to λ = 3 should have been cut back";
  EXPECT_TRUE(quadratic);
  // Homogeneous solution regardless of the path: F11 = 3 everywhere.
  for (const auto& F : M.point_deformation_gradients(solver.displacement()))
    EXPECT_NEAR(F(0, 0), 3.0, 1e-8);  // Newton tolerance 1e-10 on a 10×10 grid
}

TEST(Newton, LinearSolversAgree) {
  // Energy form (symmetric): CHOLMOD, UMFPACK, SparseLU and BiCGSTAB give the
  // same equilibrium to the Newton tolerance.
  auto s = uniaxial(10, 1.5);
  NeoHookeanPlaneStress mat({1.0, 10.0});
  Model M(s.body, mat, {Correspondence::bond_associated, BoundaryForm::energy});
  std::vector<Eigen::VectorXd> u;
  for (auto ls : {LinearSolver::cholmod, LinearSolver::umfpack, LinearSolver::sparse_lu,
                  LinearSolver::bicgstab}) {
    NewtonOptions o;
    o.steps = 2;
    o.tolerance = 1e-10;
    o.linear = ls;
    StaticSolver solver(M, s.sets, {}, o);
    solver.run();
    u.push_back(solver.displacement());
  }
  for (std::size_t i = 1; i < u.size(); ++i)
    EXPECT_LT((u[i] - u[0]).norm(), 1e-8 * u[0].norm()) << "solver " << i;  // tolerance 1e-10
}

TEST(Newton, RigidBodyConstraintMissing) {
  auto s = uniaxial(10, 1.5);
  NeoHookeanPlaneStrain mat({1.0, 10.0});
  Model M(s.body, mat);
  auto no_y = s.sets;
  no_y.erase(no_y.begin() + 1);  // drop the pin
  try {
    StaticSolver solver(M, no_y, {}, {});
    FAIL() << "expected InputError";
  } catch (const pdcg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no displacement constraint in y"), std::string::npos);
  }
}

namespace {
// Two pieces: a unit sheet cut through by a crack on x = 0.5, the left edge held, the right
// edge moved rigidly along x by 0.1 t: every internal force is round-off at any load.
struct CutSheet {
  Discretization body;
  std::vector<DisplacementSet> sets;
};
CutSheet cut_sheet() {
  GridSpec g;
  g.spacing = 0.1;
  g.cracks = {Crack{Vec3(0.5, -0.1, 0), Vec3(0.5, 1.1, 0)}};
  CutSheet s{Discretization::grid(g), {}};
  DisplacementSet left{"left", {}, {}}, right{"right", {}, {}};
  left.component[0] = left.component[1] = [](double) { return 0.0; };
  right.component[0] = [](double t) { return 0.1 * t; };
  right.component[1] = [](double) { return 0.0; };
  for (std::size_t i = 0; i < s.body.size(); ++i) {
    const double x = s.body.positions()[i].x();
    if (x < g.spacing) left.points.push_back(i);
    if (x > 1 - g.spacing) right.points.push_back(i);
  }
  s.sets = {left, right};
  return s;
}
}  // namespace

// Round-off floor (docs/solver.md §4, "Round-off floor"): a body cut in two whose pieces are moved rigidly by
// their grips has round-off internal forces; with a force floor f₀ its relative residual is
// that noise over f₀ and Newton cannot lower it. Measured noise: ‖R‖ ≈ 7e-16 at the first
// iterations, drifting up ≈ 3× over 9 iterations of round-off increments (1–2e-15).
// f₀ = 5e-8: residual ≈ 1.4e-8 … 4e-8 > the tolerance 1e-8 but within 10× — accepted at the
// floor, and the state is the closed form (the right piece translated by 0.1, the left at
// rest); f₀ = 1e-9: ≈ 7e-7 … 2e-6, 70–200× the tolerance — refused, as before the rule;
// f₀ = 1e-6: ≈ 7e-10, below the tolerance — the ordinary convergence test, no floor.
TEST(Newton, RoundoffFloorAcceptsOnlyNoiseNearTheTolerance) {
  const auto solve = [](double floor, StepReport& out) {
    auto s = cut_sheet();
    NeoHookeanPlaneStress mat({1.0, 10.0});
    Model M(s.body, mat);
    NewtonOptions o;
    o.steps = 1;
    o.tolerance = 1e-8;
    o.max_cutbacks = 0;
    StaticSolver solver(M, s.sets, {}, o);
    solver.set_force_floor(floor);
    solver.run([&](const StepReport& r) { out = r; });
    double err = 0;  // the closed form: u = (0.1, 0) right of the cut, 0 left of it
    for (std::size_t k = 0; k < s.body.size(); ++k) {
      const double ux = s.body.positions()[k].x() > 0.5 ? 0.1 : 0.0;
      err = std::max(
          err,
          (solver.displacement().segment<2>(2 * k) - Eigen::Vector2d(ux, 0)).cwiseAbs().maxCoeff());
    }
    return err;
  };
  StepReport r;
  const double err = solve(5e-8, r);
  EXPECT_TRUE(r.roundoff_floor);
  EXPECT_GT(r.residual, 1e-8) << "the noise must sit above the tolerance for this check";
  EXPECT_LE(r.residual, kRoundoffResidualFactor * 1e-8);
  EXPECT_LT(err, 1e-12);  // round-off increments of 1e-15 from the exact rigid motion
  StepReport ordinary;
  EXPECT_LT(solve(1e-6, ordinary), 1e-12);
  EXPECT_FALSE(ordinary.roundoff_floor);
  EXPECT_LE(ordinary.residual, 1e-8);
  StepReport refused;
  EXPECT_THROW(solve(1e-9, refused), pdcg::NumericalError);
}
