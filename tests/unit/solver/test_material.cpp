// Neo-Hookean materials: P = ∂Ψ/∂F and A = ∂P/∂F against central finite
// differences, objectivity, and closed-form limits nobody here computed
// (small-strain isotropic elasticity, incompressible uniaxial nominal stress).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <random>

#include "pdcg/solver/material.hpp"
#include "pdcg_test.hpp"

using namespace pdcg::solver;

namespace {

Mat3 random_F(std::mt19937& rng, int dim) {
  // Stretches in [0.4, 3] and a random rotation: a large, general deformation.
  std::uniform_real_distribution<double> s(0.4, 3.0), a(-3.14, 3.14);
  Mat3 U = Mat3::Zero();
  for (int i = 0; i < 3; ++i) U(i, i) = s(rng);
  Mat3 R = Mat3::Identity();
  if (dim == 3) {
    R = Eigen::AngleAxisd(a(rng), Eigen::Vector3d(s(rng), s(rng) - 1.7, s(rng)).normalized())
            .toRotationMatrix();
  } else {
    const double t = a(rng);
    R.topLeftCorner<2, 2>() << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
    U(2, 2) = 1.0;
  }
  Mat3 shear = Mat3::Identity();
  shear(0, 1) = 0.3 * a(rng) / 3.14;
  Mat3 F = R * U * shear;
  if (dim == 2) {
    F.col(2).setZero();
    F.row(2).setZero();
    F(2, 2) = 1.0;
  }
  return F;
}

void check_derivatives(const Material& m, std::uint32_t seed) {
  std::mt19937 rng(seed);
  const int d = m.dimension();
  for (int trial = 0; trial < 20; ++trial) {
    const Mat3 F = random_F(rng, d);
    double psi;
    Mat3 P;
    Tangent A;
    ASSERT_TRUE(m.evaluate(F, &psi, &P, &A));
    const double h = 1e-6;
    std::vector<double> p_fd, p_an, a_fd, a_an;
    for (int b = 0; b < d; ++b)
      for (int L = 0; L < d; ++L) {
        Mat3 Fp = F, Fm = F;
        Fp(b, L) += h;
        Fm(b, L) -= h;
        double sp, sm;
        Mat3 Pp, Pm;
        ASSERT_TRUE(m.evaluate(Fp, &sp, &Pp, nullptr));
        ASSERT_TRUE(m.evaluate(Fm, &sm, &Pm, nullptr));
        p_fd.push_back((sp - sm) / (2 * h));
        p_an.push_back(P(b, L));
        for (int a = 0; a < d; ++a)
          for (int J = 0; J < d; ++J) {
            a_fd.push_back((Pp(a, J) - Pm(a, J)) / (2 * h));
            a_an.push_back(A(flat(a, J), flat(b, L)));
          }
      }
    // Central differences with h = 1e-6 have truncation ~h² and round-off ~1e-16/h:
    // 1e-6 relative to the largest entry is met by a correct derivative only.
    EXPECT_LT(pdcg::test::max_norm_relative_error(p_an, p_fd), 1e-6)
        << m.name() << " P, trial " << trial;
    EXPECT_LT(pdcg::test::max_norm_relative_error(a_an, a_fd), 1e-6)
        << m.name() << " A, trial " << trial;
    // Hyperelastic tangent is major-symmetric.
    EXPECT_LT((A - A.transpose()).norm(), 1e-10 * A.norm()) << m.name();
  }
}

void check_objectivity(const Material& m) {
  std::mt19937 rng(7);
  const int d = m.dimension();
  for (int trial = 0; trial < 10; ++trial) {
    const Mat3 F = random_F(rng, d);
    Mat3 Q = Mat3::Identity();
    if (d == 3) {
      Q = Eigen::AngleAxisd(0.7 + trial, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    } else {
      const double t = 0.3 + trial;
      Q.topLeftCorner<2, 2>() << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
    }
    double s1, s2;
    Mat3 P1, P2;
    ASSERT_TRUE(m.evaluate(F, &s1, &P1, nullptr));
    ASSERT_TRUE(m.evaluate(Q * F, &s2, &P2, nullptr));
    // Ψ(QF) = Ψ(F), P(QF) = Q P(F); only round-off differs.
    EXPECT_NEAR(s2, s1, 1e-12 * std::abs(s1) + 1e-14);
    EXPECT_LT((P2 - Q * P1).norm(), 1e-11 * P1.norm() + 1e-14);
  }
}

const NeoHookeanParameters kParams{1.3, 11.0};

}  // namespace

TEST(NeoHookean, ThreeDDerivativesMatchFiniteDifferences) {
  check_derivatives(NeoHookean3D(kParams), 1);
}
TEST(NeoHookean, PlaneStrainDerivativesMatchFiniteDifferences) {
  check_derivatives(NeoHookeanPlaneStrain(kParams), 2);
}
TEST(NeoHookean, PlaneStressDerivativesMatchFiniteDifferences) {
  check_derivatives(NeoHookeanPlaneStress(kParams), 3);
}
TEST(NeoHookean, Objectivity) {
  check_objectivity(NeoHookean3D(kParams));
  check_objectivity(NeoHookeanPlaneStrain(kParams));
  check_objectivity(NeoHookeanPlaneStress(kParams));
}

TEST(NeoHookean, ReferenceStateIsStressFree) {
  for (auto k : {Kinematics::three_d, Kinematics::plane_strain, Kinematics::plane_stress}) {
    auto m = make_neo_hookean(kParams, k);
    double psi;
    Mat3 P;
    ASSERT_TRUE(m->evaluate(Mat3::Identity(), &psi, &P, nullptr));
    EXPECT_NEAR(psi, 0.0, 1e-14);
    EXPECT_LT(P.norm(), 1e-13);
  }
}

// Small-strain limit = isotropic linear elasticity with shear modulus μ and
// bulk modulus K (closed form): E = 9Kμ/(3K+μ), ν = (3K−2μ)/(2(3K+μ)).
TEST(NeoHookean, SmallStrainLimitIsLinearElasticity) {
  const double mu = kParams.shear_modulus, K = kParams.bulk_modulus;
  const double E = 9 * K * mu / (3 * K + mu), nu = (3 * K - 2 * mu) / (2 * (3 * K + mu));
  const double lam = K - 2.0 * mu / 3.0;  // Lamé λ
  Tangent A;
  Mat3 P;
  // 3D tangent at F = I: A_aJbL = λ δ_aJ δ_bL + μ (δ_ab δ_JL + δ_aL δ_bJ).
  ASSERT_TRUE(NeoHookean3D(kParams).evaluate(Mat3::Identity(), nullptr, &P, &A));
  for (int a = 0; a < 3; ++a)
    for (int J = 0; J < 3; ++J)
      for (int b = 0; b < 3; ++b)
        for (int L = 0; L < 3; ++L) {
          const double e =
              lam * (a == J) * (b == L) + mu * ((a == b) * (J == L) + (a == L) * (b == J));
          EXPECT_NEAR(A(flat(a, J), flat(b, L)), e, 1e-12);  // exact up to round-off
        }
  // Plane stress tangent at I: C1111 = E/(1−ν²), C1122 = Eν/(1−ν²), C1212 = μ.
  ASSERT_TRUE(NeoHookeanPlaneStress(kParams).evaluate(Mat3::Identity(), nullptr, &P, &A));
  EXPECT_NEAR(A(flat(0, 0), flat(0, 0)), E / (1 - nu * nu), 1e-12);
  EXPECT_NEAR(A(flat(0, 0), flat(1, 1)), E * nu / (1 - nu * nu), 1e-12);
  EXPECT_NEAR(A(flat(0, 1), flat(0, 1)), mu, 1e-12);
  // Plane-stress thickness strain under small uniaxial in-plane strain ε:
  // with ε₂₂ = 0 and σ₃₃ = 0: ε₃₃ = −λ_L/(λ_L+2μ) ε = −ν/(1−ν) ε.
  const double eps = 1e-6;
  Mat3 F = Mat3::Identity();
  F(0, 0) += eps;
  const double l3 = NeoHookeanPlaneStress(kParams).thickness_stretch(F);
  // Relative error of the linearisation is O(ε): 1e-4 relative is far above it.
  EXPECT_NEAR((l3 - 1.0) / eps, -nu / (1 - nu), 1e-4 * nu / (1 - nu));
}

// Incompressible limit (K ≫ μ), uniaxial tension (plane stress, P₂₂ = 0):
// nominal stress P₁₁ = μ(λ − λ⁻²) (Treloar), lateral stretch λ^(−1/2).
TEST(NeoHookean, NearlyIncompressibleUniaxialMatchesTreloar) {
  const double mu = 1.0, K = 1e5;
  NeoHookeanPlaneStress m({mu, K});
  for (double lam : {1.5, 2.0, 3.0}) {
    // Scalar root solve of P₂₂(λ, f) = 0 for the lateral stretch f (secant).
    auto p22 = [&](double f) {
      Mat3 F = Mat3::Identity();
      F(0, 0) = lam;
      F(1, 1) = f;
      Mat3 P;
      EXPECT_TRUE(m.evaluate(F, nullptr, &P, nullptr));
      return P(1, 1);
    };
    double f0 = 1.0 / std::sqrt(lam) * 0.99, f1 = 1.0 / std::sqrt(lam) * 1.01;
    for (int it = 0; it < 60 && std::abs(f1 - f0) > 1e-15; ++it) {
      const double g0 = p22(f0), g1 = p22(f1);
      const double f2 = f1 - g1 * (f1 - f0) / (g1 - g0);
      f0 = f1;
      f1 = f2;
    }
    Mat3 F = Mat3::Identity();
    F(0, 0) = lam;
    F(1, 1) = f1;
    Mat3 P;
    ASSERT_TRUE(m.evaluate(F, nullptr, &P, nullptr));
    // Compressibility corrections are O(μ/K) = 1e-5: 1e-4 relative covers them.
    EXPECT_NEAR(P(0, 0), mu * (lam - 1.0 / (lam * lam)), 1e-4 * mu * lam);
    EXPECT_NEAR(f1, 1.0 / std::sqrt(lam), 1e-4);
    EXPECT_NEAR(m.thickness_stretch(F), 1.0 / std::sqrt(lam), 1e-4);
  }
}

// The batched stress of the residual (Material::stress4: AVX2 J^(−2/3) by Newton on CPUs with
// AVX2 + FMA, the scalar evaluate otherwise) against evaluate, lane by lane: large general
// deformations (J from ≈ 0.03 to ≈ 60), a scaled one (J = 10⁶, 10⁻⁶), inadmissible lanes
// (J ≤ 0, NaN) that must be flagged, and J = 10⁻³⁰⁰ (outside the vector path's range: the
// scalar fallback; P overflows there in both).
TEST(NeoHookean, BatchedStressMatchesEvaluate) {
  std::mt19937 rng(11);
  for (auto k : {Kinematics::three_d, Kinematics::plane_strain, Kinematics::plane_stress}) {
    auto m = make_neo_hookean(kParams, k);
    const int d = m->dimension();
    for (int batch = 0; batch < 64; ++batch) {
      Mat3 F[4];
      for (auto& Fk : F) Fk = random_F(rng, d);
      if (batch == 1) F[1] *= 100.0;  // J = 10⁶ (3D), 10⁴ (2D)
      if (batch == 2) F[2] *= 0.01;
      if (batch == 3) F[0](0, 0) = std::nan("");
      if (batch == 4) F[3].row(0) *= -1.0;  // J < 0
      if (batch == 5 && k != Kinematics::plane_stress) F[1] *= 1e-100;
      double Fs[36], Ps[36];
      const int pts[4] = {0, 1, 2, 3};
      for (int q = 0; q < 4; ++q)
        for (int a = 0; a < d; ++a)
          for (int J = 0; J < d; ++J) Fs[4 * (d * a + J) + q] = F[q](a, J);
      const unsigned good = m->stress4(pts, Fs, Ps);
      for (int q = 0; q < 4; ++q) {
        Mat3 P;
        const bool ok = m->evaluate(F[q], nullptr, &P, nullptr);
        ASSERT_EQ(ok, ((good >> q) & 1u) != 0) << "batch " << batch << " lane " << q;
        if (!ok) continue;
        if (!P.topLeftCorner(d, d).allFinite()) {  // J = 10⁻³⁰⁰: J⁻² overflows in both paths
          EXPECT_FALSE(std::isfinite(Ps[q]));
          continue;
        }
        // Both paths carry round-off of the two stress terms, each of size ≈ (μ + K)·(J^(−2/3)
        // |F| + (J² + J⁻²)|F⁻ᵀ|): 1e-14 of that scale is ≈ 50 ulp (J^(−2/3) by Newton is
        // within 4e-16 of pow; the sums are ordered differently).
        const Mat3 H = F[q].topLeftCorner(d, d).inverse().transpose();
        const double J = F[q].topLeftCorner(d, d).determinant();
        const double scale = (kParams.shear_modulus + kParams.bulk_modulus) *
                                 (std::pow(std::abs(J), -2.0 / 3.0) * F[q].squaredNorm() +
                                  (J * J + 1.0 / (J * J)) * H.norm()) +
                             1e-300;
        for (int a = 0; a < d; ++a)
          for (int J2 = 0; J2 < d; ++J2)
            EXPECT_LE(std::abs(Ps[4 * (d * a + J2) + q] - P(a, J2)), 1e-14 * scale)
                << "batch " << batch << " lane " << q << " (" << a << "," << J2 << ")";
      }
    }
  }
}
