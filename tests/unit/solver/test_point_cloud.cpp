// Surface face vectors of point clouds (docs/solver.md §2.1): Wigner–Seitz faces of lattices
// against their closed forms, the lattice rule against the grid path, the ball-clipped Voronoi
// rule on a perturbed grid (Σ s = 0, zero in the interior), and the homogeneous patch test
// (an affine field is an exact discrete equilibrium at every point with s_k = 0).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pdcg/solver/discretization.hpp"
#include "pdcg/solver/material.hpp"
#include "pdcg/solver/model.hpp"
#include "pdcg/solver/perturb.hpp"
#include "pdcg/solver/point_cloud.hpp"

using namespace pdcg::solver;

namespace {

Eigen::Matrix3d cols(const Vec3& a, const Vec3& b, const Vec3& c) {
  Eigen::Matrix3d A;
  A << a, b, c;
  return A;
}

}  // namespace

TEST(PointCloud, WignerSeitzFacesOfLattices) {
  // square h = 2: 4 faces of length 2; triangular a = 1.3: 6 faces a/√3; simple cubic: 6 faces
  // h²; FCC (cube a): 12 faces √2 a²/8 (rhombic dodecahedron); BCC: 8 hexagons + 6 squares.
  auto areas = [](int d, const Eigen::Matrix3d& A) {
    std::vector<double> out;
    for (const auto& f : wigner_seitz_faces(d, A)) out.push_back(f.area.norm());
    std::sort(out.begin(), out.end());
    return out;
  };
  const double tol = 1e-12;  // clipping arithmetic only
  auto sq = areas(2, cols({2, 0, 0}, {0, 2, 0}, {0, 0, 1}));
  ASSERT_EQ(sq.size(), 4u);
  for (double a : sq) EXPECT_NEAR(a, 2.0, tol);
  const double a = 1.3;
  auto tri = areas(2, cols({a, 0, 0}, {0.5 * a, std::sqrt(3.0) / 2 * a, 0}, {0, 0, 1}));
  ASSERT_EQ(tri.size(), 6u);
  for (double v : tri) EXPECT_NEAR(v, a / std::sqrt(3.0), tol);
  auto sc = areas(3, Eigen::Matrix3d::Identity() * 0.5);
  ASSERT_EQ(sc.size(), 6u);
  for (double v : sc) EXPECT_NEAR(v, 0.25, tol);
  auto fcc = areas(3, cols({0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}) * a);
  ASSERT_EQ(fcc.size(), 12u);
  for (double v : fcc) EXPECT_NEAR(v, std::sqrt(2.0) * a * a / 8, tol);
  auto bcc = areas(3, cols({0.5, 0.5, 0.5}, {0.5, 0.5, -0.5}, {0.5, -0.5, 0.5}));
  EXPECT_EQ(bcc.size(), 14u);
}

TEST(PointCloud, LatticeRuleEqualsTheGridPath) {
  // Cell-centre grids (2D with a hole, 3D box): the points alone, through lattice detection and
  // missing Wigner–Seitz neighbours, give the grid path's s_k exactly — except on the hole's
  // surface, where the grid path knows the true circle (s_k = −∫ n dS over the owned arc,
  // docs/solver.md §3) and the point cloud only the staircase of missing neighbours. There
  // the two agree in total (Σ over the hole = 0 for both) and everywhere else exactly.
  for (int d : {2, 3}) {
    GridSpec g;
    g.dimension = d;
    g.spacing = d == 2 ? 0.05 : 0.1;
    g.size = d == 2 ? Vec3(1.0, 0.8, 1.0) : Vec3(0.5, 0.4, 0.3);
    g.origin = Vec3(0.2, -0.1, 0.0);
    const Hole hole{Vec3(0.6, 0.3, 0), 0.17};
    if (d == 2) g.holes.push_back(hole);
    // The cloud's lattice rule gives whole cells; the grid path's cut-cell volumes at a hole
    // (docs/solver.md §2) come from the circle, which the points alone do not know.
    g.cut_cells = false;
    DiscretizationOptions opt;
    const auto D = Discretization::grid(g, opt);
    const auto c = analyse_cloud(d, D.positions(), {}, 0.0, {});
    ASSERT_EQ(c.rule, SurfaceRule::lattice) << d;
    EXPECT_NEAR(c.spacing, g.spacing, 1e-12);
    double err = 0;
    Vec3 hole_grid = Vec3::Zero(), hole_cloud = Vec3::Zero();
    for (std::size_t i = 0; i < D.size(); ++i) {
      EXPECT_NEAR(c.volume[i], D.volumes()[i], 1e-15);
      if (d == 2 && (D.positions()[i] - hole.center).norm() < hole.radius + 2 * g.spacing) {
        hole_grid += D.surface()[i];
        hole_cloud += c.surface[i];
        continue;
      }
      err = std::max(err, (c.surface[i] - D.surface()[i]).norm());
    }
    EXPECT_LT(err, 1e-14) << d;
    EXPECT_LT(hole_grid.norm(), 1e-14);
    EXPECT_LT(hole_cloud.norm(), 1e-14);
  }
}

