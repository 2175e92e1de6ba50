#!/usr/bin/env python3
"""Relaxed-ion and clamped-ion elastic constants from LAMMPS (independent of pdcg).

usage: lammps_elastic.py DATA POTENTIAL OUT.json [--strain 1e-4] [--sheet]

POTENTIAL is a pdcg potential file (LAMMPS commands: units, mass, pair_style, pair_coeff, …;
pair_coeff files are found through LAMMPS_POTENTIALS). For each of the six Voigt strains
±e (normal: `change_box x scale 1±e remap`; shear: tilt yz/xz/xy by ±e·L, engineering
strain) the box is fixed and
  - clamped: the atoms are only remapped affinely (every atom follows F);
  - relaxed: `minimize` of the atoms (cg, line quadratic, dmax 0.01 Å, force tolerance
    1e-11 eV/Å) when the strained atoms carry a force above 1e-10 eV/Å (else nothing to relax).
C_ij = −(p_i(+e_j) − p_i(−e_j)) / (2e) from LAMMPS's pressure tensor (p = −σ, Voigt order
xx yy zz yz xz xy), in GPa (metal units: bar × 1e-4). The central difference has an O(e²)
truncation error: the script repeats the relaxed set at 2e and reports
fd_error = max |C(2e) − C(e)| / 3 / max|C| (Richardson: C(2e) − C(e) ≈ 3·c·e²).
--sheet: a 2D sheet in a 3D box (vacuum along z): the constants are areal (× L_z, GPa·Å =
0.1 N/m), reported as N/m, only the in-plane strains are applied.
Reference: LAMMPS examples/ELASTIC (the same stress differences, with minimize per strain).
"""
import json
import sys

import numpy as np
from lammps import lammps

VOIGT = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]


def split_potential(path):
    units, rest = "metal", []
    for line in open(path):
        s = line.split("#")[0].strip()
        if not s:
            continue
        if s.startswith("units"):
            units = s.split()[1]
        else:
            rest.append(s)
    return units, rest


def stress(data, potential, j, e, relax):
    """LAMMPS pressure tensor (Voigt order) after strain e along Voigt component j."""
    units, cmds = split_potential(potential)
    lmp = lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    lmp.command(f"units {units}")
    lmp.command("atom_style atomic")
    lmp.command("atom_modify map array")
    lmp.command(f"read_data {data} nocoeff")
    for c in cmds:
        lmp.command(c)
    lmp.command("change_box all triclinic")
    lmp.command("neighbor 1.0 bin")
    lmp.command("neigh_modify every 1 delay 0 check yes")
    if e != 0.0:
        b = lmp.extract_box()
        lo, hi, xy, yz, xz = b[0], b[1], b[2], b[3], b[4]
        L = [hi[k] - lo[k] for k in range(3)]
        if j < 3:
            lmp.command(f"change_box all {'xyz'[j]} scale {1.0 + e:.17g} remap")
        elif j == 3:
            lmp.command(f"change_box all yz final {yz + e * L[2]:.17g} remap units box")
        elif j == 4:
            lmp.command(f"change_box all xz final {xz + e * L[2]:.17g} remap units box")
        else:
            lmp.command(f"change_box all xy final {xy + e * L[1]:.17g} remap units box")
    lmp.command("thermo_style custom step pe pxx pyy pzz pyz pxz pxy fmax")
    lmp.command("run 0")
    # a strain that puts no force on the atoms (Bravais lattices, centrosymmetric bases) leaves
    # nothing to minimise: started from round-off forces, cg's line search can jump (measured:
    # FCC Cu at +2e-4 along y ended at fmax 0.1 eV/Å), so minimise only when there is a force
    if relax and lmp.get_thermo("fmax") > 1e-10:
        lmp.command("min_style cg")
        lmp.command("min_modify line quadratic dmax 0.01")
        lmp.command("minimize 0.0 1e-11 20000 200000")
        lmp.command("run 0")
    p = [lmp.get_thermo(k) for k in ("pxx", "pyy", "pzz", "pyz", "pxz", "pxy")]
    fmax = lmp.get_thermo("fmax")
    b = lmp.extract_box()
    lz = b[1][2] - b[0][2]
    lmp.close()
    return np.array(p), fmax, lz


def constants(data, potential, e, relax, strains):
    C = np.zeros((6, 6))
    fmax = 0.0
    lz = 1.0
    for j in strains:
        pp, fp, lz = stress(data, potential, j, e, relax)
        pm, fm, _ = stress(data, potential, j, -e, relax)
        fmax = max(fmax, fp, fm)
        C[:, j] = -(pp - pm) / (2 * e)
    return C, fmax, lz


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    e = 1e-4
    if "--strain" in sys.argv:
        e = float(sys.argv[sys.argv.index("--strain") + 1])
        args.remove(sys.argv[sys.argv.index("--strain") + 1])
    sheet = "--sheet" in sys.argv
    data, potential, out = args[:3]
    units, _ = split_potential(potential)
    to_gpa = {"metal": 1e-4, "real": 1.01325e-4}[units]
    strains = [0, 1, 5] if sheet else range(6)
    Cr, fmax, lz = constants(data, potential, e, True, strains)
    Cr2, fmax2, _ = constants(data, potential, 2 * e, True, strains)
    fmax = max(fmax, fmax2)
    Cc, _, _ = constants(data, potential, e, False, strains)
    scale = to_gpa * (lz * 0.1 if sheet else 1.0)  # GPa, or GPa·Å × 0.1 = N/m for a sheet
    Cr, Cr2, Cc = Cr * scale, Cr2 * scale, Cc * scale
    fd = float(np.abs(Cr2 - Cr).max() / 3 / np.abs(Cr).max())
    res = {
        "data": data, "potential": potential, "strain": e, "unit": "N/m" if sheet else "GPa",
        "C_relaxed": Cr.tolist(), "C_clamped": Cc.tolist(), "C_relaxed_2e": Cr2.tolist(),
        "fd_error": fd, "max_force_after_minimize": fmax,
        "asymmetry": float(np.abs(Cr - Cr.T).max() / np.abs(Cr).max()) if not sheet else None,
    }
    json.dump(res, open(out, "w"), indent=1)
    print(f"{data}: C11 {Cr[0,0]:.6g} C12 {Cr[0,1]:.6g} C44/C66 {Cr[5,5] if sheet else Cr[3,3]:.6g} "
          f"(relaxed), fd error {fd:.1e}, max force {fmax:.1e}")


if __name__ == "__main__":
    main()
