/// \file
/// Peridynamic bodies made from atoms (docs/theory.md §1–4, docs/bodies.md).
///
/// A Body is a nonhomogeneous PD body whose constitutive model IS the interatomic potential.
/// It has an atomic layer — one point per atom k with reference position x_k, mass M_k, type,
/// family of bonds ξ_kj (CSR, periodic images, atomistic::Families) and the multibody energy
/// ψ_k(Y⟨ξ_kj⟩) of a Potential — and optional layers added by coarse-graining:
///
///  - delta (§1):        ρ(x) = Σ_k M_k Δ(x − x_k),  W(Y, x) = Σ_k Δ(x − x_k) ψ_k(Y).
///  - statistical (§2):  ρ(x) = Σ_k M_k P_k(x),  ψ_k replaced by its expectation over the
///                         independent position densities P_j of the atoms (Statistics).
///  - rescaled (§4):     W_ε(Y) = W(E(Y)), (E(Y))⟨ξ⟩ = ε⁻¹ Y⟨εξ⟩; points at εx_k, bonds εξ,
///                         point masses and energies ×ε^d (density and W unchanged).
///  - homogenised (§3):  continuum points x_p with discrete kernel weights w_kp
///                         (Σ_p w_kp = 1 for every atom k): m_p = Σ_k w_kp M_k and the
///                         weighted atomic bond sets, point energy E_p(Y) = Σ_k w_kp ψ_k(Y).
///
/// The kind is the last operation applied. Energies and forces of the atomic layer are computed
/// by an Evaluator (which owns its work arrays, so repeated evaluations allocate nothing).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/atomistic/families.hpp"
#include "pdcg/atomistic/potential.hpp"
#include "pdcg/core/units.hpp"

namespace pdcg::body {

enum class BodyKind { delta, statistical, homogenised, rescaled };
std::string_view to_string(BodyKind kind);
/// Parses "delta|statistical|homogenised|rescaled" (also "homogenized"); InputError otherwise.
BodyKind parse_body_kind(std::string_view name, std::string_view where = {});

/// Statistical densities P_k of the atomic layer (docs/theory.md §2).
struct Statistics {
  enum class Form { gaussian, empirical };
  enum class Method { cubature, sampling };
  Form form = Form::gaussian;
  /// gaussian: cubature (Gauss–Hermite, pair potentials only) or sampling (any potential).
  Method method = Method::cubature;
  int order = 3;                ///< Gauss–Hermite points per dimension (cubature)
  std::int64_t samples = 1000;  ///< joint samples of all atom positions (sampling)
  std::uint64_t seed = 12345;   ///< random seed (sampling): results are reproducible
  /// gaussian: per-atom covariance Σ_k (symmetric), 6 per atom: the upper triangle row by row
  /// (Σxx, Σxy, Σxz, Σyy, Σyz, Σzz); covariance_of / set_covariance convert. The means are
  /// the reference positions x_k of the body.
  std::vector<double> covariance;
  /// empirical: the frames, each 3N positions (same convention as Body::x: x_k + the frame's
  /// displacement of atom k), frames.size() = S.
  std::vector<std::vector<double>> frames;

  /// Σ_k as a full 3×3 matrix.
  Eigen::Matrix3d covariance_of(std::size_t k) const {
    const double* c = covariance.data() + 6 * k;
    Eigen::Matrix3d m;
    m << c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5];
    return m;
  }
  /// Stores the upper triangle of C as Σ_k (covariance must hold 6 per atom).
  void set_covariance(std::size_t k, const Eigen::Matrix3d& C) {
    double* c = covariance.data() + 6 * k;
    c[0] = C(0, 0);
    c[1] = C(0, 1);
    c[2] = C(0, 2);
    c[3] = C(1, 1);
    c[4] = C(1, 2);
    c[5] = C(2, 2);
  }
};