TEST(PointCloud, VoronoiRuleOnAPerturbedGrid) {
  // 2D 20×20 grid (Δx = 0.05), every coordinate jittered by up to ±0.1Δx: no lattice, so the
  // ball-clipped Voronoi rule (R = h̄). Σ s_k = 0 to round-off; points more than 1.5Δx inside
  // have s_k = 0; each straight edge carries its length within 5%: the ball bulges out at the
  // two corners (≈ 0.37Δx each on a square grid, 3.7% of this 20Δx edge) and the jitter
  // moves the faces.
  GridSpec g;
  g.spacing = 0.05;
  const auto P = perturbed_grid(g, 0.1, 7);
  const auto c = analyse_cloud(2, P.positions(), {}, 0.05 * 0.05, {});
  ASSERT_EQ(c.rule, SurfaceRule::voronoi);
  Vec3 sum = Vec3::Zero();
  Vec3 left = Vec3::Zero(), top = Vec3::Zero();
  for (std::size_t i = 0; i < P.size(); ++i) {
    const Vec3& x = P.positions()[i];
    sum += c.surface[i];
    const bool inner = x.x() > 0.075 && x.x() < 0.925 && x.y() > 0.075 && x.y() < 0.925;
    if (inner) {
      EXPECT_EQ(c.surface[i].norm(), 0.0) << x.transpose();
    }
    if (x.x() < 0.05) left += c.surface[i];
    if (x.y() > 0.95) top += c.surface[i];
  }
  EXPECT_LT(sum.norm(), 1e-15);
  std::printf("perturbed grid: left edge Σ s = (%.6f, %.6f), top edge Σ s = (%.6f, %.6f)\n",
              left.x(), left.y(), top.x(), top.y());
  EXPECT_NEAR(left.x(), -1.0, 0.05);
  EXPECT_NEAR(top.y(), 1.0, 0.05);
}

TEST(PointCloud, VoronoiRuleOnAFlatEdgeIsExact) {
  // A perfect square grid through the Voronoi rule (lattice detection bypassed): an edge point
  // away from corners has s = h n exactly (its two side faces cancel by symmetry).
  GridSpec g;
  g.spacing = 0.1;
  const auto D = Discretization::grid(g);
  const auto s = voronoi_surface(2, D.positions(), 0.1, {});
  for (std::size_t i = 0; i < D.size(); ++i) {
    const Vec3& x = D.positions()[i];
    if (x.y() > 0.9 && x.x() > 0.15 && x.x() < 0.85) {
      EXPECT_NEAR(s[i].x(), 0.0, 1e-15);
      EXPECT_NEAR(s[i].y(), 0.1, 1e-15);
    }
  }
}

