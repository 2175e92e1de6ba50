#!/usr/bin/python3
"""CSV table of every analysed run under DIR (the analysis.json files written by analyze.py).

Usage: collect.py DIR > summary.csv
"""
import glob
import json
import os
import sys

COLS = ["run", "atoms", "W", "a", "a_over_W", "rate", "T", "peak_stress", "critical_strain",
        "init_strain", "init_stress", "speed", "speed_over_cR", "on_plane", "path_on_plane",
        "path_max_offset_rows", "path_on_plane_all", "defects_running", "defects_end", "sigma_sqrt_a", "sigma_griffith",
        "peak_over_griffith", "sigma_G_statics", "eps_G_statics", "peak_over_G_statics",
        "strain_over_G_statics", "wall_seconds"]


def main():
    rows = []
    for p in sorted(glob.glob(os.path.join(sys.argv[1], "*", "analysis.json"))):
        r = json.load(open(p))
        r["run"] = os.path.basename(os.path.dirname(p))
        meta = open(os.path.join(os.path.dirname(p), "meta.txt")).read().split()
        if "wall_seconds" in meta:
            r["wall_seconds"] = int(meta[meta.index("wall_seconds") + 1])
        rows.append(r)
    rows.sort(key=lambda r: (r["atoms"], r["a"], -r["rate"]))
    print(",".join(COLS))
    for r in rows:
        print(",".join(("%.5g" % r[c]) if isinstance(r.get(c), float) else str(r.get(c, ""))
                       for c in COLS))


if __name__ == "__main__":
    main()
