/// \file
/// Hyperelastic materials for the correspondence solver: energy density Ψ(F),
/// first Piola–Kirchhoff stress P = ∂Ψ/∂F and tangent A = ∂P/∂F.
///
/// Interface choice: one abstract class `Material` (virtual evaluate), so that
/// the solver, the scene reader and a later Cauchy–Born material (whose energy
/// comes from a PD model and is known only at run time) all meet at one type.
/// The virtual call is made once per BA bond per assembly, next to a 3×3
/// inverse and a 9×9 tangent; its cost is negligible there. The concrete
/// Neo-Hookean variants are small value types (two doubles).
///
/// Conventions. F is always passed as a 3×3 matrix. A material of
/// dimension() == 2 reads only the in-plane block F(0:1,0:1) and fills only
/// the in-plane blocks of P and A (the rest is set to zero); the out-of-plane
/// kinematics (plane strain F₃₃ = 1, plane stress P₃₃ = 0) is the material's
/// business. The tangent is stored flat: A(3a+J, 3b+L) = ∂P_aJ/∂F_bL.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>

namespace pdcg::solver {

using Mat3 = Eigen::Matrix3d;

/// The solver's vector kernels (the AVX2 + FMA residual sweep and Neo-Hookean stress4, taken at
/// run time when the CPU has both) are allowed by default; set_vector_kernels(false) makes
/// every later evaluation take the portable loops (same results to round-off; a switch to
/// compare the two paths in one process, e.g. workflows/bench/roofline.sh). Process-wide.
void set_vector_kernels(bool enabled);
/// True when the vector kernels are compiled in, the CPU has AVX2 and FMA, and they are allowed.
bool vector_kernels();
using Tangent = Eigen::Matrix<double, 9, 9>;

/// Flat index of the component (a, J) of a 3×3 tensor in a Tangent.
constexpr int flat(int a, int J) { return 3 * a + J; }

class Material {
 public:
  virtual ~Material() = default;
  /// 2 (plane problems: only the in-plane block is used) or 3.
  virtual int dimension() const = 0;
  /// Evaluates Ψ, P and A at F (any output may be null). Returns false when F
  /// is inadmissible (J ≤ 0, or the plane-stress local solve failed); the
  /// outputs are then unspecified and the caller should cut back its step.
  virtual bool evaluate(const Mat3& F, double* psi, Mat3* P, Tangent* A) const = 0;
  /// The material of point `point` of the body (per-point materials of a nonhomogeneous body,
  /// e.g. the per-point Cauchy–Born material of a model with surfaces; docs/elastic.md §7).
  /// The solver evaluates a stencil with the material of its centre (a BA stencil B_ij: point
  /// i's). Homogeneous materials: evaluate(F, …).
  virtual bool evaluate_at(int point, const Mat3& F, double* psi, Mat3* P, Tangent* A) const {
    (void)point;
    return evaluate(F, psi, P, A);
  }
  /// Stress only, for four deformation gradients at once (the BA residual batches its
  /// constitutive updates over four stencils; the Neo-Hookean materials vectorise them).
  /// Structure of arrays over the d×d block (d = dimension()): F[4 (d a + J) + k] is F_aJ of
  /// gradient k, P likewise; points[k] as in evaluate_at. Returns a bit mask, bit k set when
  /// gradient k is admissible (P of the others is unspecified). The default calls
  /// evaluate_at once per gradient.
  virtual unsigned stress4(const int* points, const double* F, double* P) const;
  /// Full 3×3 deformation gradient the material works with (plane stress:
  /// F₃₃ from P₃₃ = 0; plane strain: F₃₃ = 1). For output (Cauchy stress).
  virtual Mat3 full_deformation_gradient(const Mat3& F) const = 0;
  /// A short human-readable name, e.g. "neo-hookean (plane stress)".
  virtual std::string name() const = 0;
  virtual std::unique_ptr<Material> clone() const = 0;
};

/// Compressible Neo-Hookean of Behera, Roy & Madenci (seed):
///   Ψ = μ/2 (Ī₁ − 3) + K/8 (J − 1/J)²,  Ī₁ = J^(−2/3) tr C,  C = FᵀF,
///   P = μ J^(−2/3) (F − ⅓ tr C F⁻ᵀ) + K/4 (J² − J⁻²) F⁻ᵀ.
/// Small-strain limit: shear modulus μ, bulk modulus K.
/// Tangent (H = F⁻ᵀ):
///   ∂P_aJ/∂F_bL = μJ^(−2/3)[δ_ab δ_JL − ⅔ F_bL H_aJ − ⅔ H_bL F_aJ + ⅔·⅓ I₁ H_bL H_aJ
///                 + ⅓ I₁ H_aL H_bJ]
///               + K/2 (J² + J⁻²) H_aJ H_bL − K/4 (J² − J⁻²) H_aL H_bJ.
struct NeoHookeanParameters {
  double shear_modulus = 1.0;  ///< μ
  double bulk_modulus = 10.0;  ///< K
};

/// 3D evaluation (free function, used by all three variants). Returns false if J ≤ 0.
bool neo_hookean_3d(const NeoHookeanParameters& p, const Mat3& F, double* psi, Mat3* P, Tangent* A);

class NeoHookean3D final : public Material {
 public:
  explicit NeoHookean3D(NeoHookeanParameters p) : p_(p) {}
  int dimension() const override { return 3; }
  bool evaluate(const Mat3& F, double* psi, Mat3* P, Tangent* A) const override {
    return neo_hookean_3d(p_, F, psi, P, A);
  }
  unsigned stress4(const int* points, const double* F, double* P) const override;
  Mat3 full_deformation_gradient(const Mat3& F) const override { return F; }
  std::string name() const override { return "neo-hookean (3d)"; }
  std::unique_ptr<Material> clone() const override { return std::make_unique<NeoHookean3D>(*this); }
  const NeoHookeanParameters& parameters() const { return p_; }

