// Discretisation and assembly: exactness of the BA/PDDO deformation gradients
// for linear fields, weight normalisation, tangent vs central finite
// differences of the internal force, energy gradient vs finite differences of
// the energy, and the zero-energy modes of a free body (BA vs classical).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <random>

#include "pdcg/core/error.hpp"
#include "pdcg/solver/discretization.hpp"
#include "pdcg/solver/model.hpp"
#include "pdcg_test.hpp"

using namespace pdcg::solver;

namespace {

Discretization small_grid(int dim, int n, double factor = 3.015) {
  GridSpec g;
  g.dimension = dim;
  g.size = Vec3(1.0, 1.0, dim == 3 ? 1.0 : 0.0);
  if (dim == 2) g.size.z() = 1.0;
  g.spacing = 1.0 / n;
  DiscretizationOptions o;
  o.horizon_factor = factor;
  return Discretization::grid(g, o);
}

Eigen::VectorXd affine(const Discretization& D, const Mat3& H, const Vec3& c) {
  const int d = D.dimension();
  Eigen::VectorXd u(d * D.size());
  for (std::size_t i = 0; i < D.size(); ++i) {
    const Vec3 v = H * D.positions()[i] + c;
    for (int a = 0; a < d; ++a) u[d * i + a] = v(a);
  }
  return u;
}

Mat3 in_plane(Mat3 F, int d) {
  if (d == 2) {
    F.row(2).setZero();
    F.col(2).setZero();
    F(2, 2) = 1.0;
  }
  return F;
}

}  // namespace

TEST(Discretization, GridCountsAndFamilies) {
  const auto D = small_grid(2, 10);
  EXPECT_EQ(D.size(), 100u);
  // Interior point family with δ = 3.015Δx: lattice points in a disc of radius
  // 3.015 minus the centre = 28 (Gauss circle count N(3) = 29).
  const std::size_t centre = 5 * 10 + 5;
  EXPECT_EQ(D.families().end(centre) - D.families().begin(centre), 28);
  // Surface face vectors sum to zero and the left edge carries length 1 (∮ n dS).
  Vec3 sum = Vec3::Zero(), left = Vec3::Zero();
  for (std::size_t i = 0; i < D.size(); ++i) {
    sum += D.surface()[i];
    if (D.positions()[i].x() < 0.1) left += D.surface()[i];
  }
  EXPECT_LT(sum.norm(), 1e-14);
  EXPECT_NEAR(left.x(), -1.0, 1e-14);
}

TEST(Discretization, HolesAndCracks) {
  GridSpec g;
  g.size = Vec3(1, 1, 1);
  g.spacing = 0.05;
  g.holes.push_back({Vec3(0.5, 0.5, 0), 0.2});
  g.cracks.push_back({Vec3(0.0, 0.5, 0), Vec3(0.3, 0.5, 0)});
  const auto D = Discretization::grid(g);
  for (const auto& x : D.positions()) EXPECT_GE((x - Vec3(0.5, 0.5, 0)).norm(), 0.2);
  // No bond crosses the crack.
  const auto& H = D.families();
  for (std::size_t i = 0; i < D.size(); ++i)
    for (auto q = H.begin(i); q < H.end(i); ++q)
      EXPECT_FALSE(crosses(g.cracks[0], D.positions()[i], D.positions()[H.index[q]]));
  // Crack faces are surface: points just below the crack have an upward face.
  bool found = false;
  for (std::size_t i = 0; i < D.size(); ++i)
    // (x < 0.25: the point at x = 0.275 also borders the hole, whose arc adds to its s_k)
    if (std::abs(D.positions()[i].y() - 0.475) < 1e-9 && D.positions()[i].x() < 0.25) {
      EXPECT_NEAR(D.surface()[i].y(), 0.05, 1e-14);
      found = true;
    }
  EXPECT_TRUE(found);
}

