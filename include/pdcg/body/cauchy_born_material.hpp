/// \file
/// The Cauchy–Born material of a pdcg model file behind the BA solver's material interface
/// (solver::Material, include/pdcg/solver/material.hpp): Ψ(F) = W(F) of the body, P and
/// A = ∂P/∂F from the analytic force-state tangents (cauchy_born.hpp, docs/elastic.md).
///
/// Header-only on purpose: the body module comes before the solver module and does not link
/// it; solver::Material is an interface with inline members only, so a consumer that links
/// both (the scene) can use this adapter without a dependency cycle.
///
/// Kinematics: a body of dimension 3 is a 3D material; a body of dimension 2 (a film in the
/// xy plane) is a plane-strain material — the in-plane block of F is used with F₃₃ = 1 and only
/// the in-plane blocks of P and A are filled (the convention of solver::Material).
/// Inner relaxation: the body-level material relaxes the basis of a perfect crystal
/// (IonRelaxation::automatic: relaxed W, P, A; a body that is not a perfect crystal is
/// clamped-ion with a warning). The per-point material of a crystal with a basis uses the
/// relaxed shifts of the model's bulk crystal (CauchyBorn::point_sum; clamped-ion on request,
/// with a warning). Limits: one material for the whole body (body-level W); the
/// per-point form W_p of a homogenised body is CauchyBorn::points. Each evaluation costs one family
/// per distinct atomic environment (one for a perfect Bravais crystal).
#pragma once

#include <fmt/format.h>

#include <Eigen/Dense>
#include <atomic>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "pdcg/body/cauchy_born.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/body/quasi_harmonic.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/solver/material.hpp"

namespace pdcg::body {

namespace detail {
/// The solver's view of a Cauchy–Born state scaled by `scale` (1 for the body-level W, 1/V_p
/// for a point's share): ψ, P and A copied out; in 2D the out-of-plane row/column of P and
/// the corresponding rows/columns of A are zeroed (plane strain, F₃₃ = 1). False for a
/// non-finite energy (the solver treats the state as inadmissible).
inline bool copy_cauchy_born_state(const CauchyBornState& s, double scale, int dimension,
                                   double* psi, solver::Mat3* P, solver::Tangent* A) {
  if (!std::isfinite(s.W)) return false;
  if (psi) *psi = scale * s.W;
  if (P) {
    *P = scale * s.P;
    if (dimension == 2) {
      P->row(2).setZero();
      P->col(2).setZero();
    }
  }
  if (A) {
    *A = scale * s.A;
    if (dimension == 2)
      for (int r = 0; r < 9; ++r)
        for (int c = 0; c < 9; ++c)
          if (r / 3 == 2 || r % 3 == 2 || c / 3 == 2 || c % 3 == 2) (*A)(r, c) = 0.0;
  }
  return true;
}
/// Runs `eval` (a Cauchy–Born evaluation) into s. A NumericalError — an inner relaxation or
/// a lattice that failed at this F — is an inadmissible state for the solver: false, with one
/// warning per call site (`said`).
template <class Eval>
bool evaluate_admissible(Eval&& eval, CauchyBornState& s, std::atomic<bool>& said) {
  try {
    s = eval();
  } catch (const NumericalError& e) {
    if (!said.exchange(true))
      log::warn("{} (the solver treats such states as inadmissible)", e.what());
    return false;
  }
  return true;
}
}  // namespace detail

class CauchyBornMaterial final : public solver::Material {
 public:
  /// `ion`: inner relaxation of a crystal with a basis (cauchy_born.hpp; the scene's
  /// `material.ion_relaxation`, default automatic).
  explicit CauchyBornMaterial(std::shared_ptr<const Body> body, std::string source = {},
                              IonRelaxation ion = IonRelaxation::automatic)
      : body_(std::move(body)),
        cb_(std::make_shared<CauchyBorn>(*body_, ion)),
        source_(std::move(source)) {}
  /// Reads a pdcg-body file (`material: {model: cauchy-born, file: res.h5}`).
  static std::unique_ptr<CauchyBornMaterial> from_file(
      const std::string& path, IonRelaxation ion = IonRelaxation::automatic) {
    return std::make_unique<CauchyBornMaterial>(std::make_shared<const Body>(read_body(path)), path,
                                                ion);
  }
  /// True when the material's values are the relaxed-ion ones (CauchyBorn::relaxed_values).
  bool relaxed_values() const { return cb_->relaxed_values(); }

