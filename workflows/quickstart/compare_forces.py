#!/usr/bin/env python3
"""Compare pdcg forces (CSV id,fx,fy,fz,pe after a `#` units line) with the forces in a LAMMPS dump (fx fy fz columns)."""
import csv
import json
import sys

pd = {int(r["id"]): (float(r["fx"]), float(r["fy"]), float(r["fz"])) for r in csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith("#"))}  # `#`: units line
lines = open(sys.argv[2]).read().splitlines()
# frame: optional third argument, 0-based, negative from the end (default 0)
frame = int(sys.argv[3]) if len(sys.argv) > 3 else 0
starts = [i for i, l in enumerate(lines) if l.startswith("ITEM: ATOMS")]
start = starts[frame]
cols = lines[start].split()[2:]
md = {}
for l in lines[start + 1:start + 1 + len(pd)]:
    f = dict(zip(cols, l.split()))
    md[int(f["id"])] = (float(f["fx"]), float(f["fy"]), float(f["fz"]))
assert md.keys() == pd.keys(), "atom ids differ"
num = max(abs(a - b) for i in md for a, b in zip(pd[i], md[i]))
den = max(abs(b) for i in md for b in md[i])
net = max(abs(sum(pd[i][c] for i in pd)) for c in range(3))
json.dump({"atoms": len(pd), "max_norm_relative_error": num / den, "max_force": den, "net_force": net},
          sys.stdout, indent=1)
