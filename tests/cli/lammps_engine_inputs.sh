#!/usr/bin/env bash
# Embedded LAMMPS from the command line, with decks a user writes:
# 1. a NaCl-like rocksalt in atom_style charge with lj/cut/coul/cut (charges from the data
#    file) through `pdcg atoms2pd` + `pdcg forces`, against the forces `lmp` writes;
# 2. LAMMPS errors (truncated tersoff/mod file, element missing from the file, misspelled
#    style, k-space electrostatics, a charge style without charges) as pdcg input errors:
#    exit code 2 and a message with the commands file, its line and LAMMPS's own words.
# Usage: lammps_engine_inputs.sh PDCG
set -euo pipefail
pdcg=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"
export LAMMPS_POTENTIALS=${LAMMPS_POTENTIALS:-/usr/share/lammps/potentials}

cat > in.nacl <<'LMP'
units metal
atom_style charge
boundary p p p
lattice custom 5.64 a1 1 0 0 a2 0 1 0 a3 0 0 1 basis 0 0 0 basis 0.5 0.5 0 &
  basis 0.5 0 0.5 basis 0 0.5 0.5 basis 0.5 0 0 basis 0 0.5 0 basis 0 0 0.5 basis 0.5 0.5 0.5
region b block 0 2 0 2 0 2
create_box 2 b
create_atoms 1 region b basis 1 1 basis 2 1 basis 3 1 basis 4 1 basis 5 2 basis 6 2 &
  basis 7 2 basis 8 2
mass 1 22.99
mass 2 35.45
set type 1 charge 1.0
set type 2 charge -1.0
pair_style lj/cut/coul/cut 5.0
pair_coeff 1 1 0.1 2.5
pair_coeff 2 2 0.1 4.0
pair_coeff 1 2 0.1 3.2
displace_atoms all random 0.05 0.05 0.05 42 units box
write_data nacl.data
dump d all custom 1 nacl.dump id type x y z fx fy fz
dump_modify d format float %.17g
run 0
LMP
cat > nacl.pot <<'POT'
units metal
atom_style charge
pair_style lj/cut/coul/cut 5.0
pair_coeff 1 1 0.1 2.5
pair_coeff 2 2 0.1 4.0
pair_coeff 1 2 0.1 3.2
POT
lmp -in in.nacl -log none -screen none
"$pdcg" atoms2pd --input nacl.data --potential nacl.pot -o nacl.h5
"$pdcg" forces nacl.h5 -o f.csv
python3 - <<'PY'
lines = open("nacl.dump").read().split("\n")
i = lines.index("ITEM: ATOMS id type x y z fx fy fz")
ref = {int(l.split()[0]): [float(v) for v in l.split()[5:8]] for l in lines[i + 1:] if l.strip()}
got = {}
# '#' lines (the units line) are comments; then the header id,fx,fy,fz,pe
for l in [l for l in open("f.csv").read().split("\n") if not l.startswith("#")][1:]:
    if l.strip():
        w = l.split(",")
        got[int(w[0])] = [float(v) for v in w[1:4]]
assert sorted(got) == sorted(ref), "atom ids differ"
scale = max(abs(v) for f in ref.values() for v in f)
err = max(abs(a - b) for k in ref for a, b in zip(got[k], ref[k])) / scale
print(f"rocksalt lj/cut/coul/cut body forces vs lmp: max-norm relative error {err:.3g}")
# pairwise style: LAMMPS's analytic dimer forces, summation-order round-off (measured 3.6e-14;
# the central differences used before gave 8.7e-9)
assert err < 1e-12, err
assert scale > 0.1, "perturbed configuration must have nonzero forces"
PY

# A Si configuration for the error cases.
printf 'units metal\nlattice diamond 5.431\nregion b block 0 2 0 2 0 2\ncreate_box 1 b\ncreate_atoms 1 region b\nmass 1 28.0855\nwrite_data si.data\n' > in.si
lmp -in in.si -log none -screen none

# expect_error NAME POTFILE PATTERN...: atoms2pd exits 2 and stderr holds every pattern
expect_error() {
  local name=$1 pot=$2
  shift 2
  set +e
  "$pdcg" atoms2pd --input si.data --potential "$pot" -o "$name.h5" 2> "$name.err"
  local rc=$?
  set -e
  echo "$name: exit $rc: $(tail -n 3 "$name.err" | tr '\n' ' ')"
  [[ $rc -eq 2 ]] || { echo "FAIL $name: exit code $rc, expected 2"; cat "$name.err"; exit 1; }
  for p in "$@"; do
    grep -qF -- "$p" "$name.err" || { echo "FAIL $name: no '$p' in stderr"; cat "$name.err"; exit 1; }
  done
  [[ ! -e "$name.h5" ]] || { echo "FAIL $name: output written"; exit 1; }
}

head -n 25 "$LAMMPS_POTENTIALS/Si.tersoff.mod" > cut.tersoff.mod  # Si entry cut after 7 values
printf 'units metal\nmass 1 28.0855\npair_style tersoff/mod\npair_coeff * * cut.tersoff.mod Si\n' > trunc.pot
expect_error truncated trunc.pot "trunc.pot:4" "Incorrect format in tersoff/mod potential file"

printf 'units metal\nmass 1 28.0855\npair_style tersoff/mod\npair_coeff * * Si.tersoff.mod Ge\n' > element.pot
expect_error element element.pot "element.pot:4" "missing an entry"

printf 'units metal\nmass 1 28.0855\npair_style tersof/mod\npair_coeff * * Si.tersoff.mod Si\n' > typo.pot
expect_error typo typo.pot "typo.pot:3" "tersof/mod"

printf 'units metal\natom_style charge\npair_style lj/cut/coul/long 5.0\npair_coeff * * 0.01 2.0\nkspace_style ewald 1e-6\n' > long.pot
expect_error kspace long.pot "long.pot:5" "kspace_style"

printf 'units metal\npair_style buck/coul/cut 6.0\npair_coeff * * 1000.0 0.3 10.0\n' > noq.pot
expect_error noq noq.pot "noq.pot:2" "atom attribute q"
echo "all engine input cases behave"