  int dimension() const override { return body_->dimension == 2 ? 2 : 3; }
  bool evaluate(const solver::Mat3& F, double* psi, solver::Mat3* P,
                solver::Tangent* A) const override {
    const solver::Mat3 Ff = full_deformation_gradient(F);
    if (!(Ff.determinant() > 0.0)) return false;
    CauchyBornState s;
    static std::atomic<bool> said{false};  // inner relaxation failed: an inadmissible state
    if (!detail::evaluate_admissible([&] { return cb_->evaluate(Ff, A != nullptr); }, s, said))
      return false;
    return detail::copy_cauchy_born_state(s, 1.0, dimension(), psi, P, A);
  }
  solver::Mat3 full_deformation_gradient(const solver::Mat3& F) const override {
    if (dimension() == 3) return F;
    solver::Mat3 G = solver::Mat3::Identity();
    G.topLeftCorner<2, 2>() = F.topLeftCorner<2, 2>();
    return G;
  }
  std::string name() const override {
    std::string n = "cauchy-born (";  // append, not "literal" + string (GCC 12 -Wrestrict)
    n.append(dimension() == 2 ? "plane strain" : "3d");
    if (!source_.empty()) n.append(", ").append(source_);
    return n.append(")");
  }
  std::unique_ptr<solver::Material> clone() const override {
    return std::make_unique<CauchyBornMaterial>(*this);
  }
  const CauchyBorn& cauchy_born() const { return *cb_; }

 private:
  std::shared_ptr<const Body> body_;
  std::shared_ptr<const CauchyBorn>
      cb_;  // holds a reference to *body_ (shared, so clones stay valid)
  std::string source_;
};

/// The quasi-harmonic Cauchy–Born material at temperature T (docs/temperature.md §3.1; the scene's
/// `material: {model: cauchy-born, file: …, temperature: T, free_energy: quasi-harmonic}`):
/// Ψ(F) = W_T(F), P and A of body::QuasiHarmonicCauchyBorn (static part analytic, vibrational
/// part central differences in E). 3D periodic delta bodies only (≤ 3000 atoms); every
/// evaluation diagonalises the cell's dense (3N)² Hessian 13 times (73 with the tangent), so it
/// is meant for small cells of the crystal. A lattice that is unstable at F (ω² ≤ 0) is an
/// inadmissible state for the solver (false, one warning).
class QuasiHarmonicCauchyBornMaterial final : public solver::Material {
 public:
  /// `strain_step`: the central-difference step in E of the vibrational part (the scene's
  /// `quasi_harmonic_step`; QuasiHarmonicCauchyBorn).
  QuasiHarmonicCauchyBornMaterial(std::shared_ptr<const Body> body, double temperature,
                                  std::string source = {},
                                  double strain_step = kQuasiHarmonicStepDefault)
      : body_(std::move(body)),
        qh_(std::make_shared<QuasiHarmonicCauchyBorn>(*body_, temperature, strain_step)),
        source_(std::move(source)) {}
  static std::unique_ptr<QuasiHarmonicCauchyBornMaterial> from_file(
      const std::string& path, double temperature, double strain_step = kQuasiHarmonicStepDefault) {
    return std::make_unique<QuasiHarmonicCauchyBornMaterial>(
        std::make_shared<const Body>(read_body(path)), temperature, path, strain_step);
  }
  int dimension() const override { return 3; }
  bool evaluate(const solver::Mat3& F, double* psi, solver::Mat3* P,
                solver::Tangent* A) const override {
    if (!(F.determinant() > 0.0)) return false;
    CauchyBornState s;
    static std::atomic<bool> said{false};  // unstable lattice: an inadmissible state
    if (!detail::evaluate_admissible([&] { return qh_->evaluate(F, A != nullptr); }, s, said))
      return false;
    return detail::copy_cauchy_born_state(s, 1.0, 3, psi, P, A);
  }
  solver::Mat3 full_deformation_gradient(const solver::Mat3& F) const override { return F; }
  std::string name() const override {
    std::string n = fmt::format("cauchy-born quasi-harmonic (T = {}", qh_->temperature());
    if (!source_.empty()) n.append(", ").append(source_);
    return n.append(")");
  }
  std::unique_ptr<solver::Material> clone() const override {
    return std::make_unique<QuasiHarmonicCauchyBornMaterial>(*this);
  }
  const QuasiHarmonicCauchyBorn& quasi_harmonic() const { return *qh_; }

