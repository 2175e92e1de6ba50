// Hard case for rupture (ctest label `stability`, docs/effects.md).
#include <gtest/gtest.h>

#include <cmath>

#include "pdcg/core/error.hpp"
#include "pdcg/solver/rupture.hpp"

using namespace pdcg::solver;

// Hard case: many broken bonds at a crack tip, points cut loose entirely.
TEST(RuptureStability, ManyBrokenBondsAtACrackTipGiveNoNaN) {
  GridSpec g;
  g.spacing = 1.0 / 20;
  g.cracks.push_back({Vec3(0, 0.5, 0), Vec3(0.3, 0.5, 0)});
  auto body = Discretization::grid(g);
  auto mat = make_neo_hookean({1.0, 100.0}, Kinematics::plane_stress);
  Model model(body, *mat);
  std::vector<int> top, bottom, pin;
  for (std::size_t i = 0; i < body.size(); ++i) {
    const Vec3& x = body.positions()[i];
    if (x.y() > 0.97) top.push_back(static_cast<int>(i));
    if (x.y() < 0.03) bottom.push_back(static_cast<int>(i));
    if (x.y() < 0.03 && x.x() < 0.03) pin.push_back(static_cast<int>(i));
  }
  std::vector<DisplacementSet> ds(2);
  ds[0] = {"bottom", bottom, {}};
  ds[0].component[1] = [](double) { return 0.0; };
  ds[0].component[0] = [](double) { return 0.0; };
  ds[1] = {"top", top, {}};
  ds[1].component[1] = [](double t) { return 0.05 * t; };
  ds[1].component[0] = [](double) { return 0.0; };
  NewtonOptions no;
  no.steps = 1;
  StaticSolver solver(model, ds, {}, no);
  Rupture rup(body, model, {RuptureCriterion::bond_stretch, 10.0, 50});
  // Break every bond crossing y = 0.5 for x < 0.7 and every bond of the points within
  // 2 spacings of (0.5, 0.5): a ragged tip with detached points.
  const Vec3 c(0.5, 0.5, 0);
  const auto& fam = body.families();
  for (std::size_t i = 0; i < body.size(); ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      const int j = fam.index[q];
      const Vec3 &xi = body.positions()[i], &xj = body.positions()[j];
      const bool cross = (xi.y() - 0.5) * (xj.y() - 0.5) < 0 && std::max(xi.x(), xj.x()) < 0.7;
      const bool near = (xi - c).norm() < 0.1 || (xj - c).norm() < 0.1;
      if ((cross || near) && body.bond_index(j, static_cast<int>(i)) < 0)
        ADD_FAILURE() << "asymmetric " << i << " " << j << " " << xi.transpose() << " | "
                      << xj.transpose();
      else if (cross || near)
        body.break_bond(static_cast<int>(i), j);
    }
  rup.commit(solver.displacement());
  rup.stagger(solver);
  solver.advance_to(1.0);
  std::printf("broken %zu, detached %zu, ill-posed stencils %zu\n", body.broken_bonds(),
              model.anchors().size(), body.suppressed_stencils());
  EXPECT_GT(body.broken_bonds(), 300u);
  EXPECT_GT(model.anchors().size(), 0u);
  EXPECT_TRUE(solver.displacement().allFinite());
  EXPECT_TRUE(solver.internal_force().allFinite());
  for (double D : body.damage()) {
    EXPECT_GE(D, 0.0);
    EXPECT_LE(D, 1.0);
  }
  // stencil weights and gradients stay finite (ill-posed ones are switched off, not NaN)
  for (double w : body.bond_stencils().weight) EXPECT_TRUE(std::isfinite(w));
  for (double gv : body.bond_stencils().grad) EXPECT_TRUE(std::isfinite(gv));
}

// A free fragment: at half the load, every bond crossing the boundary of the square
// (0.35, 0.65)² breaks, so the (stressed) points inside hang together but on no grip. Its
// rigid motions are null modes of K; with rupture.fragments = anchor each of its
// points is parked by a spring at its displacement when cut loose. Peer: the same broken
// set with the fragment's points held by a prescribed displacement at those values instead.
// The fragment exerts no force on the rest of the body in either, so the rest must reach the
// same state and grip reactions.
namespace {
struct FragmentSheet {
  Discretization body;
  std::vector<int> top, bottom, inside;
  FragmentSheet() : body(make()) {
    for (std::size_t i = 0; i < body.size(); ++i) {
      const Vec3& x = body.positions()[i];
      if (x.y() > 0.97) top.push_back(static_cast<int>(i));
      if (x.y() < 0.03) bottom.push_back(static_cast<int>(i));
      if (in(x)) inside.push_back(static_cast<int>(i));
    }
  }
  // after Rupture enabled it on the body
  void cut() {
    const auto& fam = body.families();
    for (std::size_t i = 0; i < body.size(); ++i)
      for (auto q = fam.begin(i); q < fam.end(i); ++q) {
        const int j = fam.index[q];
        if (in(body.positions()[i]) != in(body.positions()[j]) && static_cast<int>(i) < j)
          body.break_bond(static_cast<int>(i), j);
      }
  }
  static bool in(const Vec3& x) {
    return std::max(std::abs(x.x() - 0.5), std::abs(x.y() - 0.5)) < 0.15;
  }
  static Discretization make() {
    GridSpec g;
    g.spacing = 1.0 / 20;
    return Discretization::grid(g);
  }
  std::vector<DisplacementSet> grips() const {
    std::vector<DisplacementSet> ds(2);
    ds[0] = {"bottom", bottom, {}};
    ds[0].component[0] = ds[0].component[1] = [](double) { return 0.0; };
    ds[1] = {"top", top, {}};
    ds[1].component[0] = [](double) { return 0.0; };
    ds[1].component[1] = [](double t) { return 0.05 * t; };
    return ds;
  }
  std::vector<char> held() const {
    std::vector<char> h(2 * body.size(), 0);
    for (int p : top) h[2 * p] = h[2 * p + 1] = 1;
    for (int p : bottom) h[2 * p] = h[2 * p + 1] = 1;
    return h;
  }
};
}  // namespace

