#!/usr/bin/python3
"""One row of crack snapshots from several runs (docs/img/brittle_md.png).

Usage: figure.py OUT.png RUN_DIR:FRACTION[:TITLE] ...
  FRACTION  which frame: the first whose crack tip has run this fraction of the ligament W - a
            (1 = the last frame)
Atoms with fewer than 6 neighbours within rb in red, more in blue (dislocation cores show as
red/blue pairs), the rest grey.
"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from analyze import read_meta  # noqa: E402
from dumpio import frames  # noqa: E402

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    out, specs = sys.argv[1], sys.argv[2:]
    fig, axs = plt.subplots(1, len(specs), figsize=(3.2 * len(specs), 3.6))
    axs = np.atleast_1d(axs)
    for ax, spec in zip(axs, specs):
        parts = spec.split(":")
        run, q = parts[0], float(parts[1])
        meta = read_meta(os.path.join(run, "meta.txt"))
        s = np.loadtxt(os.path.join(run, "series.txt"), ndmin=2)
        tipof = dict(zip(s[:, 0].astype(int), s[:, 3]))
        a, W, n = meta["a"], meta["W"], int(meta["atoms"])
        fr = [(st, d) for st, d in frames(os.path.join(run, "frames.dump"))
              if np.count_nonzero(d[:, 4] < 6) < 0.2 * n]
        pick = fr[-1]
        if q < 1:
            for st, d in fr:
                if tipof.get(int(st), -1) >= a + q * (W - a):
                    pick = (st, d)
                    break
        st, d = pick
        c = d[:, 4]
        col = np.where(c < 6, "r", np.where(c > 6, "b", "0.8"))
        ax.scatter(d[:, 2], d[:, 3], s=min(4.0, 40000.0 / n), c=col, lw=0, rasterized=True)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        title = parts[2] if len(parts) > 2 else os.path.basename(os.path.abspath(run))
        ax.set_title(f"{title}\nt = {st * meta['dt']:.0f} τ, strain {st * meta['dt'] * meta['rate']:.4f}",
                     fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    fig.savefig(out, dpi=72)


if __name__ == "__main__":
    main()
