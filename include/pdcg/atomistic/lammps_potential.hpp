/// \file
/// Force states of any LAMMPS pair style without a native implementation (tersoff, sw, meam,
/// …), as a Potential: the fallback that lets bodies, homogenisation, rescaling and the
/// Cauchy–Born material use every potential LAMMPS knows.
///
/// ψ_k is LAMMPS's `compute pe/atom` of atom k. It depends only on the relative positions of
/// the atoms within its energy range, so it is evaluated on a free cluster made of atom k at
/// the origin and its family partners at Y⟨ξ_kj⟩ (periodic images of one atom are distinct
/// partners, exactly as LAMMPS's ghost atoms are), and
///   t_kj = ∂ψ_k/∂Y⟨ξ_kj⟩ ≈ [ψ_k(Y + h e) − ψ_k(Y − h e)] / (2h)      (central differences)
/// for each partner and direction: 6n + 1 `run 0` per family on one persistent LAMMPS
/// instance (a mutex serialises the calls: LAMMPS is not re-entrant). Slow — about 0.1 s per
/// family of 50 atoms — and it allocates; meant for bodies of a few thousand atoms.
///
/// Energy range: LAMMPS splits a three-body or bond-order energy over its atoms, which can be
/// 2 r_c apart (r_c: the pair cutoff), so the family cutoff is 2 r_c. r_c is measured, not
/// looked up: the largest distance at which a dimer of each type pair has nonzero energy
/// (bisection to 1e-9 relative), which works for any style.
#pragma once

#include <memory>

#include "pdcg/atomistic/potential.hpp"

namespace pdcg::atomistic {

/// Returns the fallback potential for `spec` (a pair style this LAMMPS build knows, no
/// bond_style). Throws InputError when LAMMPS is not enabled, the style or a potential file
/// is missing, or a bond_style is present.
std::unique_ptr<Potential> make_lammps_potential(const PotentialSpec& spec);

}  // namespace pdcg::atomistic