/// Homogenisation layer (docs/theory.md §3).
struct Homogenisation {
  std::string kernel;          ///< kernel name (coarsen/kernels.hpp)
  double width = 0.0;          ///< kernel width parameter
  std::vector<double> points;  ///< 3P continuum point positions x_p
  std::vector<double> volume;  ///< P reference volumes V_p (ρ̄_p = m_p / V_p)
  std::vector<double> mass;    ///< P masses m_p = Σ_k w_kp M_k
  /// CSR point → atoms: for point p, atoms atom[offset[p] .. offset[p+1]) with weights w.
  std::vector<std::int64_t> offset;
  std::vector<std::int32_t> atom;
  std::vector<double> weight;
  /// Grid description when the points form a regular grid (empty otherwise): origin (3),
  /// axes (9, columns = grid steps), counts (3).
  std::vector<double> grid_origin, grid_axes;
  std::vector<std::int64_t> grid_counts;

  std::size_t size() const { return volume.size(); }
};

/// A potential file (or table) the model needs, stored verbatim so a model file is self-contained.
struct EmbeddedFile {
  std::string name;  ///< as the pair_coeff line names it
  std::string contents;
};

struct Body {
  BodyKind kind = BodyKind::delta;
  UnitStyle units = UnitStyle::lj;
  /// Spatial dimension d of the body (1 for a chain along x, 2 for a film in xy, 3). Governs
  /// volumes (the first d box edges) and rescaling (masses and energies ×ε^d).
  int dimension = 3;
  atomistic::Box box;  ///< reference box (periodic directions, volume)

  // Atomic layer, sorted by id.
  std::vector<std::int64_t> id;
  std::vector<int> type;
  std::vector<double> x;     ///< 3N reference positions
  std::vector<double> mass;  ///< N point masses
  atomistic::Families families;

  /// The interaction as evaluated: for a rescaled body this is the ε-wrapper around
  /// base_potential (rescaled_potential below); otherwise the same object.
  std::shared_ptr<const atomistic::Potential> potential;
  std::shared_ptr<const atomistic::Potential> base_potential;
  atomistic::PotentialSpec potential_spec;  ///< the LAMMPS command lines
  std::vector<EmbeddedFile> potential_files;

  double epsilon = 1.0;  ///< rescaling factor ε = δ'/δ applied so far (1 = none)
  /// Horizon δ of the atomic layer as built (the family cutoff, before rescaling); the current
  /// horizon is ε·base_horizon.
  double base_horizon = 0.0;
  double horizon() const { return epsilon * base_horizon; }
  std::optional<Statistics> statistics;
  std::optional<Homogenisation> homogenisation;
  std::vector<std::string> provenance;  ///< one line per step (input files, commands)

  std::size_t size() const { return id.size(); }
  bool periodic() const { return box.periodic[0] || box.periodic[1] || box.periodic[2]; }
  /// Reference volume V₀ of the body: the d-dimensional measure of the first d edge vectors
  /// of the box (det H for d = 3). For free (non-periodic) bodies this is the box as given in
  /// the input (LAMMPS always has one): the user controls it; see docs/bodies.md.
  double reference_volume() const;
};

struct DeltaBodyOptions {
  int dimension = 3;
  /// Cutoff for the families; 0 = the potential's cutoff.
  double cutoff = 0.0;
  std::string source;  ///< configuration file name (messages, provenance)
  /// True when nothing stated the periodicity of atoms.box (a data file, no `boundary` command,
  /// no --boundary): LAMMPS's default `boundary p p p` is assumed, and a periodic box whose
  /// images overlap the atoms is refused (check_periodic_images). False: the periodicity was
  /// stated (boundary command, dump header, option) and an overlap only warns.
  bool periodicity_assumed = false;
};

/// Overlapping periodic images: the closest pair through a periodic image (an atom and an
/// image of another atom or of itself, within the families) closer than 0.7 times the closest
/// pair inside the box — far inside the repulsive core, as a free cluster written into a box
/// that only just holds it gives (the images of opposite faces land on each other). Throws
/// InputError naming both atoms, the image shift and the fix (`boundary s s s` in the commands
/// file, or --boundary "f f f") when `assumed`; logs a warning otherwise. Configurations
/// without a pair inside the box (a one-atom cell) cannot be judged and pass.
void check_periodic_images(const atomistic::Atoms& atoms, const atomistic::Families& families,
                           bool assumed, std::string_view source);

