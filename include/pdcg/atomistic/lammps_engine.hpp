/// \file
/// Embedded LAMMPS (liblammps through its C library interface, behind a PIMPL: no LAMMPS
/// header reaches pdcg's public headers).
///
/// LammpsEngine evaluates any interaction model LAMMPS knows — the reference for the native
/// potentials in tests, and the fallback for styles pdcg has no native implementation of
/// (tersoff, sw, meam, …): per-atom energies (compute pe/atom: pair energy split ½–½, bond
/// energy ½–½, EAM embedding energy on its atom) and forces for one configuration.
/// Force states (t_kj) for many-body fallback styles are not available: bodies built on such
/// styles need a native Potential (a later issue).
///
/// Per evaluation: a fresh instance (`-log none -screen none -nocite`), `units`, `atom_style`,
/// `atom_modify map array`, boundary from Box::periodic (non-periodic = `f`, the box widened to
/// hold every atom), a temporary data file (box with tilt, masses, atoms, bonds) read by
/// `read_data`, the potential commands rebuilt from the PotentialSpec (potential files replaced
/// by their resolved paths), `compute pe/atom`, `run 0`. Debian's liblammps aborts the process
/// on any LAMMPS error, so styles, files and type counts are validated before any command.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"
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

  /// The LAMMPS commands of the last evaluation (for diagnostics).
  const std::vector<std::string>& commands() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdcg::atomistic