 private:
  NeoHookeanParameters p_;
};

/// Plane strain: F = [[F₂, 0], [0, 1]]; Ψ, P and A are the 3D ones restricted to
/// the in-plane block (P₃₃ ≠ 0 is the out-of-plane reaction stress).
class NeoHookeanPlaneStrain final : public Material {
 public:
  explicit NeoHookeanPlaneStrain(NeoHookeanParameters p) : p_(p) {}
  int dimension() const override { return 2; }
  bool evaluate(const Mat3& F, double* psi, Mat3* P, Tangent* A) const override;
  unsigned stress4(const int* points, const double* F, double* P) const override;
  Mat3 full_deformation_gradient(const Mat3& F) const override;
  std::string name() const override { return "neo-hookean (plane strain)"; }
  std::unique_ptr<Material> clone() const override {
    return std::make_unique<NeoHookeanPlaneStrain>(*this);
  }

 private:
  NeoHookeanParameters p_;
};

/// Plane stress: F = [[F₂, 0], [0, λ₃]] with λ₃ solving P₃₃(F₂, λ₃) = 0 (local
/// safeguarded Newton). Ψ₂(F₂) = Ψ(F₂, λ₃(F₂)); P₂ = in-plane block of P
/// (envelope theorem, P₃₃ = 0); consistent condensed tangent
///   A₂_aJbL = A_aJbL − A_aJ33 A_33bL / A_3333.
class NeoHookeanPlaneStress final : public Material {
 public:
  explicit NeoHookeanPlaneStress(NeoHookeanParameters p) : p_(p) {}
  int dimension() const override { return 2; }
  bool evaluate(const Mat3& F, double* psi, Mat3* P, Tangent* A) const override;
  Mat3 full_deformation_gradient(const Mat3& F) const override;
  /// λ₃ with P₃₃ = 0 for the in-plane block of F; NaN if the solve fails.
  double thickness_stretch(const Mat3& F) const;
  std::string name() const override { return "neo-hookean (plane stress)"; }
  std::unique_ptr<Material> clone() const override {
    return std::make_unique<NeoHookeanPlaneStress>(*this);
  }

 private:
  NeoHookeanParameters p_;
};

/// Kinematic setting of a Neo-Hookean material.
enum class Kinematics { three_d, plane_strain, plane_stress };
std::unique_ptr<Material> make_neo_hookean(NeoHookeanParameters p, Kinematics k);

}  // namespace pdcg::solver
