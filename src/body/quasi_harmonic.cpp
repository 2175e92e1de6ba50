#include "pdcg/body/quasi_harmonic.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <vector>

#include "lindemann.hpp"
#include "pdcg/body/lattice.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/units.hpp"

namespace pdcg::body {

namespace {

void check_body(const Body& body, double temperature) {
  // Delta, rescaled and homogenised bodies: the free energy is that of the atomic layer (the
  // crystal the model stands for; docs/theory.md (2.8)). A statistical body is an expectation
  // over moving atoms already: a second, harmonic, average over the same motion is not defined.
  if (body.statistics || body.dimension != 3 || !body.box.periodic[0] || !body.box.periodic[1] ||
      !body.box.periodic[2])
    throw InputError(
        "the quasi-harmonic free energy needs a periodic 3D delta body (or a homogenised or "
        "rescaled model of one)")
        .key("body")
        .value(fmt::format(
            "{} body{}, dimension {}, periodic {}{}{}", to_string(body.kind),
            body.statistics && body.kind != BodyKind::statistical ? " of statistical atoms" : "",
            body.dimension, body.box.periodic[0] ? "x" : "", body.box.periodic[1] ? "y" : "",
            body.box.periodic[2] ? "z" : ""))
        .expected(
            "a delta body of a crystal cell periodic along x, y and z (a statistical body's "
            "energy is already an average over the atoms' motion; the free energy replaces it)")
        .fix(
            "build it with pdcg atoms2pd --density delta from one relaxed frame of a periodic "
            "cell");
  if (body.homogenisation) {
    // The free energy of the atoms is the model's only if every atom counts once in its
    // energy, w_k = Σ_p w_kp = 1 (the static W(F) is then the atoms' too)
    std::vector<double> wk(body.size(), 0.0);
    const auto& h = *body.homogenisation;
    for (std::size_t q = 0; q < h.size(); ++q)
      for (auto c = h.offset[q]; c < h.offset[q + 1]; ++c)
        wk[static_cast<std::size_t>(h.atom[static_cast<std::size_t>(c)])] +=
            h.weight[static_cast<std::size_t>(c)];
    std::size_t worst = 0;
    for (std::size_t k = 0; k < wk.size(); ++k)
      if (std::abs(wk[k] - 1.0) > std::abs(wk[worst] - 1.0)) worst = k;
    if (!wk.empty() && !(std::abs(wk[worst] - 1.0) <= 1e-9))  // partition of unity: round-off
      throw InputError(
          "quasi-harmonic free energy of a homogenised body: an atom does not count once in "
          "the model's energy")
          .key("body")
          .value(fmt::format("atom {}: Σ_p w_kp = {:.12g}", worst, wk[worst]))
          .expected("Σ_p w_kp = 1 for every atom (a periodic grid covering the cell)")
          .fix("homogenise the periodic cell on a grid that covers it, or use its delta body");
  }
  constexpr std::size_t kMaxAtoms = 3000;  // dense (3N)² Hessian: 648 MB at 3000 atoms
  if (body.size() > kMaxAtoms)
    throw InputError("body too large for the dense quasi-harmonic Hessian")
        .key("body")
        .value(fmt::format("{} atoms", body.size()))
        .expected(fmt::format("at most {} atoms (a supercell of the crystal)", kMaxAtoms))
        .fix("use a smaller periodic supercell of the crystal (e.g. 4×4×4 cubic cells)");
  if (!(temperature >= 0.0) || !std::isfinite(temperature))
    throw InputError("temperature must be non-negative and finite")
        .key("temperature")
        .value(fmt::format("{}", temperature))
        .expected("T ≥ 0 in the body's temperature unit (kelvin; k_B T/ε in units lj)");
}

struct Vibrations {
  double U = 0.0, sum_ln_omega = 0.0, smallest_omega2 = 0.0;
  double sum_inverse_omega2 = 0.0;  ///< Σ_i 1/ω_i² (mass-weighted)
};

// The atoms a rescaled body stands for (docs/theory.md §4, (2.8)): by (4.6) its Hessian is
// ε^(d−2) that of the atoms and its masses ε^d theirs, so every frequency of its points is
// ω' = ω/ε, its energy and volume ε^d the atoms'. Returned in the atoms' terms (ε = 1 for
// delta and homogenised bodies).
struct AtomScale {
  double eps = 1.0, eps_d = 1.0;
  explicit AtomScale(const Body& b) : eps(b.epsilon), eps_d(std::pow(b.epsilon, b.dimension)) {}
};

// Eigenvalues of the mass-weighted Hessian at y = F x (the body is checked by the caller), in
// the atoms' terms (AtomScale).
Vibrations vibrations(const Body& body, const Eigen::Matrix3d& F) {
  const auto& fam = body.families;
  const auto& pot = *body.potential;
  const std::size_t n = body.size(), dim = 3 * n;
  const Eigen::Matrix3d hy = F * fam.h;
  std::vector<double> y(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d v =
        F * Eigen::Vector3d(body.x[3 * i], body.x[3 * i + 1], body.x[3 * i + 2]);
    for (int a = 0; a < 3; ++a) y[3 * i + static_cast<std::size_t>(a)] = v[a];
  }
  // H = ∂²U/∂y∂y from each family's K_bc (theory.md (1.7)): with Y_b = y_j(b) − y_k,
  // H_{j_b j_c} += K_bc, H_{k j_c} −= K_bc, H_{j_b k} −= K_bc, H_{kk} += K_bc. Serial (scatter).
  Eigen::MatrixXd H =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(dim), static_cast<Eigen::Index>(dim));
  std::vector<double> K, work, t;
  atomistic::FamilyGather gather;
  // a pair potential's tangent is block-diagonal (K_bc = 0 for b ≠ c): only K_bb is scattered
  const bool pairwise = pot.pairwise();
  Vibrations v;
  for (std::size_t k = 0; k < n; ++k) {
    const auto b0 = static_cast<std::size_t>(fam.offset[k]);
    const std::size_t m = static_cast<std::size_t>(fam.offset[k + 1]) - b0;
    if (m == 0) continue;
    K.resize(9 * m * m);
    t.resize(3 * m);
    work.resize(atomistic::Potential::tangent_workspace(static_cast<std::int64_t>(m)));
    const atomistic::FamilyState f = gather(fam, body.type, y, hy, k);
    v.U += pot.force_state(f, t.data());
    pot.force_state_tangent(f, K.data(), work.data());
    const auto ik = static_cast<Eigen::Index>(3 * k);
    for (std::size_t bj = 0; bj < m; ++bj) {
      const auto ij =
          static_cast<Eigen::Index>(3 * static_cast<std::size_t>(fam.neighbor[b0 + bj]));
      for (std::size_t bc = pairwise ? bj : 0; bc < (pairwise ? bj + 1 : m); ++bc) {
        const auto ic =
            static_cast<Eigen::Index>(3 * static_cast<std::size_t>(fam.neighbor[b0 + bc]));
        const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> blk(K.data() +
                                                                                 9 * (bj * m + bc));
        H.block<3, 3>(ij, ic) += blk;
        H.block<3, 3>(ik, ic) -= blk;
        H.block<3, 3>(ij, ik) -= blk;
        H.block<3, 3>(ik, ik) += blk;
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      H.block<3, 3>(static_cast<Eigen::Index>(3 * i), static_cast<Eigen::Index>(3 * j)) /=
          std::sqrt(body.mass[i] * body.mass[j]);
  const Eigen::MatrixXd Hs = 0.5 * (H + H.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Hs, Eigen::EigenvaluesOnly);
  const Eigen::VectorXd& w2 = es.eigenvalues();  // ascending; the first 3 are the translations
  v.smallest_omega2 = w2[3];
  // a translation is ω² = 0 up to round-off of H; a vibration must lie clearly above it
  const double scale = w2.cwiseAbs().maxCoeff();
  if (!(w2[3] > 1e-10 * scale))
    throw NumericalError(
        fmt::format("quasi-harmonic free energy: the lattice is unstable at this F (a vibrational "
                    "eigenvalue ω² = {:.6g}, largest {:.6g}); the free energy does not exist there",
                    w2[3], scale));
  for (Eigen::Index i = 3; i < w2.size(); ++i) {
    v.sum_ln_omega += 0.5 * std::log(w2[i]);
    v.sum_inverse_omega2 += 1.0 / w2[i];
  }
  // the points' ω' = ω/ε → the atoms' ω = ε ω'; U' = ε^d U
  const AtomScale a(body);
  if (a.eps != 1.0) {
    const double modes = static_cast<double>(w2.size() - 3);
    v.U /= a.eps_d;
    v.sum_ln_omega += modes * std::log(a.eps);
    v.smallest_omega2 *= a.eps * a.eps;
    v.sum_inverse_omega2 /= a.eps * a.eps;
  }
  return v;
}

const Body& checked_material_body(const Body& body, double temperature, double step) {
  check_body(body, temperature);
  if (!(step >= kQuasiHarmonicStepMin && step <= kQuasiHarmonicStepMax))
    throw InputError("quasi-harmonic material: central-difference strain step out of range")
        .key("strain_step")
        .value(fmt::format("{}", step))
        .expected(fmt::format("{:g} ≤ h ≤ {:g} (default {:g})", kQuasiHarmonicStepMin,
                              kQuasiHarmonicStepMax, kQuasiHarmonicStepDefault))
        .fix(
            "a step of 1e-4 for analytic potentials, ≈ 1e-2 for tabulated EAM "
            "(docs/temperature.md §3.1)");
  const LatticeInfo lat = detect_lattice(body);
  if (lat.perfect && lat.basis > 1 && !lat.centrosymmetric)
    throw InputError(
        "the quasi-harmonic material holds every atom at F x; this crystal's basis "
        "would relax under F")
        .key("body")
        .value(lat.summary)
        .expected(
            "a Bravais lattice, or a crystal whose every atom is a centre of inversion "
            "(B2, L1₂, NaCl)")
        .fix(
            "use the static Cauchy–Born material (no temperature) for this crystal: inner "
            "relaxation of the free energy is not implemented");
  // Lindemann (1910): crystals melt when the rms displacement reaches ≈ 0.10–0.15 of the
  // nearest-neighbour distance. Classical harmonic crystal: Σ_k m_k ⟨|u_k|²⟩ = k_B T Σ_i ω_i⁻²,
  // so ⟨|u|²⟩ ≈ k_B T Σ_i ω_i⁻² / (N m̄). A temperature in the wrong units lands far beyond.
  if (temperature > 0.0 && lat.nearest > 0.0) {
    const Vibrations v = vibrations(body, Eigen::Matrix3d::Identity());  // the atoms'
    const AtomScale a(body);
    double mass = 0.0;
    for (double m : body.mass) mass += m / a.eps_d;
    const double kT = unit_constants(body.units).boltz * temperature;
    const double lindemann = std::sqrt(kT * v.sum_inverse_omega2 / mass) / (lat.nearest / a.eps);
    detail::require_below_melting(lindemann, temperature, body.units, "temperature",
                                  "harmonic rms displacement");
  }
  return body;
}

// Strain components e_I of the finite differences: E = Σ e_I B_I, B_I = e_i e_iᵀ (I < 3) or
// e_j e_kᵀ + e_k e_jᵀ (shears 23, 13, 12); m_I = 1 or 2 turns ∂/∂e_I into tensor components.
constexpr std::array<std::array<int, 2>, 6> kVoigt{
    {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}}};

Eigen::Matrix3d strain_basis(int I) {
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  const auto [j, k] = kVoigt[static_cast<std::size_t>(I)];
  B(j, k) += 1.0;
  if (j != k) B(k, j) += 1.0;
  return B;
}

}  // namespace

namespace {
// The spline tables of a native EAM potential (nullptr for other potentials).
const atomistic::EamView* eam_tables(const Body& body) {
  for (const auto* pot : {body.potential.get(), body.base_potential.get()})
    if (pot && pot->eam_view() && pot->eam_view()->rdr > 0.0) return pot->eam_view();
  return nullptr;
}
}  // namespace

double quasi_harmonic_knot_step(const Body& body) {
  const atomistic::EamView* eam = eam_tables(body);
  if (!eam) {
    // an EAM style evaluated through LAMMPS (tables not visible here): the bound of Cu_u3.eam
    const atomistic::Potential* pot =
        body.base_potential ? body.base_potential.get() : body.potential.get();
    return pot && pot->style().rfind("eam", 0) == 0 ? 5e-3 : 0.0;
  }
  const LatticeInfo lat = detect_lattice(body);
  if (!(lat.nearest > 0.0)) return 0.0;
  return 2.0 * body.epsilon / (eam->rdr * lat.nearest);  // r_nn of the atoms: nearest / ε
}

QuasiHarmonic quasi_harmonic(const Body& body, const Eigen::Matrix3d& F, double temperature) {
  check_body(body, temperature);
  const double kT = unit_constants(body.units).boltz * temperature;
  const Vibrations v = vibrations(body, F);
  QuasiHarmonic q;
  q.smallest_omega2 = v.smallest_omega2;
  q.sum_ln_omega = v.sum_ln_omega;
  const double V0 = body.reference_volume() / AtomScale(body).eps_d;  // the atoms' volume
  const double modes = static_cast<double>(3 * body.size() - 3);
  q.energy_density = v.U / V0;
  q.free_energy_density =
      (v.U + kT * (q.sum_ln_omega - modes * (kT > 0 ? std::log(kT) : 0.0))) / V0;
  return q;
}

QuasiHarmonicCauchyBorn::QuasiHarmonicCauchyBorn(const Body& body, double temperature,
                                                 double strain_step)
    : body_(checked_material_body(body, temperature, strain_step)),
      cb_(body, IonRelaxation::clamped),
      temperature_(temperature),
      kT_(unit_constants(body.units).boltz * temperature),
      step_(strain_step),
      knot_step_(quasi_harmonic_knot_step(body)) {}

double QuasiHarmonicCauchyBorn::sum_ln_omega(const Eigen::Matrix3d& F) const {
  return vibrations(body_, F).sum_ln_omega;
}

CauchyBornState QuasiHarmonicCauchyBorn::evaluate(const Eigen::Matrix3d& F, bool tangent) const {
  CauchyBornState st = cb_.evaluate(F, tangent);  // static lattice: analytic W, P, A
  if (kT_ == 0.0) return st;
  const double V0 = body_.reference_volume() / AtomScale(body_).eps_d;  // the atoms' volume
  const double c = kT_ / V0;
  const double modes = static_cast<double>(3 * body_.size() - 3);
  const Eigen::Matrix3d E0 = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
  // S at the strain E: F(E) = (I + 2E)^½ (S depends on FᵀF only)
  auto S = [&](const Eigen::Matrix3d& E) {
    const Eigen::Matrix3d C = Eigen::Matrix3d::Identity() + 2.0 * E;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
    if (!(es.eigenvalues().minCoeff() > 0.0))
      throw NumericalError("quasi-harmonic material: FᵀF not positive definite");
    const Eigen::Matrix3d U = es.eigenvectors() * es.eigenvalues().cwiseSqrt().asDiagonal() *
                              es.eigenvectors().transpose();
    return sum_ln_omega(U);
  };
  const double h = step_;
  const double s0 = S(E0);
  std::array<double, 6> sp{}, sm{};
  for (int I = 0; I < 6; ++I) {
    sp[static_cast<std::size_t>(I)] = S(E0 + h * strain_basis(I));
    sm[static_cast<std::size_t>(I)] = S(E0 - h * strain_basis(I));
  }
  // ∂S/∂E (tensor, symmetric)
  Eigen::Matrix3d dS = Eigen::Matrix3d::Zero();
  for (int I = 0; I < 6; ++I) {
    const auto [j, k] = kVoigt[static_cast<std::size_t>(I)];
    const double g = (sp[static_cast<std::size_t>(I)] - sm[static_cast<std::size_t>(I)]) / (2 * h);
    const double m = j == k ? 1.0 : 2.0;
    dS(j, k) = dS(k, j) = g / m;
  }
  st.W += c * (s0 - modes * std::log(kT_));
  st.P += c * F * dS;
  if (!tangent) return st;
  // Tabulated EAM: LAMMPS's cubic splines are C¹, so the force-state tangents jump at the knots
  // (every dr of the table) and S′ jumps where a shell of bonds crosses one. Within one piece
  // the fourth derivative of the potential is zero: a step that moves the bonds by less than a
  // knot interval gives the local derivative of one piece, not the stiffness
  // (docs/temperature.md §3.1, measured for Cu).
  if (step_ < knot_step_) {
    static std::atomic<bool> said{false};
    if (!said.exchange(true))
      log::warn(
          "quasi-harmonic stiffness of a tabulated EAM potential with strain step {:g}: the "
          "splines' second derivatives jump at the table's knots (every {} in r), and a step "
          "that moves the nearest-neighbour bonds by less than one knot interval gives the "
          "stiffness of one spline piece (for Cu_u3.eam at 600 K the thermal C11 is −12 GPa "
          "with steps ≤ 1e-3 and −3 GPa with 1e-2); use a step ≥ {:.2g}, e.g. {:g} "
          "(pdcg elastic --quasi-harmonic-step, scene material.quasi_harmonic_step), or secant "
          "slopes of the stress over ±1 % strain",
          step_,
          eam_tables(body_) ? fmt::format("{:g}", 1.0 / eam_tables(body_)->rdr) : std::string("dr"),
          knot_step_, std::min(kQuasiHarmonicStepMax, std::max(knot_step_, 1e-2)));
  }
  // ∂²S/∂e_I∂e_J, then the tensor ∂²S/∂E_ab∂E_cd = that / (m_I m_J)
  Eigen::Matrix<double, 6, 6> d2;
  for (int I = 0; I < 6; ++I) {
    const auto i = static_cast<std::size_t>(I);
    d2(I, I) = (sp[i] - 2 * s0 + sm[i]) / (h * h);
    for (int J = I + 1; J < 6; ++J) {
      const Eigen::Matrix3d a = h * strain_basis(I), b = h * strain_basis(J);
      d2(I, J) = d2(J, I) =
          (S(E0 + a + b) - S(E0 + a - b) - S(E0 - a + b) + S(E0 - a - b)) / (4 * h * h);
    }
  }
  // Voigt index of the tensor pair (a, b): 00→0, 11→1, 22→2, 12→3, 02→4, 01→5
  auto vi = [](int a, int b) {
    if (a == b) return a;
    const int s = a + b;
    return s == 3 ? 3 : s == 2 ? 4 : 5;
  };
  auto mult = [](int a, int b) { return a == b ? 1.0 : 2.0; };
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J)
      for (int k = 0; k < 3; ++k)
        for (int L = 0; L < 3; ++L) {
          double a = i == k ? dS(J, L) : 0.0;
          for (int M = 0; M < 3; ++M)
            for (int N = 0; N < 3; ++N)
              a += F(i, M) * F(k, N) * d2(vi(M, J), vi(N, L)) / (mult(M, J) * mult(N, L));
          st.A(3 * i + J, 3 * k + L) += c * a;
        }
  return st;
}

}  // namespace pdcg::body
