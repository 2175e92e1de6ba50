#!/usr/bin/python3
"""Compares two `pdcg run` output directories: reactions.csv and the fields of the last results
file. usage: compare_runs.py REF_DIR RUN_DIR TOLERANCE

Relative differences: per reaction column max |a − b| over the steps divided by the load, the
largest reaction of any column (a reaction that vanishes by symmetry, e.g. the pin's, is
round-off of the load and has no scale of its own); per field
max |a − b| / max |a| over points and components (displacement, deformation gradient, first
Piola–Kirchhoff stress). Prints them; exit 1 if one exceeds TOLERANCE or the shapes differ.
"""
import csv
import pathlib
import sys

import h5py
import numpy as np


def reactions(d):
    rows = [r for r in csv.reader(l for l in open(d / "reactions.csv") if not l.startswith("#"))]
    return rows[0], np.array([[float(x) for x in r] for r in rows[1:]])


def main():
    ref, run, tol = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]), float(sys.argv[3])
    worst, bad = 0.0, []
    h1, r1 = reactions(ref)
    h2, r2 = reactions(run)
    if h1 != h2 or r1.shape != r2.shape:
        print(f"reactions.csv: columns or steps differ: {h1} {r1.shape} vs {h2} {r2.shape}")
        return 1
    load = np.max(np.abs(r1[:, 2:]))
    for j, name in enumerate(h1[2:], start=2):
        rel = np.max(np.abs(r1[:, j] - r2[:, j])) / load
        print(f"reaction {name}: max |Δ| / load = {rel:.3e} (max |ref| {np.max(np.abs(r1[:, j])):.6g})")
        worst = max(worst, rel)
        if not rel <= tol:
            bad.append(name)
    last = sorted(ref.glob("results_*.h5"))[-1].name
    with h5py.File(ref / last) as a, h5py.File(run / last) as b:
        for f in ("displacement", "deformation_gradient", "first_piola_kirchhoff"):
            x, y = a["fields/" + f][...], b["fields/" + f][...]
            if x.shape != y.shape:
                print(f"{last} {f}: shapes differ {x.shape} {y.shape}")
                return 1
            rel = np.max(np.abs(x - y)) / np.max(np.abs(x))
            print(f"{last} {f}: max |Δ| / max |ref| = {rel:.3e}")
            worst = max(worst, rel)
            if not rel <= tol:
                bad.append(f)
    print(f"worst {worst:.3e}, tolerance {tol:.1e}: {'FAIL ' + ', '.join(bad) if bad else 'ok'}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