 private:
  std::shared_ptr<const Body> body_;
  std::shared_ptr<const QuasiHarmonicCauchyBorn> qh_;  // refers to *body_ (shared)
  std::string source_;
};

/// Per-point Cauchy–Born material of a nonhomogeneous model (free surfaces, defects;
/// docs/elastic.md §7): point p of the model (homogenisation point, or atom of a delta/rescaled
/// body) has
///   W_p(F) = E_p(F) / V_p,   E_p(F) = Σ_k w_kp ψ_k(Fξ)   (CauchyBorn::point_sum),
/// P_p and A_p its analytic derivatives, V_p the point's volume in the solver's discretisation
/// (the same volumes, so Σ_p V_p W_p(F) is the model's energy under Y = Fξ). The solver point
/// index is the model point index (`geometry: {shape: model}` keeps the model's order); a BA
/// stencil B_ij uses point i's material. evaluate(F) (no point) is the body-level W(F).
/// Crystals with a basis (`ion` not clamped): every atom k sits at Fξ + s*_{c(k)}(F), s* the
/// relaxed shifts of the model's bulk crystal (docs/elastic.md §7, docs/theory.md §11), so
/// Σ_p V_p W_p(F) is the model's energy under those positions; InputError when the atoms cannot
/// be assigned to the bulk's sublattices (fix: IonRelaxation::clamped).
class PerPointCauchyBornMaterial final : public solver::Material {
 public:
  PerPointCauchyBornMaterial(std::shared_ptr<const Body> body, std::vector<double> volume,
                             std::string source = {}, IonRelaxation ion = IonRelaxation::automatic)
      : body_(std::move(body)),
        cb_(std::make_shared<CauchyBorn>(*body_, ion, true)),
        volume_(std::make_shared<const std::vector<double>>(std::move(volume))),
        source_(std::move(source)) {
    if (volume_->size() != cb_->point_count())
      throw InputError("per-point Cauchy–Born material: one volume per model point needed")
          .value(fmt::format("{} volumes for {} points", volume_->size(), cb_->point_count()));
  }

  int dimension() const override { return body_->dimension == 2 ? 2 : 3; }
  bool evaluate(const solver::Mat3& F, double* psi, solver::Mat3* P,
                solver::Tangent* A) const override {
    const solver::Mat3 Ff = full_deformation_gradient(F);
    if (!(Ff.determinant() > 0.0)) return false;
    CauchyBornState s;
    static std::atomic<bool> said{false};  // inner relaxation failed: an inadmissible state
    if (!detail::evaluate_admissible([&] { return cb_->evaluate(Ff, A != nullptr); }, s, said))
      return false;
    return finish(s, 1.0, psi, P, A);
  }
  bool evaluate_at(int point, const solver::Mat3& F, double* psi, solver::Mat3* P,
                   solver::Tangent* A) const override {
    const solver::Mat3 Ff = full_deformation_gradient(F);
    if (!(Ff.determinant() > 0.0)) return false;
    const auto p = static_cast<std::size_t>(point);
    CauchyBornState s;
    static std::atomic<bool> said{false};  // the bulk's relaxation failed: an inadmissible state
    if (!detail::evaluate_admissible([&] { return cb_->point_sum(p, Ff, A != nullptr); }, s, said))
      return false;
    return finish(s, 1.0 / (*volume_)[p], psi, P, A);
  }
  solver::Mat3 full_deformation_gradient(const solver::Mat3& F) const override {
    if (dimension() == 3) return F;
    solver::Mat3 G = solver::Mat3::Identity();
    G.topLeftCorner<2, 2>() = F.topLeftCorner<2, 2>();
    return G;
  }
  std::string name() const override {
    std::string n = "cauchy-born per point (";
    n.append(dimension() == 2 ? "plane strain" : "3d");
    n.append(fmt::format(", {} points", volume_->size()));
    if (!source_.empty()) n.append(", ").append(source_);
    return n.append(")");
  }
  std::unique_ptr<solver::Material> clone() const override {
    return std::make_unique<PerPointCauchyBornMaterial>(*this);
  }
  const CauchyBorn& cauchy_born() const { return *cb_; }

 private:
  bool finish(const CauchyBornState& s, double scale, double* psi, solver::Mat3* P,
              solver::Tangent* A) const {
    return detail::copy_cauchy_born_state(s, scale, dimension(), psi, P, A);
  }
  std::shared_ptr<const Body> body_;
  std::shared_ptr<const CauchyBorn> cb_;
  std::shared_ptr<const std::vector<double>> volume_;
  std::string source_;
};

}  // namespace pdcg::body
