#!/usr/bin/python3
"""Molecular statics reference for the per-point Cauchy–Born strip test (docs/elastic.md §7).

Triangular LJ strip (lj/cut 2.5, zero-stress lattice constant a0 = 1.1132013035564603: shells
a, √3a, 2a inside the cutoff), 20 × ny atoms, all edges free; the atoms with x ≤ 0.56 are held at
x (y free), the atoms with x ≥ 19a − 0.56 are displaced by e·19a in x and held there, the atom at
the origin is held in y — the boundary sets the scene selects in
tests/unit/scene/test_per_point_cauchy_born.cpp. LAMMPS minimises the rest (cg, ftol 1e-13);
the reaction of the right set is minus the sum of the forces `fix setforce` removed.
Usage: /usr/bin/python3 per_point_strip_statics.py   (prints ny, e, reaction)
"""
import numpy as np
from lammps import lammps

A = 1.1132013035564603
H = A * np.sqrt(3) / 2


def reaction(nx, ny, e):
    lmp = lammps(cmdargs=["-log", "none", "-screen", "none"])
    lmp.commands_string(f"""
units lj
dimension 2
atom_style atomic
boundary f f p
region box block -10 {nx * A + 10} -10 {ny * H + 10} -0.5 0.5
create_box 1 box
mass 1 1.0
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0
""")
    for j in range(ny):
        for i in range(nx):
            lmp.command(f"create_atoms 1 single {(i + 0.5 * (j % 2)) * A:.15f} {j * H:.15f} 0.0")
    length = (nx - 1) * A
    lmp.commands_string(f"""
region rl block INF {0.56 + 1e-6} INF INF INF INF
region rr block {length - 0.56 - 1e-6} INF INF INF INF INF
region rp block -0.01 0.01 -0.01 0.01 INF INF
group left region rl
group right region rr
group pin region rp
displace_atoms right move {e * length} 0 0
fix fl left setforce 0.0 NULL 0.0
fix fr right setforce 0.0 NULL 0.0
fix fp pin setforce NULL 0.0 0.0
fix e2 all enforce2d
min_style cg
minimize 0 1e-13 100000 1000000
""")
    fr = lmp.extract_fix("fr", 0, 1, 0)
    lmp.close()
    return -fr


if __name__ == "__main__":
    for ny in (8, 16):
        for e in (0.0, 0.02):
            print(f"ny {ny} e {e}: reaction {reaction(20, ny, e):.6f}")
