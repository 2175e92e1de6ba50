#!/usr/bin/env python3
"""Post-process the MD fracture run of in.fracture.

Usage: md_fracture.py <out-dir> [wall-seconds]
Reads <out-dir>/md_meta.txt, md_stress_strain.txt (strain, nominal stress) and <out-dir>/md_fracture.dump;
writes <out-dir>/md_fracture.json with the peak nominal stress, the critical strain (strain at
the peak), the stress after rupture, the simulated time and the run size, and
<out-dir>/md_fracture.png (the sheet at the peak and at the end).
"""
import json
import os
import sys

import numpy as np

out = sys.argv[1]
wall = float(sys.argv[2]) if len(sys.argv) > 2 else None
path = os.path.join(out, "md_stress_strain.txt")
meta = dict(kv.split("=") for kv in open(os.path.join(out, "md_meta.txt")).read().split())
rate, dt = float(meta["rate"]), float(meta["dt"])
d = np.loadtxt(path)
strain, stress = d[:, 0], d[:, 1]
# The grip force fluctuates thermally and with elastic waves (a few % of the peak); the peak is
# taken on a running mean over 5 samples (500 steps = 2.5 τ, 0.25 % strain at rate 1e-3).
k = 5
smooth = np.convolve(stress, np.ones(k) / k, mode="same")
i = int(np.argmax(smooth[k:-k])) + k
res = {
    "atoms": int(meta["atoms"]),
    "a0": float(meta["a0"]),
    "width": float(meta["W"]),
    "grip_distance": float(meta["L0"]),
    "strain_rate": rate,
    "timestep": dt,
    "peak_stress": float(smooth[i]),
    "peak_stress_raw": float(stress.max()),
    "critical_strain": float(strain[i]),
    "final_strain": float(strain[-1]),
    "final_stress": float(smooth[-k - 1]),
    "steps": int(round(strain[-1] / (rate * dt))),
    "simulated_time": float(strain[-1] / rate),
    "wall_seconds": wall,
}
json.dump(res, open(os.path.join(out, "md_fracture.json"), "w"), indent=1)

try:  # snapshots (optional: needs matplotlib)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lines = open(os.path.join(out, "md_fracture.dump")).read().splitlines()
    starts = [j for j, l in enumerate(lines) if l.startswith("ITEM: ATOMS")]
    steps = [int(lines[j - 7]) for j in starts]
    want = [int(round(res["critical_strain"] / res["final_strain"] * (len(starts) - 1))), len(starts) - 1]
    fig, axes = plt.subplots(1, 2, figsize=(9, 4.4))
    for ax, f in zip(axes, want):
        n = int(lines[starts[f] - 5])
        xy = np.array([[float(v) for v in l.split()[2:4]] for l in lines[starts[f] + 1:starts[f] + 1 + n]])
        ax.plot(xy[:, 0], xy[:, 1], ".", ms=1.5, color="k")
        ax.set_aspect("equal")
        ax.set_title(f"MD, strain {steps[f] * dt * rate:.3f}")
        ax.set_xlabel("x (σ)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "md_fracture.png"), dpi=110)
except ImportError:
    pass
print(json.dumps(res))