TEST(RuptureStability, FreeFragmentIsParkedAndCarriesNoLoad) {
  auto mat = make_neo_hookean({1.0, 100.0}, Kinematics::plane_stress);
  NewtonOptions no;
  no.steps = 2;
  no.tolerance = 1e-11;
  // parked by springs (rupture.fragments: anchor), cut loose at t = 0.5
  FragmentSheet a;
  Model model_a(a.body, *mat);
  const auto ds_a = a.grips();
  StaticSolver solver_a(model_a, ds_a, {}, no);
  RuptureOptions oa{RuptureCriterion::bond_stretch, 10.0, 50};
  oa.anchor_fragments = true;
  Rupture rup_a(a.body, model_a, oa);
  solver_a.advance_to(0.5);
  const Eigen::VectorXd u_cut = solver_a.displacement();
  a.cut();
  rup_a.set_held_dofs(a.held());
  rup_a.commit(u_cut);
  // the square holds 6 × 6 points (x = 0.375 … 0.625): one fragment, every point parked
  ASSERT_EQ(a.inside.size(), 36u);
  EXPECT_EQ(rup_a.free_fragments(), 1u);
  EXPECT_EQ(rup_a.fragment_points(), 36u);
  EXPECT_EQ(model_a.anchors(), a.inside);
  ASSERT_NO_THROW(solver_a.advance_to(1.0));
  // peer: the fragment held at its displacement when cut by a prescribed displacement
  FragmentSheet b;
  Model model_b(b.body, *mat);
  auto ds_b = b.grips();
  for (int p : b.inside) {  // one set per fragment point: its own value
    DisplacementSet set{"fragment", {p}, {}};
    for (int c = 0; c < 2; ++c)
      set.component[c] = [&u_cut, p, c](double) { return u_cut[2 * p + c]; };
    ds_b.push_back(set);
  }
  StaticSolver solver_b(model_b, ds_b, {}, no);
  RuptureOptions ob{RuptureCriterion::bond_stretch, 10.0, 50};
  ob.anchor_fragments = false;
  Rupture rup_b(b.body, model_b, ob);
  b.cut();
  rup_b.commit(solver_b.displacement());
  EXPECT_TRUE(model_b.anchors().empty());
  ASSERT_NO_THROW(solver_b.advance_to(1.0));
  const auto& ua = solver_a.displacement();
  const auto& ub = solver_b.displacement();
  // the fragment was stressed when cut (its points moved ≈ 0.0125 with the sheet)
  double moved = 0;
  for (int p : a.inside) moved = std::max(moved, std::abs(u_cut[2 * p + 1]));
  EXPECT_GT(moved, 0.005);
  // Same state of the rest and the same top reaction: both solves end at a relative
  // residual ≤ 1e-11, and the 800-dof tangent's condition (≈ 1e3) amplifies that to ≤ 1e-8.
  std::vector<char> frag(a.body.size(), 0);
  for (int p : a.inside) frag[p] = 1;
  double diff = 0, scale = 0;
  for (std::size_t k = 0; k < a.body.size(); ++k) {
    if (frag[k]) continue;
    for (int c = 0; c < 2; ++c) {
      diff = std::max(diff, std::abs(ua[2 * k + c] - ub[2 * k + c]));
      scale = std::max(scale, std::abs(ub[2 * k + c]));
    }
  }
  EXPECT_GT(scale, 0.04);  // the top grip moved 0.05
  EXPECT_LT(diff, 1e-8 * scale);
  double fa = 0, fb = 0;
  for (int p : a.top) {
    fa += solver_a.internal_force()[2 * p + 1];
    fb += solver_b.internal_force()[2 * p + 1];
  }
  EXPECT_GT(fb, 0.0);
  EXPECT_NEAR(fa, fb, 1e-8 * std::abs(fb));
  // The springs hold a free body: their forces (= minus the fragment's internal forces)
  // sum to zero (linear momentum of the BA forces; 1e-9 of the top reaction: round-off of
  // 36 points' forces at the solve's residual).
  Eigen::Vector2d spring = Eigen::Vector2d::Zero();
  const auto& f = solver_a.internal_force();
  for (int p : a.inside) spring += Eigen::Vector2d(f[2 * p], f[2 * p + 1]);
  EXPECT_LT(spring.norm(), 1e-9 * fb);
  std::printf(
      "fragment: %zu points parked; top reaction %.12g (peer held by Dirichlet %.12g); "
      "rest of the body max |Δu| %.2e\n",
      model_a.anchors().size(), fa, fb, diff);
}
