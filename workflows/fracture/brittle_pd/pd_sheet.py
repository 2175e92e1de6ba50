#!/usr/bin/python3
"""PD counterpart of the brittle MD sheet (docs/fracture.md §7.6): scene writer and analysis.

  pd_sheet.py scene SYSDIR RUNDIR --n N [--m M] [--notch Q] [--rule brittle|soft] [--rho R]
                    [--strain-max S] [--steps K] [--tip-factor F]
      writes RUNDIR/sheet.yaml and RUNDIR/info.json
  pd_sheet.py analyze RUNDIR [--reference CSV]
      reads RUNDIR/reactions.csv and the results_*.h5 files, writes RUNDIR/analysis.json and
      prints one CSV row (header with --header)

SYSDIR is a make_decks.py directory of lj15 after in.relax and in.surface (a0.txt, gamma.txt)
holding the coarse model res.h5 (run.sh builds it as the flagship pipeline does: perfect
lattice -> delta body -> homogenised -> rescaled by 2; its Cauchy-Born material is the atoms').

Geometry: the MD sheet of in.fracture at nx = 100, ny = 58 (11 600 atoms): width W = 100 a0,
height 2 ny rows of h = (sqrt(3)/2) a0 (116 h = 1.0046 W), crack plane at mid-height, an edge
notch of length a = round(Q nx) a0 from the left edge. PD grid: cell centres, spacing
dx = W / N, round(116 h / dx) rows (even: the notch plane lies between two rows of points), so
the PD sheet is W x (rows dx) (N = 40: 40 rows, 0.45 % shorter than the MD sheet). Horizon
m dx. Grips as in MD, frictionless: the bottom and top rows of points are held / moved in y,
free in x; one point of the bottom row is also held in x (removes the rigid translation; MD has
none to remove at T > 0 because the grips carry no x force). Strain = grip displacement / L0
(L0 = H - dx between the grip rows' centres; MD: 114 h), stress = grip force / W.
Rupture: fracture_energy with G_c = 2 gamma of the close-packed row (gamma.txt, relaxed; the
crack faces of the MD sheet are close-packed rows), brittle (elastic-brittle pairs) or
softening: linear with elastic_limit rho. Nothing is fitted to the MD fracture.
"""
import argparse
import csv
import glob
import json
import math
import os
import sys


def scene(o):
    d = os.path.abspath(o.sysdir)
    a0 = float(open(os.path.join(d, "a0.txt")).read())
    g = dict(l.split()[:2] for l in open(os.path.join(d, "gamma.txt")) if l.startswith("gamma"))
    Gc = 2 * float(g["gamma_relaxed"])
    nx, ny = 100, 58  # the 11 600-atom sheet of the MD series (run.sh -n 100)
    h = math.sqrt(3) / 2 * a0
    W = nx * a0
    H_md = 2 * ny * h
    dx = W / o.n
    rows = 2 * round(H_md / dx / 2)
    H = rows * dx
    L0 = H - dx
    a = round(o.notch * nx) * a0
    smax = o.strain_max
    e1, K = o.strain_start, o.steps
    if e1 > 0:
        # first load step straight to the grip strain e1 (below the first break: the sheet is
        # elastic there and fracture_energy accumulates work as differences of Psi, exact on any
        # path), then K - 1 equal steps to smax: strain(t) = e1 min(1, K t) + (smax - e1)
        # max(0, (K t - 1)/(K - 1)), min and max written with abs()
        ydisp = (f"{e1 * L0:.15g}*(1 + {K}*t - abs(1 - {K}*t))/2 + "
                 f"{(smax - e1) * L0:.15g}*(({K}*t - 1) + abs({K}*t - 1))/(2*{K - 1})")
    else:
        ydisp = f"{smax * L0:.15g}*t"
    # tip calibration (docs/fracture.md §7.6b): the rule gets G_c / f, f the G/G_c at which the
    # uncalibrated rule initiates a sharp pre-crack in the Williams K-field (§5.3); 1 = none
    Grule = Gc / o.tip_factor
    if o.rule == "brittle":
        rule = f"{{criterion: fracture_energy, G_c: {Grule:.15g}}}"
    else:
        rule = (f"{{criterion: fracture_energy, G_c: {Grule:.15g}, softening: linear, "
                f"elastic_limit: {o.rho:g}, damage_tolerance: {o.damage_tolerance:g}, "
                f"max_passes: {o.max_passes}}}")
    text = f"""# PD counterpart of the brittle MD sheet lj15 W = 100 a0 (written by pd_sheet.py; docs/fracture.md §7.6)
units: lj
dimension: 2
plane: strain
geometry:
  shape: rectangle
  origin: [0.0, 0.0]
  size: [{W:.15g}, {H:.15g}]
  spacing: {dx:.15g}
  cracks: [{{from: [-1.0, {H / 2:.15g}], to: [{a:.15g}, {H / 2:.15g}]}}]
horizon: {{factor: {o.m:g}}}
material: {{model: cauchy-born, file: {os.path.join(d, 'res.h5')}}}
boundary:
  - {{name: bottom, region: {{y_max: {dx / 2:.15g}}}, displacement: {{y: 0.0}}}}
  - {{name: pin, region: {{point: [{(o.n // 2 + 0.5) * dx:.15g}, {dx / 2:.15g}]}}, displacement: {{x: 0.0}}}}
  - {{name: top, region: {{y_min: {H - dx / 2:.15g}}}, displacement: {{y: "{ydisp}"}}}}
loading: {{steps: {o.steps}}}
solver: {{type: newton, tolerance: 1.0e-8, max_iterations: 30, linear: lu}}
effects: [rupture]
rupture: {rule}
output: {{directory: pd, every: 1}}
"""
    os.makedirs(o.rundir, exist_ok=True)
    open(os.path.join(o.rundir, "sheet.yaml"), "w").write(text)
    info = dict(a0=a0, G_c=Gc, tip_factor=o.tip_factor, G_c_rule=Grule, W=W, H=H, H_md=H_md, dx=dx, n=o.n, rows=rows, L0=L0, L0_md=(2 * ny - 2) * h,
                a=a, notch_cells=a / dx, m=o.m, delta=o.m * dx, rule=o.rule,
                rho=o.rho if o.rule == "soft" else None,
                damage_tolerance=o.damage_tolerance if o.rule == "soft" else None, strain_max=smax, strain_start=e1, steps=o.steps,
                points=o.n * rows, run=f"W{nx}_a{round(o.notch * nx)}")
    json.dump(info, open(os.path.join(o.rundir, "info.json"), "w"), indent=1)