TEST(Discretization, HoleSurfaceVectorsFromTheTrueCircleAndSphere) {
  // The points bordering a hole carry s_k = −∫_{Γ_k} n dS over the part Γ_k of the true
  // circle / sphere they own (docs/solver.md §3), checked against the geometry alone:
  //  · Σ s_k over the hole = −∮ n dS = 0 (the parts tile the surface; round-off only);
  //  · Σ |s_k| = perimeter 2πR / area 4πR² up to the chord deficit of each part
  //    (|∫_Γ n| < |Γ| by ≈ (angle subtended)²/24 relative: ≤ 0.4% for parts of ≲ 0.3 rad);
  //  · the half facing +x carries −∫ n_x dS = −2R (circle) / −πR² (sphere) up to the
  //    ownership split at n_x ≈ 0 (second order in the split's angular offset, ≤ 1%);
  //  · every s_k points into the hole, and the straight outer edges keep their exact faces.
  for (int dim : {2, 3})
    for (auto nodes : {GridNodes::cell_centres, GridNodes::vertices}) {
      GridSpec g;
      g.dimension = dim;
      g.nodes = nodes;
      g.spacing = 0.05;
      g.size = dim == 2 ? Vec3(1.0, 0.8, 1.0) : Vec3(1.0, 1.0, 1.0);
      const Hole hole{dim == 2 ? Vec3(0.6, 0.37, 0) : Vec3(0.48, 0.53, 0.51),
                      dim == 2 ? 0.17 : 0.27};
      g.holes.push_back(hole);
      DiscretizationOptions o;
      o.horizon_factor = 2.015;
      const auto D = Discretization::grid(g, o);
      Vec3 sum = Vec3::Zero(), right = Vec3::Zero(), left = Vec3::Zero();
      double mag = 0;
      std::size_t n = 0;
      for (std::size_t i = 0; i < D.size(); ++i) {
        Vec3 r = D.positions()[i] - hole.center;
        if (dim == 2) r.z() = 0;
        const Vec3& s = D.surface()[i];
        if (D.positions()[i].x() < 1e-9 + (nodes == GridNodes::vertices ? 0 : 0.025)) left += s;
        if (r.norm() > hole.radius + 2 * g.spacing) continue;
        sum += s;
        mag += s.norm();
        if (r.x() > 0) right += s;
        if (s.norm() > 0) {
          ++n;
          EXPECT_LT(s.dot(r), 0.0) << dim << " " << D.positions()[i].transpose();
        }
      }
      const double pi = std::acos(-1.0), R = hole.radius;
      const double full = dim == 2 ? 2 * pi * R : 4 * pi * R * R;
      const double half = dim == 2 ? 2 * R : pi * R * R;
      std::printf(
          "dim %d nodes %d: %zu hole points, |Σ s| = %.2e, Σ|s| / full = %.6f, "
          "right half Σ s_x / exact = %.6f\n",
          dim, static_cast<int>(nodes), n, sum.norm(), mag / full, -right.x() / half);
      EXPECT_LT(sum.norm(), 1e-13 * full);
      EXPECT_NEAR(mag / full, 1.0, 4e-3);
      EXPECT_NEAR(-right.x() / half, 1.0, 1e-2);
      EXPECT_NEAR(left.x(), -(dim == 2 ? 0.8 : 1.0), 1e-13);  // outer edge unchanged
    }
  // A hole that reaches past the box keeps the staircase faces (axis-aligned s_k).
  GridSpec g;
  g.spacing = 0.05;
  g.holes.push_back({Vec3(1.0, 0.5, 0), 0.2});
  const auto D = Discretization::grid(g);
  for (const auto& s : D.surface())
    for (int a = 0; a < 2; ++a)  // sums of whole cell faces of length Δx
      EXPECT_NEAR(s(a) / g.spacing, std::round(s(a) / g.spacing), 1e-12) << s.transpose();
}

TEST(Discretization, BadInputIsReported) {
  GridSpec g;
  g.spacing = 0.1;
  DiscretizationOptions o;
  o.horizon = 0.05;
  EXPECT_THROW(Discretization::grid(g, o), pdcg::InputError);
  g.spacing = 0.3;  // 1/0.3 is not an integer
  EXPECT_THROW(Discretization::grid(g), pdcg::InputError);
  // Horizon = spacing: a corner BA family has collinear points only -> ill-posed.
  g.spacing = 0.1;
  o.horizon = 0.1;
  EXPECT_THROW(Discretization::grid(g, o), pdcg::NumericalError);
}

