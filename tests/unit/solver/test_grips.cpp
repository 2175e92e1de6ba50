// Grips on the body surface (docs/solver.md §4, "Grips on the surface"): on the cell-centred
// grid the outermost points sit Δx/2 inside the faces; a displacement set with surface
// offsets prescribes the PDDO extrapolation u_k + (F̄_k − I) o_k to the face instead of u_k.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "pdcg/solver/newton.hpp"

using namespace pdcg::solver;

namespace {

// Closed-form homogeneous uniaxial state: F = diag(λ, f) with P₂₂(λ, f) = 0 (bisection on the
// material itself: plane strain F₃₃ = 1, plane stress F₃₃ from P₃₃ = 0 inside the material).
Mat3 uniaxial(const Material& m, double lambda) {
  double lo = 0.05, hi = 1.0;
  for (int k = 0; k < 200; ++k) {
    const double f = 0.5 * (lo + hi);
    Mat3 F = Mat3::Identity();
    F(0, 0) = lambda;
    F(1, 1) = f;
    Mat3 P;
    m.evaluate(F, nullptr, &P, nullptr);
    (P(1, 1) > 0 ? hi : lo) = f;
  }
  Mat3 F = Mat3::Identity();
  F(0, 0) = lambda;
  F(1, 1) = 0.5 * (lo + hi);
  return F;
}

struct Uniaxial {
  double reaction = 0, lateral = 0, reaction_exact = 0, lateral_exact = 0, balance = 1;
};

// Unit sheet, n × n cell-centred grid, left face u_x = 0, right face u_x = λ − 1 (the faces
// x = 0 and x = 1, not the point columns), bottom-left point u_y = 0; lateral faces free.
Uniaxial stretch(int n, Kinematics kin, double K, double lambda, bool surface) {
  GridSpec g;
  g.spacing = 1.0 / n;
  const Discretization body = Discretization::grid(g);
  const auto mat = make_neo_hookean({1.0, K}, kin);
  const Model model(body, *mat);
  const double h = 0.5 * g.spacing, tol = 1e-9;
  std::vector<int> left, right, pin, top, bottom;
  for (std::size_t i = 0; i < body.size(); ++i) {
    const Vec3& x = body.positions()[i];
    const int p = static_cast<int>(i);
    if (x.x() < h + tol) left.push_back(p);
    if (x.x() > 1 - h - tol) right.push_back(p);
    if (x.x() < h + tol && x.y() < h + tol) pin.push_back(p);
    if (x.y() > 1 - h - tol) top.push_back(p);
    if (x.y() < h + tol) bottom.push_back(p);
  }
  std::vector<DisplacementSet> ds(3);
  ds[0] = {"left", left, {}};
  ds[0].component[0] = [](double) { return 0.0; };
  ds[1] = {"pin", pin, {}};
  ds[1].component[1] = [](double) { return 0.0; };
  ds[2] = {"right", right, {}};
  ds[2].component[0] = [=](double t) { return (lambda - 1) * t; };
  if (surface) {
    ds[0].surface_offset.assign(left.size(), Vec3(-h, 0, 0));
    ds[2].surface_offset.assign(right.size(), Vec3(h, 0, 0));
  }
  NewtonOptions no;
  no.steps = 4;
  no.tolerance = 1e-11;
  StaticSolver solver(model, ds, {}, no);
  solver.run();
  const Eigen::VectorXd& u = solver.displacement();
  Uniaxial r;
  r.reaction = solver.reaction(2).x();
  double ut = 0, ub = 0;
  for (int p : top) ut += u[2 * p + 1] / top.size();
  for (int p : bottom) ub += u[2 * p + 1] / bottom.size();
  r.lateral = 1 + (ut - ub) / (1 - 2 * h);
  const Mat3 F = uniaxial(*mat, lambda);
  Mat3 P;
  mat->evaluate(F, nullptr, &P, nullptr);
  r.reaction_exact = P(0, 0) * 1.0;  // nominal stress × the face length 1
  r.lateral_exact = F(1, 1);
  r.balance = solver.force_balance();
  return r;
}

}  // namespace

// λ = 3 uniaxial on a 10 × 10 grid: with the grips on the faces the discrete solution is the
// closed-form homogeneous state (round-off: the weak form reproduces every homogeneous state,
// and the extrapolation to the face is exact for it), for plane strain and plane stress,
// K/μ = 10 and 100. The point-column grips of the same grid stretch by 2/(1 − Δx) instead.
// PDCG_GRIP_CELLS=40 runs the same cases at Δx = 1/40 and prints the table of
// docs/solver.md §4 (PDCG_GRIP_POINTS=1: with the point-column grips for comparison).
TEST(Grips, SurfaceGripsGiveTheClosedFormUniaxialStretch) {
  const char* env = std::getenv("PDCG_GRIP_CELLS");
  const int n = env ? std::atoi(env) : 10;
  for (Kinematics kin : {Kinematics::plane_strain, Kinematics::plane_stress})
    for (double K : {10.0, 100.0}) {
      const Uniaxial r = stretch(n, kin, K, 3.0, true);
      if (env) {
        // PDCG_GRIP_POINTS=1: also the point-column grips of the same grid
        const Uniaxial p =
            std::getenv("PDCG_GRIP_POINTS") ? stretch(n, kin, K, 3.0, false) : Uniaxial{};
        std::printf(
            "table: %s K=%g n=%d | surface: reaction %+.2e lateral %+.2e balance %.1e | points: "
            "reaction %+.2e lateral %+.2e\n",
            kin == Kinematics::plane_strain ? "strain" : "stress", K, n,
            r.reaction / r.reaction_exact - 1, r.lateral / r.lateral_exact - 1, r.balance,
            p.reaction / p.reaction_exact - 1, p.lateral / p.lateral_exact - 1);
      }
      SCOPED_TRACE(testing::Message()
                   << (kin == Kinematics::plane_strain ? "strain" : "stress") << " K = " << K);
      // 1e-9: Newton tolerance 1e-11 times the conditioning of the K = 100 system
      EXPECT_NEAR(r.reaction / r.reaction_exact - 1, 0.0, 1e-9);
      EXPECT_NEAR(r.lateral / r.lateral_exact - 1, 0.0, 1e-9);
      EXPECT_LT(r.balance, 1e-8);
    }
  // The point columns as grips: stretch 1 + 2/(1 − 0.1) = 3.22, reaction ≈ 6% high.
  const Uniaxial p = stretch(10, Kinematics::plane_stress, 100.0, 3.0, false);
  EXPECT_GT(p.reaction / p.reaction_exact - 1, 0.04);
}
