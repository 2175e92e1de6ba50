#!/usr/bin/env python3
"""Compare `pdcg elastic --json` (relaxed and --clamped-ion) with lammps_elastic.py.

usage: compare.py NAME PDCG_RELAXED.json PDCG_CLAMPED.json LAMMPS.json [--tol 5e-3] [--csv F]

Entries compared: the Voigt constants whose LAMMPS value exceeds 5 % of the largest (the others
are zero by symmetry; their pdcg and LAMMPS values are both round-off/FD noise), relative to
their own LAMMPS value. Sheets (LAMMPS unit N/m): the in-plane entries 11, 22, 12, 66, pdcg's
areal GPa·Å × 0.1. Exit 1 when a relaxed or clamped entry misses the tolerance.
"""
import json
import sys

import numpy as np

args = [a for a in sys.argv[1:] if not a.startswith("--")]
tol = 5e-3
if "--tol" in sys.argv:
    tol = float(sys.argv[sys.argv.index("--tol") + 1])
    args.remove(sys.argv[sys.argv.index("--tol") + 1])
csv = None
if "--csv" in sys.argv:
    csv = sys.argv[sys.argv.index("--csv") + 1]
    args.remove(csv)
name, fr, fc, fl = args[:4]
pr, pc, lm = json.load(open(fr)), json.load(open(fc)), json.load(open(fl))
sheet = lm["unit"] == "N/m"
scale = 0.1 if sheet else 1.0
Cr = np.array(pr["GPa"]["C_voigt"]) * scale
Cc = np.array(pc["GPa"]["C_voigt"]) * scale
Lr, Lc = np.array(lm["C_relaxed"]), np.array(lm["C_clamped"])
assert pr["ion_relaxation"] == "relaxed", pr["ion_relaxation"]
assert pc["ion_relaxation"] == "clamped", pc["ion_relaxation"]
idx = [0, 1, 5] if sheet else range(6)
labels = ["11", "22", "33", "44", "55", "66"]
rows, worst_r, worst_c = [], 0.0, 0.0
big = np.abs(Lr).max()
for i in idx:
    for j in idx:
        if j < i or abs(Lr[i, j]) < 0.05 * big:
            continue
        er = abs(Cr[i, j] - Lr[i, j]) / abs(Lr[i, j])
        ec = abs(Cc[i, j] - Lc[i, j]) / abs(Lc[i, j])
        worst_r, worst_c = max(worst_r, er), max(worst_c, ec)
        rows.append((f"C{labels[i][0]}{labels[j][0]}" if i < 3 and j < 3 else
                     f"C{labels[i]}" if i == j else f"C{i+1}{j+1}",
                     Cr[i, j], Lr[i, j], er, Cc[i, j], Lc[i, j], ec))
unit = lm["unit"]
print(f"{name} ({unit}; LAMMPS strain ±{lm['strain']:g}, FD error {lm['fd_error']:.1e}, "
      f"max force after minimize {lm['max_force_after_minimize']:.1e}, "
      f"shift iterations {pr.get('relaxation_iterations')})")
print(f"  {'':5} {'pdcg relaxed':>13} {'LAMMPS relaxed':>15} {'rel.diff':>9}   "
      f"{'pdcg clamped':>13} {'LAMMPS clamped':>15} {'rel.diff':>9}")
for r in rows:
    print(f"  {r[0]:5} {r[1]:13.6g} {r[2]:15.6g} {r[3]:9.1e}   {r[4]:13.6g} {r[5]:15.6g} {r[6]:9.1e}")
if csv:
    with open(csv, "a") as f:
        for r in rows:
            f.write(f"{name},{r[0]},{r[1]:.8g},{r[2]:.8g},{r[3]:.3e},{r[4]:.8g},{r[5]:.8g},{r[6]:.3e},"
                    f"{lm['fd_error']:.2e},{unit}\n")
ok = worst_r <= tol and worst_c <= tol
print(f"  worst relaxed {worst_r:.1e}, clamped {worst_c:.1e} (tolerance {tol:g}): "
      f"{'ok' if ok else 'FAIL'}")
sys.exit(0 if ok else 1)