TEST(Discretization, GradientsExactForLinearFields) {
  for (int dim : {2, 3}) {
    const auto D = small_grid(dim, dim == 2 ? 12 : 6);
    const Mat3 H =
        in_plane((Mat3() << 0.3, -0.7, 0.2, 1.1, -0.4, 0.5, 0.9, 0.1, -0.2).finished(), dim) -
        (dim == 2 ? Mat3(Eigen::Vector3d(0, 0, 1).asDiagonal()) : Mat3::Zero());
    const Eigen::VectorXd u = affine(D, H, Vec3(0.3, -0.2, 0.1));
    for (auto kind : {Correspondence::bond_associated, Correspondence::classical}) {
      NeoHookeanParameters p{1.0, 10.0};
      auto mat = make_neo_hookean(p, dim == 3 ? Kinematics::three_d : Kinematics::plane_strain);
      Model M(D, *mat, {kind, BoundaryForm::weak});
      const auto F = M.point_deformation_gradients(u);
      const Mat3 Fe = Mat3::Identity() + H;
      double err = 0;
      for (const auto& Fi : F) err = std::max(err, (Fi - Fe).cwiseAbs().maxCoeff());
      // Exact up to round-off of O(100) terms of size O(1).
      EXPECT_LT(err, 1e-12) << "dim " << dim;
    }
    // Every BA stencil too.
    const Stencils& S = D.bond_stencils();
    double err = 0;
    for (std::size_t s = 0; s < S.size(); ++s) {
      Mat3 F = Mat3::Zero();
      for (auto q = S.offsets[s]; q < S.offsets[s + 1]; ++q)
        for (int a = 0; a < dim; ++a)
          for (int J = 0; J < dim; ++J) F(a, J) += u[dim * S.index[q] + a] * S.grad[q * dim + J];
      err = std::max(err, (F - H).topLeftCorner(dim, dim).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(err, 1e-12);
  }
}

TEST(Discretization, WeightsNormalisedAndHomogeneousEnergyExact) {
  const auto D = small_grid(2, 10);
  const auto& H = D.families();
  for (std::size_t i = 0; i < D.size(); ++i) {
    double s = 0;
    for (auto q = H.begin(i); q < H.end(i); ++q) s += D.bond_weights()[q] * D.volumes()[H.index[q]];
    EXPECT_NEAR(s, 1.0, 1e-13);
  }
  NeoHookeanPlaneStrain mat({1.0, 10.0});
  Model M(D, mat);
  Mat3 F = Mat3::Identity();
  F(0, 0) = 1.7;
  F(0, 1) = 0.3;
  F(1, 1) = 0.8;
  double psi;
  mat.evaluate(F, &psi, nullptr, nullptr);
  // Π = Ψ(F) |Ω| with |Ω| = 1, up to round-off.
  EXPECT_NEAR(M.energy(affine(D, F - Mat3::Identity(), Vec3::Zero())), psi, 1e-12 * psi);
}

TEST(Model, HomogeneousStateGivesSurfaceTractionsOnly) {
  // Weak form: for u linear, f_k = P(F) s_k exactly (BA and classical).
  const auto D = small_grid(2, 12);
  NeoHookeanPlaneStress mat({1.0, 10.0});
  Mat3 F = Mat3::Identity();
  F(0, 0) = 2.0;
  F(0, 1) = 0.4;
  F(1, 1) = 0.7;
  Mat3 P;
  mat.evaluate(F, nullptr, &P, nullptr);
  for (auto kind : {Correspondence::bond_associated, Correspondence::classical}) {
    Model M(D, mat, {kind, BoundaryForm::weak});
    Eigen::VectorXd f;
    ASSERT_TRUE(M.internal_force(affine(D, F - Mat3::Identity(), Vec3(1, 2, 0)), f));
    double err = 0;
    for (std::size_t k = 0; k < D.size(); ++k) {
      const Vec3 t = P * D.surface()[k];
      err = std::max(err, std::abs(f[2 * k] - t.x()) + std::abs(f[2 * k + 1] - t.y()));
    }
    // Forces are O(|P| Δx) ~ 0.1; round-off of sums of ~500 terms.
    EXPECT_LT(err, 1e-12);
  }
}

TEST(Discretization, VertexGridVolumesFacesAndHomogeneousState) {
  // Vertex grid of a holed plate and a cube: points on the boundary, dual-cell volumes
  // (half on faces, quarter/eighth at corners) and dual-cell boundary faces. Σ V = the
  // area of the union of dual cells, Σ s = 0 (closed surface), the left face carries
  // exactly its length/area, and the weak form is exact for a homogeneous state.
  for (int dim : {2, 3}) {
    GridSpec g;
    g.dimension = dim;
    g.spacing = dim == 2 ? 0.05 : 0.2;
    g.nodes = GridNodes::vertices;
    if (dim == 2) g.holes.push_back({Vec3(0.5, 0.5, 0), 0.2});
    g.cut_cells = false;  // the staircase volumes (cut cells: checked below)
    const auto D = Discretization::grid(g);
    const long n = std::lround(1.0 / g.spacing) + 1;
    std::size_t on_left = 0;
    double vol = 0;
    Vec3 sum = Vec3::Zero(), left = Vec3::Zero();
    for (std::size_t i = 0; i < D.size(); ++i) {
      vol += D.volumes()[i];
      sum += D.surface()[i];
      if (D.positions()[i].x() == 0.0) {
        ++on_left;
        left += D.surface()[i];
      }
    }
    EXPECT_EQ(on_left, static_cast<std::size_t>(dim == 2 ? n : n * n));
    EXPECT_LT(sum.norm(), 1e-13) << "dim " << dim << " sum " << sum.transpose();
    EXPECT_NEAR(left.x(), -1.0, 1e-13) << "dim " << dim;
    if (dim == 3) {
      EXPECT_EQ(D.size(), static_cast<std::size_t>(n * n * n));
      EXPECT_NEAR(vol, 1.0, 1e-13);
    } else {
      // staircase hole: the removed dual cells are whole cells of area Δx²
      const double removed = 1.0 - vol;
      const double cells = removed / (g.spacing * g.spacing);
      EXPECT_NEAR(cells, std::round(cells), 1e-9);
      EXPECT_NEAR(removed, M_PI * 0.04, 0.02);  // staircase of a radius-0.2 hole at Δx = 0.05
    }
    const auto mat =
        make_neo_hookean({1.0, 10.0}, dim == 2 ? Kinematics::plane_strain : Kinematics::three_d);
    Mat3 F = Mat3::Identity();
    F(0, 0) = 1.6;
    F(0, 1) = 0.3;
    F(1, 1) = 0.8;
    if (dim == 3) F(2, 2) = 1.1;
    Mat3 P;
    mat->evaluate(F, nullptr, &P, nullptr);
    const Model M(D, *mat);
    Eigen::VectorXd f;
    ASSERT_TRUE(M.internal_force(affine(D, F - Mat3::Identity(), Vec3(0.1, 0.2, 0.3)), f));
    double err = 0;
    for (std::size_t k = 0; k < D.size(); ++k) {
      const Vec3 t = P * D.surface()[k];
      for (int a = 0; a < dim; ++a) err = std::max(err, std::abs(f[dim * k + a] - t(a)));
    }
    // Forces are O(|P| Δx^(d−1)); round-off of sums of a few hundred terms.
    EXPECT_LT(err, 1e-12) << "dim " << dim;
    if (dim == 2) {
      // Cut cells on the vertex grid: the dual cells clipped to the box and to the circle
      // tile the body, Σ V = 1 − πR² to round-off, and the homogeneous state stays exact.
      g.cut_cells = true;
      const auto C = Discretization::grid(g);
      ASSERT_EQ(C.size(), D.size());
      double vc = 0;
      for (double v : C.volumes()) vc += v;
      EXPECT_NEAR(vc, 1.0 - M_PI * 0.04, 1e-13);
      const Model MC(C, *mat);
      ASSERT_TRUE(MC.internal_force(affine(C, F - Mat3::Identity(), Vec3(0.1, 0.2, 0.3)), f));
      double errc = 0;
      for (std::size_t k = 0; k < C.size(); ++k) {
        const Vec3 t = P * C.surface()[k];
        for (int a = 0; a < dim; ++a) errc = std::max(errc, std::abs(f[dim * k + a] - t(a)));
      }
      EXPECT_LT(errc, 1e-12);  // the same round-off bound
    }
  }
}

namespace {

// Random large deformation: rotation · stretch (up to 3) + a random field of
// amplitude 0.1Δx (small enough that every stencil keeps J > 0).
Eigen::VectorXd random_large_deformation(const Discretization& D, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> r(-1, 1);
  const int d = D.dimension();
  Mat3 U = Mat3::Identity();
  U(0, 0) = 3.0;
  U(1, 1) = 0.6;
  if (d == 3) U(2, 2) = 1.4;
  U(0, 1) = 0.3;
  Mat3 R = (d == 3) ? Mat3(Eigen::AngleAxisd(0.8, Vec3(1, 2, 2).normalized()))
                    : Mat3(Eigen::AngleAxisd(0.8, Vec3(0, 0, 1)));
  Eigen::VectorXd u = affine(D, in_plane(R * U, d) - Mat3::Identity(), Vec3(0.1, 0.2, 0.3));
  for (int i = 0; i < u.size(); ++i) u[i] += 0.1 * D.spacing() * r(rng);
  return u;
}

void check_tangent(const Discretization& D, const Material& mat, ModelOptions opt) {
  Model M(D, mat, opt);
  const Eigen::VectorXd u = random_large_deformation(D, 11);
  Eigen::VectorXd f, fp, fm;
  SparseRow K;
  ASSERT_TRUE(M.internal_force_and_tangent(u, f, K));
  Eigen::VectorXd f2;
  ASSERT_TRUE(M.internal_force(u, f2));
  EXPECT_LT((f - f2).norm(), 1e-13 * f.norm());
  const Eigen::MatrixXd Kd = Eigen::MatrixXd(K);
  Eigen::MatrixXd Kfd(Kd.rows(), Kd.cols());
  const double h = 1e-6 * D.spacing();
  for (int j = 0; j < u.size(); ++j) {
    Eigen::VectorXd up = u, um = u;
    up[j] += h;
    um[j] -= h;
    ASSERT_TRUE(M.internal_force(up, fp));
    ASSERT_TRUE(M.internal_force(um, fm));
    Kfd.col(j) = (fp - fm) / (2 * h);
  }
  std::vector<double> a(Kd.data(), Kd.data() + Kd.size()), e(Kfd.data(), Kfd.data() + Kfd.size());
  // Central differences (h = 1e-6 Δx): truncation ~1e-12, round-off ~1e-10
  // relative; 1e-6 of the largest entry fails for any wrong term.
  EXPECT_LT(pdcg::test::max_norm_relative_error(a, e), 1e-6) << mat.name();
  if (opt.boundary == BoundaryForm::energy) {
    EXPECT_LT((Kd - Kd.transpose()).norm(), 1e-12 * Kd.norm());
    // f = ∂Π/∂u.
    std::vector<double> g(u.size()), gf(u.size());
    for (int j = 0; j < u.size(); ++j) {
      Eigen::VectorXd up = u, um = u;
      up[j] += h;
      um[j] -= h;
      gf[j] = (M.energy(up) - M.energy(um)) / (2 * h);
      g[j] = f[j];
    }
    // Energies O(1) differenced at h ~ 1e-7: round-off ~1e-9/1e-7 relative... 1e-6 ok.
    EXPECT_LT(pdcg::test::max_norm_relative_error(g, gf), 1e-6) << mat.name();
  }
}

}  // namespace

TEST(Model, TangentMatchesFiniteDifferences2D) {
  const auto D = small_grid(2, 7);
  const NeoHookeanParameters p{1.0, 10.0};
  for (auto k : {Kinematics::plane_strain, Kinematics::plane_stress})
    for (auto c : {Correspondence::bond_associated, Correspondence::classical})
      for (auto b : {BoundaryForm::weak, BoundaryForm::energy}) {
        SCOPED_TRACE(::testing::Message()
                     << "kinematics " << int(k) << " corr " << int(c) << " bnd " << int(b));
        check_tangent(D, *make_neo_hookean(p, k), {c, b});
      }
}

TEST(Model, TangentMatchesFiniteDifferences3D) {
  const auto D = small_grid(3, 4, 2.015);
  const NeoHookeanParameters p{1.0, 10.0};
  for (auto c : {Correspondence::bond_associated, Correspondence::classical})
    for (auto b : {BoundaryForm::weak, BoundaryForm::energy}) {
      SCOPED_TRACE(::testing::Message() << "corr " << int(c) << " bnd " << int(b));
      check_tangent(D, NeoHookean3D(p), {c, b});
    }
}

namespace {
// Eigenvalues of the (symmetric) energy Hessian at u = 0, relative to the
// largest one: rigid motions are zero to round-off (< 1e-8); the classical
// model's zero-energy (hourglass) modes are pinned only by the asymmetric
// boundary families and sit at ~1e-5 on a 10×10 grid (they are exactly zero
// on a periodic body), the BA model's softest deformation mode at ~1e-2.
struct Spectrum {
  int zero = 0;  ///< below 1e-8: rigid motions
  int soft = 0;  ///< below 1e-3: rigid motions + spurious modes
};
Spectrum spectrum(const Discretization& D, const Material& mat, Correspondence c) {
  Model M(D, mat, {c, BoundaryForm::energy});
  Eigen::VectorXd f;
  SparseRow K;
  EXPECT_TRUE(M.internal_force_and_tangent(Eigen::VectorXd::Zero(M.dofs()), f, K));
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(K), Eigen::EigenvaluesOnly);
  const auto& ev = es.eigenvalues();
  const double mx = ev.cwiseAbs().maxCoeff();
  Spectrum s;
  for (int i = 0; i < ev.size(); ++i) {
    s.zero += std::abs(ev[i]) < 1e-8 * mx;
    s.soft += std::abs(ev[i]) < 1e-3 * mx;
  }
  EXPECT_GT(ev.minCoeff(), -1e-8 * mx);  // no negative eigenvalue at the stress-free state
  return s;
}
int zero_singular_values(const Discretization& D, const Material& mat) {
  Model M(D, mat, {Correspondence::bond_associated, BoundaryForm::weak});
  Eigen::VectorXd f;
  SparseRow K;
  EXPECT_TRUE(M.internal_force_and_tangent(Eigen::VectorXd::Zero(M.dofs()), f, K));
  const Eigen::MatrixXd Kd(K);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Kd);
  const auto& sv = svd.singularValues();
  int n = 0;
  for (int i = 0; i < sv.size(); ++i) n += sv[i] < 1e-8 * sv[0];
  return n;
}
}  // namespace

