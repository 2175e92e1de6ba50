/// \file
/// Cauchy–Born material of a pdcg body (docs/theory.md §8, docs/elastic.md).
///
/// Under a homogeneous deformation Y_F⟨ξ⟩ = Fξ every bond b of atom k has Y_b = F ξ_b, and the
/// energy density of the body is
///   W(F) = (1/V₀) Σ_k ψ_k(F ξ_b, b ∈ k),
/// with first Piola–Kirchhoff stress and tangent (chain rule through Y_b = F ξ_b):
///   P_iJ(F)    = ∂W/∂F_iJ   = (1/V₀) Σ_k Σ_b t_b,i ξ_b,J,
///   A_iJkL(F)  = ∂P_iJ/∂F_kL = (1/V₀) Σ_k Σ_b Σ_c K_bc,ik ξ_b,J ξ_c,L,
/// where t_b = ∂ψ_k/∂Y_b (Potential::force_state) and K_bc,ik = ∂t_b,i/∂Y_c,k
/// (Potential::force_state_tangent, analytic for the native styles). A is stored as a 9×9
/// matrix, row 3i+J, column 3k+L. It has the major symmetry A_iJkL = A_kLiJ.
///
/// Strain-based elastic constants (second derivative of W with respect to the Green–Lagrange
/// strain E = ½(FᵀF − I), the standard definition LAMMPS's ELASTIC example approximates at a
/// stress-free state): with S = F⁻¹P (second Piola–Kirchhoff stress)
///   A_iJkL = δ_ik S_JL + F_iM F_kN C_MJNL   ⇒   C_MJNL = F⁻¹_Mi F⁻¹_Nk (A_iJkL − δ_ik S_JL).
/// At F = I: C = A − δ_ik S_JL (= A when the reference is stress free).
///
/// Inner relaxation (docs/theory.md §11, docs/elastic.md §2.2): for a perfect crystal with a
/// basis of n_b > 1 atoms per primitive cell (detect_lattice) the sublattices b = 1 … n_b−1 shift
/// by s_b relative to sublattice 0 (held: removes the rigid translation, the null space of
/// W_ss), every bond becomes Y_b = Fξ_b + s_{c(j)} − s_{c(k)}, and
///   W(F) = min_s W(F, s)  (Newton on s with the analytic K, energy line search, warm start),
///   P = ∂W/∂F at s* (envelope theorem),  A = A_FF − A_Fs A_ss⁻¹ A_sF (Schur complement).
/// Bravais lattices have nothing to relax (the clamped formulas above, bitwise); lattices
/// whose every atom is a centre of inversion (B2, L1₂) relax to s* = 0 (round-off).
/// IonRelaxation::clamped keeps every atom at F ξ (the clamped-ion values). Bodies in dimension 2
/// lie in the xy plane: the 3×3 formulas with F₃₃ = 1, F₁₃ = F₂₃ = F₃₁ = F₃₂ = 0 are the
/// plane-strain reduction, and V₀ is the reference area. Homogenised bodies: W_p(F) = (1/V_p) Σ_k
/// w_kp ψ_k(Fξ) per point; the body's W is Σ_p V_p W_p / V₀ = (1/V₀) Σ_k (Σ_p w_kp) ψ_k (= the
/// delta body's W since Σ_p w_kp = 1). Rescaled bodies use the ε-wrapped potential on the scaled
/// bonds (W_ε(F) = W(F), docs/theory.md §4). Statistical bodies are not supported (InputError).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "pdcg/body/body.hpp"
#include "pdcg/body/lattice.hpp"

