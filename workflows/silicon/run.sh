#!/usr/bin/env bash
# Silicon from atoms to a BA scene (docs/elastic.md §6, "Silicon: atoms to a BA scene"): the
# chain for a crystal with a basis, each stage checked against LAMMPS.
#
#   workflows/silicon/run.sh [OUT=results/silicon]     (~1 min; PDCG=/path/to/pdcg optional)
#
#  1. LAMMPS: diamond Si (Debian's Si.sw) with x = [110], y = [-110], z = [001] (192 atoms),
#     box relaxed to zero stress, written with write_data; a copy with the atoms displaced at
#     random by up to 0.05 Å, dumped with LAMMPS's forces.
#  2. pdcg atoms2pd: the delta bodies; `pdcg forces` of the displaced one vs LAMMPS's forces.
#  3. pdcg elastic: relaxed-ion (default) and clamped-ion constants in the crystal's frame vs
#     LAMMPS (atoms minimised at each strain; ../elastic_relaxed/lammps_elastic.py).
#  4. pdcg dispersion --path auto: the 6 branches (3 acoustic, 3 optical) of the primitive cell;
#     the long-wave speeds along Γ–X (a cubic axis) vs sqrt(C/ρ) of LAMMPS's relaxed-ion C11
#     and C44 (Born: long acoustic waves see the relaxed basis); si_dispersion.png.
#  5. pdcg run block.yaml: a 125-point BA block in uniaxial strain along [110] whose material is
#     the Cauchy–Born W of si.h5, relaxed-ion and clamped-ion: C'11, C'12, C'13 from the
#     reactions vs LAMMPS's.
# Writes summary.txt; exit 1 when a check misses its tolerance (each stated with its reason).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
OUT=${1:-$PDCG_ROOT/results/silicon}
PY=/usr/bin/python3
if [[ -z "${PDCG:-}" ]]; then
  [[ -f "$PDCG_BUILD/CMakeCache.txt" ]] || cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target pdcg >/dev/null
  PDCG=$PDCG_BUILD/pdcg
fi
export LAMMPS_POTENTIALS=${LAMMPS_POTENTIALS:-/usr/share/lammps/potentials}
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
cd "$OUT"
: >summary.txt
say() { echo "$*" | tee -a summary.txt; }

say "== 1. LAMMPS: diamond Si, Si.sw, x = [110], y = [-110], z = [001], box at zero stress"
printf 'units metal\nmass 1 28.0855\npair_style sw\npair_coeff * * Si.sw Si\n' >pot
cat >prep.in <<'IN'
units metal
boundary p p p
lattice diamond 5.431 orient x 1 1 0 orient y -1 1 0 orient z 0 0 1
region b block 0 2 0 2 0 3
create_box 1 b
create_atoms 1 box
mass 1 28.0855
pair_style sw
pair_coeff * * Si.sw Si
fix r all box/relax aniso 0.0 vmax 0.001
min_modify line quadratic
minimize 0 1e-12 20000 200000
unfix r
minimize 0 1e-12 20000 200000
write_data si.data nocoeff
displace_atoms all random 0.05 0.05 0.05 20261202 units box
run 0
write_dump all custom displaced.dump id type x y z fx fy fz modify format float %.17g
IN
lmp -in prep.in -log prep.log -screen none -nocite

say "== 2. delta bodies; forces of the displaced atoms vs LAMMPS"
"$PDCG" -q atoms2pd --input si.data --potential pot -o si.h5
"$PDCG" -q atoms2pd --input displaced.dump --potential pot -o displaced.h5
"$PDCG" -q forces displaced.h5 -o forces.csv
$PY "$HERE/../quickstart/compare_forces.py" forces.csv displaced.dump >forces.json

say "== 3. elastic constants, relaxed-ion and clamped-ion, vs LAMMPS"
"$PDCG" elastic si.h5 --json >relaxed.json 2>relaxed.err
"$PDCG" elastic si.h5 --json --clamped-ion >clamped.json 2>clamped.err
$PY "$HERE/../elastic_relaxed/lammps_elastic.py" si.data pot lammps.json --strain 1e-4 >lammps.txt
fail=0
echo "system,entry,pdcg_relaxed,lammps_relaxed,rel_diff_relaxed,pdcg_clamped,lammps_clamped,rel_diff_clamped,lammps_fd_error,unit" >elastic.csv
$PY "$HERE/../elastic_relaxed/compare.py" si_sw_110 relaxed.json clamped.json lammps.json --csv elastic.csv \
  | tee -a summary.txt || fail=1

say "== 4. dispersion of the primitive cell (6 branches) and the long-wave speeds"
"$PDCG" -q dispersion si.h5 --path auto --nk 400 -o dispersion.csv 2>/dev/null
$PY "$HERE/../lib/plot_dispersion.py" si_dispersion.png \
  "diamond Si (Stillinger–Weber), delta body of the [110]-oriented cell" dispersion.csv:"pdcg" >/dev/null

