#!/usr/bin/env bash
# Dumps with any column set, written by LAMMPS (`lmp`) as a user would: one MD run of a perturbed
# fcc LJ crystal dumped with full and partial column sets, a 1D chain (atomistics/chain1d)
# dumped as `id xu vx`, a dump of an empty group and a `dump xyz` file.
#  - what an operation needs is accepted from any column set, and the numbers equal those of
#    the full-column dump of the same run: exactly where the same values are printed (x = xu
#    when no atom crosses a boundary; no id column with `dump_modify sort id`), to a stated
#    tolerance where fractional columns are converted;
#  - the measured dispersion of the chain from `id xu vx` equals that from `id type xu yu zu`
#    exactly, and lies within one frequency bin of the closed form;
#  - what is missing is refused with exit code 2, naming the columns, the file and the line of
#    the frame's ITEM: ATOMS, and the dump command to write instead (never a crash);
#  - zero atoms and xyz files get their own messages.
# Usage: column_sets.sh /path/to/pdcg <source-dir>
set -u
pdcg=$1 src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
fail=0
ok() { echo "ok   $1"; }
bad() { echo "FAIL $1"; fail=1; }

# --- perturbed fcc LJ crystal, 108 atoms, 2 types; frames at steps 0 and 5 -------------------
# The lattice origin (0.25) keeps every atom 0.2 sigma inside the box: no atom crosses a
# boundary in 5 steps at T = 0.05, so x and xu are the same numbers.
cat > fcc.in <<'IN'
units lj
atom_style atomic
boundary p p p
lattice fcc 0.8442 origin 0.25 0.25 0.25
region box block 0 3 0 3 0 3
create_box 2 box
create_atoms 1 box
set type 1 type/fraction 2 0.3 8123
mass * 1.0
displace_atoms all random 0.04 0.04 0.04 5813
pair_style lj/cut 2.5
pair_coeff * * 1.0 1.0
velocity all create 0.05 4928 dist gaussian
fix 1 all nve
timestep 0.002
group none type 3
dump full all custom 5 full.dump id type x y z
dump xu all custom 5 xu.dump id type xu yu zu
dump xs all custom/gz 5 xs.dump.gz id type xs ys zs
dump mixed all custom 5 mixed.dump id type xs yu z
dump notype all custom 5 notype.dump id x y z
dump noid all custom 5 noid.dump type x y z
dump yz all custom 5 yz.dump id type y z
dump onlyx all custom 5 onlyx.dump id type x
dump empty none custom 5 empty.dump id type x y z
dump xyz all xyz 5 fcc.xyz
dump_modify full format float %20.15g sort id
dump_modify xu format float %20.15g sort id
dump_modify xs format float %20.15g sort id
dump_modify mixed format float %20.15g sort id
dump_modify notype format float %20.15g sort id
dump_modify noid format float %20.15g sort id
dump_modify yz format float %20.15g sort id
dump_modify onlyx format float %20.15g sort id
dump_modify empty format float %20.15g sort id
run 5
IN
lmp -in fcc.in -log none -screen none >/dev/null || { echo "FAIL lmp fcc"; exit 1; }
# a tilted box: fractional x mixed with Cartesian y z cannot be converted axis by axis
cat > tri.in <<'IN'
units lj
atom_style atomic
boundary p p p
lattice fcc 0.8442 origin 0.25 0.25 0.25
region box prism 0 3 0 3 0 3 0.5 0 0
create_box 1 box
create_atoms 1 box
mass 1 1.0
pair_style lj/cut 2.5
pair_coeff * * 1.0 1.0
dump tmix all custom 1 tmix.dump id type xs yu zu
dump txs all custom 1 txs.dump id type xs ys zs
dump tx all custom 1 tx.dump id type x y z
dump_modify txs format float %20.15g sort id
dump_modify tx format float %20.15g sort id
run 0
IN
lmp -in tri.in -log none -screen none >/dev/null || { echo "FAIL lmp tri"; exit 1; }
printf 'units lj\npair_style lj/cut 2.5\npair_coeff * * 1.0 1.0\nmass * 1.0\n' > lj.in

