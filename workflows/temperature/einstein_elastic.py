#!/usr/bin/env python3
"""Isothermal stiffness of the Einstein (`--temperature`) statistical body of Cu against MD
(docs/temperature.md §3.3).

    einstein_elastic.py OUT T [T ...]     env PDCG, CELLS=4, SAMPLES=500; strain e = 0.01

The same protocol as elastic.py (MD's: secant slopes of the Cauchy stress between the strains
±e, ε_xx for C11 and C12, γ_xy for C44) applied to two readings of the Einstein body:
  carried   the body of the T = 0 lattice (widths Σ_k = k_B T H_k⁻¹ of the unstrained lattice)
            deformed by F: `pdcg energy --F F --stress`, σ = P Fᵀ/J — the statistical body's
            own d(∂W/∂F), its widths carried along by F (theory.md (2.4));
  re-equilibrated  a body built with `--temperature T` on each strained lattice (LAMMPS
            `change_box` as md_cu.in), σ = P at F = I — the widths of the strained well.
Both stresses are potential parts only; the kinetic stress −n k_B T I (n = N/V) adds
+n k_B T to the C11 and C12 slopes (its volume dependence) and nothing to C44. The expectation
is sampled (`--samples`, EAM is many-body); the same seed for every body, so the sampling noise
largely cancels in the differences (`SEEDS` > 1 repeats with other draws: the spread is
the error). Units GPa (pdcg eV/Å³ × 160.21765).
"""
import json
import os
import subprocess
import sys

import numpy as np

PDCG = os.environ.get("PDCG", "pdcg")
E = 0.01
CELLS = int(os.environ.get("CELLS", "4"))
SAMPLES = os.environ.get("SAMPLES", "500")
FAMILY = "5.95"  # as analyse.py: cutoff 4.95 Å + 1 Å skin
KB = 8.617333262e-5
GPA = 160.21765
POT = "units metal\natom_style atomic\nmass 1 63.55\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n"
LMP = """units metal
atom_style atomic
boundary p p p
lattice fcc 3.615
region box block 0 {c} 0 {c} 0 {c}
create_box 1 box
create_atoms 1 box
mass 1 63.55
pair_style eam
pair_coeff 1 1 Cu_u3.eam
{strain}
write_dump all custom {out} id type x y z modify format float %.17g
"""
STRAINS = {"xx+": (E, 0.0), "xx-": (-E, 0.0), "xy+": (0.0, E), "xy-": (0.0, -E)}


def run(*args, cwd="/usr/share/lammps/potentials"):
    return subprocess.run(list(args), check=True, capture_output=True, text=True, cwd=cwd).stdout


def lattice(d, name, exx, gxy):
    out = os.path.join(d, f"lattice_{name}.dump")
    strain = ""
    if exx:
        strain = f"change_box all x scale {1 + exx!r} remap units box"
    if gxy:
        strain = ("change_box all triclinic\n"
                  f"change_box all xy final {gxy * CELLS * 3.615!r} remap units box")
    with open(os.path.join(d, f"make_{name}.in"), "w") as f:
        f.write(LMP.format(c=CELLS, strain=strain, out=out))
    run("lmp", "-in", os.path.join(d, f"make_{name}.in"), "-log", "none", "-screen", "none")
    return out


def body(d, name, dump, T):
    pot = os.path.join(d, "cu.pot")
    with open(pot, "w") as f:
        f.write(POT)
    h5 = os.path.join(d, f"einstein_{name}_{T:g}.h5")
    run(PDCG, "-q", "atoms2pd", "--input", dump, "--potential", pot, "--density", "statistical",
        "--temperature", str(T), "--samples", SAMPLES, "--family-cutoff", FAMILY, "-o", h5)
    return h5


def cauchy(h5, F):
    j = json.loads(run(PDCG, "-q", "energy", h5, "--F", " ".join(repr(x) for x in F.ravel()),
                       "--stress", "--json"))
    P = np.array(j["stress"]).reshape(3, 3)
    return P @ F.T / np.linalg.det(F) * GPA, j["volume"]


def F_of(exx, gxy):
    F = np.eye(3)
    F[0, 0] += exx
    F[0, 1] = gxy
    return F


def slopes(s):
    return dict(C11=(s["xx+"][0, 0] - s["xx-"][0, 0]) / (2 * E),
                C12=(s["xx+"][1, 1] - s["xx-"][1, 1]) / (2 * E),
                C44=(s["xy+"][0, 1] - s["xy-"][0, 1]) / (2 * E))


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    d = os.path.abspath(out)
    dumps = {n: lattice(d, n, *s) for n, s in STRAINS.items()}
    dumps["0"] = lattice(d, "0", 0.0, 0.0)
    rows = []
    for T in map(float, sys.argv[2:]):
        ref = body(d, "0", dumps["0"], T)
        carried, requil = {}, {}
        for n, (exx, gxy) in STRAINS.items():
            carried[n], V = cauchy(ref, F_of(exx, gxy))
            requil[n], _ = cauchy(body(d, n, dumps[n], T), np.eye(3))
        nkT = 4 * CELLS**3 * KB * T / V * GPA  # n k_B T, GPa
        for label, s in (("carried", carried), ("re-equilibrated", requil)):
            c = slopes(s)
            c["C11"] += nkT
            c["C12"] += nkT
            rows.append((T, label, c))
            print(f"T {T:g} K {label}: C11 {c['C11']:.2f} C12 {c['C12']:.2f} C44 {c['C44']:.2f}"
                  f" GPa (kinetic n k_B T = {nkT:.3f})", flush=True)
    with open(os.path.join(out, "einstein_elastic.txt"), "w") as f:
        for T, label, c in rows:
            f.write(f"{T:g} {label} {c['C11']:.4f} {c['C12']:.4f} {c['C44']:.4f}\n")


if __name__ == "__main__":
    main()
