#!/usr/bin/env bash
# `pdcg surface` against LAMMPS (docs/fracture.md §4): the bulk crystal (one cubic cell) is made
# by `lmp`, pdcg cuts and relaxes the slab; workflows/fracture/surface_lammps.py builds the slab
# in LAMMPS from scratch (oriented lattice, `boundary p p s`, `min_style cg`) with the same
# number of layers, and the surface energies γ must agree: unrelaxed to 1e-10 relative (the same
# atoms: round-off of two sums whose difference is ~5 % of each), relaxed to 1e-8 (both
# minimisers stop at |f| ≤ 1e-10: the energy error is ~|f|²/k ≪ 1e-12). Bad input exits 2.
# Usage: surface_lammps.sh /path/to/pdcg SOURCE_DIR fast|slow
set -u
pdcg=$1
src=$2
mode=${3:-fast}
lmpref=/usr/bin/python3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
fail=0

bulk() {  # name style scale mass pair...
  local name=$1 units=$2 style=$3 scale=$4 mass=$5
  shift 5
  cat > make_$name.in <<IN
units $units
boundary p p p
lattice $style $scale
region box block 0 1 0 1 0 1
create_box 1 box
create_atoms 1 box
mass 1 $mass
write_data $name.data
IN
  lmp -log none -screen none -in make_$name.in || { echo "lmp failed ($name)"; exit 1; }
  printf 'units %s\nboundary p p p\nmass 1 %s\n' "$units" "$mass" > $name.pot
  for l in "$@"; do printf '%s\n' "$l" >> $name.pot; done
  "$pdcg" atoms2pd --input $name.data --potential $name.pot -o $name.h5 > /dev/null || { echo "atoms2pd failed ($name)"; exit 1; }
}

# LJ: a = 1.55 (lj units: `lattice fcc` takes the reduced density 4/a³, as the reference script)
bulk lj lj fcc 1.0741499110469603 1.0 "pair_style lj/cut 2.5" "pair_coeff 1 1 1.0 1.0"
bulk cu metal fcc 3.615 63.546 "pair_style eam" "pair_coeff 1 1 Cu_u3.eam"
[ "$mode" = fast ] || bulk si metal diamond 5.431 28.0855 "pair_style sw" "pair_coeff * * Si.sw Si"
[ "$mode" = fast ] || bulk si-tersoff metal diamond 5.431 28.0855 "pair_style tersoff" "pair_coeff * * Si.tersoff Si"

compare() {  # system plane periods [extra pdcg options]
  local sys=$1 plane=$2 periods=$3
  shift 3
  # timeout: a stalled MPI singleton start of the LAMMPS module fails this case, not the test run
  timeout 240 "$lmpref" "$src/workflows/fracture/surface_lammps.py" --system $sys --plane $plane --periods $periods > ref_${sys}_$plane.json \
    || { echo "FAIL: LAMMPS reference $sys ($plane)"; fail=1; return; }
  local height
  height=$(python3 -c "import json; print(repr(json.load(open('ref_${sys}_$plane.json'))['height']))")
  "$pdcg" surface $sys.h5 --plane $plane --thickness "$height" --json "$@" > pd_${sys}_$plane.json 2> err.txt \
    || { echo "FAIL: pdcg surface $sys ($plane)"; cat err.txt; fail=1; return; }
  python3 - "$sys" "$plane" <<'PY' || fail=1
import json, sys
s, p = sys.argv[1], sys.argv[2]
ref = json.load(open(f"ref_{s}_{p}.json"))
pd = json.load(open(f"pd_{s}_{p}.json"))
ok = pd["cell"]["layers"] == ref["layers"]
u = abs(pd["unrelaxed"]["gamma"] - ref["gamma"]) / abs(ref["gamma"])
r = abs(pd["relaxed"]["gamma"] - ref["gamma_relaxed"]) / abs(ref["gamma_relaxed"])
ok &= u < 1e-10 and r < 1e-8  # reasons in the header
if pd["units"] == "metal":  # eV/Å² → J/m²: 1.602176634e-19 J / 1e-20 m² (LAMMPS's eV: 8 digits)
    ok &= abs(pd["relaxed"]["gamma_J_per_m2"] / pd["relaxed"]["gamma"] / 16.02176634 - 1) < 1e-7
print(f"  {s} ({p}): {pd['cell']['layers']} layers ({ref['layers']} in LAMMPS); gamma unrelaxed "
      f"{pd['unrelaxed']['gamma']:.15g} vs {ref['gamma']:.15g} (rel {u:.1e}); relaxed "
      f"{pd['relaxed']['gamma']:.15g} vs {ref['gamma_relaxed']:.15g} (rel {r:.1e}); "
      f"{pd['unrelaxed']['gamma_J_per_m2'] or '-'} J/m^2 unrelaxed"
      f"{'' if ok else '  <-- FAIL'}")
raise SystemExit(0 if ok else 1)
PY
}

