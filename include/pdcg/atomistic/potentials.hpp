/// \file
/// Native interatomic potentials as PD constitutive models (docs/theory.md §1), built from the
/// LAMMPS commands of a PotentialSpec.
///
/// Native pair styles (https://docs.lammps.org/pair_style.html), same double-precision
/// formulas as LAMMPS so that energies and forces agree to round-off:
///   lj/cut     φ(r) = 4ε[(σ/r)¹² − (σ/r)⁶] − φ_shift, r < r_c,ij  (PairLJCut; mixing of ε, σ,
///              r_c for unset I≠J pairs by pair_modify mix geometric|arithmetic|sixthpower as
///              PairLJCut::init_one; φ_shift = 4ε[(σ/r_c)¹² − (σ/r_c)⁶] with pair_modify shift yes)
///   morse      φ(r) = D₀[e^{−2α(r−r₀)} − 2e^{−α(r−r₀)}] − φ_shift   (PairMorse)
///   zero       φ = 0 (only sets the cutoff)
///   eam        DYNAMO funcfl files, one per type (PairEAM; r·φ = 27.2·0.529·Z_i Z_j)
///   eam/alloy  DYNAMO setfl file (PairEAMAlloy)
///   eam/fs     Finnis–Sinclair setfl file, ρ_ij per element pair (PairEAMFS)
/// EAM tables are converted and splined exactly as PairEAM::file2array/array2spline/interpolate
/// and evaluated with the coefficient formulas of PairEAM::compute; in `units real` a file
/// tagged `UNITS: metal` is converted as the LAMMPS readers convert it (docs/potentials.md).
/// ψ_k = ½ Σ_j s_kj φ(r_kj) for pair styles (s_kj the special_bonds lj factor of the minimum
/// image of a special partner, 1 for its farther images; LAMMPS drops pairs with s = 0 from
/// its neighbour lists), ψ_k = F_k(ρ̄_k) + ½ Σ_j φ(r_kj) for EAM, with
/// F extended linearly beyond ρ_max as LAMMPS does.
///
/// Native bond styles (https://docs.lammps.org/bond_style.html), ψ_k += ½ E_b(r_kj) for every
/// molecular bond partner:
///   harmonic   E = K (r − r₀)²
///   fene       E = −½ K R₀² ln[1 − (r/R₀)²] + 4ε[(σ/r)¹² − (σ/r)⁶] + ε  (LJ part for r <
///   2^{1/6}σ),
///              with LAMMPS's clamp of the log argument at 0.1 (BondFENE::compute)
///   zero       E = 0
#pragma once

#include <memory>

#include "pdcg/atomistic/families.hpp"
#include "pdcg/atomistic/potential.hpp"

namespace pdcg::atomistic {

/// Builds the native Potential for `spec` (a pair style, a bond style, or both).
/// Throws InputError (naming the file and line of the offending command) for malformed or
/// missing coefficients, unknown elements, unreadable potential files, and for styles that
/// have no native implementation: those are evaluated by LammpsEngine (per-atom energies and
/// forces only; force states for them are not available yet).
std::unique_ptr<Potential> make_potential(const PotentialSpec& spec);

/// Family options matching LAMMPS for `potential` on a configuration with molecular `bonds`
/// (nullptr or empty: none): cutoff = potential.cutoff(); with bonds, special_lj from the spec
/// (LAMMPS's default 0 0 0 applies to bonded atoms even without a special_bonds command).
FamilyOptions family_options(const Potential& potential, const PotentialSpec& spec,
                             const std::vector<Bond>* bonds = nullptr);

}  // namespace pdcg::atomistic
