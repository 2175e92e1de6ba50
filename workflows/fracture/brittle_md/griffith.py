#!/usr/bin/python3
"""Griffith load of the notched sheet of in.fracture, from LAMMPS molecular statics (in.griffith).

At fixed grips the energy release rate is G(a) = -dPi/da, Pi the elastic energy stored at the
grip strain eps (linear: Pi ~ eps^2, G ~ eps^2). A central difference over a +- da (da = 1 lattice
spacing: one column, two nearest-neighbour bonds per column across the plane) gives G(a, eps0) at
eps0 (default 0.002, small enough to be linear); the crack can grow when G = G_c = 2 gamma:

    eps_G = eps0 sqrt(G_c / G(a, eps0)),   sigma_G = sigma(a, eps0) eps_G / eps0

sigma the nominal grip stress of the notched sheet (grip force / W). The lattice softens at
percent strains, so the statics are repeated once at eps_G and eps_G, sigma_G corrected from there
(the correction is reported: sigma_G_linear vs sigma_G). No geometry factor F(a/W) is assumed:
this is Griffith's load of this very sheet (finite width, grips, edge crack), by LAMMPS alone.

Usage: griffith.py SYSDIR --nx NX --ny NY --notch N [N ...] [--eps 0.002]
  SYSDIR is a make_decks.py directory after in.relax and in.surface (a0.txt, gamma.txt).
Writes SYSDIR/griffith_W<nx>.json: {notch: {a, G0, sigma0, eps_G, sigma_G, ...}}; prints a table.
"""
import argparse
import json
import math
import os
import subprocess


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("sysdir")
    ap.add_argument("--nx", type=int, required=True)
    ap.add_argument("--ny", type=int, required=True)
    ap.add_argument("--notch", type=int, nargs="+", required=True)
    ap.add_argument("--eps", type=float, default=0.002)
    o = ap.parse_args()
    d = os.path.abspath(o.sysdir)
    a0 = float(open(os.path.join(d, "a0.txt")).read())
    g = dict(l.split()[:2] for l in open(os.path.join(d, "gamma.txt")) if l.startswith("gamma"))
    Gc = 2 * float(g["gamma_relaxed"])
    work = os.path.join(d, f"griffith_W{o.nx}")
    os.makedirs(work, exist_ok=True)
    for f in ("a0.txt", "potential.mod"):
        if not os.path.exists(os.path.join(work, f)):
            os.symlink(os.path.join(d, f), os.path.join(work, f))

    def statics(notch, eps):
        """Pi and grip stress of each notch in notch - 1, notch, notch + 1 at strain eps."""
        out = os.path.join(work, "griffith.txt")
        if os.path.exists(out):
            os.remove(out)
        for n in (notch - 1, notch, notch + 1):
            subprocess.run(["nice", "-n", "10", "lmp", "-in", os.path.join(d, "in.griffith"),
                            "-var", "out", work, "-var", "nx", str(o.nx), "-var", "ny", str(o.ny),
                            "-var", "notch", str(n), "-var", "eps", repr(eps),
                            "-log", os.path.join(work, f"log.{n}"), "-screen", "none"],
                           check=True, env=dict(os.environ, OMP_NUM_THREADS="1"))
        rows = {}
        for line in open(out):
            w = line.split()
            rows[int(w[0])] = dict(a=float(w[1]), Pi=float(w[4]), sigma=float(w[5]), fnorm=float(w[7]))
        G = -(rows[notch + 1]["Pi"] - rows[notch - 1]["Pi"]) / (rows[notch + 1]["a"] - rows[notch - 1]["a"])
        return rows[notch]["a"], G, rows[notch]["sigma"]

    res = {}
    for n in o.notch:
        a, G0, s0 = statics(n, o.eps)
        e1 = o.eps * math.sqrt(Gc / G0)  # linear elasticity: G ~ eps^2
        r = dict(a=a, G_c=Gc, eps0=o.eps, G0=G0, sigma0=s0, eps_G_linear=e1, sigma_G_linear=s0 * e1 / o.eps)
        # the lattice softens at percent strains: one correction step at eps = eps_G_linear,
        # assuming G ~ eps^2 and sigma ~ eps only across the small remaining change
        _, G1, s1 = statics(n, e1)
        e2 = e1 * math.sqrt(Gc / G1)
        r.update(G1=G1, sigma1=s1, eps_G=e2, sigma_G=s1 * e2 / e1)
        res[n] = r
        print(f"W {o.nx} notch {n} a {a:.4f}: linear G(eps0={o.eps}) = {G0:.6g}, sigma0 = {s0:.6g} -> "
              f"eps_G {e1:.5f}, sigma_G {r['sigma_G_linear']:.5f}; at that strain G = {G1:.5g} G_c = {Gc:.5g}"
              f" -> eps_G {e2:.5f}, sigma_G {r['sigma_G']:.5f}")
    path = os.path.join(d, f"griffith_W{o.nx}.json")
    old = json.load(open(path)) if os.path.exists(path) else {}
    old.update({str(k): v for k, v in res.items()})  # keep the notches computed before
    json.dump(old, open(path, "w"), indent=1)


if __name__ == "__main__":
    main()
