// Cut-cell volumes at holes (docs/solver.md §2, "Cut-cell volumes"): the measure of a cell ∩
// disk / ball against closed forms (circular segment, spherical cap, whole disk and ball
// tiled by cells), and the grid's volumes: Σ V = the body's exact measure, the point stencils
// stay exact for linear fields, and rebuild_broken keeps the cut volumes.
#include <gtest/gtest.h>

#include <cmath>

#include "pdcg/solver/cut_cells.hpp"
#include "pdcg/solver/discretization.hpp"

using namespace pdcg::solver;

namespace {

const double pi = std::acos(-1.0);

// Circular segment beyond the chord at distance t from the centre: R² acos(t/R) − t√(R² − t²).
double segment(double R, double t) {
  return R * R * std::acos(t / R) - t * std::sqrt(R * R - t * t);
}

GridSpec plate(int dim, double spacing, bool cut) {
  GridSpec g;
  g.dimension = dim;
  g.size = Vec3::Ones();
  g.spacing = spacing;
  g.holes.push_back({Vec3(0.5, 0.5, dim == 3 ? 0.5 : 0.0), 0.2});
  g.cut_cells = cut;
  return g;
}

}  // namespace

TEST(CutCells, DiskRectangleAreaMatchesClosedForms) {
  const Vec3 c(0.3, -0.2, 0.0);
  const double R = 0.7;
  // Whole disk inside; half disk; a segment cut by one line; a segment cut by two lines.
  EXPECT_NEAR(disk_rectangle_area(Vec3(-5, -5, 0), Vec3(5, 5, 0), c, R), pi * R * R, 1e-15);
  EXPECT_NEAR(disk_rectangle_area(Vec3(0.3, -5, 0), Vec3(5, 5, 0), c, R), 0.5 * pi * R * R, 1e-15);
  for (double t : {-0.69, -0.3, 0.0, 0.25, 0.6999}) {
    EXPECT_NEAR(disk_rectangle_area(Vec3(c.x() + t, -5, 0), Vec3(5, 5, 0), c, R), segment(R, t),
                1e-15)
        << t;
    EXPECT_NEAR(disk_rectangle_area(Vec3(-5, c.y() + t, 0), Vec3(5, 5, 0), c, R), segment(R, t),
                1e-15)
        << t;
  }
  // Between two parallel chords t1 < t2: segment(t1) − segment(t2).
  EXPECT_NEAR(disk_rectangle_area(Vec3(-5, c.y() - 0.2, 0), Vec3(5, c.y() + 0.5, 0), c, R),
              segment(R, -0.2) - segment(R, 0.5), 1e-15);
  // Disjoint and degenerate boxes.
  EXPECT_EQ(disk_rectangle_area(Vec3(1.0, 0, 0), Vec3(2, 1, 0), c, R), 0.0);
  EXPECT_EQ(disk_rectangle_area(Vec3(0, 0, 0), Vec3(0, 1, 0), c, R), 0.0);
  // Cells tiling the disk (edges on the tangent lines included: Δx = 0.1 puts cell edges at
  // 0.3 and 0.7 around R = 0.2 at 0.5, where asin(X/R) lost 1e-9 of the area before).
  for (int n : {10, 40, 41, 160}) {
    const double h = 1.0 / n;
    double sum = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        sum += disk_rectangle_area(Vec3(i * h, j * h, 0), Vec3((i + 1) * h, (j + 1) * h, 0),
                                   Vec3(0.5, 0.5, 0), 0.2);
    EXPECT_NEAR(sum / (pi * 0.04), 1.0, 1e-13) << n;  // round-off of n² terms
  }
}

TEST(CutCells, BallBoxVolumeMatchesClosedForms) {
  const Vec3 c(0.5, 0.5, 0.5);
  const double R = 0.2, ball = 4.0 / 3.0 * pi * R * R * R;
  EXPECT_NEAR(ball_box_volume(Vec3(0, 0, 0), Vec3(1, 1, 1), c, R) / ball, 1.0, 1e-13);
  EXPECT_NEAR(ball_box_volume(Vec3(0, 0, 0), Vec3(0.5, 0.5, 0.5), c, R) / (ball / 8), 1.0, 1e-13);
  // Spherical caps of height t (cut by a plane normal to each axis): πt²(3R − t)/3.
  for (double t : {0.01, 0.1, 0.2, 0.33})
    for (int a = 0; a < 3; ++a) {
      Vec3 lo = Vec3::Zero(), hi = Vec3::Ones();
      lo(a) = c(a) + R - t;
      EXPECT_NEAR(ball_box_volume(lo, hi, c, R) / (pi * t * t * (3 * R - t) / 3), 1.0, 1e-11)
          << t << " axis " << a;
    }
  // Cells tiling the ball: Σ = 4πR³/3 (the quadrature's error would not cancel in the sum:
  // the cut cells' pieces are integrated separately).
  for (int n : {20, 23}) {
    const double h = 1.0 / n;
    double sum = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
          sum += ball_box_volume(Vec3(i * h, j * h, k * h),
                                 Vec3((i + 1) * h, (j + 1) * h, (k + 1) * h), c, R);
    EXPECT_NEAR(sum / ball, 1.0, 1e-11) << n;
  }
}