def crack_path(h5file, info, strain):
    """Per column of points right of the notch: the pair of adjacent rows (j, j+1) with the
    largest opening u_y(j+1) - u_y(j); the crack crosses that column between the two rows if the
    opening exceeds 10 times the mean row-to-row displacement of the sheet at that grip strain
    (strain dx: an open crack, brittle or softened, carries the grip displacement over one row
    pair; an intact column only elastic strain, at most a few times the mean near the tip).
    Offset in rows from the notch plane (between rows rows/2 - 1 and rows/2)."""
    import h5py
    import numpy as np
    with h5py.File(h5file, "r") as f:
        u = np.asarray(f["fields/displacement"])
        x = np.asarray(f["points/reference"])
    n, rows, dx = info["n"], info["rows"], info["dx"]
    if len(x) != n * rows:
        raise SystemExit(f"pd_sheet.py: {h5file}: expected {n * rows} points, found {len(x)}")
    i = np.floor(x[:, 0] / dx).astype(int)
    j = np.floor(x[:, 1] / dx).astype(int)
    U = np.zeros((rows, n))
    U[j, i] = u[:, 1]
    plane = rows // 2 - 1
    first = int(math.ceil(info["a"] / dx - 1e-9))  # first column whose centre is right of the tip
    path = []
    for c in range(first, n):
        jump = U[1:, c] - U[:-1, c]
        k = int(np.argmax(jump))
        path.append(((c + 0.5) * dx, k - plane if jump[k] > 10 * strain * dx else None))
    return path


