/// \file
/// Explicit dynamics of a PD body's point layer (docs/dynamics.md).
///
/// Equations of motion of the points k (families fixed in the reference configuration):
///   M_k ÿ_k = c · f_k(y),   f_k = Σ_j (t_kj − t_jk)   (body::Evaluator),
/// with c = ftm2v of the body's LAMMPS unit style (1 in lj units). For a delta body this is
/// fixed-family molecular dynamics (f_k = −∂U/∂y_k exactly); for a rescaled body it is its
/// coarse surrogate. Periodic boxes are kept fixed; positions are carried unwrapped (the
/// families' image shifts refer to them).
///
/// Velocity Verlet in the update order of LAMMPS `fix nve` (FixNVE::initial/final_integrate):
///   v ← v + ½Δt c f/M;   y ← y + Δt v;   f ← f(y);   v ← v + ½Δt c f/M.
///
/// Stable time step (Gershgorin): linearising about y, the stiffness K = ∂(−f)/∂y is the sum
/// over points k of the Hessians H⁽ᵏ⁾ of ψ_k, assembled from the force-state tangent
/// A_jm = ∂t_kj/∂Y_km (Potential::force_state_tangent): H_jm = A_jm, H_jk = −Σ_m A_jm,
/// H_km = −Σ_j A_jm, H_kk = Σ_jm A_jm. The eigenvalues ω² of c M⁻¹K (similar to the symmetric
/// c M^{-½} K M^{-½}) satisfy, by Gershgorin's theorem on the rows of M⁻¹K,
///   ω_max² ≤ c · max_i (Σ_l |K_il|) / M_i ≤ c · max_i (Σ_k Σ_l |H⁽ᵏ⁾_il|) / M_i,
/// i, l running over the 3N degrees of freedom. Velocity Verlet is stable for Δt ω_max < 2
/// (the undamped central-difference limit), so Δt_stable = 2/ω_bound is a safe limit
/// (≤ the true one). Runs refuse Δt > Δt_stable unless forced.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/body/body.hpp"

namespace pdcg::dynamics {

namespace detail {
struct EamRows;
}

struct StableStep {
  double omega_bound = 0.0;      ///< Gershgorin bound on ω_max (time units of the body)
  double dt_stable = 0.0;        ///< 2 / omega_bound
  std::int64_t critical_id = 0;  ///< atom id of the row attaining the bound
};

/// Gershgorin bound of the linearised stiffness about positions y (3N, body order; empty =
/// reference). Throws InputError for a missing or non-positive mass.
StableStep stable_time_step(const body::Body& body, std::span<const double> y = {});

/// Refuses dt > limit.dt_stable unless `force` (InputError giving both numbers and ω_bound).
void require_stable_time_step(double dt, const StableStep& limit, bool force);

/// Checks every mass is finite and positive; InputError naming the atom id otherwise.
void check_masses(const body::Body& body, const std::string& source);

/// Gaussian velocities at temperature T (std::mt19937_64 seeded with `seed`, reproducible),
/// only the first `body.dimension` components non-zero, zero total momentum, then scaled so
/// that the temperature with dof = d(N − 1) is exactly T (as LAMMPS `velocity create … loop
/// geom` followed by `zero linear` and rescaling; not LAMMPS's own random stream).
std::vector<double> thermal_velocities(const body::Body& body, double temperature,
                                       std::uint64_t seed);

/// Velocities of a configuration (dump with vx vy vz) matched to the body by atom id.
/// InputError if the file has no velocities or its ids differ from the body's.
std::vector<double> velocities_from_atoms(const body::Body& body, const atomistic::Atoms& atoms,
                                          const std::string& source);

struct Thermo {
  std::int64_t step = 0;
  double time = 0.0;
  double kinetic = 0.0;    ///< ½ mvv2e Σ M v²
  double potential = 0.0;  ///< Σ_k ψ_k
  double total = 0.0;
  double temperature = 0.0;  ///< 2 KE / (dof k_B), dof = d(N − 1)
};

/// Force kernels of VelocityVerlet: `automatic` takes the vector variant where one exists and
/// the CPU runs it (native EAM without special factors on AVX2 + FMA CPUs, chosen at run time),
/// `scalar` always the scalar loops (for tests comparing the two; results agree to round-off),
/// `general` the general body::Evaluator for every style (both ends of every bond, gather over
/// reverse bonds: the reference the dedicated pair, EAM and many-body paths are checked and
/// benchmarked against).
enum class Kernels { automatic, scalar, general };

/// True when the vector EAM kernel is compiled in and this CPU has AVX2 and FMA.
bool eam_vector_kernel_available();

/// Velocity Verlet over a body. Allocates nothing in step() (after construction); OpenMP over
/// points in the updates and in the force evaluation.
class VelocityVerlet {
 public:
  /// y0, v0: 3N positions (unwrapped, body order) and velocities. dt > 0.
  VelocityVerlet(const body::Body& body, std::vector<double> y0, std::vector<double> v0, double dt,
                 Kernels kernels = Kernels::automatic);

