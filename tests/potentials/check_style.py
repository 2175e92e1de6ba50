#!/usr/bin/env python3
"""One potential-style test file (tests/potentials/*.yaml) against pdcg, as a user runs pdcg:
the file's LAMMPS data and commands through `pdcg atoms2pd`, `pdcg forces` and
`pdcg energy --stress`, compared with the LAMMPS reference stored in the file
(tests/potentials/generate.py wrote it with LAMMPS; nothing of pdcg made it):

  forces            max |f_pdcg − f_LAMMPS| / max |f_LAMMPS|, by atom id
  per-atom energy   max |ψ_k − pe/atom_k| / max |pe/atom|
  energy            |U_pdcg − U_LAMMPS| / |U_LAMMPS|
  virial            the symmetric part of −P·V₀ (P = ∂W/∂F at F = I, energy per reference
                    volume) against LAMMPS's virial Σ r_i f_j (energy units), relative to its
                    largest component

each within the file's `epsilon` (its reason is in the file). Usage:
    check_style.py PDCG FILE.yaml
Exit 0 when every check holds, 1 otherwise (the numbers are printed either way)."""
import csv
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import yaml


def run(cmd, cwd):
    res = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {res.returncode}:\n{res.stderr}{res.stdout}")
    return res.stdout


def main(pdcg, path):
    with open(path) as fh:
        case = yaml.safe_load(fh)
    ref = case["reference"]
    eps = float(case["epsilon"])
    name = os.path.basename(path)
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "atoms.data"), "w") as fh:
            fh.write(case["data"])
        with open(os.path.join(tmp, "commands.in"), "w") as fh:
            fh.write(case["commands"])
        run([pdcg, "-q", "atoms2pd", "--input", "atoms.data", "--potential", "commands.in",
             "-o", "body.h5"], tmp)
        run([pdcg, "-q", "forces", "body.h5", "-o", "forces.csv"], tmp)
        out = run([pdcg, "-q", "energy", "body.h5", "--F", "1 0 0 0 1 0 0 0 1", "--json",
                   "--stress"], tmp)
        with open(os.path.join(tmp, "forces.csv")) as fh:
            rows = list(csv.DictReader(line for line in fh if not line.startswith("#")))
    energy = json.loads(out[out.index("{"):out.rindex("}") + 1])
    got = {int(r["id"]): [float(r[k]) for k in ("fx", "fy", "fz", "pe")] for r in rows}
    ids = [int(f[0]) for f in ref["forces"]]
    failures = []

    def check(what, err, tol):
        ok = err <= tol
        print(f"{'ok  ' if ok else 'FAIL'} {name}: {what} relative error {err:.2e} (epsilon {tol:g})")
        if not ok:
            failures.append(what)

    if sorted(got) != sorted(ids) or len(ids) != ref["natoms"]:
        sys.exit(f"FAIL {name}: pdcg wrote {len(got)} atoms, LAMMPS has {ref['natoms']}")
    f_ref = np.array([f[1:] for f in ref["forces"]])
    f_got = np.array([got[i][:3] for i in ids])
    check("forces", np.abs(f_got - f_ref).max() / np.abs(f_ref).max(), eps)
    e_ref = np.array([e[1] for e in ref["per_atom_energy"]])
    e_got = np.array([got[int(e[0])][3] for e in ref["per_atom_energy"]])
    check("per-atom energies", np.abs(e_got - e_ref).max() / np.abs(e_ref).max(), eps)
    check("energy", abs(energy["energy"] - ref["energy"]) / abs(ref["energy"]), eps)
    P = np.array(energy["stress"]).reshape(3, 3)
    W = -0.5 * (P + P.T) * energy["volume"]  # minus the work conjugate: the virial
    w_got = np.array([W[0, 0], W[1, 1], W[2, 2], W[0, 1], W[0, 2], W[1, 2]])
    w_ref = np.array(ref["virial"])
    check("virial", np.abs(w_got - w_ref).max() / np.abs(w_ref).max(), eps)
    return 1 if failures else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))
