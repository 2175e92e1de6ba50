#!/usr/bin/env python3
"""Write <dir>/sheet.yaml: the BA-solver scene of the notched coarse LJ sheet (docs/flagship.md).

Usage: sheet_scene.py <dir>    (reads <dir>/a0.txt and <dir>/elastic_res.json; prints JSON)

Geometry = the MD sheet of atomistics/lj_sheet/in.fracture (nx = 40 close-packed columns,
2·ny = 46 rows, edge notch over a quarter of the width at mid-height), on a 16 × 16 grid of
spacing Δ = 2.5 a0, W = 40 a0 (MD: 40 a0), H = 40 a0 (MD: 46·(√3/2)a0 = 39.84 a0). The
material does not depend on Δ (W_ε(F) = W(F)); Δ sets the resolution of the notch and the
run time. Grips: the bottom and top rows of cells, clamped in x,
pulled in y, as the two grip rows of atoms in MD. Material: the Cauchy–Born material of the
homogenised + rescaled model (res.h5). Rupture: a PD bond breaks when its stretch exceeds
λ_c = r_infl / a0, the inflection point of the LJ bond energy (where the bond's axial stiffness
vanishes, docs/elastic.md §5) over the lattice's nearest-neighbour distance.
"""
import json
import math
import os
import sys

d = sys.argv[1]
a0 = float(open(os.path.join(d, "a0.txt")).read())
el = json.load(open(os.path.join(d, "elastic_res.json")))
eps, n = 2, 16
W = H = 40 * a0  # MD: width 40 a0, height 46·(√3/2)·a0 = 39.84 a0
dx = W / n  # 2.5 a0 (the Cauchy–Born material is local: the grid need not be ε·a0)
L0 = H - dx  # distance between the loaded rows of points
r_infl = el["bond_inflection_stretch"] * 2 ** (1 / 6)  # r_min = 2^(1/6) σ, σ = 1 (potential.lj)
lam_c = r_infl / a0
strain_max, steps = 0.084, 24
notch = 0.25 * W
scene = f"""# Flagship: notched coarse triangular LJ sheet pulled to rupture (written by sheet_scene.py).
units: lj
dimension: 2
plane: strain
geometry:
  shape: rectangle
  origin: [0.0, 0.0]
  size: [{W:.12g}, {H:.12g}]
  spacing: {dx:.12g}
  cracks: [{{from: [-1.0, {H / 2:.12g}], to: [{notch:.12g}, {H / 2:.12g}]}}]
horizon: {{factor: 3.015}}
material: {{model: cauchy-born, file: res.h5}}
boundary:
  - {{name: bottom, region: {{y_max: {dx / 2:.12g}}}, displacement: {{x: 0.0, y: 0.0}}}}
  - {{name: top, region: {{y_min: {H - dx / 2:.12g}}}, displacement: {{x: 0.0, y: "{strain_max * L0:.12g}*t"}}}}
loading: {{steps: {steps}}}
solver: {{type: newton, tolerance: 1.0e-8, max_iterations: 30, linear: lu}}
effects: [rupture]
rupture: {{criterion: bond_stretch, critical: {lam_c:.12g}}}
output: {{directory: pd, every: 1}}
"""
open(os.path.join(d, "sheet.yaml"), "w").write(scene)
json.dump({"a0": a0, "epsilon": eps, "spacing": dx, "width": W, "height": H, "grip_distance": L0,
           "notch": notch, "r_infl": r_infl, "critical_stretch": lam_c, "strain_max": strain_max,
           "steps": steps, "points": n * n}, sys.stdout, indent=1)
