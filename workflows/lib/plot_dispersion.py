#!/usr/bin/env python3
"""Plot dispersion CSVs written by `pdcg dispersion`.

usage: plot_dispersion.py OUT.png TITLE CSV[:LABEL] [CSV[:LABEL] ...]   (several curves)
   or: plot_dispersion.py CSV OUT.png TITLE                              (what the CLI calls)
Every column named omega* (not omega_ref*) is drawn against `kappa`; measured CSVs (with a
`power` column) are drawn as points. A `# path labels: G@0 X@1.157 …` line (pdcg dispersion
--path) puts the labelled points on the κ axis. Leading `#` lines are comments (pdcg's units line,
docs/formats.md); the axis labels take their units from it.
Errors (unreadable CSV, missing or read-only output directory, no matplotlib) give one line on
stderr naming the file and exit status 2 — no traceback.
"""
import csv
import os
import re
import sys


class PlotError(Exception):
    pass


def read(path):
    try:
        with open(path) as f:
            lines = f.read().splitlines()
    except OSError as e:
        raise PlotError(f"{path}: cannot read the CSV: {e.strerror}")
    comments = [l for l in lines if l.startswith("#")]
    rows = list(csv.DictReader([l for l in lines if not l.startswith("#")]))
    if not rows or "kappa" not in rows[0]:
        raise PlotError(f"{path}: not a dispersion CSV (expected a header with kappa and omega… columns)")
    cols = [c for c in rows[0] if c.startswith("omega") and not c.startswith("omega_ref")]
    try:
        k = [float(r["kappa"]) for r in rows]
        data = {c: [float(r[c]) for r in rows] for c in cols}
    except (TypeError, ValueError) as e:
        raise PlotError(f"{path}: bad number in the CSV: {e}")
    units, ticks = {}, []
    for c in comments:
        if c.startswith("# path labels:"):  # "# path labels: G@0 X@1.157 … K|U@7.0": corners
            for t in c.split(":", 1)[1].split():
                label, _, at = t.rpartition("@")
                try:
                    ticks.append((float(at), label.replace("G", "Γ")))
                except ValueError:
                    raise PlotError(f"{path}: bad path label {t!r} (expected LABEL@KAPPA)")
            continue  # "# pdcg dispersion: units metal; kappa, kx, ky, kz [1/Angstrom], omega* [rad/ps] …"
        for names, unit in re.findall(r"([A-Za-z_*, ]+) \[([^\]]+)\]", c):
            for n in names.replace(",", " ").split():
                units[n.rstrip("*")] = unit
    units["ticks"] = ticks
    return k, data, "power" in rows[0], units


def check_output(out):
    d = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(d):
        raise PlotError(f"{out}: the output directory {d} does not exist (create it first)")
    if not os.access(d, os.W_OK):
        raise PlotError(f"{out}: the output directory {d} is not writable")


def main(argv):
    if len(argv) < 2:
        raise PlotError("usage: plot_dispersion.py CSV OUT.png [TITLE]  or  OUT.png TITLE CSV[:LABEL] ...")
    if argv[0].endswith(".csv"):
        csvs, out, title = [(argv[0], None)], argv[1], argv[2] if len(argv) > 2 else ""
    else:
        out, title = argv[0], argv[1]
        csvs = [(a.split(":", 1)[0], a.split(":", 1)[1] if ":" in a else None) for a in argv[2:]]
    check_output(out)
    curves = [(path, label, *read(path)) for path, label in csvs]
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise PlotError("matplotlib is not installed for this python3 (apt-get install python3-matplotlib)")
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    styles = ["-", "--", ":", "-."]
    units = {}
    for i, (path, label, k, cols, measured, u) in enumerate(curves):
        units = units or u
        for j, (c, w) in enumerate(cols.items()):
            lab = (label or path) if j == 0 else None
            if measured:
                ax.plot(k, w, "o", ms=4, label=lab, color=f"C{i}")
            else:
                ax.plot(k, w, styles[i % 4], lw=1.5, label=lab, color=f"C{i}")
    ticks = units.get("ticks") or []
    if ticks:  # a labelled path: corners as ticks, a line at each; κ is the path length
        ax.set_xticks([t for t, _ in ticks], [l for _, l in ticks])
        for t, _ in ticks:
            ax.axvline(t, color="0.7", lw=0.6)
        ax.set_xlim(ticks[0][0], ticks[-1][0])
        ax.set_xlabel(f"path length along the labelled points [{units.get('kappa', '1/length')}]")
    else:
        ax.set_xlabel(f"κ [{units.get('kappa', '1/length')}]")
    ax.set_ylabel(f"ω [{units.get('omega', 'rad/time')}]")
    ax.set_title(title)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    try:
        fig.savefig(out, dpi=120)
    except OSError as e:
        raise PlotError(f"{out}: cannot write the plot: {e.strerror}")


if __name__ == "__main__":
    try:
        main(sys.argv[1:])
    except PlotError as e:
        print(f"plot_dispersion.py: {e}", file=sys.stderr)
        sys.exit(2)