  /// One step. energy = false lets the pair kernel skip Σφ (LAMMPS evaluates energies only
  /// on thermo steps, eflag); thermo() then computes the potential energy on demand.
  void step(bool energy = true);
  void run(std::int64_t steps) {
    for (std::int64_t s = 0; s < steps; ++s) step();
  }
  Thermo thermo() const;
  std::int64_t steps_done() const { return step_; }
  double time_step() const { return dt_; }
  std::span<const double> positions() const { return {y_.data(), v_.size()}; }
  std::span<const double> velocities() const { return v_; }
  std::span<const double> forces() const { return {f_.data(), v_.size()}; }
  /// True when the force evaluation runs the vector EAM kernel (Kernels::automatic, native EAM
  /// without special factors, AVX2 + FMA CPU).
  bool vector_eam() const { return eam_rows_ != nullptr; }
  /// True when forces come from the many-body kernel (native sw, tersoff; not handed over to
  /// the general path).
  bool manybody_kernel() const { return manybody_ && !mb_fallback_; }
  /// Number of short-list builds of the many-body kernel so far (0: not used).
  std::int64_t short_list_builds() const { return mb_builds_; }

 private:
  void evaluate(bool energy = true);
  void evaluate_pairwise(bool energy);
  double pair_energy() const;
  void evaluate_eam();
  bool evaluate_manybody();
  void setup_half();
  void setup_manybody();
  void build_short_lists();
  void update_ghosts();
  void fold_ghosts(double* f, std::size_t stride) const;
  void reduce_thread_forces(double* f, int used);
  const body::Body& body_;
  /// Pairwise potentials (ψ_k = ½Σφ, t_jk(−Y) = −t_kj(Y)): each pair once through a half
  /// family (f_k += 2t_kj, f_j −= 2t_kj, energy 2ψ_half) instead of both bonds and a gather.
  bool half_ = false;
  std::vector<std::int64_t> half_offset_;
  std::vector<std::int32_t> half_neighbor_;
  std::vector<int> half_type_, half_bond_type_;
  std::vector<double> half_factor_;  ///< pair factors per half bond (empty: all 1)
  /// Ghost points (LAMMPS's ghost atoms): periodic images y_a + H·n reached by half bonds,
  /// stored after the N points in y_ and f_ (half_neighbor_ indexes both), refreshed before
  /// each evaluation; their forces are added to their points after it. Replaces a 3-double
  /// image shift per half bond by one ghost per distinct (point, image).
  std::vector<std::int32_t> ghost_atom_;
  std::vector<double> ghost_shift_;                    ///< 3 per ghost: H·n
  std::vector<int> type_ext_;                          ///< types of points and ghosts
  mutable std::vector<std::vector<double>> thread_f_;  ///< mutable: scratch of pair_energy()
  std::vector<std::vector<double>> thread_y_, thread_t_;
  /// Native EAM without molecular bonds (Potential::eam_view): the LAMMPS scheme over the half
  /// families, ρ̄ pass (scattered to both ends), F'(ρ̄) pass, force pass
  /// f_k += s Y, f_j −= s Y, s = (F'_k ρ'_{j→k} + F'_j ρ'_{k→j} + φ')/r; no per-bond storage.
  const atomistic::EamView* eam_ = nullptr;
  std::vector<double> rho_, fp_;
  std::vector<std::vector<double>> thread_rho_;
  /// The EAM tables in the vector kernel's row layout (null: the scalar loops), see
  /// src/dynamics/eam_kernel.hpp. The half-family arrays then carry 3 padding entries.
  std::shared_ptr<const detail::EamRows> eam_rows_;
  /// Native many-body styles (Potential::has_manybody_kernel: sw, tersoff): the LAMMPS scheme,
  /// each pair and triplet once at one owner with forces to every atom it moves, over short
  /// lists (partners within short_cutoff() + skin, drawn from the families, owned pairs
  /// first) rebuilt when a point has moved by more than half the skin since the last build;
  /// ghosts for every (point, image) a family bond reaches. mb_fallback_: a point moved so far
  /// from its reference that a partner within r_c might lie outside its family (or has more
  /// than 512 partners within r_c); the general Evaluator is used from then on.
  bool manybody_ = false, mb_fallback_ = false, mb_built_ = false;
  std::vector<std::int32_t> mb_bond_ext_;    ///< per family bond (owned first): point or ghost
  std::vector<std::int32_t> mb_bond_owned_;  ///< per point: owned bonds of its family
  std::vector<std::int32_t> mb_neighbor_, mb_count_, mb_owned_;
  std::vector<double> mb_reference_;  ///< reference positions of points and ghosts
  std::vector<double> mb_built_y_;    ///< positions at the last list build
  double mb_list_sq_ = 0.0, mb_half_skin_sq_ = 0.0, mb_family_sq_ = 0.0;
  double mb_short_cutoff_ = 0.0;  ///< r_c of the short lists
  double mb_displacement_ = 0.0;  ///< largest distance of a point from its reference at the build
  std::int64_t mb_builds_ = 0;

  body::Evaluator ev_;
  std::vector<double> y_, v_, f_, inv_mass_;
  double dt_, ftm2v_, mvv2e_, boltz_, potential_ = 0.0;
  bool potential_current_ = true;  ///< false after a forces-only step of the pair kernel
  std::int64_t step_ = 0;
};

/// LAMMPS text dump of a run, frames appended in memory-free streaming to a temporary file and
/// renamed into place by commit() (pdcg::io::AtomicTextFile): `ITEM: ATOMS id type x y z ix iy
/// iz vx vy vz` with positions wrapped into the periodic box and image flags (readers unwrap).
class DumpWriter {
 public:
  explicit DumpWriter(const std::string& path);
  ~DumpWriter();
  void write(const body::Body& body, std::int64_t step, std::span<const double> y,
             std::span<const double> v);
  void commit();

 private:
  struct Impl;
  Impl* impl_;
};

}  // namespace pdcg::dynamics