TEST(Model, FreeBodyZeroModes2D) {
  const auto D = small_grid(2, 10);
  NeoHookeanPlaneStrain mat({1.0, 10.0});
  const auto ba = spectrum(D, mat, Correspondence::bond_associated);
  const auto cl = spectrum(D, mat, Correspondence::classical);
  EXPECT_EQ(ba.zero, 3);
  EXPECT_EQ(ba.soft, 3);  // nothing soft besides rigid motions
  EXPECT_EQ(cl.zero, 3);
  EXPECT_GT(cl.soft, 20) << "classical correspondence should show spurious (near-)zero modes";
  std::printf("2D free body 10x10: soft modes (<1e-3 max) BA %d, classical %d\n", ba.soft, cl.soft);
  EXPECT_EQ(zero_singular_values(D, mat), 3);  // weak-form operator: rigid motions only
}

TEST(Model, FreeBodyZeroModes3D) {
  const auto D = small_grid(3, 5, 2.015);
  NeoHookean3D mat({1.0, 10.0});
  const auto ba = spectrum(D, mat, Correspondence::bond_associated);
  const auto cl = spectrum(D, mat, Correspondence::classical);
  EXPECT_EQ(ba.zero, 6);
  EXPECT_EQ(ba.soft, 6);
  EXPECT_EQ(cl.zero, 6);
  EXPECT_GT(cl.soft, 12);  // 21 measured; BA has none
  std::printf("3D free body 5x5x5: soft modes (<1e-3 max) BA %d, classical %d\n", ba.soft, cl.soft);
  EXPECT_EQ(zero_singular_values(D, mat), 6);
}

