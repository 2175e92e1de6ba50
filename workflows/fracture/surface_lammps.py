#!/usr/bin/python3
"""Surface energy of a crystal plane computed by LAMMPS alone (the reference for `pdcg surface`).

The slab is built in LAMMPS from scratch, independently of pdcg: an oriented lattice
(`lattice ... orient x/y/z`, z along the plane normal), a periodic box of whole lattice periods
(`region ... units box`, periods computed from the fcc Bravais lattice below), `create_atoms`;
E_bulk is `run 0` of the periodic box, then `change_box all boundary p p s` opens the two
surfaces (the cut lies at z = 0, moved into the widest gap between atomic layers by
`displace_atoms` for lattices with unequal gaps such as diamond (111)), E_slab is `run 0`, and the
relaxed energies come from `min_style cg` with `minimize 0 FTOL ...` (box fixed).

    gamma = (E_slab - E_bulk) / (2 lx ly)

Usage: surface_lammps.py --system lj|cu|si|si-tersoff --plane 100|110|111 --periods NZ [--inplane NX NY]
                         [--ftol 1e-12] [--lj-a 1.55] [--write-data SLAB.data]
Prints one JSON object. Needs the `lammps` Python module of /usr/bin/python3 (Debian's).
"""
import argparse
import json
import math
import sys

from lammps import lammps

ORIENT = {  # x, y, z (z: the plane normal), right-handed
    "100": ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
    "110": ((0, 0, 1), (1, -1, 0), (1, 1, 0)),
    "111": ((1, -1, 0), (1, 1, -2), (1, 1, 1)),
}


def period(a, d):
    """Shortest translation of the fcc Bravais lattice (a/2)(h,k,l), h+k+l even, along d."""
    n = math.sqrt(sum(c * c for c in d))
    return a * n / 2 if sum(d) % 2 == 0 else a * n


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--system", required=True, choices=["lj", "cu", "si", "si-tersoff"])
    ap.add_argument("--plane", required=True, choices=sorted(ORIENT))
    ap.add_argument("--periods", type=int, required=True, help="lattice periods along the normal")
    ap.add_argument("--inplane", type=int, nargs=2, default=[2, 2])
    ap.add_argument("--ftol", type=float, default=1e-12)
    ap.add_argument("--lj-a", type=float, default=1.55, help="LJ fcc lattice constant (sigma)")
    ap.add_argument("--no-relax", action="store_true")
    ap.add_argument("--write-data", default="", help="write the relaxed slab (LAMMPS data file)")
    o = ap.parse_args()

    if o.system == "lj":
        a, units, style = o.lj_a, "lj", "fcc"
        scale = 4.0 / a**3  # lj units: `lattice fcc` takes the reduced density
        pair = ["pair_style lj/cut 2.5", "pair_coeff 1 1 1.0 1.0"]
        mass, basis_atoms = 1.0, 4
    elif o.system == "cu":
        a, units, style, scale = 3.615, "metal", "fcc", 3.615
        pair = ["pair_style eam", "pair_coeff 1 1 Cu_u3.eam"]
        mass, basis_atoms = 63.546, 4
    else:
        a, units, style, scale = 5.431, "metal", "diamond", 5.431
        pair = (["pair_style sw", "pair_coeff * * Si.sw Si"] if o.system == "si" else
                ["pair_style tersoff", "pair_coeff * * Si.tersoff Si"])
        mass, basis_atoms = 28.0855, 8
    ox, oy, oz = ORIENT[o.plane]
    px, py, pz = (period(a, d) for d in (ox, oy, oz))
    lx, ly, lz = o.inplane[0] * px, o.inplane[1] * py, o.periods * pz

    L = lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    cmd = L.command
    cmd(f"units {units}")
    cmd("boundary p p p")
    cmd("atom_modify map array")
    orient = " ".join(f"orient {ax} {d[0]} {d[1]} {d[2]}" for ax, d in zip("xyz", (ox, oy, oz)))
    cmd(f"lattice {style} {scale!r} {orient}")
    cmd(f"region box block 0 {lx!r} 0 {ly!r} 0 {lz!r} units box")
    cmd("create_box 1 box")
    cmd("create_atoms 1 box")
    cmd(f"mass 1 {mass}")
    for p in pair:
        cmd(p)
    cmd("thermo_style custom step pe fnorm")
    cmd("thermo_modify norm no")
    natoms = L.get_natoms()
    expected = round(basis_atoms * lx * ly * lz / a**3)
    if natoms != expected:
        sys.exit(f"surface_lammps.py: created {natoms} atoms, expected {expected}")

    # cut in the middle of the widest gap between layers: z-heights modulo lz
    x = L.numpy.extract_atom("x")
    # layer heights as fractions of lz, rounded to 1e-9 (an atom at lz - round-off is at 0)
    fr = sorted({round((float(z) / lz) % 1.0, 9) % 1.0 for z in x[:natoms, 2]})
    gaps = [((fr[(i + 1) % len(fr)] - fr[i]) % 1.0 or 1.0, fr[i]) for i in range(len(fr))]
    gap, below = max(gaps)
    zs = fr
    mid = (below + 0.5 * gap) * lz
    cmd(f"displace_atoms all move 0 0 {-mid!r} units box")  # remapped into the periodic box

    cmd("run 0")
    e_bulk = L.get_thermo("pe")
    out = {"system": o.system, "plane": o.plane, "atoms": natoms, "lx": lx, "ly": ly,
           "height": lz, "layers": len(zs), "area": lx * ly, "e_bulk": e_bulk}
    if not o.no_relax:
        cmd("min_style cg")
        cmd(f"minimize 0.0 {o.ftol!r} 100000 1000000")
        out["e_bulk_relaxed"] = L.get_thermo("pe")
        out["fnorm_bulk"] = L.get_thermo("fnorm")
    cmd("change_box all boundary p p s")
    cmd("run 0")
    out["e_slab"] = L.get_thermo("pe")
    out["gamma"] = (out["e_slab"] - e_bulk) / (2 * lx * ly)
    if not o.no_relax:
        cmd("min_style cg")
        cmd(f"minimize 0.0 {o.ftol!r} 100000 1000000")
        out["e_slab_relaxed"] = L.get_thermo("pe")
        out["fnorm_slab"] = L.get_thermo("fnorm")
        out["gamma_relaxed"] = (out["e_slab_relaxed"] - out["e_bulk_relaxed"]) / (2 * lx * ly)
        if o.write_data:
            cmd(f"write_data {o.write_data}")
    L.close()
    json.dump(out, sys.stdout)
    print()


if __name__ == "__main__":
    main()
