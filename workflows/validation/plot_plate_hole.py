#!/usr/bin/env python3
"""Comparison plot and markdown table: FEM reference vs pdcg runs (the per-step lines that
test_validation prints). Usage: plot_plate_hole.py fem.csv OUTDIR pdcg_<spacing>.txt..."""
import re
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

fem_file, out = sys.argv[1], sys.argv[2]
rows = [l.strip().split(",") for l in open(fem_file) if l[0].isdigit()]
d = np.array([float(r[1]) for r in rows])
fem = np.array([float(r[-1]) for r in rows])
runs = {}
for f in sys.argv[3:]:
    h = re.search(r"pdcg_([0-9.]+)\.txt", f)[1]
    vals = [float(m[1]) for m in re.finditer(r"pdcg\s+(\S+)", open(f).read())]
    runs[h] = np.array([0.0] + vals)
fig, ax = plt.subplots(1, 2, figsize=(10, 4))
ax[0].plot(d, fem, "k-", lw=2, label="FEM (P2, extrapolated)")
for h, r in runs.items():
    ax[0].plot(d[: len(r)], r, "o--", ms=3, label=f"pdcg BA, Δx = {h}")
    ax[1].plot(d[1 : len(r)], 100 * (r[1:] - fem[1 : len(r)]) / fem[1 : len(r)], "o-", ms=3, label=f"Δx = {h}")
ax[0].set_xlabel("d"); ax[0].set_ylabel("reaction R_x"); ax[0].legend()
ax[1].axhline(2, color="r", ls=":"); ax[1].axhline(-2, color="r", ls=":", label="±2% (acceptance)")
ax[1].set_xlabel("d"); ax[1].set_ylabel("pdcg − FEM [%]"); ax[1].legend()
fig.suptitle("Plate with a hole, plane strain Neo-Hookean μ = 1, K = 10")
fig.tight_layout()
fig.savefig(f"{out}/plate_hole_validation.png", dpi=110)
with open(f"{out}/plate_hole_table.md", "w") as t:
    hs = list(runs)
    t.write("| d | FEM | " + " | ".join(f"pdcg Δx={h} (rel.)" for h in hs) + " |\n")
    t.write("|---|---|" + "---|" * len(hs) + "\n")
    for k in range(1, len(d)):
        t.write(f"| {d[k]:.2f} | {fem[k]:.6f} | " + " | ".join(
            f"{runs[h][k]:.6f} ({100*(runs[h][k]-fem[k])/fem[k]:+.2f}%)" if k < len(runs[h]) else "—" for h in hs) + " |\n")
print(f"wrote {out}/plate_hole_validation.png and plate_hole_table.md")
