#include "pdcg/solver/material.hpp"

#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "residual_avx2.hpp"

namespace pdcg::solver {

namespace detail {
std::atomic<bool> vector_kernels_allowed{true};
}  // namespace detail

void set_vector_kernels(bool enabled) {
  detail::vector_kernels_allowed.store(enabled, std::memory_order_relaxed);
}

bool vector_kernels() {
#ifdef PDCG_SOLVER_AVX2
  return detail::cpu_has_avx2_fma();
#else
  return false;
#endif
}

unsigned Material::stress4(const int* points, const double* F, double* P) const {
  const int d = dimension();
  unsigned good = 0;
  for (int k = 0; k < 4; ++k) {
    Mat3 Fk = Mat3::Identity(), Pk;
    for (int a = 0; a < d; ++a)
      for (int J = 0; J < d; ++J) Fk(a, J) = F[4 * (d * a + J) + k];
    if (!evaluate_at(points[k], Fk, nullptr, &Pk, nullptr)) continue;
    good |= 1u << k;
    for (int a = 0; a < d; ++a)
      for (int J = 0; J < d; ++J) P[4 * (d * a + J) + k] = Pk(a, J);
  }
  return good;
}

unsigned NeoHookean3D::stress4(const int* points, const double* F, double* P) const {
#ifdef PDCG_SOLVER_AVX2
  if (detail::cpu_has_avx2_fma()) {
    const unsigned m = detail::neo_hookean_stress4_avx2(3, p_.shear_modulus, p_.bulk_modulus, F, P);
    if (m != detail::kNotHandled) return m;
  }
#endif
  return Material::stress4(points, F, P);
}

unsigned NeoHookeanPlaneStrain::stress4(const int* points, const double* F, double* P) const {
#ifdef PDCG_SOLVER_AVX2
  if (detail::cpu_has_avx2_fma()) {
    const unsigned m = detail::neo_hookean_stress4_avx2(2, p_.shear_modulus, p_.bulk_modulus, F, P);
    if (m != detail::kNotHandled) return m;
  }
#endif
  return Material::stress4(points, F, P);
}

bool neo_hookean_3d(const NeoHookeanParameters& p, const Mat3& F, double* psi, Mat3* P,
                    Tangent* A) {
  // Cofactor matrix cof F = J F⁻ᵀ (J by its first row): one pass gives both J and
  // H = F⁻ᵀ (Eigen's determinant() + inverse() computed the cofactors twice).
  Mat3 cof;
  cof(0, 0) = F(1, 1) * F(2, 2) - F(1, 2) * F(2, 1);
  cof(0, 1) = F(1, 2) * F(2, 0) - F(1, 0) * F(2, 2);
  cof(0, 2) = F(1, 0) * F(2, 1) - F(1, 1) * F(2, 0);
  const double J = F(0, 0) * cof(0, 0) + F(0, 1) * cof(0, 1) + F(0, 2) * cof(0, 2);
  if (!(J > 0.0) || !std::isfinite(J)) return false;
  const double mu = p.shear_modulus, K = p.bulk_modulus;
  const double I1 = F.squaredNorm();            // tr C
  const double Jm23 = std::pow(J, -2.0 / 3.0);  // (1/cbrt(J)² measured no cheaper in glibc)
  if (psi) {
    const double v = J - 1.0 / J;
    *psi = 0.5 * mu * (Jm23 * I1 - 3.0) + 0.125 * K * v * v;
  }
  if (!P && !A) return true;
  cof(1, 0) = F(0, 2) * F(2, 1) - F(0, 1) * F(2, 2);
  cof(1, 1) = F(0, 0) * F(2, 2) - F(0, 2) * F(2, 0);
  cof(1, 2) = F(0, 1) * F(2, 0) - F(0, 0) * F(2, 1);
  cof(2, 0) = F(0, 1) * F(1, 2) - F(0, 2) * F(1, 1);
  cof(2, 1) = F(0, 2) * F(1, 0) - F(0, 0) * F(1, 2);
  cof(2, 2) = F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0);
  const Mat3 H = cof / J;  // F⁻ᵀ
  const double J2 = J * J, Jm2 = 1.0 / J2;
  if (P) *P = mu * Jm23 * (F - (I1 / 3.0) * H) + 0.25 * K * (J2 - Jm2) * H;
  if (A) {
    const double c1 = mu * Jm23;
    const double cv1 = 0.5 * K * (J2 + Jm2), cv2 = 0.25 * K * (J2 - Jm2);
    for (int a = 0; a < 3; ++a)
      for (int Jc = 0; Jc < 3; ++Jc)
        for (int b = 0; b < 3; ++b)
          for (int L = 0; L < 3; ++L) {
            const double iso = (a == b && Jc == L ? 1.0 : 0.0) -
                               (2.0 / 3.0) * (F(b, L) * H(a, Jc) + H(b, L) * F(a, Jc)) +
                               (2.0 / 9.0) * I1 * H(b, L) * H(a, Jc) +
                               (I1 / 3.0) * H(a, L) * H(b, Jc);
            (*A)(flat(a, Jc), flat(b, L)) =
                c1 * iso + cv1 * H(a, Jc) * H(b, L) - cv2 * H(a, L) * H(b, Jc);
          }
  }
  return true;
}