// Distributed evaluation (docs/scale-out.md): the points split into parts, each part's model
// evaluates the energy stencils centred at its points and the weak-form rows of its points
// (Model::restrict_evaluation); the parts' partial forces and tangents sum to the unrestricted
// ones. Reference: the unrestricted Model (the serial solver's, checked against finite
// differences above); tolerance 1e-13 of max |f|, max |K|: only the summation order differs.
TEST(Model, RestrictedEvaluationsSumToTheFullOne) {
  for (const auto corr : {Correspondence::bond_associated, Correspondence::classical})
    for (const int dim : {2, 3}) {
      GridSpec g;
      g.dimension = dim;
      g.size = Vec3(1.0, 1.0, dim == 3 ? 0.5 : 1.0);
      g.spacing = dim == 2 ? 0.1 : 0.25;
      if (dim == 2) g.holes.push_back({Vec3(0.5, 0.5, 0), 0.2});  // weak rows on the hole too
      const auto D = Discretization::grid(g);
      const auto mat =
          make_neo_hookean({1.0, 10.0}, dim == 3 ? Kinematics::three_d : Kinematics::plane_strain);
      const ModelOptions opt{corr, BoundaryForm::weak};
      Model full(D, *mat, opt);
      ASSERT_FALSE(full.weak_points().empty());
      std::mt19937 rng(7);
      std::uniform_real_distribution<double> U(-0.02, 0.02);
      Eigen::VectorXd u = affine(D, Mat3::Identity() * 0.05, Vec3::Zero());
      for (Eigen::Index i = 0; i < u.size(); ++i) u[i] += U(rng);
      Eigen::VectorXd f_full, f;
      SparseRow K_full, K;
      ASSERT_TRUE(full.internal_force_and_tangent(u, f_full, K_full));
      const Eigen::MatrixXd Kd_full(K_full);
      // three parts: slabs in x (any split works; the parts must cover every point once)
      Eigen::VectorXd f_sum = Eigen::VectorXd::Zero(f_full.size()), f_res_sum = f_sum;
      Eigen::MatrixXd K_sum = Eigen::MatrixXd::Zero(Kd_full.rows(), Kd_full.cols());
      for (int part = 0; part < 3; ++part) {
        std::vector<char> owned(D.size());
        for (std::size_t k = 0; k < D.size(); ++k)
          owned[k] = static_cast<int>(3 * D.positions()[k].x()) == part;
        Model m(D, *mat, opt);
        m.restrict_evaluation(owned);
        ASSERT_TRUE(m.restricted());
        ASSERT_TRUE(m.internal_force_and_tangent(u, f, K));
        f_sum += f;
        K_sum += Eigen::MatrixXd(K);
        ASSERT_TRUE(m.internal_force(u, f));
        f_res_sum += f;
        // The evaluation reads u only at this part's points and its ghosts: the members of its
        // stencils and the point families of the weak points whose stresses its weak rows
        // read. u made NaN everywhere else gives the same partial force and tangent, bitwise.
        {
          std::vector<char> read(D.size(), 0);
          for (int mbr : m.evaluated_stencils().index) read[static_cast<std::size_t>(mbr)] = 1;
          const auto& weak = m.weak_points();
          const Stencils& P = D.point_stencils();
          for (std::size_t w = 0; w < weak.size(); ++w)
            if (owned[static_cast<std::size_t>(weak[w])])
              for (auto c = m.flux().begin(w); c < m.flux().end(w); ++c) {
                const auto l = static_cast<std::size_t>(
                    weak[static_cast<std::size_t>(m.flux().index[static_cast<std::size_t>(c)])]);
                for (auto r = P.offsets[l]; r < P.offsets[l + 1]; ++r)
                  read[static_cast<std::size_t>(P.index[static_cast<std::size_t>(r)])] = 1;
              }
          Eigen::VectorXd u_ghost = u, f_ghost, f_part;
          SparseRow K_ghost;
          for (std::size_t k = 0; k < D.size(); ++k)
            if (!read[k] && !owned[k])
              for (int a = 0; a < dim; ++a) u_ghost[dim * k + a] = std::nan("");
          ASSERT_TRUE(m.internal_force(u, f_part));
          ASSERT_TRUE(m.internal_force(u_ghost, f_ghost));
          EXPECT_TRUE(f_ghost.cwiseEqual(f_part).all()) << "part " << part << ", " << dim << "D";
          ASSERT_TRUE(m.internal_force_and_tangent(u_ghost, f_ghost, K_ghost));
          EXPECT_TRUE(Eigen::MatrixXd(K_ghost).cwiseEqual(Eigen::MatrixXd(K)).all());
        }
        // the rows this part touches are the members of its stencils and its weak rows
        for (std::size_t k = 0; k < D.size(); ++k)
          if (K.outerIndexPtr()[dim * k + 1] == K.outerIndexPtr()[dim * k])
            for (int a = 0; a < dim; ++a) EXPECT_EQ(f[dim * k + a], 0.0);
      }
      const double fs = f_full.cwiseAbs().maxCoeff(), ks = Kd_full.cwiseAbs().maxCoeff();
      EXPECT_LE((f_sum - f_full).cwiseAbs().maxCoeff(), 1e-13 * fs) << dim;
      EXPECT_LE((f_res_sum - f_full).cwiseAbs().maxCoeff(), 1e-13 * fs) << dim;
      EXPECT_LE((K_sum - Kd_full).cwiseAbs().maxCoeff(), 1e-13 * ks) << dim;
      // and back: an empty mask restores the full evaluation, bitwise
      Model m(D, *mat, opt);
      m.restrict_evaluation(std::vector<char>(D.size(), 0));
      m.restrict_evaluation({});
      EXPECT_FALSE(m.restricted());
      Eigen::VectorXd f_ref;
      ASSERT_TRUE(full.internal_force(u, f_ref));
      ASSERT_TRUE(m.internal_force(u, f));
      EXPECT_EQ((f - f_ref).cwiseAbs().maxCoeff(), 0.0);
    }
}