namespace pdcg::body {

using Matrix9d = Eigen::Matrix<double, 9, 9>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct CauchyBornState {
  double W = 0.0;                               ///< energy density
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();  ///< first Piola–Kirchhoff stress
  Matrix9d A = Matrix9d::Zero();  ///< ∂P/∂F (row 3i+J, col 3k+L); zero if not asked
  /// Relaxed sublattice shifts s_b (3 per basis site, site 0 held at 0; in the body's length
  /// unit) and the Newton iterations spent; empty / 0 without inner relaxation.
  std::vector<double> shift;
  int iterations = 0;
};

/// Inner (ion) relaxation of crystals with a basis (docs/elastic.md §2.2):
///   relaxed   — the body must be a perfect crystal (detect_lattice); anything else is an
///               InputError naming what was found (use clamped, or a perfect periodic cell);
///   automatic — relaxed for a perfect crystal, clamped-ion (with a log line) otherwise;
///   clamped   — every atom follows F (warning for a crystal whose basis would relax).
enum class IonRelaxation { automatic, relaxed, clamped };

class CauchyBorn {
 public:
  /// Throws InputError for statistical bodies or bodies without families/volume, and (mode
  /// relaxed) for a body that is not a perfect crystal.
  /// `per_point`: the object serves point_sum of a nonhomogeneous model (docs/elastic.md §7):
  /// in a mode other than clamped, the atoms are assigned to the sublattices of the model's bulk
  /// crystal (its interior atoms) and, for a crystal with a basis, point_sum uses the bulk's
  /// relaxed shifts s*(F) (InputError naming the atom and the fix `ion_relaxation: clamped`
  /// when an atom cannot be assigned). The body-level evaluate() is unchanged by it.
  explicit CauchyBorn(const Body& body, IonRelaxation ion = IonRelaxation::automatic,
                      bool per_point = false);
  /// True when evaluate() minimises over sublattice shifts (perfect crystal with a basis, mode
  /// not clamped). False for Bravais lattices (nothing to relax) and clamped-ion material.
  bool relaxing() const { return relax_; }
  /// The values evaluate() returns are the relaxed-ion ones: relaxing(), or a perfect Bravais
  /// lattice in a mode other than clamped (relaxation is a no-op there).
  bool relaxed_values() const { return relaxed_values_; }

  /// W, P and (if `tangent`) A of the whole body at F.
  CauchyBornState evaluate(const Eigen::Matrix3d& F, bool tangent = true) const;
  /// Energy density only.
  double energy(const Eigen::Matrix3d& F) const { return evaluate(F, false).W; }
  /// Per homogenised point p: W_p, P_p, A_p (InputError if the body is not homogenised, or if
  /// the material relaxes: per-point values are clamped-ion only — construct it clamped).
  std::vector<CauchyBornState> points(const Eigen::Matrix3d& F, bool tangent = true) const;

  /// Per-point sums of a nonhomogeneous body (surfaces, defects; docs/elastic.md §7): the
  /// points are the homogenisation points of a homogenised body, else the atoms. Point p's
  /// energy under Y = Fξ and its derivatives, NOT divided by a volume:
  ///   E_p(F) = Σ_k w_kp ψ_k(Fξ),  ∂E_p/∂F = Σ_k w_kp Σ_b t_b ⊗ ξ_b,  ∂²E_p/∂F∂F (as A),
  /// w_kp = 1 for k = p on a delta or rescaled body. Atoms of one environment class are
  /// evaluated once per point (interior points of a perfect crystal: one family). Serial,
  /// thread-local work arrays: callable from the solver's OpenMP loops.
  /// Inner relaxation (point_relaxing(); docs/theory.md §11, "per point"): every atom k sits at
  /// Fξ + s*_{c(k)}(F), s* the bulk crystal's relaxed shifts (shared by all points), and
  ///   E_p(F) = Σ_k w_kp ψ_k(Fξ_b + s*_{c(j)} − s*_{c(k)}),
  ///   ∂E_p/∂F = ∂_F E_p + ∂_s E_p · S,  S = ds*/dF = −W_ss⁻¹ W_sF (bulk),
  ///   ∂²E_p/∂F∂F = E_FF + E_Fs S + Sᵀ E_sF + Sᵀ E_ss S + ∂_s E_p · dS/dF,
  /// the last term a third derivative of the bulk energy (docs/theory.md (11.5)), by central
  /// differences of the bulk's path Hessian along λ = −W_ss⁻¹ ∂_s E_p (step kPointShiftStep·d_nn);
  /// `shift` of the result holds s*(F). A material
  /// constructed without `per_point` whose evaluate() relaxes (relaxing()) throws InputError here.
  std::size_t point_count() const { return pt_offset_.size() - 1; }
  CauchyBornState point_sum(std::size_t p, const Eigen::Matrix3d& F, bool tangent = true) const;
  /// point_sum relaxes the sublattices with the bulk's shifts (per_point construction, mode not
  /// clamped, bulk crystal with a basis). False for a Bravais bulk (nothing to relax).
  bool point_relaxing() const { return pt_relax_; }
  /// Per atom: its sublattice c(k) of the bulk crystal (0 … point_basis()−1); empty unless
  /// the sublattices were assigned (per_point construction, mode not clamped).
  const std::vector<std::int32_t>& sublattice() const { return sub_; }
  /// Sublattices of the model's bulk crystal (the environment classes of its interior atoms);
  /// 0 when not detected.
  int point_basis() const { return bulk_basis_; }
  /// Step |δλ| / d_nn of the central difference of the per-point tangent's dS/dF term.
  static constexpr double kPointShiftStep = 1e-5;

