#!/usr/bin/env python3
"""Plot dispersion CSVs written by `pdcg dispersion`.

usage: plot_dispersion.py OUT.png TITLE CSV[:LABEL] [CSV[:LABEL] ...]   (several curves)
   or: plot_dispersion.py CSV OUT.png TITLE                              (what the CLI calls)
Every column named omega* (not omega_ref*) is drawn against `kappa`; measured CSVs (with a
`power` column) are drawn as points.
"""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    cols = [c for c in rows[0] if c.startswith("omega") and not c.startswith("omega_ref")]
    k = [float(r["kappa"]) for r in rows]
    return k, {c: [float(r[c]) for r in rows] for c in cols}, "power" in rows[0]


def main(argv):
    if argv[0].endswith(".csv"):
        csvs, out, title = [(argv[0], None)], argv[1], argv[2] if len(argv) > 2 else ""
    else:
        out, title = argv[0], argv[1]
        csvs = [(a.split(":", 1)[0], a.split(":", 1)[1] if ":" in a else None) for a in argv[2:]]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    styles = ["-", "--", ":", "-."]
    for i, (path, label) in enumerate(csvs):
        k, cols, measured = read(path)
        for j, (c, w) in enumerate(cols.items()):
            lab = (label or path) if j == 0 else None
            if measured:
                ax.plot(k, w, "o", ms=4, label=lab, color=f"C{i}")
            else:
                ax.plot(k, w, styles[i % 4], lw=1.5, label=lab, color=f"C{i}")
    ax.set_xlabel("κ (1/length)")
    ax.set_ylabel("ω (1/time)")
    ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=120)


if __name__ == "__main__":
    main(sys.argv[1:])
