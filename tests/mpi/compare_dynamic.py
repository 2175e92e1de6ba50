#!/usr/bin/python3
"""Compares two explicit-dynamics output directories of `pdcg run`: series.csv and the fields of
every results file. usage: compare_dynamic.py REF_DIR RUN_DIR TOLERANCE

series.csv: the same rows (steps) and times; the broken-bond count of every sampled step equal
(an integer: no tolerance); the energies (kinetic, internal, total, total_verlet) relative to the
largest total energy of the reference run; each reaction column relative to the largest reaction
of any column. Fields, at every output step: displacement and velocity relative to their maximum;
the damage (broken fraction of each point's family) equal at every point. Prints the worst
relative differences; exit 1 if one exceeds TOLERANCE, a count differs or the shapes differ.
"""
import csv
import pathlib
import sys

import h5py
import numpy as np

ENERGIES = ("kinetic", "internal", "total", "total_verlet")


def series(d):
    rows = [r for r in csv.reader(l for l in open(d / "series.csv") if not l.startswith("#"))]
    return rows[0], np.array([[float(x) for x in r] for r in rows[1:]])


def main():
    ref, run, tol = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]), float(sys.argv[3])
    worst, bad = 0.0, []

    def check(name, rel):
        nonlocal worst
        print(f"{name}: {rel:.3e}")
        worst = max(worst, rel)
        if not rel <= tol:
            bad.append(name)

    h1, s1 = series(ref)
    h2, s2 = series(run)
    if h1 != h2 or s1.shape != s2.shape:
        print(f"series.csv: columns or rows differ: {h1} {s1.shape} vs {h2} {s2.shape}")
        return 1
    col = {name: j for j, name in enumerate(h1)}
    if not np.array_equal(s1[:, col["step"]], s2[:, col["step"]]):
        print("series.csv: the sampled steps differ")
        return 1
    check("time", np.max(np.abs(s1[:, col["t"]] - s2[:, col["t"]])) / np.max(s1[:, col["t"]]))
    if "broken_bonds" in col:
        b1, b2 = s1[:, col["broken_bonds"]], s2[:, col["broken_bonds"]]
        print(f"broken bonds at the end: {int(b1[-1])} (reference), {int(b2[-1])}")
        if not np.array_equal(b1, b2):
            first = int(np.argmax(b1 != b2))
            print(f"FAIL: broken-bond counts differ from step {int(s1[first, 0])} on")
            bad.append("broken_bonds")
    scale = np.max(np.abs(s1[:, col["total"]]))
    for name in ENERGIES:
        check(f"energy {name} / max |total|",
              np.max(np.abs(s1[:, col[name]] - s2[:, col[name]])) / scale)
    reactions = [j for name, j in col.items() if "_f" in name]
    if reactions:
        load = np.max(np.abs(s1[:, reactions]))
        check("reactions / max |reaction|",
              np.max(np.abs(s1[:, reactions] - s2[:, reactions])) / load)
    files = sorted(p.name for p in ref.glob("results_*.h5"))
    if files != sorted(p.name for p in run.glob("results_*.h5")):
        print("results files differ")
        return 1
    for field in ("displacement", "velocity"):
        rel = 0.0
        for name in files:
            with h5py.File(ref / name) as a, h5py.File(run / name) as b:
                x, y = a["fields/" + field][...], b["fields/" + field][...]
                if x.shape != y.shape:
                    print(f"{name} {field}: shapes differ {x.shape} {y.shape}")
                    return 1
                m = np.max(np.abs(x))
                if m > 0:
                    rel = max(rel, np.max(np.abs(x - y)) / m)
        check(f"{field}, {len(files)} output steps, max |Δ| / max |ref|", rel)
    for name in files:
        with h5py.File(ref / name) as a, h5py.File(run / name) as b:
            if "fields/damage" in a and not np.array_equal(a["fields/damage"][...],
                                                          b["fields/damage"][...]):
                print(f"FAIL: {name}: the damage fields differ")
                bad.append("damage " + name)
    print(f"worst {worst:.3e}, tolerance {tol:.1e}: {'FAIL ' + ', '.join(bad) if bad else 'ok'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
