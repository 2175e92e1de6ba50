#!/usr/bin/python3
"""Same crack path and load-displacement curve? Compares two runs of the same scene
(docs/effects.md §2, "Free fragments", "Factor reuse"): over the load steps both wrote,
the largest reaction difference relative to the peak reaction of the first run, the
broken-bond counts, and over the output steps both wrote the largest difference of the
damage field (fields/damage) and of the displacement relative to its largest value.

usage: compare_runs.py RUN_A RUN_B
"""
import glob
import os
import sys

import h5py
import numpy as np


def reactions(run):
    rows = [l.strip().split(",") for l in open(os.path.join(run, "reactions.csv"))
            if not l.startswith("#")]
    head, rows = rows[0], [[float(x) for x in r] for r in rows[1:]]
    return head, np.array(rows)


a, b = sys.argv[1], sys.argv[2]
head, ra = reactions(a)
_, rb = reactions(b)
n = min(len(ra), len(rb))
cols = [i for i, h in enumerate(head) if h.endswith(("_fx", "_fy", "_fz"))]
peak = np.abs(ra[:, cols]).max()
dr = np.abs(ra[:n, cols] - rb[:n, cols]).max() / peak
same_broken = bool((ra[:n, -1] == rb[:n, -1]).all())
print(f"load steps compared {n - 1} (of {len(ra) - 1} and {len(rb) - 1}); last t {ra[n - 1, 1]:.4g}; "
      f"max |reaction difference| / peak reaction {dr:.2e}; broken bonds equal at every "
      f"step: {same_broken} (last {int(ra[n - 1, -1])} vs {int(rb[n - 1, -1])})")
dd, du, files = 0.0, 0.0, 0
for fa in sorted(glob.glob(os.path.join(a, "results_*.h5"))):
    fb = os.path.join(b, os.path.basename(fa))
    if not os.path.exists(fb):
        continue
    with h5py.File(fa) as A, h5py.File(fb) as B:
        files += 1
        dd = max(dd, float(np.abs(A["fields/damage"][()] - B["fields/damage"][()]).max()))
        ua, ub = A["fields/displacement"][()], B["fields/displacement"][()]
        du = max(du, float(np.abs(ua - ub).max() / max(np.abs(ua).max(), 1e-300)))
print(f"output steps compared {files}: max |damage difference| {dd:.2e}; "
      f"max |displacement difference| / max |u| {du:.2e}")