# pdcg's energy of the slab LAMMPS relaxed (Cu (100), boundary p p s): the energies of one
# configuration agree to round-off, so the relaxed-γ difference above is the minimisers' alone
cross_energy() {
  timeout 240 "$lmpref" "$src/workflows/fracture/surface_lammps.py" --system cu --plane 100 --periods 6 \
    --write-data cu_slab_relaxed.data > ref_cross.json || { echo "FAIL: LAMMPS relaxed slab"; fail=1; return; }
  "$pdcg" atoms2pd --input cu_slab_relaxed.data --potential cu.pot --boundary "p p f" -o cu_slab.h5 > /dev/null \
    && "$pdcg" energy cu_slab.h5 --F "1 0 0 0 1 0 0 0 1" --json > pd_cross.json \
    || { echo "FAIL: pdcg energy of the LAMMPS-relaxed slab"; fail=1; return; }
  python3 - <<'PY' || fail=1
import json
ref, pd = json.load(open("ref_cross.json")), json.load(open("pd_cross.json"))
d = abs(pd["energy"] - ref["e_slab_relaxed"]) / abs(ref["e_slab_relaxed"])
print(f"  cu (100) slab relaxed by LAMMPS: pdcg energy {pd['energy']:.15g}, LAMMPS {ref['e_slab_relaxed']:.15g} "
      f"(rel {d:.1e})")
raise SystemExit(0 if d < 1e-12 else 1)  # one configuration, two sums of 96 energies: round-off
PY
}

if [ "$mode" = fast ]; then
  compare lj 111 4
  compare cu 100 6
  cross_energy
  # bad input: exit 2 with the option named
  for args in "--plane 11" "--plane 111 --normal 1,1,1" "--plane 1x1" "--normal 1,0" "--plane 100 --min-style bfgs"; do
    "$pdcg" surface lj.h5 $args > /dev/null 2> err.txt
    rc=$?
    if [ $rc -ne 2 ]; then echo "FAIL: pdcg surface $args exited $rc (expected 2)"; cat err.txt; fail=1; fi
  done
  # an unconverged relaxation is a numerical failure (exit 1), never a γ
  "$pdcg" surface lj.h5 --plane 100 --max-iterations 2 > out.txt 2> err.txt
  rc=$?
  if [ $rc -ne 1 ] || [ -s out.txt ] || ! grep -q "did not converge" err.txt; then
    echo "FAIL: unconverged relaxation: exit $rc (expected 1, no output)"; cat err.txt; fail=1
  fi
  "$pdcg" surface lj.h5 --normal "1 1.4142135623730951 0" > /dev/null 2> err.txt
  grep -q "not a lattice plane" err.txt && grep -q "normal" err.txt || { echo "FAIL: irrational normal not refused"; cat err.txt; fail=1; }
else
  compare lj 100 7
  compare lj 110 10
  compare cu 110 8
  compare cu 111 4
  compare si 100 6
  compare si 111 4
  compare si-tersoff 111 4
  compare cu 111 4 --min-style fire
fi
exit $fail