# max |a - b| over the force columns of two CSVs (id,fx,fy,fz) with the same ids
maxdiff() {
  /usr/bin/python3 - "$1" "$2" <<'PY'
import csv, sys
a = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith("#"))); b = list(csv.DictReader(l for l in open(sys.argv[2]) if not l.startswith("#")))
assert [r["id"] for r in a] == [r["id"] for r in b] and len(a) == 108, "ids differ"
print(max(abs(float(r[k]) - float(s[k])) for r, s in zip(a, b) for k in ("fx", "fy", "fz")))
PY
}
# Tolerance for fractional columns: xs printed with 15 significant digits and lo + L*xs
# round positions by <= 1e-14 L = 5e-14 sigma; LJ bond stiffness < 1e3 eps/sigma^2 at these
# distances over ~80 family bonds gives force differences < 1e-8 (observed ~1e-12).
tol=1e-8

expect_error() {  # expect_error <name> <regex> <pdcg args...>
  local name=$1 regex=$2; shift 2
  local out code
  out=$("$pdcg" "$@" 2>&1) && code=0 || code=$?
  if [ "$code" = 2 ] && grep -Eq -- "$regex" <<<"$out"; then ok "$name"
  else bad "$name (exit $code): $out"; fi
}

# atoms2pd from each column set that holds positions and types; reference forces of the bodies
for f in full xu xs mixed noid; do
  in=$f.dump; [ "$f" = xs ] && in=xs.dump.gz
  if "$pdcg" -q atoms2pd --input "$in" --frame 0 --potential lj.in -o "b_$f.h5" >/dev/null 2>err.txt \
     && "$pdcg" -q forces "b_$f.h5" -o "f_$f.csv" 2>>err.txt; then ok "atoms2pd + forces from $in"
  else bad "atoms2pd from $in: $(cat err.txt)"; fi
done
for f in xu noid; do
  cmp -s f_full.csv "f_$f.csv" && ok "atoms2pd $f.dump: reference forces equal the full dump's exactly" \
    || bad "atoms2pd $f.dump: forces differ from full.dump"
done
for f in xs mixed; do
  d=$(maxdiff f_full.csv "f_$f.csv" 2>&1)
  if /usr/bin/python3 -c "import sys; sys.exit(0 if float('$d') <= $tol else 1)" 2>/dev/null; then
    ok "atoms2pd $f: reference forces within $tol of the full dump's (max diff $d)"
  else bad "atoms2pd $f: max force difference $d > $tol"; fi
done
# forces at the positions of frame 1 (step 5) of each deformed dump, body from full.dump frame 0
for f in full xu xs mixed notype; do
  in=$f.dump; [ "$f" = xs ] && in=xs.dump.gz
  "$pdcg" -q forces b_full.h5 --deformed "$in" --frame 1 -o "d_$f.csv" 2>err.txt \
    && ok "forces --deformed $in" || bad "forces --deformed $in: $(cat err.txt)"
done
for f in xu notype; do
  cmp -s d_full.csv "d_$f.csv" && ok "forces --deformed $f.dump equals full.dump exactly" \
    || bad "forces --deformed $f.dump differs from full.dump"
done
for f in xs mixed; do
  d=$(maxdiff d_full.csv "d_$f.csv" 2>&1)
  if /usr/bin/python3 -c "import sys; sys.exit(0 if float('$d') <= $tol else 1)" 2>/dev/null; then
    ok "forces --deformed $f: within $tol of full.dump (max diff $d)"
  else bad "forces --deformed $f: max force difference $d > $tol"; fi
done
# the frame's ITEM: ATOMS is line 9 of frame 0 and line 9 + 9 + 108 = 126 of frame 1
fix='dump custom \.\.\. id type x y z|dump 1 all custom 100 traj.dump id type x y z'
expect_error "atoms2pd id type y z: x missing" \
  "yz.dump:9: pdcg atoms2pd needs column x \(or xu, xs, xsu\) that frame 0 \(timestep 0\) does not have: got 'ITEM: ATOMS id type y z'.*$fix" \
  atoms2pd --input yz.dump --frame 0 --potential lj.in -o x.h5