TEST(CutCells, GridVolumesSumToTheBodyMeasure) {
  for (int dim : {2, 3}) {
    const double h = dim == 2 ? 0.025 : 0.1;
    const double exact = dim == 2 ? 1.0 - pi * 0.04 : 1.0 - 4.0 / 3.0 * pi * 0.008;
    DiscretizationOptions o;
    const auto whole = Discretization::grid(plate(dim, h, false), o);
    const auto cut = Discretization::grid(plate(dim, h, true), o);
    ASSERT_EQ(whole.size(), cut.size());  // the same points: no point inside a hole
    double sum_whole = 0, sum_cut = 0, vmin = 1e300, vmax = 0;
    for (std::size_t i = 0; i < cut.size(); ++i) {
      sum_whole += whole.volumes()[i];
      sum_cut += cut.volumes()[i];
      vmin = std::min(vmin, cut.volumes()[i]);
      vmax = std::max(vmax, cut.volumes()[i]);
      EXPECT_EQ(cut.surface()[i], whole.surface()[i]);  // s_k unchanged (true circle / sphere)
    }
    const double cell = std::pow(h, dim);
    EXPECT_NEAR(sum_whole, whole.size() * cell, 1e-12);
    EXPECT_NEAR(sum_cut / exact, 1.0, 1e-12) << dim;  // exact measure, to round-off
    // Measured: the whole-cell body is off by +0.27% (2D, Δx = 0.025) / +2.5% (3D, Δx = 0.1).
    EXPECT_GT(std::abs(sum_whole / exact - 1), 1e-3) << dim;
    // A cut cell keeps more than half its cell: its centre is outside the convex hole, so the
    // hole lies beyond the tangent plane at its nearest point, which leaves the centre's half.
    // An orphan cell adds less than a cell to a neighbour.
    EXPECT_GT(vmin, cell / 2) << dim;
    EXPECT_LT(vmax, 2.5 * cell) << dim;
  }
}

TEST(CutCells, StencilsExactAndRebuildKeepsVolumes) {
  DiscretizationOptions o;
  auto body = Discretization::grid(plate(2, 0.05, true), o);
  const auto vol = body.volumes();
  auto check_linear = [&](const Stencils& S) {
    // Σ_m G^m = 0 and Σ_m ξ_m ⊗ G^m = I on every stencil (first-order PDDO, any volumes).
    double worst = 0;
    const auto& x = body.positions();
    for (std::size_t s = 0; s < S.size(); ++s) {
      if (S.weight[s] == 0) continue;
      Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
      Eigen::Vector2d g0 = Eigen::Vector2d::Zero();
      for (auto r = S.offsets[s]; r < S.offsets[s + 1]; ++r) {
        const Eigen::Vector2d g(S.grad[2 * r], S.grad[2 * r + 1]);
        g0 += g;
        M += (x[S.index[r]] - x[S.center[s]]).head<2>() * g.transpose();
      }
      worst =
          std::max({worst, g0.norm() * body.spacing(), (M - Eigen::Matrix2d::Identity()).norm()});
    }
    return worst;
  };
  EXPECT_LT(check_linear(body.point_stencils()), 1e-11);
  EXPECT_LT(check_linear(body.bond_stencils()), 1e-11);
  // Break the bonds of a cut-cell point next to the hole and rebuild: volumes unchanged, the
  // rebuilt stencils exact with them.
  int k = -1;
  for (std::size_t i = 0; i < body.size(); ++i)
    if (std::abs(vol[i] - 0.0025) > 1e-6 && k < 0) k = static_cast<int>(i);
  ASSERT_GE(k, 0);
  body.enable_rupture();
  const auto& F = body.families();
  for (auto q = F.begin(k); q < F.begin(k) + 3; ++q) body.break_bond(k, F.index[q]);
  EXPECT_GT(body.rebuild_broken(), 0u);
  EXPECT_EQ(body.volumes(), vol);
  EXPECT_LT(check_linear(body.point_stencils()), 1e-11);
  EXPECT_LT(check_linear(body.bond_stencils()), 1e-11);
}
