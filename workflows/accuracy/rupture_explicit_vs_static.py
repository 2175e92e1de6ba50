"""Analysis of workflows/accuracy/rupture_explicit_vs_static.sh: OUT/compare.csv + compare.png.

Columns: case, peak load (top reaction F_y), displacement at the peak, critical stretch
(1 + ū at the first broken bond), crack tip x, the damage-weighted mean |y − 0.5| of the
damaged points (damage > 0.3, x > 0.3) and the damaged fraction of the sheet at the end,
bonds broken, wall time (s), steps.
"""
import csv
import glob
import math
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

out, umax, V, rise = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
wall = {}
with open(os.path.join(out, "walltime.txt")) as f:
    for line in f:
        name, rc, sec = line.split()
        wall[name] = (int(rc), float(sec))


def read(path):
    with open(path) as f:
        r = list(csv.DictReader(l for l in f if not l.startswith("#")))  # units line
    return {k: np.array([float(x[k]) for x in r]) for k in r[0]}


def last_fields(case):
    files = sorted(glob.glob(os.path.join(out, case, "results_*.h5")))
    with h5py.File(files[-1]) as h:
        return h["points/reference"][()], h["fields/damage"][()]


rows, curves = [], {}
for case in ("static", "explicit"):
    if case == "static":
        d = read(os.path.join(out, case, "reactions.csv"))
        u = umax * d["t"]
    else:
        d = read(os.path.join(out, case, "series.csv"))
        t = d["t"]
        u = V * (t - rise * (1 - np.exp(-t / rise)))
    F = -d["top_fy"] if np.mean(d["top_fy"]) < 0 else d["top_fy"]
    # the explicit reaction carries the inertia of the grip's wave; the peak is taken on a
    # running mean over 1% of the run
    if case == "explicit":
        w = max(1, len(F) // 100)
        F = np.convolve(F, np.ones(w) / w, mode="same")
    curves[case] = (u, F)
    b = d["broken_bonds"]
    k_first = int(np.argmax(b > 0)) if (b > 0).any() else -1
    X, D = last_fields(case)
    dam = D > 0.3
    right = dam & (X[:, 0] > 0.3)
    tip = X[right, 0].max() if right.any() else 0.3
    # crack path: damage-weighted mean distance of the damaged points (x > 0.3) from the
    # crack line, and the damaged fraction of the sheet (a single crack: a few percent)
    off = (float(np.sum(D[right] * np.abs(X[right, 1] - 0.5)) / np.sum(D[right]))
           if right.any() else 0.0)
    k = int(np.argmax(F))
    rows.append({
        "case": case,
        "peak_load": F[k],
        "u_at_peak": u[k],
        "critical_stretch": 1 + u[k_first] if k_first >= 0 else math.nan,
        "tip_x": tip,
        "mean_offset_from_crack_line": off,
        "damaged_fraction": float(np.mean(dam)),
        "bonds_broken": int(b[-1]),
        "wall_s": wall[case][1],
        "exit": wall[case][0],
        "steps": len(F) - 1,
    })
    rows[-1]["_X"], rows[-1]["_D"] = X, D
with open(os.path.join(out, "compare.csv"), "w", newline="") as f:
    keys = [k for k in rows[0] if not k.startswith("_")]
    w = csv.DictWriter(f, fieldnames=keys)
    w.writeheader()
    for r in rows:
        w.writerow({k: (f"{r[k]:.6g}" if isinstance(r[k], float) else r[k]) for k in keys})
for r in rows:
    print(", ".join(f"{k} {r[k]:.5g}" if isinstance(r[k], float) else f"{k} {r[k]}"
                    for k in r if not k.startswith("_")))
fig, ax = plt.subplots(1, 3, figsize=(13, 4))
for case, (u, F) in curves.items():
    ax[0].plot(u, F, label=case)
ax[0].set_xlabel("top displacement ū")
ax[0].set_ylabel("top reaction F_y")
ax[0].legend()
for a, r in zip(ax[1:], rows):
    sc = a.scatter(r["_X"][:, 0], r["_X"][:, 1], c=r["_D"], s=12, vmin=0, vmax=1, cmap="magma_r")
    a.set_title(f"{r['case']}: damage at ū = {umax:g}")
    a.set_aspect("equal")
fig.colorbar(sc, ax=ax[2])
fig.tight_layout()
fig.savefig(os.path.join(out, "compare.png"), dpi=110)
print("wrote", os.path.join(out, "compare.csv"), os.path.join(out, "compare.png"))