expect_error "atoms2pd id type x: y, z missing" \
  "onlyx.dump:9: pdcg atoms2pd needs columns y \(or yu, ys, ysu\), z \(or zu, zs, zsu\)" \
  atoms2pd --input onlyx.dump --frame 0 --potential lj.in -o x.h5
expect_error "atoms2pd id x y z: type missing" \
  "notype.dump:9: pdcg atoms2pd needs column type that frame 0" \
  atoms2pd --input notype.dump --frame 0 --potential lj.in -o x.h5
expect_error "atoms2pd --frames without id: id missing" \
  "noid.dump:9: pdcg atoms2pd needs column id that frame 0" \
  atoms2pd --input noid.dump --frames 0:1 --density statistical --potential lj.in -o x.h5
expect_error "forces --deformed id type y z: x missing" \
  "yz.dump:126: pdcg forces --deformed needs column x \(or xu, xs, xsu\) that frame 1 \(timestep 5\)" \
  forces b_full.h5 --deformed yz.dump --frame 1 -o x.csv
expect_error "forces --deformed without id: id missing" \
  "noid.dump:126: pdcg forces --deformed needs column id that frame 1" \
  forces b_full.h5 --deformed noid.dump --frame 1 -o x.csv
expect_error "atoms2pd tilted box, xs with yu zu: refused" \
  "tmix.dump:9: frame 0 \(timestep 0\) mixes fractional and other position columns in a tilted box" \
  atoms2pd --input tmix.dump --potential lj.in -o x.h5
"$pdcg" -q atoms2pd --input txs.dump --potential lj.in -o b_txs.h5 >/dev/null && "$pdcg" -q forces b_txs.h5 -o f_txs.csv 2>/dev/null \
  && "$pdcg" -q atoms2pd --input tx.dump --potential lj.in -o b_tx.h5 >/dev/null && "$pdcg" -q forces b_tx.h5 -o f_tx.csv 2>/dev/null \
  || bad "tilted box xs ys zs / x y z"
d=$(maxdiff f_tx.csv f_txs.csv 2>&1)
/usr/bin/python3 -c "import sys; sys.exit(0 if float('$d') <= $tol else 1)" 2>/dev/null \
  && ok "tilted box: xs ys zs within $tol of x y z (max diff $d)" || bad "tilted box xs ys zs: $d"
[ ! -e x.h5 ] && [ ! -e x.csv ] && ok "no output file after a refusal" || bad "output written after a refusal"

# a type far beyond any LAMMPS type count (a corrupt column) is refused, not allocated for
sed '10s/^1 1 /1 2147483647 /' full.dump > bigtype.dump
expect_error "atoms2pd: type 2147483647 refused" \
  "bigtype.dump: type of atom id 1: atom type too large for a dump without a declared type count: got '2147483647'" \
  atoms2pd --input bigtype.dump --frame 0 --potential lj.in -o x.h5
# a data file that declares 10^5 atom types (the type-pair tables would need ~80 GB): refused
printf 'big\n\n2 atoms\n100000 atom types\n0 4 xlo xhi\n0 4 ylo yhi\n0 4 zlo zhi\n\nAtoms # atomic\n\n1 1 0 0 0\n2 1 1.1 0 0\n' > bigtypes.data
expect_error "atoms2pd: 10^5 declared atom types refused" \
  "bigtypes.data: atom types: too many atom types declared: got '100000'" \
  atoms2pd --input bigtypes.data --potential lj.in -o x.h5

# --- zero atoms ------------------------------------------------------------------------------
out=$("$pdcg" inspect empty.dump 2>&1) && code=0 || code=$?
if [ "$code" = 0 ] && grep -Eq "types: +none: frame 0 \(timestep 0\) has zero atoms \(empty.dump:4: ITEM: NUMBER OF ATOMS 0\)" <<<"$out"; then
  ok "inspect: zero atoms named with file and line"
