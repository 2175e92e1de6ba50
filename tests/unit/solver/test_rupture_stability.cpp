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
