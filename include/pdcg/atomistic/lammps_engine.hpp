/// \file
/// Embedded LAMMPS (liblammps through its C library interface, behind a PIMPL: no LAMMPS
/// header reaches pdcg's public headers).
///
/// LammpsEngine evaluates any interaction model LAMMPS knows — the reference for the native
/// potentials in tests, and the fallback for styles pdcg has no native implementation of
/// (tersoff, sw, meam, …): per-atom energies (compute pe/atom: pair energy split ½–½, bond
/// energy ½–½, EAM embedding energy on its atom) and forces for one configuration.
/// Force states (t_kj = ∂ψ_k/∂y_j) for fallback styles come from central differences of the
/// per-atom energies (energy_derivatives below; atomistic::lammps_force_states in families.hpp).
///
/// Per evaluation: a fresh instance (`-log none -screen none -nocite`), `units`, `atom_style`,
/// `atom_modify map array`, boundary from Box::periodic (non-periodic = `f`, the box widened to
/// hold every atom), a temporary data file (box with tilt, masses, atoms, bonds) read by
/// `read_data`, the potential commands rebuilt from the PotentialSpec (potential files replaced
/// by their resolved paths), `compute pe/atom`, `run 0`.
///
/// LAMMPS errors. Debian's liblammps is built without C++ exceptions
/// (lammps_config_has_exceptions() == 0): any LAMMPS error calls exit(1) — or MPI_Abort —
/// inside the library, and with `-screen none -log none` the message is lost. So pdcg checks
/// what it can itself (styles, files, type counts), refuses what would give wrong forces
/// (long-range electrostatics), and runs every command sequence once in a separate process of
/// the `lmp` executable of the same LAMMPS installation (check_lammps_commands) before the
/// library runs it: a LAMMPS error there becomes an InputError with LAMMPS's own message and
/// the user's command and line; LAMMPS's warnings go to pdcg's log.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/atomistic/families.hpp"
#include "pdcg/atomistic/potential.hpp"

namespace pdcg::atomistic {

struct LammpsResult {
  std::vector<double> energy;  ///< per atom (pe/atom), in the order of the input atoms
  std::vector<double> force;   ///< 3N, in the order of the input atoms
  double total_energy = 0.0;   ///< Σ energy
};

class LammpsEngine {
 public:
  /// Validates the spec (styles known to this liblammps, potential files found). Throws
  /// InputError when LAMMPS is not enabled in this build or a style/file is missing.
  explicit LammpsEngine(PotentialSpec spec);
  ~LammpsEngine();
  LammpsEngine(LammpsEngine&&) noexcept;
  LammpsEngine& operator=(LammpsEngine&&) noexcept;

  /// Energies and forces of `atoms` (types 1..ntypes; atoms.bonds for molecular styles).
  /// Positions may lie outside a periodic box (LAMMPS wraps them).
  LammpsResult evaluate(const Atoms& atoms) const;

  /// Derivatives of every per-atom energy with respect to every atom position, by central
  /// differences on one LAMMPS instance:
  ///   ∂ψ_k/∂y_{j,d} ≈ [ψ_k(y + h e_{j,d}) − ψ_k(y − h e_{j,d})] / (2h),   error O(h²).
  /// For each atom j (input order) and direction d = 0,1,2, sink(j, d, dpsi) receives
  /// dpsi[k] for every atom k (input order); the span is valid during the call only. Returns
  /// the unperturbed evaluation. 6N + 1 `run 0` evaluations of the whole configuration:
  /// O(N²) work, meant for small configurations (up to a few thousand atoms).
  /// In a periodic box an atom moves with all its images, so ψ_k's dependence on two images
  /// of the same atom is summed (callers check that families hold one image per atom).
  using DerivativeSink = std::function<void(std::size_t j, int d, std::span<const double> dpsi)>;
  LammpsResult energy_derivatives(const Atoms& atoms, double step,
                                  const DerivativeSink& sink) const;