else bad "inspect zero atoms (exit $code): $out"; fi
expect_error "atoms2pd: zero atoms" \
  "empty.dump:4: pdcg atoms2pd needs atoms, but frame 0 \(timestep 0\) has zero atoms" \
  atoms2pd --input empty.dump --frame 0 --potential lj.in -o x.h5

# --- dump xyz ----------------------------------------------------------------------------------
xyzfix='dump 1 all custom N traj.dump id type x y z'
expect_error "inspect xyz: refused by name" "fcc.xyz:1: an xyz file \(dump xyz\) is not read.*$xyzfix" inspect fcc.xyz
expect_error "atoms2pd xyz: refused by name" "fcc.xyz:1: an xyz file \(dump xyz\) is not read" \
  atoms2pd --input fcc.xyz --potential lj.in -o x.h5
expect_error "dispersion xyz: refused by name" "fcc.xyz:1: an xyz file \(dump xyz\) is not read" \
  dispersion --trajectory fcc.xyz --dt 0.002 -o x.csv

# --- 1D chain dumped as `id xu vx` -------------------------------------------------------------
sed -e '/^run /i dump px all custom ${every} ${out}/chain_xu_vx.dump id xu vx\ndump_modify px format float %20.15g sort id\ndump pf all custom ${every} ${out}/chain_full.dump id type xu yu zu\ndump_modify pf format float %20.15g sort id' \
  "$src/atomistics/chain1d/in.chain" > in.chain
grep -q "chain_xu_vx.dump id xu vx" in.chain || bad "could not add the dumps to in.chain"
lmp -in in.chain -var out . -var mu2 0.25 -log none -screen none >/dev/null || { echo "FAIL lmp chain"; exit 1; }
/usr/bin/python3 - > closed.csv <<'PY'
import math
mu2 = 0.25
print("kappa,omega")
for i in range(0, 401):
    k = math.pi * i / 400
    print(f"{k:.17g},{math.sqrt(2*(1-math.cos(k)) + 2*mu2*(1-math.cos(2*k))):.17g}")
PY
"$pdcg" -q dispersion --trajectory chain_full.dump --dt 0.01 -o m_full.csv --compare closed.csv >/dev/null \
  && "$pdcg" -q dispersion --trajectory chain_xu_vx.dump --dt 0.01 -o m_x.csv --compare closed.csv >/dev/null \
  || bad "dispersion of the chain dumps"
cmp -s m_full.csv m_x.csv && ok "chain: dispersion from 'id xu vx' equals 'id type xu yu zu' exactly" \
  || bad "chain: dispersion from 'id xu vx' differs from the full dump"
# closed form: every ridge point within one frequency bin (the transform's resolution)
/usr/bin/python3 - <<'PY' && ok "chain 'id xu vx': ridge within one bin of the closed form" || bad "chain 'id xu vx' vs closed form"
import csv, sys
rows = list(csv.DictReader(l for l in open("m_x.csv") if not l.startswith("#")))
assert len(rows) == 16, len(rows)
worst = max(abs(float(r["error_in_bins"])) for r in rows)
print(f"   worst |error| = {worst:.3f} bins")
sys.exit(0 if worst <= 1.0 else 1)
PY
expect_error "dispersion 'id xu vx' --component y: y missing" \
  "chain_xu_vx.dump:9: pdcg dispersion --trajectory needs column y \(or yu, ys, ysu\) that frame 0 \(timestep 0\) does not have: got 'ITEM: ATOMS id xu vx'" \
  dispersion --trajectory chain_xu_vx.dump --dt 0.01 --component y -o x.csv
expect_error "dispersion 'id xu vx' --axis z: z missing" \
  "chain_xu_vx.dump:9: pdcg dispersion --trajectory needs column z \(or zu, zs, zsu\)" \
  dispersion --trajectory chain_xu_vx.dump --dt 0.01 --axis z -o x.csv

exit $fail