namespace {
Mat3 embed(const Mat3& F, double f33) {
  Mat3 G = Mat3::Zero();
  G.topLeftCorner<2, 2>() = F.topLeftCorner<2, 2>();
  G(2, 2) = f33;
  return G;
}
void restrict_in_plane(Mat3* P, Tangent* A) {
  if (P) {
    P->row(2).setZero();
    P->col(2).setZero();
  }
  if (A) {
    for (int i = 0; i < 9; ++i)
      if (i % 3 == 2 || i / 3 == 2) {
        A->row(i).setZero();
        A->col(i).setZero();
      }
  }
}
}  // namespace

bool NeoHookeanPlaneStrain::evaluate(const Mat3& F, double* psi, Mat3* P, Tangent* A) const {
  if (!A) {
    // Stress only (the residual, once per BA stencil): the same formulas on the 2×2 block,
    // F₃₃ = 1, F⁻ᵀ in-plane = cof(F₂)/J; identical to the 3D path up to round-off, at about
    // half its cost (the 3×3 path dominated the 2D residual: 24 of 60 instructions per term).
    const double a = F(0, 0), b = F(0, 1), c = F(1, 0), d = F(1, 1);
    const double J = a * d - b * c;
    if (!(J > 0.0) || !std::isfinite(J)) return false;
    const double mu = p_.shear_modulus, K = p_.bulk_modulus;
    const double I1 = a * a + b * b + c * c + d * d + 1.0;
    const double Jm23 = std::pow(J, -2.0 / 3.0);
    if (psi) {
      const double v = J - 1.0 / J;
      *psi = 0.5 * mu * (Jm23 * I1 - 3.0) + 0.125 * K * v * v;
    }
    if (P) {
      const double iJ = 1.0 / J, J2 = J * J;
      const double h00 = d * iJ, h01 = -c * iJ, h10 = -b * iJ, h11 = a * iJ;  // F⁻ᵀ
      const double c1 = mu * Jm23, c2 = c1 * I1 / 3.0, c3 = 0.25 * K * (J2 - 1.0 / J2);
      P->setZero();
      (*P)(0, 0) = c1 * a - c2 * h00 + c3 * h00;
      (*P)(0, 1) = c1 * b - c2 * h01 + c3 * h01;
      (*P)(1, 0) = c1 * c - c2 * h10 + c3 * h10;
      (*P)(1, 1) = c1 * d - c2 * h11 + c3 * h11;
    }
    return true;
  }
  if (!neo_hookean_3d(p_, embed(F, 1.0), psi, P, A)) return false;
  restrict_in_plane(P, A);
  return true;
}

Mat3 NeoHookeanPlaneStrain::full_deformation_gradient(const Mat3& F) const { return embed(F, 1.0); }