  /// The LAMMPS commands of the last evaluation (for diagnostics).
  const std::vector<std::string>& commands() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The LAMMPS commands of `spec` (mass, pair_style, pair_coeff with potential files resolved,
/// pair_modify, bond_style, bond_coeff, special_bonds). Defined only when LAMMPS is embedded.
std::vector<std::string> lammps_potential_commands(const PotentialSpec& spec);

/// One LAMMPS command and the line of `spec.source` it comes from (0: pdcg's own command).
struct LammpsCommand {
  std::string text;
  long line = 0;
};

/// lammps_potential_commands with the source line of each command.
std::vector<LammpsCommand> lammps_potential_command_lines(const PotentialSpec& spec);

/// Runs `commands` as an input script of the `lmp` executable in a child process
/// (`$PDCG_LMP`, else `lmp` on PATH; the same installation as liblammps) and reads its log.
/// A LAMMPS error (or a crash) throws InputError: source and line of the failing command in
/// `spec.source` (the pair_style line when the failing command is pdcg's own, e.g. `run 0`),
/// the command, LAMMPS's message, and `context` (what pdcg was doing). LAMMPS's WARNING lines
/// are written to pdcg's log (each distinct text once per process). Returns false, after a
/// one-time log warning, when no `lmp` executable is found: then a LAMMPS error stops the
/// process as before. Defined only when LAMMPS is embedded.
bool check_lammps_commands(const std::vector<LammpsCommand>& commands, const PotentialSpec& spec,
                           std::string_view context);

/// Refuses (InputError with the reason and the fix) what the engine cannot evaluate right:
/// long-range (k-space) pair styles (`*/long`, `*/msm`), which need a kspace_style whose
/// reciprocal-space energy is not a sum over finite families.
void require_engine_representable(const PotentialSpec& spec);

/// Per-type charges (PotentialSpec::type_charge) from the charges of a configuration, for the
/// fallback Potential (its clusters carry charges per type). No-op for atom styles without
/// charges, when `atoms` carries none, or when the spec sets every type's charge already
/// (`set type T charge Q`; a configuration that disagrees with those is an InputError).
/// InputError when two atoms of one type carry different charges: the fix is one type per
/// charge. Adds the `set type T charge Q` lines to spec.lines (so model files keep them).
void take_type_charges(PotentialSpec& spec, const Atoms& atoms);

/// Force states of a style evaluated by embedded LAMMPS (many-body through the per-atom
/// energy, docs/theory.md §1): ψ_k and t_b = ∂ψ_k/∂Y⟨ξ_b⟩ for every bond b = (k → j) of
/// `families`, at the configuration `atoms` (same atoms and order as the families were built
/// from, positions possibly deformed). ψ_k is a function of the relative positions only, so
/// ∂ψ_k/∂Y⟨ξ_kj⟩ = ∂ψ_k/∂y_j, taken from LammpsEngine::energy_derivatives; then
/// f_k = Σ_b (t_b − t_reverse[b]) is the LAMMPS force up to the O(h²) truncation.
/// Requirements, checked with an InputError naming the atoms: (1) a family holds at most one
/// periodic image of each atom (box edges longer than twice the horizon); (2) the horizon
/// covers everything ψ_k depends on — for three-body and bond-order styles (sw, tersoff)
/// LAMMPS splits each three-body energy over its atoms, which can be 2 r_c apart, so the
/// families need cutoff ≥ 2 r_c. Any derivative of ψ_k with respect to an atom outside k's
/// family larger than 1e-7 of the largest derivative is such an error.
/// step: finite-difference step (length units); 0 = 1e-5 × mean reference bond length.
/// Returns Σ_k ψ_k.
double lammps_force_states(const LammpsEngine& engine, const Atoms& atoms, const Families& families,
                           std::span<double> psi_out, std::span<double> t_out, double step = 0.0);

}  // namespace pdcg::atomistic