TEST(PointCloud, AffineFieldIsAnExactEquilibriumAwayFromTheSurface) {
  // Homogeneous patch test on clouds: u = (F − I)x with a general F (rotation, stretch, shear);
  // the weak-form force is f_k = P(F) s_k, so every point with s_k = 0 is in equilibrium to
  // round-off and the affine field solves the Dirichlet problem whose prescribed points are
  // the surface points. Lattice rule (grid 2D, 3D) and Voronoi rule (perturbed 2D and 3D grids).
  struct Case {
    int d;
    double jitter;
  };
  for (const Case cs : {Case{2, 0.0}, Case{3, 0.0}, Case{2, 0.1}, Case{3, 0.1}}) {
    GridSpec g;
    g.dimension = cs.d;
    g.spacing = cs.d == 2 ? 0.1 : 0.2;
    DiscretizationOptions opt;
    opt.horizon_factor = cs.d == 2 ? 3.015 : 2.015;
    const auto src = cs.jitter > 0 ? perturbed_grid(g, cs.jitter, 3) : Discretization::grid(g);
    const double h = g.spacing;
    const auto c = analyse_cloud(cs.d, src.positions(), {}, std::pow(h, cs.d), {});
    EXPECT_EQ(c.rule, cs.jitter > 0 ? SurfaceRule::voronoi : SurfaceRule::lattice);
    Vec3 total = Vec3::Zero();
    for (const auto& v : c.surface) total += v;
    EXPECT_LT(total.norm(), 1e-13 * std::pow(h, cs.d - 1));  // Σ s_k = 0 (closed body)
    const auto D =
        Discretization::from_points(cs.d, src.positions(), c.volume, c.surface, c.spacing, {}, opt);
    auto mat = cs.d == 2 ? make_neo_hookean({1.0, 10.0}, Kinematics::plane_strain)
                         : make_neo_hookean({1.0, 10.0}, Kinematics::three_d);
    const Model M(D, *mat);
    Eigen::Matrix3d F;
    F << 1.3, 0.2, 0.1, -0.15, 0.9, 0.05, 0.1, -0.05, 1.1;
    Eigen::VectorXd u(M.dofs());
    for (std::size_t k = 0; k < D.size(); ++k)
      for (int a = 0; a < cs.d; ++a)
        u[cs.d * k + a] = ((F - Eigen::Matrix3d::Identity()) * D.positions()[k])(a);
    Eigen::VectorXd f;
    ASSERT_TRUE(M.internal_force(u, f));
    Mat3 P;
    mat->evaluate(F, nullptr, &P, nullptr);
    const double scale = P.norm() * std::pow(h, cs.d - 1);
    double interior = 0, surface = 0;
    std::size_t n_int = 0;
    for (std::size_t k = 0; k < D.size(); ++k) {
      const Vec3 ps = P * c.surface[k];
      double e = 0;
      for (int a = 0; a < cs.d; ++a) e = std::max(e, std::abs(f[cs.d * k + a] - ps(a)));
      if (c.surface[k].norm() == 0) {
        interior = std::max(interior, e);
        ++n_int;
      } else {
        surface = std::max(surface, e);
      }
    }
    std::printf(
        "d = %d jitter %.1f: %zu interior points, max |f − P s|/(|P| h^(d−1)) = %.2e "
        "(interior), %.2e (surface)\n",
        cs.d, cs.jitter, n_int, interior / scale, surface / scale);
    EXPECT_GT(n_int, 0u);
    EXPECT_LT(interior / scale, 1e-12);  // round-off of the stencil sums
    EXPECT_LT(surface / scale, 1e-12);   // f = P s at every point for a homogeneous state
  }
}

// Crystals with a basis are not lattices of their points: diamond's bond vectors span a lattice
// of cell a³/16 that also holds the empty tetrahedral sites (diamond has a³/8 per atom), a
// honeycomb's a triangular lattice of cell a²/(2√3) with the hexagons' centres empty (the sheet
// has √3a²/4 per atom). The lattice rule took that cell as the point volume (a silent factor
// 2 or 3/2 on every energy density of such a model); these clouds take the Voronoi rule and the
// caller's volume per point, while an fcc cloud (Bravais) keeps the lattice rule with its
// primitive cell a³/4 — closed forms.
TEST(PointCloud, CrystalsWithABasisAreNotTakenForTheLatticeOfTheirBonds) {
  const double a = 5.431;  // any lattice constant
  std::vector<Vec3> diamond, fcc;
  const Vec3 fcc_basis[4] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        for (const auto& b : fcc_basis) {
          const Vec3 site = a * (Vec3(i, j, k) + b);
          fcc.push_back(site);
          diamond.push_back(site);
          diamond.push_back(site + a * Vec3(0.25, 0.25, 0.25));
        }
  const double per_atom = a * a * a / 8;
  const auto cd = analyse_cloud(3, diamond, {}, per_atom, {});
  EXPECT_EQ(cd.rule, SurfaceRule::voronoi);
  EXPECT_DOUBLE_EQ(cd.volume[0], per_atom);
  const auto cf = analyse_cloud(3, fcc, {}, 1.0, {});
  ASSERT_EQ(cf.rule, SurfaceRule::lattice);
  EXPECT_NEAR(cf.volume[0], a * a * a / 4, 1e-12 * a * a * a);  // |det| of fcc's primitive cell
  // honeycomb: two atoms per cell of the triangular lattice a1 = a(1, 0), a2 = a(½, √3/2)
  std::vector<Vec3> honeycomb;
  const Vec3 a1(a, 0, 0), a2(0.5 * a, 0.5 * std::sqrt(3.0) * a, 0);
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) {
      const Vec3 site = double(i) * a1 + double(j) * a2;
      honeycomb.push_back(site);
      honeycomb.push_back(site + (a1 + a2) / 3.0);
    }
  const double per_atom_2d = std::sqrt(3.0) * a * a / 4;
  const auto ch = analyse_cloud(2, honeycomb, {}, per_atom_2d, {});
  EXPECT_EQ(ch.rule, SurfaceRule::voronoi);
  EXPECT_DOUBLE_EQ(ch.volume[0], per_atom_2d);
}