double NeoHookeanPlaneStress::thickness_stretch(const Mat3& F) const {
  // P₃₃(λ) = μ J^(−2/3) (λ − I₁/(3λ)) + K/4 (J² − J⁻²)/λ with J = J₂ λ. It is
  // increasing in λ (A₃₃₃₃ > 0 for this energy), negative as λ → 0⁺ and positive
  // as λ → ∞: Newton from λ = J₂^(−1/2) (incompressible guess), safeguarded by a
  // bracket that bisection falls back on.
  const double J2d = F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0);
  if (!(J2d > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  double lo = 0.0, hi = std::numeric_limits<double>::infinity();
  double lam = 1.0 / std::sqrt(J2d);
  // P₃₃ and A₃₃₃₃ = ∂P₃₃/∂λ of neo_hookean_3d at diag(F₂, λ) in closed form (F⁻ᵀ₃₃ = 1/λ):
  //   A₃₃₃₃ = μJ^(−2/3) (5I₁/(9λ²) − 1/3) + K/4 (J² + 3J⁻²)/λ²,
  // scalars only (the full 3×3×3×3 tangent per iteration was a third of a plane-stress
  // assembly: measured with perf on the 50 × 50 rupture sheet, docs/effects.md §2).
  const double mu = p_.shear_modulus, K = p_.bulk_modulus;
  const double I1p = F(0, 0) * F(0, 0) + F(0, 1) * F(0, 1) + F(1, 0) * F(1, 0) + F(1, 1) * F(1, 1);
  for (int it = 0; it < 100; ++it) {
    const double J = J2d * lam;
    if (!(J > 0.0) || !std::isfinite(J)) return std::numeric_limits<double>::quiet_NaN();
    const double I1 = I1p + lam * lam, il = 1.0 / lam, Jm23 = std::pow(J, -2.0 / 3.0);
    const double J2 = J * J, Jm2 = 1.0 / J2;
    const double r = mu * Jm23 * (lam - I1 * il / 3.0) + 0.25 * K * (J2 - Jm2) * il;
    const double d =
        mu * Jm23 * (5.0 * I1 * il * il / 9.0 - 1.0 / 3.0) + 0.25 * K * (J2 + 3.0 * Jm2) * il * il;
    if (r > 0)
      hi = std::min(hi, lam);
    else
      lo = std::max(lo, lam);
    if (std::abs(r) <= 1e-14 * (p_.shear_modulus + p_.bulk_modulus)) return lam;
    double next = lam - r / d;
    if (!(d > 0) || !(next > lo) || !(next < hi))
      next = std::isfinite(hi) ? 0.5 * (lo + hi) : 2.0 * lam;
    if (std::abs(next - lam) <= 1e-15 * lam) return next;
    lam = next;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

bool NeoHookeanPlaneStress::evaluate(const Mat3& F, double* psi, Mat3* P, Tangent* A) const {
  const double lam = thickness_stretch(F);
  if (!std::isfinite(lam)) return false;
  Tangent A3;
  Mat3 P3;
  // The 3D tangent only when the condensed one is asked for: the stress-only calls (the
  // residual, ADR's one force per iteration) spent ≈ 40 % of their time on the 81 entries
  // of A3 (perf, 30 × 30 rupture sheet, docs/effects.md §2); P3 does not depend on them.
  if (!neo_hookean_3d(p_, embed(F, lam), psi, P || A ? &P3 : nullptr, A ? &A3 : nullptr))
    return false;
  if (P) {
    *P = P3;
    restrict_in_plane(P, nullptr);
  }
  if (A) {
    // Condensation of the thickness stretch: dλ/dF_bL = −A_33bL / A_3333.
    const double a33 = A3(8, 8);
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 9; ++j) (*A)(i, j) = A3(i, j) - A3(i, 8) * A3(8, j) / a33;
    restrict_in_plane(nullptr, A);
  }
  return true;
}

Mat3 NeoHookeanPlaneStress::full_deformation_gradient(const Mat3& F) const {
  return embed(F, thickness_stretch(F));
}

std::unique_ptr<Material> make_neo_hookean(NeoHookeanParameters p, Kinematics k) {
  switch (k) {
    case Kinematics::three_d:
      return std::make_unique<NeoHookean3D>(p);
    case Kinematics::plane_strain:
      return std::make_unique<NeoHookeanPlaneStrain>(p);
    case Kinematics::plane_stress:
      return std::make_unique<NeoHookeanPlaneStress>(p);
  }
  return nullptr;
}

}  // namespace pdcg::solver