  const Body& body() const { return body_; }
  /// Number of distinct atomic environments (atoms whose families coincide — same type and
  /// the same bonds ξ to 1e-10·max|ξ|, partner types, special factors — are evaluated once).
  std::size_t environments() const { return classes_; }
  /// The body's lattice (detect_lattice), checked at construction: a crystal with a basis
  /// whose sites are not centres of inversion gets a warning (clamped-ion values), any other
  /// body that is not a perfect Bravais lattice an info line (cauchy_born_lattice_note).
  const LatticeInfo& lattice() const { return lattice_; }

 private:
  /// Per-atom ψ_k, Σ_b t_b⊗ξ_b (9 per atom), Σ_bc K_bc ξ_b ξ_c (81 per atom, if tangent).
  void per_atom(const Eigen::Matrix3d& F, bool tangent, std::vector<double>& psi,
                std::vector<double>& p, std::vector<double>& a) const;
  /// ψ, Σ_b t_b⊗ξ_b and (if `tangent`) Σ_bc K_bc ξ_b ξ_c of atom k's family at F.
  struct Scratch;
  void family(std::int64_t k, const Eigen::Matrix3d& F, bool tangent, Scratch& s, double& psi,
              double* p9, double* a81) const;
  /// Inner relaxation: sums of w·(ψ, P, A_FF, ∂/∂s, A_sF, A_ss) over the classes at shifts s.
  struct RelaxSums;
  void family_shifted(std::size_t slot, const Eigen::Matrix3d& F, const double* shift, bool tangent,
                      Scratch& s, RelaxSums& out) const;
  /// family_shifted for atom k of weight w, own site `own`, partner sites `partner` (one per
  /// bond), `nsub` sites; `xi` the family's reference bonds (nullptr: derived into s.xi).
  void family_sites(std::int64_t k, double w, const double* xi, int own,
                    const std::int32_t* partner, int nsub, const Eigen::Matrix3d& F,
                    const double* shift, bool tangent, Scratch& s, RelaxSums& out) const;
  /// Sums over the body's classes (bulk = false) or over one atom per sublattice of the
  /// model's bulk crystal (bulk = true, per-point relaxation).
  void relaxed_sums(bool bulk, const Eigen::Matrix3d& F, const double* shift, bool tangent,
                    Scratch& s, RelaxSums& out) const;
  /// Newton on the free shifts of that set: converged shifts, sums (with tangent) and the
  /// eigen-decomposition of W_ss on the free shifts; returns the Newton steps.
  struct Relaxation;
  int relax(bool bulk, const Eigen::Matrix3d& F, Relaxation& r) const;
  CauchyBornState evaluate_relaxed(const Eigen::Matrix3d& F, bool tangent) const;
  CauchyBornState point_sum_relaxed(std::size_t p, const Eigen::Matrix3d& F, bool tangent) const;
  void assign_sublattices(IonRelaxation ion);
  void require_clamped(const char* what) const;
  const Body& body_;
  bool relax_ = false, relaxed_values_ = false;
  bool per_point_ = false, pt_relax_ = false;
  int bulk_basis_ = 0;
  double bulk_nearest_ = 0.0;
  std::vector<std::int32_t> sub_;        ///< per atom: bulk sublattice (per-point relaxation)
  std::vector<std::int32_t> bond_site_;  ///< per bond: the partner's sublattice
  std::vector<std::int32_t> bulk_rep_;   ///< one interior atom per bulk sublattice
  std::uint64_t id_ = 0;                 ///< unique per object: key of the thread-local warm start
  std::vector<std::int64_t> rep_sub_offset_;  ///< per class slot: CSR into rep_sub_
  std::vector<std::int32_t> rep_sub_;  ///< [own site, site of each family member …] per slot
  std::vector<std::int32_t> representative_;  ///< per atom: the atom evaluated for its class
  std::vector<std::int32_t> multiplicity_;
  std::size_t classes_ = 0;
  LatticeInfo lattice_;
  std::vector<std::int32_t> reps_;  ///< one atom per class
  std::vector<double> rep_weight_;  ///< Σ_{k ∈ class} w_k (w_k = Σ_p w_kp, or 1)
  std::int64_t nmax_ = 0;           ///< largest family
  /// Reference bonds ξ of the representatives' families when there are few classes (≤ 64:
  /// the solver's hot path evaluates them once per stencil; deriving ξ from the positions
  /// there would cost ≈ 40 instructions per bond, +28 % per energy evaluation). CSR by slot
  /// in reps_ (sorted ascending); empty otherwise (ξ is then derived per call).
  std::vector<std::int64_t> rep_xi_offset_;
  std::vector<double> rep_xi_;
  /// per point: (representative atom, Σ w_kp over the point's atoms of that class), CSR
  std::vector<std::int64_t> pt_offset_{0};
  std::vector<std::int32_t> pt_rep_;
  std::vector<double> pt_weight_;
};

/// Strain-based elastic constants C_MJNL = ∂²W/∂E_MJ∂E_NL from (F, P, A) (formula above),
/// in Voigt order 11, 22, 33, 23, 13, 12.
Matrix6d voigt_elastic_constants(const Eigen::Matrix3d& F, const CauchyBornState& state);

/// Voigt and Reuss averages of bulk and shear modulus (3D), or the 2D (areal, in-plane) ones
/// for dimension 2: K = (C11+C22+2C12)/4, G = (C11+C22−2C12+4C66)/8 (Voigt).
struct Moduli {
  double bulk_voigt = 0, shear_voigt = 0, bulk_reuss = 0, shear_reuss = 0;
};
Moduli moduli(const Matrix6d& C, int dimension);

/// Neo-Hookean Ψ = μ/2(Ī₁ − 3) + K/8(J − 1/J)², Ī₁ = J^(−2/3) tr(FᵀF), fitted by linear
/// least squares to W(F) − W(I) − S₀:E(F) of the Cauchy–Born material, E = ½(FᵀF − I).
/// S₀ = P(I) is the stress of the reference lattice (nonzero when the lattice constant is not
/// the potential's zero-stress one, e.g. because of the cutoff); the neo-Hookean law is stress
/// free at F = I, so the fit describes the energy beyond the work of that residual stress
/// (an objective term: S₀:E depends on FᵀF only).
struct NeoHookeanFit {
  double mu = 0, bulk = 0;
  Eigen::Matrix3d reference_stress = Eigen::Matrix3d::Zero();  ///< S₀ = P(I)
  double rms_error = 0;       ///< RMS of the residual W_fit − W_CB over the set
  double relative_error = 0;  ///< rms_error / RMS of W_CB − W(I)
  int samples = 0;
};
/// Deformation set: uniaxial stretch λ and 1/λ... (along x, y[, z]), equi-biaxial stretch and
/// simple shear γ, for `steps` values each up to `max_stretch` (λ ∈ [1/max, max], γ ≤ max − 1);
/// plane strain (F₃₃ = 1, only in-plane deformations) in dimension 2.
std::vector<Eigen::Matrix3d> fit_deformations(int dimension, double max_stretch, int steps);
NeoHookeanFit fit_neo_hookean(const CauchyBorn& cb, const std::vector<Eigen::Matrix3d>& set);

/// Critical bond stretch from a pair potential (types i, j): the inflection point r_infl of
/// φ (φ'' = 0 beyond the minimum r₀, where the bond's axial stiffness vanishes), returned as
/// r_infl / r₀ (LJ: (26/7)^(1/6)/2^(1/6) = (13/7)^(1/6) ≈ 1.1087; Morse: 1 + ln2/(α r₀)).
/// Found by bisection on ∂t/∂r from force_state_tangent of a one-bond family. Throws
/// InputError for a potential that is not pairwise or has no minimum within its cutoff.
double pair_inflection_stretch(const atomistic::Potential& potential, int type_i, int type_j);

/// Material-level alternative valid for any potential: the uniaxial (lateral F = 1) stretch λ_c
/// of the Cauchy–Born material along unit `direction` at which P·n·n peaks (loss of strong
/// ellipticity in that direction); scanned up to `max_stretch` with `steps` points then
/// refined by bisection on the tangent. Returns 0 if no peak in range.
double uniaxial_peak_stretch(const CauchyBorn& cb, const Eigen::Vector3d& direction,
                             double max_stretch = 1.6, int steps = 60);

/// What the clamped-ion Cauchy–Born material (IonRelaxation::clamped: every atom follows F)
/// means for a body of this lattice: empty when it is exact (a perfect Bravais lattice, or a
/// perfect crystal whose every atom is a centre of inversion: B2, L1₂, NaCl); otherwise one
/// message naming the lattice, that W, P and C are the clamped-ion (unrelaxed) values, and what
/// to do. `warning` is set when the values are those of a crystal with a basis that would relax
/// (diamond, hcp, honeycomb …); unset for defects/surfaces (the body's own clamped average).
struct LatticeNote {
  std::string text;
  bool warning = false;
};
LatticeNote cauchy_born_lattice_note(const LatticeInfo& lattice);
/// The note for a material of mode `ion` (what evaluate() returns): empty for relaxed values
/// of a perfect crystal; clamped values of a crystal whose basis would relax: a warning naming
/// them as requested clamped-ion values; not a perfect crystal (any mode): a warning that inner
/// relaxation is unavailable and the values are those of the atoms held at Fξ.
LatticeNote cauchy_born_lattice_note(const LatticeInfo& lattice, IonRelaxation ion);

}  // namespace pdcg::body
