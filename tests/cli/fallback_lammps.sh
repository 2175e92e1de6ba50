#!/usr/bin/env bash
# `pdcg atoms2pd` + `pdcg forces` on a Si tersoff/mod configuration (a pair style with no
# native implementation: force states through embedded LAMMPS) against the forces the `lmp`
# binary writes for the same atoms.
# Usage: fallback_lammps.sh PDCG
set -euo pipefail
pdcg=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"
cat > in.si <<'LMP'
units metal
boundary p p p
lattice diamond 5.431
region b block 0 2 0 2 0 2
create_box 1 b
create_atoms 1 region b
mass 1 28.0855
pair_style tersoff/mod
pair_coeff * * Si.tersoff.mod Si
displace_atoms all random 0.1 0.1 0.1 42
dump d all custom 1 si.dump id type x y z fx fy fz
dump_modify d format float %.17g
run 0
LMP
printf 'units metal\nmass 1 28.0855\npair_style tersoff/mod\npair_coeff * * Si.tersoff.mod Si\n' > si.pot
LAMMPS_POTENTIALS=${LAMMPS_POTENTIALS:-/usr/share/lammps/potentials} lmp -in in.si -log none -screen none
"$pdcg" atoms2pd --input si.dump --potential si.pot -o si.h5
"$pdcg" forces si.h5 -o f.csv
python3 - <<'PY'
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
print(f"tersoff/mod body forces vs lmp: max-norm relative error {err:.3g}")
# central differences of LAMMPS energies (h = 1e-5 x mean bond): ~1e-8; 1e-7 leaves margin
assert err < 1e-7, err
assert scale > 0.1, "perturbed configuration must have nonzero forces"
PY
