#!/usr/bin/env python3
"""Isothermal elastic constants of the classical quasi-harmonic free energy from LAMMPS alone
(the reference of `pdcg elastic --quasi-harmonic T`; docs/temperature.md §3, §4):

    F_T(E) = U(E) + k_B T Σ_i ln ω_i(E)     (+ a constant),   C_IJ = (1/V₀) ∂²F_T/∂E_I∂E_J,

U = LAMMPS's pe of the cell deformed by F(E) = (I + 2E)^½ (E the Green–Lagrange strain), ω_i²
the eigenvalues of the mass-weighted Hessian from central differences of LAMMPS forces (step
1e-5 in the positions), the 3 translations dropped; second derivatives by central differences
in E (step h, default 1e-3). Voigt shear components are the tensor ones (C44 = ∂²/∂E₂₃² / 4).

    qha_elastic.py SYSTEM LATTICE.dump T [h]     SYSTEM: lj (lj/cut 2.5 shifted) | cu (Cu_u3.eam)

LATTICE.dump is a LAMMPS dump (id type x y z) of the relaxed T = 0 cell (md.in / md_cu.in
write it as lattice.dump). Prints C11, C12, C44 (static, thermal, total) in energy/volume of
the unit style (and GPa for metal).
"""
import sys

import numpy as np
from lammps import lammps

SYSTEMS = {
    "lj": ("lj", 1.0, "mass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0 2.5\n"
           "pair_modify shift yes\n"),
    "cu": ("metal", 8.617333262e-5, "mass 1 63.55\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n"),
}


def read_dump(path):
    L = open(path).read().splitlines()
    n = int(L[3])
    lo_hi = np.array([list(map(float, L[5 + a].split()[:2])) for a in range(3)])
    rows = np.array([l.split()[:5] for l in L[9:9 + n]], float)
    rows = rows[np.argsort(rows[:, 0])]
    return lo_hi, rows[:, 1].astype(int), rows[:, 2:5] - lo_hi[:, 0]


class Cell:
    def __init__(self, system, dump):
        self.units, self.kB, self.commands = SYSTEMS[system]
        self.lo_hi, self.types, self.x = read_dump(dump)
        self.L = self.lo_hi[:, 1] - self.lo_hi[:, 0]
        self.n = len(self.x)

    def at(self, E):
        """pe and Σ ln ω of the cell deformed by F(E) = (I + 2E)^½."""
        w, V = np.linalg.eigh(np.eye(3) + 2 * E)
        F = V @ np.diag(np.sqrt(w)) @ V.T
        Q, R = np.linalg.qr(F @ np.diag(self.L))
        s = np.sign(np.diag(R))  # positive diagonal: a right-handed LAMMPS box
        Q, R = Q * s, (R.T * s).T
        x = (Q.T @ F @ self.x.T).T  # rotated so that the box is LAMMPS's upper-triangular one
        lmp = lammps(cmdargs=["-log", "none", "-screen", "none"])
        lmp.commands_string(f"""
units {self.units}
atom_style atomic
atom_modify map array
boundary p p p
region box prism 0 {R[0, 0]!r} 0 {R[1, 1]!r} 0 {R[2, 2]!r} {R[0, 1]!r} {R[0, 2]!r} {R[1, 2]!r} units box
create_box 1 box
""")
        lmp.create_atoms(self.n, list(range(1, self.n + 1)), [int(t) for t in self.types],
                         x.ravel().tolist())
        lmp.commands_string(self.commands + """
neighbor 1.0 bin
neigh_modify every 1 delay 0 check no
thermo_style custom step pe
thermo_modify norm no
run 0
""")
        x0 = np.array(lmp.gather_atoms("x", 1, 3)).reshape(self.n, 3)
        pe = lmp.get_thermo("pe")
        mass = lmp.extract_atom("mass")
        mvec = np.array([mass[int(t)] for t in self.types])
        step = 1e-5
        K = np.zeros((3 * self.n, 3 * self.n))
        for i in range(3 * self.n):
            col = []
            for sgn in (+1, -1):
                xx = x0.copy()
                xx.flat[i] += sgn * step
                lmp.scatter_atoms("x", 1, 3, np.ctypeslib.as_ctypes(xx.ravel()))
                lmp.command("run 0")
                col.append(np.array(lmp.gather_atoms("f", 1, 3)))
            K[:, i] = -(col[0] - col[1]) / (2 * step)
        lmp.close()
        K = 0.5 * (K + K.T)
        mw = np.repeat(1 / np.sqrt(mvec), 3)
        w2 = np.sort(np.linalg.eigvalsh(K * mw[:, None] * mw[None, :]))[3:]
        assert w2.min() > 0, w2[:5]
        return pe, 0.5 * np.log(w2).sum()


def basis(I):
    j, k = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)][I]
    B = np.zeros((3, 3))
    B[j, k] += 1
    if j != k:
        B[k, j] += 1
    return B, (1 if j == k else 2)


def main():
    system, dump, T = sys.argv[1], sys.argv[2], float(sys.argv[3])
    h = float(sys.argv[4]) if len(sys.argv) > 4 else 1e-3
    c = Cell(system, dump)
    kT = c.kB * T
    V0 = float(np.prod(c.L))
    cache = {}

    def f(E):
        key = tuple(np.round(E.ravel() / h).astype(int))
        if key not in cache:
            cache[key] = c.at(E)
        return cache[key]

    def d2(I, J):
        (a, ma), (b, mb) = basis(I), basis(J)
        if I == J:
            p, z, m = f(h * a), f(0 * a), f(-h * a)
            u = (p[0] - 2 * z[0] + m[0]) / h**2
            s = (p[1] - 2 * z[1] + m[1]) / h**2
        else:
            pp, pm, mp, mm = f(h * (a + b)), f(h * (a - b)), f(h * (b - a)), f(-h * (a + b))
            u = (pp[0] - pm[0] - mp[0] + mm[0]) / (4 * h * h)
            s = (pp[1] - pm[1] - mp[1] + mm[1]) / (4 * h * h)
        return u / (V0 * ma * mb), kT * s / (V0 * ma * mb)

    gpa = 160.21766208 if c.units == "metal" else None
    print(f"# {system}: {c.n} atoms, V0 {V0:.10g}, T {T}, strain step {h}")
    print("name,static,thermal,total" + (",total_GPa" if gpa else ""))
    for name, I, J in (("C11", 0, 0), ("C12", 0, 1), ("C44", 3, 3)):
        u, s = d2(I, J)
        line = f"{name},{u:.10g},{s:.10g},{u + s:.10g}"
        if gpa:
            line += f",{(u + s) * gpa:.8g}"
        print(line)


if __name__ == "__main__":
    main()