// set_vector_kernels(false) (the library's switch; no environment variable is read) makes the
// residual take the portable sweep: the same internal force as the AVX2 sweep to round-off, in
// 2D and 3D, and vector_kernels() reports the choice.
TEST(Model, PortableAndVectorResidualsAgree) {
  if (!vector_kernels()) GTEST_SKIP() << "no AVX2 + FMA on this CPU: one path only";
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> noise(-0.02, 0.02);
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const auto D = dim == 2 ? small_grid(2, 12) : small_grid(3, 6, 2.015);
    auto mat =
        make_neo_hookean({1.0, 10.0}, dim == 2 ? Kinematics::plane_strain : Kinematics::three_d);
    Model model(D, *mat);
    Mat3 H = Mat3::Zero();
    H(0, 0) = 0.1;
    H(0, 1) = 0.05;
    Eigen::VectorXd u = affine(D, H, Vec3::Zero());
    for (Eigen::Index i = 0; i < u.size(); ++i) u[i] += noise(rng);
    Eigen::VectorXd f_vector, f_portable;
    ASSERT_TRUE(model.internal_force(u, f_vector));
    set_vector_kernels(false);
    EXPECT_FALSE(vector_kernels());
    const bool ok = model.internal_force(u, f_portable);
    set_vector_kernels(true);
    ASSERT_TRUE(ok);
    EXPECT_TRUE(vector_kernels());
    ASSERT_EQ(f_vector.size(), f_portable.size());
    // the two sweeps sum the same terms in another order and J^(−2/3) by Newton iterations
    // (within 4e-16 of pow): 1e-13 of the largest force is ≈ 500 ulp of headroom
    EXPECT_LE((f_vector - f_portable).lpNorm<Eigen::Infinity>(),
              1e-13 * f_vector.lpNorm<Eigen::Infinity>());
    EXPECT_GT((f_vector - f_portable).lpNorm<Eigen::Infinity>(), 0.0)
        << "the two paths gave identical bits: the switch did not change the sweep";
  }
}
