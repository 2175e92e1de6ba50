#!/usr/bin/env python3
"""pdcg from Python, for LAMMPS users (docs/python.md): copy this file and change the crystal.

1. LAMMPS (its own Python module) builds an fcc Cu crystal with the EAM potential Cu_u3.eam
   and relaxes it (positions and box: fix box/relax + minimize);
2. pdcg.from_lammps turns the live instance into a peridynamic body whose forces are LAMMPS's
   (checked against `run 0`);
3. the body is homogenised onto a grid (kernel wendland-c2) and rescaled (ε = 2);
4. the Cauchy–Born elastic constants and the dispersion along G-X-W-K-G-L are computed, the
   curves of the atomic and the homogenised body plotted (matplotlib, Agg: no display);
5. a bond-associated correspondence scene, given as a Python dict, is run with the body's
   Cauchy–Born material (docs/solver.md): a plate pulled at one end.

    PYTHONPATH=build/python /usr/bin/python3 workflows/python/example.py --output out/python
"""
import argparse
import os
import sys

import numpy as np

import pdcg
from lammps import lammps

POTENTIAL = ["units metal", "pair_style eam", "pair_coeff * * Cu_u3.eam"]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--output", default="pdcg-python-example", help="output directory")
    ap.add_argument("--cells", type=int, default=4, help="fcc cells per edge (default 4)")
    args = ap.parse_args()
    os.makedirs(args.output, exist_ok=True)

    # 1. LAMMPS builds and relaxes the crystal
    lmp = lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    n = args.cells
    lmp.commands_string(f"""
units metal
atom_style atomic
boundary p p p
lattice fcc 3.6
region box block 0 {n} 0 {n} 0 {n}
create_box 1 box
create_atoms 1 region box
{POTENTIAL[1]}
{POTENTIAL[2]}
fix relax all box/relax iso 0.0
minimize 0 1e-10 1000 10000
unfix relax
""")
    a = lmp.extract_box()[1][0] / n
    print(f"LAMMPS: {lmp.get_natoms()} atoms, relaxed lattice constant a = {a:.6f} Angstrom")

    # 2. the peridynamic body of the live instance: its forces are LAMMPS's (checked)
    body = pdcg.from_lammps(lmp, commands=POTENTIAL)
    print(body)
    print(f"  energy {body.energy():.8f} eV, max |f| = {np.abs(body.forces()).max():.2e} eV/A")

    # 3. homogenise (docs/theory.md §3) and rescale (§4)
    hom = pdcg.homogenize(body, kernel="wendland-c2", width=2.0 * a, spacing=a)
    coarse = pdcg.rescale(hom, factor=2.0)
    print(hom)
    print(coarse)
    print(f"  mass conserved: {hom.point_masses.sum():.10f} = {body.masses.sum():.10f} amu")

    # 4. elastic constants (Cauchy–Born, docs/elastic.md) and dispersion (docs/theory.md §5)
    el = pdcg.elastic(body)
    C = el.C_GPa
    print(f"  C11 = {C[0, 0]:.1f} GPa, C12 = {C[0, 1]:.1f} GPa, C44 = {C[3, 3]:.1f} GPa "
          f"(bulk modulus {el.bulk_voigt * el.to_GPa:.1f} GPa)")
    path = "G-X-W-K-G-L"
    d_atoms = pdcg.dispersion(body, path=path, nk=20)
    d_hom = pdcg.dispersion(hom, path=path, nk=20, lattice="fcc", a=a)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    d_atoms.plot(ax=ax, title=f"Cu (EAM), a = {a:.4f} A: atoms (blue), homogenised (orange)")
    ax.plot(d_hom.kappa, d_hom.omega, "--", color="C1")
    png = os.path.join(args.output, "dispersion.png")
    fig.savefig(png, dpi=120, bbox_inches="tight")
    print(f"  dispersion along {path}: {d_atoms.omega.shape[0]} points, "
          f"max omega {d_atoms.omega.max():.2f} {d_atoms.omega_unit} -> {png}")

    # 5. a BA correspondence scene as a dict, with the body's Cauchy–Born material
    model = os.path.join(args.output, "cu.h5")
    body.write(model)
    L = 10 * a
    scene = {
        "units": "metal",
        "dimension": 3,
        "geometry": {"shape": "box", "origin": [0.0, 0.0, 0.0], "size": [L, L / 2, L / 2],
                     "spacing": L / 10},
        "horizon": {"factor": 3.015},
        "material": {"model": "cauchy-born", "file": model},
        "boundary": [
            {"name": "left", "region": {"x_max": 0.0},
             "displacement": {"x": 0.0, "y": 0.0, "z": 0.0}},
            {"name": "right", "region": {"x_min": L}, "displacement": {"x": f"{0.02 * L}*t"}},
        ],
        "loading": {"steps": 2},
        "solver": {"type": "newton", "tolerance": 1.0e-8, "linear": "umfpack"},
        "output": {"directory": os.path.join(args.output, "plate"), "every": 1},
    }
    steps = []
    result = pdcg.run(scene, progress=lambda label, done, total: steps.append(done))
    r = result.reactions
    print(f"  scene: {len(result.steps())} output steps in {result.directory}; reaction at "
          f"2% strain: right_fx = {r['right_fx'][-1]:.6g} eV/A (progress calls: {len(steps)})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
