#!/usr/bin/env python3
"""Isothermal stiffness at the T = 0 volume: LAMMPS NVT at strains ±e against the
quasi-harmonic free energy of pdcg (`pdcg energy --quasi-harmonic T`) and the static lattice
(docs/temperature.md §3).

    elastic.py OUT T [T ...]      (env PDCG, CELLS=4, EQUIL=5000, SAMPLE=20000; e = 0.01)

For each T: md.in at exx = ±e (uniaxial x) and gxy = ±e (simple shear xy), Cauchy stress
σ = −p (the thermo pressure tensor, kinetic part included) averaged with block errors; slopes
  C11 = dσ_xx/dε_xx,  C12 = dσ_yy/dε_xx,  C44 = dσ_xy/dγ_xy     (central, strain ±e),
the tangent stiffness of the pre-stressed (thermal pressure) cell. pdcg: delta body of the
relaxed lattice, W_T(F) = free_energy_density, P = ∂W_T/∂F by central differences (step 1e-5),
σ = P Fᵀ/det F at the same F, same slopes; T = 0 gives the static lattice's.
"""
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
PDCG = os.environ.get("PDCG", "pdcg")
E = 0.01
CELLS = os.environ.get("CELLS", "4")


def md(d, T, exx=0.0, gxy=0.0):
    os.makedirs(d, exist_ok=True)
    if not os.path.exists(os.path.join(d, "thermo.txt")):
        subprocess.run(["lmp", "-in", os.path.join(HERE, "md.in"), "-var", "T", str(T), "-var",
                        "seed", "4711", "-var", "cells", CELLS, "-var", "equil",
                        os.environ.get("EQUIL", "5000"), "-var", "sample",
                        os.environ.get("SAMPLE", "20000"), "-var", "every", "1000", "-var",
                        "out", d, "-var", "exx", str(exx), "-var", "gxy", str(gxy), "-log",
                        os.path.join(d, "log.lammps"), "-screen", "none"], check=True)
    th = np.loadtxt(os.path.join(d, "thermo.txt"))
    sig = -th[:, [2, 3, 4, 5, 6, 7]]  # σ xx yy zz yz xz xy
    b = sig[: len(sig) // 20 * 20].reshape(20, -1, 6).mean(axis=1)
    return sig.mean(axis=0), b.std(axis=0, ddof=1) / np.sqrt(20)


def w_t(body, F, T):
    out = subprocess.run([PDCG, "-q", "energy", body, "--F", " ".join(repr(x) for x in F.ravel()),
                          "--json", "--quasi-harmonic", str(T)], check=True, capture_output=True,
                         text=True).stdout
    return json.loads(out)["free_energy_density"]


def cauchy(body, F, T, comps):
    """σ_ij for (i, j) in comps from P = ∂W_T/∂F (central differences) and σ = P Fᵀ / J."""
    P = np.zeros((3, 3))
    need = {(i, k) for (i, j) in comps for k in range(3) if F[j, k] != 0}
    for (i, k) in need:
        d = np.zeros((3, 3))
        d[i, k] = 1e-5
        P[i, k] = (w_t(body, F + d, T) - w_t(body, F - d, T)) / 2e-5
    s = P @ F.T / np.linalg.det(F)
    return {c: s[c] for c in comps}


def main():
    out = sys.argv[1]
    rows = []
    for T in sys.argv[2:]:
        T = float(T)
        base = os.path.join(out, f"elastic_T_{T}")
        res = {}
        for name, exx, gxy in (("xx+", E, 0), ("xx-", -E, 0), ("xy+", 0, E), ("xy-", 0, -E)):
            res[name] = md(os.path.join(base, name), T, exx, gxy)
        (sp, ep), (sm, em) = res["xx+"], res["xx-"]
        (gp, egp), (gm, egm) = res["xy+"], res["xy-"]
        md_c = dict(C11=((sp[0] - sm[0]) / (2 * E), np.hypot(ep[0], em[0]) / (2 * E)),
                    C12=((sp[1] - sm[1]) / (2 * E), np.hypot(ep[1], em[1]) / (2 * E)),
                    C44=((gp[5] - gm[5]) / (2 * E), np.hypot(egp[5], egm[5]) / (2 * E)))
        lattice = os.path.join(base, "xx+", "lattice.dump")
        body = os.path.join(base, "lattice.h5")
        pot = os.path.join(base, "potential.in")
        with open(pot, "w") as f:
            f.write("units lj\natom_style atomic\nmass 1 1.0\npair_style lj/cut 2.5\n"
                    "pair_coeff 1 1 1.0 1.0 2.5\npair_modify shift yes\n")
        subprocess.run([PDCG, "-q", "atoms2pd", "--input", lattice, "--potential", pot,
                        "--density", "delta", "-o", body], check=True, stdout=subprocess.DEVNULL)
        model = {}
        for label, temp in (("quasi-harmonic", T), ("static", 0.0)):
            Fp, Fm = np.diag([1 + E, 1, 1]), np.diag([1 - E, 1, 1])
            a, b = cauchy(body, Fp, temp, [(0, 0), (1, 1)]), cauchy(body, Fm, temp, [(0, 0), (1, 1)])
            Gp, Gm = np.eye(3), np.eye(3)
            Gp[0, 1], Gm[0, 1] = E, -E
            c, d = cauchy(body, Gp, temp, [(0, 1)]), cauchy(body, Gm, temp, [(0, 1)])
            model[label] = dict(C11=(a[(0, 0)] - b[(0, 0)]) / (2 * E),
                                C12=(a[(1, 1)] - b[(1, 1)]) / (2 * E),
                                C44=(c[(0, 1)] - d[(0, 1)]) / (2 * E))
        for k in ("C11", "C12", "C44"):
            rows.append(f"| {T} | {k} | {md_c[k][0]:.2f} ± {md_c[k][1]:.2f} | "
                        f"{model['quasi-harmonic'][k]:.2f} | {model['static'][k]:.2f} |")
    table = ["| T* | | MD (NVT, strain ±0.01) | quasi-harmonic (pdcg) | static lattice |",
             "|---:|---|---:|---:|---:|"] + rows
    with open(os.path.join(out, "elastic.md"), "w") as f:
        f.write("\n".join(table) + "\n")
    print("\n".join(table))


if __name__ == "__main__":
    main()