say "== 5. BA block in uniaxial strain along [110], Cauchy–Born material of si.h5"
cp "$HERE/block.yaml" block.yaml
sed 's/ion_relaxation: relaxed/ion_relaxation: clamped/' block.yaml >block_clamped.yaml
"$PDCG" -q run block.yaml -o block_relaxed >block_relaxed.log 2>&1 || { tail -5 block_relaxed.log; exit 1; }
"$PDCG" -q run block_clamped.yaml -o block_clamped >block_clamped.log 2>&1 || { tail -5 block_clamped.log; exit 1; }

$PY - "$OUT" <<'PY' | tee -a summary.txt || fail=1
import csv, json, math, sys
out = sys.argv[1]
GPA = 160.21766208  # GPa per eV/Å³
EV_PER_AMU = 9648.5332  # (Å/ps)² per eV/amu
ok = True
def check(name, got, ref, tol, why):
    global ok
    rel = abs(got / ref - 1)
    good = rel <= tol
    ok &= good
    print(f"{'ok  ' if good else 'FAIL'} {name}: pdcg {got:.9g}, reference {ref:.9g}, rel. diff {rel:.1e} "
          f"(tolerance {tol:g}: {why})")

f = json.load(open(f"{out}/forces.json"))
good = f["max_norm_relative_error"] <= 1e-10
ok &= good
print(f"{'ok  ' if good else 'FAIL'} forces of {f['atoms']} displaced atoms: max |f_pdcg − f_LAMMPS| / max |f| = "
      f"{f['max_norm_relative_error']:.1e} (tolerance 1e-10: native sw vs LAMMPS differ by summation order only)")

lam = json.load(open(f"{out}/lammps.json"))
C_rel = lam["relaxed"]["C"] if "relaxed" in lam else lam["C_relaxed"]
C_cl = lam["clamped"]["C"] if "clamped" in lam else lam["C_clamped"]
# density from the data file: mass of the atoms / box volume
atoms = 0; box = []
for line in open(f"{out}/si.data"):
    t = line.split()
    if len(t) == 2 and t[1] == "atoms": atoms = int(t[0])
    if len(t) == 4 and t[2].endswith("lo") and t[3].endswith("hi"): box.append(float(t[1]) - float(t[0]))
rho = atoms * 28.0855 / (box[0] * box[1] * box[2])  # amu/Å³

# long-wave speeds along Γ–X (a cubic axis: [001]-type) from the first two κ points
# (Richardson: ω/κ = v (1 − c κ²) + …, so (4 s(κ) − s(2κ))/3 = v + O(κ⁴))
rows = [r for r in csv.reader(l for l in open(f"{out}/dispersion.csv") if not l.startswith("#"))][1:]
k1, k2 = float(rows[1][0]), float(rows[2][0])
s = lambda row, b, k: float(row[b]) / k
for b, cname, C in ((1, "C44", C_rel[3][3]), (3, "C11", C_rel[2][2])):
    v = (4 * s(rows[1], b, k1) - s(rows[2], b, k2)) / 3
    check(f"long-wave speed of branch {b} along Γ–X vs sqrt({cname}/ρ) (LAMMPS relaxed-ion)",
          v, math.sqrt(C / GPA * EV_PER_AMU / rho), 1e-6,
          "LAMMPS's central-difference error (lammps_elastic fd_error) and the O(κ⁴) remainder")
print(f"     (clamped-ion would give {math.sqrt(C_cl[3][3] / GPA * EV_PER_AMU / rho):.6g} Å/ps for the shear branch)")
print(f"     optical branches at Γ: {', '.join(f'{float(x):.6g}' for x in rows[0][4:7])} rad/ps")

def block(d):
    r = [row for row in csv.DictReader(l for l in open(f"{out}/{d}/reactions.csv") if not l.startswith("#"))]
    minus, plus = r[1], r[2]  # t = 0.5: ε = −1e-4; t = 1: ε = +1e-4
    area, de = 25.0, 2e-4  # the 5 Å × 5 Å faces; Δε between the two steps (±4e-4 Å over 4 Å)
    c = lambda key: (float(plus[key]) - float(minus[key])) / (de * area) * GPA
    return c("right_fx"), c("y1_fy"), c("z1_fz")

for d, C, name in (("block_relaxed", C_rel, "relaxed-ion"), ("block_clamped", C_cl, "clamped-ion")):
    c11, c12, c13 = block(d)
    for got, (i, j), lab in ((c11, (0, 0), "C'11"), (c12, (0, 1), "C'12"), (c13, (0, 2), "C'13")):
        check(f"BA block, {name}: {lab} from the reactions vs LAMMPS", got, C[i][j], 1e-6,
              "the weak form is exact for a homogeneous state; Newton tolerance 1e-10 and the central "
              "differences' O(ε²) of both sides")
sys.exit(0 if ok else 1)
PY
echo "summary: $OUT/summary.txt"
exit $fail