def analyze(o):
    info = json.load(open(os.path.join(o.rundir, "info.json")))
    rows = [r for r in csv.DictReader(l for l in open(os.path.join(o.rundir, "pd", "reactions.csv"))
                                      if not l.startswith("#"))]
    W, L0, smax = info["W"], info["L0"], info["strain_max"]
    e1, K = info.get("strain_start", 0.0), info["steps"]

    def strain_of(t):  # the schedule of scene()
        return (e1 * min(1.0, K * t) + (smax - e1) * max(0.0, (K * t - 1) / (K - 1))) if e1 > 0 else smax * t
    strain = [strain_of(float(r["t"])) for r in rows]
    stress = [float(r["top_fy"]) / W for r in rows]
    broken = [int(float(r["broken_bonds"])) for r in rows]
    k = max(range(len(rows)), key=lambda i: stress[i])
    broken0 = broken[0] if rows and float(rows[0]["t"]) == 0.0 else 0
    first = next((i for i in range(len(rows)) if broken[i] > broken0), None)
    res = dict(info, steps_done=len(rows), peak_stress=stress[k], critical_strain=strain[k],
               first_break_strain=strain[first] if first is not None else None,
               stress_last=stress[-1], strain_last=strain[-1], broken_last=broken[-1],
               dissipated_last=float(rows[-1].get("dissipated_energy", "nan")))
    # dissipated energy over G_c times the ligament W - a (1: the calibration's straight crack)
    res["dissipated_over_GcL"] = res["dissipated_last"] / (info["G_c"] * (W - info["a"]))
    res["first_break_stress"] = stress[first] if first is not None else None
    # initial slope (nominal stress / strain at the first step)
    k1 = next((i for i in range(len(rows)) if strain[i] > 0), None)
    res["slope0"] = stress[k1] / strain[k1] if k1 is not None and e1 == 0 else None
    tj = os.path.join(o.rundir, "time.json")
    if os.path.exists(tj):
        t = json.load(open(tj))
        res.update(wall_s=t["wall"], cpu_s=t["cpu"])
    files = sorted(glob.glob(os.path.join(o.rundir, "pd", "results_*.h5")))
    if files:
        path = crack_path(files[-1], info, strain[-1])
        cut = [p for p in path if p[1] is not None]
        res["path"] = path
        res["path_columns_cut"] = len(cut) / len(path) if path else 0.0
        res["path_on_plane"] = sum(1 for p in cut if p[1] in (0,)) / len(cut) if cut else None
        res["path_max_offset_rows"] = max(abs(p[1]) for p in cut) if cut else None
    ref = None
    if o.reference:
        for r in csv.DictReader(open(o.reference)):
            if r["run"] == f"{info['run']}_r1e-4":
                ref = r
    if ref:
        sG, eG = float(ref["sigma_G_statics"]), float(ref["eps_G_statics"])
        res.update(md_peak=float(ref["peak_stress"]), md_strain=float(ref["critical_strain"]),
                   sigma_G=sG, eps_G=eG, peak_over_G=res["peak_stress"] / sG,
                   strain_over_G=res["critical_strain"] / eG,
                   pd_over_md_peak=res["peak_stress"] / float(ref["peak_stress"]),
                   pd_over_md_strain=res["critical_strain"] / float(ref["critical_strain"]))
    json.dump(res, open(os.path.join(o.rundir, "analysis.json"), "w"), indent=1)
    cols = ["run", "n", "dx", "m", "delta", "rule", "rho", "points", "peak_stress", "critical_strain",
            "first_break_strain", "first_break_stress", "sigma_G", "peak_over_G", "strain_over_G", "md_peak", "md_strain",
            "pd_over_md_peak", "pd_over_md_strain", "path_columns_cut", "path_on_plane",
            "path_max_offset_rows", "dissipated_over_GcL", "broken_last", "strain_last", "stress_last", "slope0", "wall_s",
            "cpu_s"]
    if o.header:
        print(",".join(cols))

    def fmt(v):
        if v is None:
            return ""
        if isinstance(v, float):
            return f"{v:.5g}"
        return str(v)
    print(",".join(fmt(res.get(c)) for c in cols))


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("scene")
    s.add_argument("sysdir")
    s.add_argument("rundir")
    s.add_argument("--n", type=int, default=40, help="PD points across the width")
    s.add_argument("--m", type=float, default=3.015, help="horizon / spacing")
    s.add_argument("--notch", type=float, default=0.2, help="notch length / width")
    s.add_argument("--rule", choices=("brittle", "soft"), default="brittle")
    s.add_argument("--rho", type=float, default=0.1, help="elastic_limit of the softening law")
    s.add_argument("--damage-tolerance", type=float, default=0.01,
                   help="softening: repeat the staggered pass while a pair's damage grew by more")
    s.add_argument("--max-passes", type=int, default=2000, help="softening: staggered passes per step")
    s.add_argument("--tip-factor", type=float, default=1.0,
                   help="the rule gets G_c / this (tip calibration, docs/fracture.md §7.6b; 1: none)")
    s.add_argument("--strain-max", type=float, default=0.06)
    s.add_argument("--steps", type=int, default=60)
    s.add_argument("--strain-start", type=float, default=0.0,
                   help="first load step straight to this strain (0: uniform steps)")
    a = sub.add_parser("analyze")
    a.add_argument("rundir")
    a.add_argument("--reference", help="reference_lj15.csv of brittle_md")
    a.add_argument("--header", action="store_true")
    o = ap.parse_args()
    scene(o) if o.cmd == "scene" else analyze(o)


if __name__ == "__main__":
    sys.exit(main())
