#!/usr/bin/env python3
"""Isothermal stiffness at the T = 0 volume: LAMMPS NVT at strains ±e against pdcg's
quasi-harmonic Cauchy–Born material (`pdcg energy --quasi-harmonic T --stress`, `pdcg elastic
--quasi-harmonic T`) and the static lattice (docs/temperature.md §3).

    elastic.py OUT T [T ...]   env SYSTEM (lj: fcc LJ, md.in | cu: fcc Cu EAM, md_cu.in),
                               PDCG, CELLS=4, EQUIL=5000, SAMPLE=20000; e = 0.01

For each T: the deck at exx = ±e (uniaxial x) and gxy = ±e (simple shear xy), Cauchy stress
σ = −p (the thermo pressure tensor, kinetic part included) averaged with block errors (20
blocks of the 10-step series); slopes
  C11 = dσ_xx/dε_xx,  C12 = dσ_yy/dε_xx,  C44 = dσ_xy/dγ_xy     (central, strain ±e),
the tangent stiffness of the pre-stressed (thermal pressure) cell. pdcg: delta body of the
relaxed lattice, P_T = ∂W_T/∂F of the quasi-harmonic material at the same four F (T = 0: the
static lattice), σ = P Fᵀ/det F, same slopes. Also the tangent at F = I from `pdcg elastic
--quasi-harmonic T` (C_IJ = ∂²W_T/∂E_I∂E_J) and its zero-strain slopes C11 + S_xx,
C12 − S_yy, C44 + S_yy (S the thermal stress), for each strain step of env STEPS (lj: 1e-4;
cu: 1e-4 and 1e-2 — the EAM splines are C¹, the knot-averaging step matters). Units: lj reduced; cu GPa (LAMMPS bar × 1e-4,
pdcg eV/Å³ × 160.21766208).
"""
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
PDCG = os.environ.get("PDCG", "pdcg")
E = 0.01
CELLS = os.environ.get("CELLS", "4")
SYSTEM = os.environ.get("SYSTEM", "lj")
DECK, MD_TO_UNIT, PD_TO_UNIT, POTENTIAL = {
    "lj": ("md.in", 1.0, 1.0, "units lj\natom_style atomic\nmass 1 1.0\npair_style lj/cut 2.5\n"
           "pair_coeff 1 1 1.0 1.0 2.5\npair_modify shift yes\n"),
    "cu": ("md_cu.in", 1e-4, 160.21766208,
           "units metal\natom_style atomic\nmass 1 63.55\npair_style eam\n"
           "pair_coeff 1 1 Cu_u3.eam\n"),
}[SYSTEM]
# steps in E of the vibrational part of the tangent (`--quasi-harmonic-step`)
STEPS = os.environ.get("STEPS", {"lj": "1e-4", "cu": "1e-4 1e-2"}[SYSTEM]).split()


def cpu():
    t = os.times()
    return t.children_user + t.children_system


