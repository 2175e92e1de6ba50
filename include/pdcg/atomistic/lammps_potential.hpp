/// \file
/// Force states of any LAMMPS pair style without a native implementation (tersoff, sw, meam,
/// …), as a Potential: the fallback that lets bodies, homogenisation, rescaling and the
/// Cauchy–Born material use every potential LAMMPS knows.
///
/// ψ_k is LAMMPS's `compute pe/atom` of atom k. It depends only on the relative positions of
/// the atoms within its energy range, so it is evaluated on free clusters in a box of the
/// user's atom style, each atom carrying the charge of its type (PotentialSpec::type_charge).
/// Periodic images of one atom are distinct partners, as LAMMPS's ghost atoms are.
///
/// Whether the style is pairwise is measured at construction: ψ of an atom with six partners
/// against the sum of its six dimers (1e-10 relative), for every type pair.
///  - pairwise: family cutoff r_c; every partner j (special factor s > 0) is a dimer of a copy
///    of k and j, many dimers per `run 0`, far enough apart not to interact;
///    ψ_k = Σ s ½φ (pe/atom of k's copy), t_kj = −½ s F_j (LAMMPS's analytic force): exact to
///    round-off. Molecular bonds (native harmonic/fene/zero) and special_bonds factors from
///    the families are supported; a coulomb style needs equal lj and coul factors.
///  - many-body: LAMMPS splits a three-body or bond-order energy over its atoms, which can be
///    2 r_c apart, so the family cutoff is 2 r_c, and
///      t_kj = ∂ψ_k/∂Y⟨ξ_kj⟩ ≈ [ψ_k(Y + h e) − ψ_k(Y − h e)] / (2h)    (central differences)
///    for each partner and direction: 6n + 1 `run 0` per family (about 0.1 s per family of 50
///    atoms). No molecular bonds.
/// One persistent LAMMPS instance; a mutex serialises the calls (LAMMPS is not re-entrant).
/// r_c is measured, not looked up: the largest distance at which a dimer of each type pair has
/// nonzero energy (bisection to 1e-9 relative), which works for any style.
/// Before the first LAMMPS command the setup runs once in the `lmp` executable
/// (check_lammps_commands), so LAMMPS errors become InputErrors.
#pragma once

#include <memory>

#include "pdcg/atomistic/potential.hpp"

namespace pdcg::atomistic {

/// Returns the fallback potential for `spec` (a pair style this LAMMPS build knows; a native
/// bond_style only with a pairwise pair style). Throws InputError when LAMMPS is not enabled,
/// the style or a potential file is missing, LAMMPS rejects the commands, or the model cannot
/// be represented (k-space, hybrid, unequal lj/coul special factors with a coulomb style).
std::unique_ptr<Potential> make_lammps_potential(const PotentialSpec& spec);

}  // namespace pdcg::atomistic
