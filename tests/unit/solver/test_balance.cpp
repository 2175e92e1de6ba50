// Global force balance of the weak form (docs/solver.md §3, "Force balance"): the internal
// forces of the BA weak form sum to zero for every state — holes, cracks, broken bonds — so
// the reactions balance the applied loads to the Newton tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pdcg/solver/rupture.hpp"

using namespace pdcg::solver;

namespace {

// |Σ_k f_k| / Σ_k |f_k| for a random smooth-plus-noise displacement field (not an
// equilibrium: the identity Σ_k f_k = 0 must hold for every state).
double internal_force_sum(const Model& model, unsigned seed) {
  const auto& body = model.body();
  const int d = body.dimension();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Eigen::VectorXd u(model.dofs()), f;
  for (std::size_t k = 0; k < body.size(); ++k) {
    const Vec3& x = body.positions()[k];
    // a large non-uniform stretch (varying stress everywhere) plus point noise
    u[d * k] = 0.3 * x.x() * x.x() + 0.05 * body.spacing() * U(rng);
    u[d * k + 1] = 0.2 * std::sin(3 * x.x()) * x.y() + 0.05 * body.spacing() * U(rng);
  }
  EXPECT_TRUE(model.internal_force(u, f));
  Vec3 sum = Vec3::Zero();
  double mag = 0;
  for (std::size_t k = 0; k < body.size(); ++k)
    for (int a = 0; a < d; ++a) {
      sum(a) += f[d * k + a];
      mag += std::abs(f[d * k + a]);
    }
  return sum.norm() / mag;
}

std::vector<int> select(const Discretization& b, const std::function<bool(const Vec3&)>& in) {
  std::vector<int> out;
  for (std::size_t i = 0; i < b.size(); ++i)
    if (in(b.positions()[i])) out.push_back(static_cast<int>(i));
  return out;
}

}  // namespace

// Plate with an off-centre hole (no symmetry to cancel the defect), plane strain, pulled
// in x to 1.3: the reactions balance to ≤ 1e-6 of the load at every step (the Newton
// tolerance 1e-11 bounds the free components' share; the discrete identity is exact).
TEST(ForceBalance, PlateWithOffCentreHole) {
  GridSpec g;
  g.spacing = 0.05;
  g.holes.push_back({Vec3(0.42, 0.55, 0), 0.2});
  const Discretization body = Discretization::grid(g);
  const auto mat = make_neo_hookean({1.0, 10.0}, Kinematics::plane_strain);
  const Model model(body, *mat);
  // Identity on arbitrary states: round-off (1e-13 relative to Σ|f|).
  EXPECT_LT(internal_force_sum(model, 1), 1e-13);
  const double h = 0.5 * g.spacing;
  std::vector<DisplacementSet> ds(3);
  ds[0] = {"left", select(body, [&](const Vec3& x) { return x.x() < h + 1e-9; }), {}};
  ds[0].component[0] = [](double) { return 0.0; };
  ds[1] = {
      "pin", select(body, [&](const Vec3& x) { return x.x() < h + 1e-9 && x.y() < h + 1e-9; }), {}};
  ds[1].component[1] = [](double) { return 0.0; };
  ds[2] = {"right", select(body, [&](const Vec3& x) { return x.x() > 1 - h - 1e-9; }), {}};
  ds[2].component[0] = [](double t) { return 0.3 * t; };
  NewtonOptions no;
  no.steps = 2;
  no.tolerance = 1e-11;
  StaticSolver solver(model, ds, {}, no);
  int steps = 0;
  solver.run([&](const StepReport& r) {
    ++steps;
    EXPECT_LT(r.balance, 1e-6) << "step " << r.step;
  });
  EXPECT_EQ(steps, 2);
  // the reactions of the two grips are opposite (the load is the right one's)
  EXPECT_NEAR(solver.reaction(0).x() + solver.reaction(2).x(), 0.0, 1e-6 * solver.reaction(2).x());
}

// Edge pre-crack (the rubber sheet of workflows/rupture/edge.yaml at Δx = 0.05): plane
// stress, K = 100; top grip u_y = 0.11. Then rupture (bond stretch 1.3: bonds at the tip
// break at this load), two staggered passes: the balance holds after each, broken bonds and
// rebuilt stencils included.
TEST(ForceBalance, PreCrackedSheetAndRupture) {
  GridSpec g;
  g.spacing = 0.05;
  g.cracks.push_back({Vec3(0.0, 0.5, 0), Vec3(0.3, 0.5, 0)});
  Discretization body = Discretization::grid(g);
  const auto mat = make_neo_hookean({1.0, 100.0}, Kinematics::plane_stress);
  Model model(body, *mat);
  EXPECT_LT(internal_force_sum(model, 2), 1e-13);
  const double h = 0.5 * g.spacing;
  std::vector<DisplacementSet> ds(3);
  ds[0] = {"bottom", select(body, [&](const Vec3& x) { return x.y() < h + 1e-9; }), {}};
  ds[0].component[1] = [](double) { return 0.0; };
  ds[1] = {"pin",
           select(body, [&](const Vec3& x) { return x.y() < h + 1e-9 && x.x() > 1 - h - 1e-9; }),
           {}};
  ds[1].component[0] = [](double) { return 0.0; };
  ds[2] = {"top", select(body, [&](const Vec3& x) { return x.y() > 1 - h - 1e-9; }), {}};
  ds[2].component[1] = [](double t) { return 0.11 * t; };
  NewtonOptions no;
  no.steps = 1;
  no.tolerance = 1e-11;
  StaticSolver solver(model, ds, {}, no);
  double before = 1;
  solver.run([&](const StepReport& r) { before = r.balance; });
  EXPECT_LT(before, 1e-6);
  // rupture: two staggered passes at the same load (break, rebuild, re-equilibrate)
  Rupture rup(body, model, {RuptureCriterion::bond_stretch, 1.3, 200});
  std::size_t broke = 0;
  for (int pass = 0; pass < 2; ++pass) {
    broke += rup.break_exceeding(solver.displacement()).broken;
    StepReport rr;
    ASSERT_TRUE(solver.reequilibrate(rr));
    EXPECT_LT(rr.balance, 1e-6) << "pass " << pass;
  }
  EXPECT_GT(broke, 0u) << "the test needs broken bonds";
  EXPECT_LT(internal_force_sum(model, 3), 1e-13);  // with the broken bonds
}