def md(d, T, exx=0.0, gxy=0.0):
    os.makedirs(d, exist_ok=True)
    if not os.path.exists(os.path.join(d, "thermo.txt")):
        subprocess.run(["lmp", "-in", os.path.join(HERE, DECK), "-var", "T", str(T), "-var",
                        "seed", "4711", "-var", "cells", CELLS, "-var", "equil",
                        os.environ.get("EQUIL", "5000"), "-var", "sample",
                        os.environ.get("SAMPLE", "20000"), "-var", "every", "1000", "-var",
                        "out", d, "-var", "exx", str(exx), "-var", "gxy", str(gxy), "-log",
                        os.path.join(d, "log.lammps"), "-screen", "none"], check=True)
    th = np.loadtxt(os.path.join(d, "thermo.txt"))
    sig = -th[:, [2, 3, 4, 5, 6, 7]] * MD_TO_UNIT  # σ xx yy zz yz xz xy
    b = sig[: len(sig) // 20 * 20].reshape(20, -1, 6).mean(axis=1)
    return sig.mean(axis=0), b.std(axis=0, ddof=1) / np.sqrt(20)


def pdcg_json(*args):
    return json.loads(subprocess.run([PDCG, "-q", *args, "--json"], check=True,
                                     capture_output=True, text=True).stdout)


def cauchy(body, F, T):
    """σ of the quasi-harmonic material at F (T = 0: the static lattice)."""
    out = pdcg_json("energy", body, "--F", " ".join(repr(x) for x in F.ravel()), "--stress",
                    "--quasi-harmonic", str(T))
    P = np.array(out["free_energy_stress"]).reshape(3, 3)
    return P @ F.T / np.linalg.det(F) * PD_TO_UNIT


def main():
    out = sys.argv[1]
    rows, tangent_rows, cost = [], [], []
    for T in sys.argv[2:]:
        T = float(T)
        base = os.path.join(out, f"elastic_T_{T}")
        res = {}
        c0 = cpu()
        for name, exx, gxy in (("xx+", E, 0), ("xx-", -E, 0), ("xy+", 0, E), ("xy-", 0, -E)):
            res[name] = md(os.path.join(base, name), T, exx, gxy)
        c_md = cpu() - c0
        (sp, ep), (sm, em) = res["xx+"], res["xx-"]
        (gp, egp), (gm, egm) = res["xy+"], res["xy-"]
        md_c = dict(C11=((sp[0] - sm[0]) / (2 * E), np.hypot(ep[0], em[0]) / (2 * E)),
                    C12=((sp[1] - sm[1]) / (2 * E), np.hypot(ep[1], em[1]) / (2 * E)),
                    C44=((gp[5] - gm[5]) / (2 * E), np.hypot(egp[5], egm[5]) / (2 * E)))
        lattice = os.path.join(base, "xx+", "lattice.dump")
        body = os.path.join(base, "lattice.h5")
        pot = os.path.join(base, "potential.in")
        with open(pot, "w") as f:
            f.write(POTENTIAL)
        subprocess.run([PDCG, "-q", "atoms2pd", "--input", lattice, "--potential", pot,
                        "--density", "delta", "-o", body], check=True, stdout=subprocess.DEVNULL)
        model = {}
        c0, w0 = cpu(), time.time()
        for label, temp in (("quasi-harmonic", T), ("static", 0.0)):
            Fp, Fm = np.diag([1 + E, 1, 1]), np.diag([1 - E, 1, 1])
            a, b = cauchy(body, Fp, temp), cauchy(body, Fm, temp)
            Gp, Gm = np.eye(3), np.eye(3)
            Gp[0, 1], Gm[0, 1] = E, -E
            c, d = cauchy(body, Gp, temp), cauchy(body, Gm, temp)
            model[label] = dict(C11=(a[0, 0] - b[0, 0]) / (2 * E),
                                C12=(a[1, 1] - b[1, 1]) / (2 * E),
                                C44=(c[0, 1] - d[0, 1]) / (2 * E))
        c_secant = cpu() - c0
        # tangent at F = I, per central-difference step of the vibrational part (tabulated EAM:
        # the local step 1e-4 and the knot-averaging 1e-2; docs/temperature.md §3)
        tangents = []
        c0 = cpu()
        for step in STEPS:
            el = pdcg_json("elastic", body, "--quasi-harmonic", str(T), "--quasi-harmonic-step",
                           step)
            C = np.array(el["C_voigt"]) * PD_TO_UNIT
            S = np.array(el["S"]) * PD_TO_UNIT
            tangents.append((dict(C11=C[0, 0], C12=C[0, 1], C44=C[3, 3]),
                             dict(C11=C[0, 0] + S[0, 0], C12=C[0, 1] - S[1, 1],
                                  C44=C[3, 3] + S[1, 1])))
        c_tangent = (cpu() - c0) / len(STEPS)
        for k in ("C11", "C12", "C44"):
            m, e = md_c[k]
            q = model["quasi-harmonic"][k]
            ok = abs(q - m) <= max(0.03 * abs(m), e)
            rows.append(f"| {T:g} | {k} | {m:.2f} ± {e:.2f} | {q:.2f} | {100 * (q / m - 1):+.1f} % "
                        f"| {model['static'][k]:.2f} | {'yes' if ok else 'no'} |")
            tangent_rows.append(f"| {T:g} | {k} | " + " | ".join(
                f"{t[k]:.2f} / {b[k]:.2f}" for t, b in tangents) + " |")
        cost.append(f"T {T:g}: MD {c_md:.1f} s CPU (4 runs), pdcg secant slopes {c_secant:.1f} s CPU "
                    f"(8 stresses), pdcg elastic --quasi-harmonic {c_tangent:.1f} s CPU per step")
    table = ["| T | | MD (NVT, strain ±0.01) | quasi-harmonic (pdcg) | QH − MD | static lattice "
             "| within 3 % or the error |", "|---:|---|---:|---:|---:|---:|:---:|"] + rows
    tang = ["| T | | " + " | ".join(f"C_IJ / zero-strain slope, step {s}" for s in STEPS) + " |",
            "|---:|---|" + "---:|" * len(STEPS)] + tangent_rows
    text = "\n".join(table) + "\n\n" + "\n".join(tang) + "\n\n" + "\n".join(cost) + "\n"
    with open(os.path.join(out, "elastic.md"), "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