/// Builds a delta body from one configuration. Masses come from atoms.mass_of (per-atom or per
/// type, the atoms' type_mass filled in from the spec's `mass` commands when the atoms have
/// none). Throws InputError when an atom type is not covered by the potential, when a mass is
/// missing, when the configuration is empty, when the spec has a bond style (other than zero)
/// but the configuration carries no molecular bonds (a dump, a data file without a Bonds
/// section), when a bond type has no bond_coeff, and when periodic images overlap the atoms in
/// an assumed-periodic box (check_periodic_images).
Body make_delta_body(const atomistic::Atoms& atoms,
                     std::shared_ptr<const atomistic::Potential> potential,
                     atomistic::PotentialSpec spec, const DeltaBodyOptions& options = {});

/// Wraps a potential for a body rescaled by ε in dimension d:
///   ψ_ε(Y') = ε^d ψ(ε⁻¹Y'),   t_ε = ∂ψ_ε/∂Y' = ε^(d−1) t(ε⁻¹Y'),   cutoff ε·r_c.
/// (Per point; with point volumes ×ε^d this is W_ε(Y) = W(E(Y)), T_ε⟨ξ'⟩ = ε^−(d+1) T⟨ξ'/ε⟩.)
std::shared_ptr<const atomistic::Potential> rescaled_potential(
    std::shared_ptr<const atomistic::Potential> base, double epsilon, int dimension);

namespace detail {
struct Scratch;
}

/// Result of one evaluation of the atomic layer.
struct Evaluation {
  double energy = 0.0;             ///< Σ_k ψ_k (expected value for statistical bodies)
  std::span<const double> psi;     ///< N per-point energies ψ_k
  std::span<const double> t;       ///< 3 per bond: force states t_b
  std::span<const double> forces;  ///< 3N: f_k = Σ_b (t_b − t_reverse(b))
};

/// Evaluates energies, force states and PD internal forces of a body's atomic layer. Owns its
/// work arrays: after the first call, evaluations allocate nothing (apart from sampling
/// buffers sized once). The returned spans stay valid until the next evaluation.
class Evaluator {
 public:
  explicit Evaluator(const Body& body);
  ~Evaluator();
  Evaluator(const Evaluator&) = delete;
  Evaluator& operator=(const Evaluator&) = delete;

  /// At the reference configuration (y = x, H_y = H).
  Evaluation reference();
  /// At deformed positions y (3N, same ids/order as the body) with deformed box matrix h_y.
  Evaluation deformed(std::span<const double> y, const Eigen::Matrix3d& h_deformed);
  /// At deformed positions, box unchanged (free bodies, or periodic bodies whose box is kept).
  Evaluation deformed(std::span<const double> y);
  /// Under a homogeneous deformation y = F x, H_y = F H. For statistical bodies the densities
  /// are carried along (conforming deformation: fluctuations mapped by F).
  Evaluation homogeneous(const Eigen::Matrix3d& F);

  /// First Piola–Kirchhoff stress of the homogeneous deformation, P = ∂W/∂F (energy per
  /// reference volume; the expected value for statistical bodies, densities carried along):
  ///   P = (1/V₀) Σ_k Σ_b t_b ⊗ ξ_b                  (delta, rescaled, homogenised layers),
  ///   P = (1/V₀) E[Σ_k Σ_b t_b ⊗ (ξ_b + η_j − η_k)]   (statistical: the fluctuations η too),
  /// which at F = I is minus the virial (potential) part of the pressure tensor: the Cauchy
  /// stress of the frames' average for an empirical body (docs/temperature.md). Also leaves
  /// the evaluator's work arrays changed (spans of an earlier evaluation are stale).
  Eigen::Matrix3d stress(const Eigen::Matrix3d& F);

  /// Point energies of the homogenised layer E_p = Σ_k w_kp ψ_k from the last evaluation.
  /// Throws InputError when the body is not homogenised.
  std::vector<double> point_energies() const;

 private:
  Evaluation run(std::span<const double> y, const Eigen::Matrix3d& h_y, const Eigen::Matrix3d& G);
  const Body& body_;
  std::vector<double> y_, t_, psi_, f_;       ///< no per-bond bond vectors: built per atom
  std::vector<int> ntype_;                    ///< partner type per bond
  std::unique_ptr<detail::Scratch> scratch_;  ///< statistical work arrays
};

/// Energy density W = energy / reference volume.
inline double energy_density(const Body& body, const Evaluation& e) {
  return e.energy / body.reference_volume();
}

}  // namespace pdcg::body
