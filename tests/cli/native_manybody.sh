#!/usr/bin/env bash
# `pdcg atoms2pd` + `pdcg forces` + `pdcg energy` with the native sw and tersoff styles on
# perturbed diamond Si (216 atoms, displacements up to 0.1 Å) against what the `lmp` binary
# writes for the same atoms: forces (dump at %.17g) and the total energy.
# Usage: native_manybody.sh PDCG
set -euo pipefail
pdcg=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"
export LAMMPS_POTENTIALS=${LAMMPS_POTENTIALS:-/usr/share/lammps/potentials}
for style in "sw Si.sw" "tersoff Si.tersoff"; do
  set -- $style
  cat > in.si <<LMP
units metal
boundary p p p
lattice diamond 5.431
region b block 0 3 0 3 0 3
create_box 1 b
create_atoms 1 region b
mass 1 28.0855
pair_style $1
pair_coeff * * $2 Si
displace_atoms all random 0.1 0.1 0.1 4242 units box
thermo_style custom step pe
thermo_modify format float %.17g
dump d all custom 1 si.dump id type x y z fx fy fz
dump_modify d format float %.17g
run 0
LMP
  printf 'units metal\nmass 1 28.0855\npair_style %s\npair_coeff * * %s Si\n' "$1" "$2" > si.pot
  lmp -in in.si -log lmp.log -screen none
  "$pdcg" atoms2pd --input si.dump --potential si.pot -o si.h5
  "$pdcg" forces si.h5 -o f.csv
  "$pdcg" energy si.h5 --F "1 0 0 0 1 0 0 0 1" --json > e.json
  STYLE=$1 python3 - <<'PY'
import json, os
lines = open("si.dump").read().split("\n")
i = lines.index("ITEM: ATOMS id type x y z fx fy fz")
ref = {int(l.split()[0]): [float(v) for v in l.split()[5:8]] for l in lines[i + 1:] if l.strip()}
got = {}
for l in [l for l in open("f.csv").read().split("\n") if not l.startswith("#")][1:]:
    if l.strip():
        w = l.split(",")
        got[int(w[0])] = [float(v) for v in w[1:4]]
assert sorted(got) == sorted(ref), "atom ids differ"
scale = max(abs(v) for f in ref.values() for v in f)
err = max(abs(a - b) for k in ref for a, b in zip(got[k], ref[k])) / scale
log = open("lmp.log").read().split("\n")
k = [n for n, l in enumerate(log) if l.split()[:2] == ["Step", "PotEng"]][0]
pe = float(log[k + 1].split()[1])
e = json.load(open("e.json"))["energy"]
print(f"native {os.environ['STYLE']}: forces vs lmp {err:.3g}, energy {e:.12g} vs {pe:.12g}")
# same formulas, 17-digit I/O: round-off (the task's 1e-10)
assert err < 1e-10, err
assert abs(e - pe) < 1e-10 * abs(pe), (e, pe)
assert scale > 0.1, "perturbed configuration must have nonzero forces"
PY
done
