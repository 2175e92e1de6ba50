#!/usr/bin/env bash
# Dispersion acceptance through the CLI: LAMMPS MD of a 1D chain (atomistics/chain1d), measured
# with `pdcg dispersion --trajectory`, compared with the closed form
# ω² = 2[μ₁(1 − cos κ) + μ₂(1 − cos 2κ)] written by Python (independent of pdcg): every ridge
# point within one frequency-resolution bin (the transform's resolution; reason for the tolerance).
# Then bad inputs.  Usage: dispersion_chain.sh /path/to/pdcg <source-dir>
set -euo pipefail
pdcg=$1 src=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
fail=0
for mu2 in 0.0 0.25; do
  mkdir -p "mu2_$mu2"; cd "mu2_$mu2"
  lmp -in "$src/atomistics/chain1d/in.chain" -var out . -var mu2 "$mu2" -log none -screen none
  /usr/bin/python3 - "$mu2" > closed.csv <<'PY'
import math, sys
mu2 = float(sys.argv[1])
print("kappa,omega")
for i in range(0, 401):
    k = math.pi * i / 400
    print(f"{k:.17g},{math.sqrt(2*(1-math.cos(k)) + 2*mu2*(1-math.cos(2*k))):.17g}")
PY
  "$pdcg" -q dispersion --trajectory chain.dump --dt 0.01 -o measured.csv --compare closed.csv --spectrum S.png
  if /usr/bin/python3 - <<'PY'
import csv, sys
rows = list(csv.DictReader(l for l in open("measured.csv") if not l.startswith("#")))
assert len(rows) == 16, len(rows)
worst = max(abs(float(r["error_in_bins"])) for r in rows)
print(f"   worst |error| = {worst:.3f} bins")
sys.exit(0 if worst <= 1.0 else 1)
PY
  then echo "ok   chain mu2=$mu2: ridge within one bin of the closed form"
  else echo "FAIL chain mu2=$mu2"; fail=1; fi
  /usr/bin/python3 -c "import matplotlib.image as m; a = m.imread('S.png'); assert a.shape[0] > 100 and a.shape[1] > 100" \
    && echo "ok   spectrum PNG decodes" || { echo "FAIL spectrum PNG"; fail=1; }
  cd ..
done

expect_error() {  # expect_error <name> <regex> <args...>
  local name=$1 regex=$2; shift 2
  local out code
  out=$("$pdcg" dispersion "$@" 2>&1) && code=0 || code=$?
  if [ "$code" = 2 ] && grep -Eq -- "$regex" <<<"$out"; then echo "ok   $name"
  else echo "FAIL $name (exit $code): $out"; fail=1; fi
}
d=mu2_0.0/chain.dump
expect_error too-few-frames   'chain.dump.*too few frames.*0:2 selects 3 of 1024 frames.*at least 4 frames' --trajectory $d --dt 0.01 --frames 0:2 -o x.csv
# Δω = 2π/(1024 · 0.1) = 0.0614 is coarser than 0.001: 62832 frames needed
expect_error resolution       'chain.dump: --resolution: trajectory too short for the requested frequency resolution.*Δω = 0.06136.*at least 62832 frames' --trajectory $d --dt 0.01 --resolution 0.001 -o x.csv
expect_error no-dt            'time between frames is unknown.*--dt' --trajectory $d -o x.csv
expect_error axis-not-periodic 'not periodic along the wave axis'   --trajectory $d --dt 0.01 --axis y -o x.csv
expect_error frames-range     'frame index out of range.*frames 0 to 1023' --trajectory $d --dt 0.01 --frames 0:5000 -o x.csv
# an atom that leaves its plane: move atom 5 by 0.7 spacing in the last frame
/usr/bin/python3 - "$d" > left.dump <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
last = max(i for i, l in enumerate(lines) if l.startswith("ITEM: ATOMS"))
for i in range(last + 1, len(lines)):
    f = lines[i].split()
    if f[0] == "5":
        f[2] = repr(float(f[2]) + 0.7); lines[i] = " ".join(f)
print("\n".join(lines))
PY
expect_error atom-left-plane  'atom id 5 in frame 1023.*left its lattice plane|left its lattice plane' --trajectory left.dump --dt 0.01 -o x.csv
# an atom that leaves the axis sideways: atom 7 moved by 0.6 spacing along y in frame 1023
/usr/bin/python3 - "$d" > sideways.dump <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
last = max(i for i, l in enumerate(lines) if l.startswith("ITEM: ATOMS"))
for i in range(last + 1, len(lines)):
    f = lines[i].split()
    if f[0] == "7":
        f[3] = repr(float(f[3]) + 0.6); lines[i] = " ".join(f)
print("\n".join(lines))
PY
expect_error atom-left-axis   'sideways.dump: atom id 7 in frame 1023: an atom left the wave axis.*0.599. from its mean position across the axis x.*less than half the transverse lattice spacing 0.5' --trajectory sideways.dump --dt 0.01 -o x.csv
# the wrong axis: a fully periodic box, --axis y: every atom lies in the plane y = 0
sed 's/^ITEM: BOX BOUNDS pp ff ff/ITEM: BOX BOUNDS pp pp pp/' $d > periodic.dump
expect_error wrong-axis       'periodic.dump: --axis: all atoms lie in one lattice plane.*y \(32 atoms, 1 plane\).*chain direction' --trajectory periodic.dump --dt 0.01 --axis y -o x.csv
# path labels unknown for the lattice: K and Q on the chain (its labels are G and X)
cat > potential.chain <<'EOF2'
units lj
mass 1 1.0
pair_style zero 2.5
pair_coeff * *
bond_style harmonic
bond_coeff 1 0.5 1.0
bond_coeff 2 0.0 2.0
special_bonds lj/coul 0.0 1.0 1.0
EOF2
"$pdcg" -q atoms2pd --input mu2_0.0/chain.data --potential potential.chain --dimension 1 --boundary "p f f" -o chain.h5
# the whole κ-grid of the periodic chain at once (FFTW): κ_m = 2πm/32, closed form to 1e-12
"$pdcg" -q dispersion chain.h5 --grid -o grid.csv >/dev/null
if /usr/bin/python3 - <<'PY'
import csv, math
rows = list(csv.DictReader(l for l in open("grid.csv") if not l.startswith("#")))
assert len(rows) == 32, len(rows)
ks = sorted(float(r["kx"]) for r in rows)
assert all(abs(k - 2 * math.pi * m / 32) < 1e-12 for k, m in zip(ks, range(-16, 16))), ks
worst = max(abs(float(r["omega_3"]) - math.sqrt(2 * (1 - math.cos(float(r["kx"]))))) for r in rows)
print(f"   grid: worst |ω − closed form| = {worst:.2e}")
assert worst < 1e-12
PY
then echo "ok   --grid equals the closed form"; else echo "FAIL --grid"; fail=1; fi
rm -f grid.csv
# model mode --compare: closed form at the same κ (written by Python) → error columns ≤ 1e-12
/usr/bin/python3 -c "
import math
print('kappa,omega')
for i in range(17):
    k = math.pi * i / 16
    print(f'{k:.17g},{math.sqrt(2 * (1 - math.cos(k))):.17g}')" > closed16.csv
out=$("$pdcg" dispersion chain.h5 --direction 1,0,0 --nk 16 -o cmp.csv --compare closed16.csv 2>&1)
if grep -q "worst error against closed16.csv" <<<"$out" && /usr/bin/python3 - <<'PY'
import csv
rows = list(csv.DictReader(l for l in open("cmp.csv") if not l.startswith("#")))
assert len(rows) == 17 and "error_1" in rows[0] and "omega_ref_1" in rows[0], rows[0].keys()
worst = max(abs(float(r["error_1"])) for r in rows)
print(f"   --compare: worst error column {worst:.2e}")
assert worst < 1e-12
PY
then echo "ok   model --compare error columns"; else echo "FAIL model --compare: $out"; fail=1; fi
rm -f cmp.csv closed16.csv
# --plot: the helper script is found next to the executable (<build>/share/pdcg), not in the
# source tree; the PNG must decode
"$pdcg" -q dispersion chain.h5 --direction 1,0,0 --nk 16 -o plotted.csv --plot plotted.png
/usr/bin/python3 -c "import matplotlib.image as m; a = m.imread('plotted.png'); assert a.shape[0] > 100 and a.shape[1] > 100" \
  && echo "ok   --plot PNG decodes" || { echo "FAIL --plot PNG"; fail=1; }
rm -f plotted.csv plotted.png
expect_error grid-and-path    '--direction and --grid|--path and --grid' chain.h5 --grid --path G-X -o x.csv
expect_error grid-and-plot    '--plot.*no curve to plot' chain.h5 --grid --plot x.png -o x.csv
expect_error path-K-on-chain  "--path.*path label unknown for this lattice.*'K'.*one of G, X for lattice chain" chain.h5 --path G-K -o x.csv
expect_error path-Q           "--path.*path label unknown for this lattice.*'Q'.*one of G, X for lattice chain" chain.h5 --path G-X-Q -o x.csv
expect_error path-bad-lattice "--lattice.*unknown lattice.*'fcc2'.*one of fcc, bcc, sc, hex, chain" chain.h5 --path G-X --lattice fcc2 --a 1 -o x.csv
# unstable-mode safeguard through the CLI: a compressed chain (rest length 1.1 at spacing 1) has
# transverse ω² = −0.2(1 − cos κ) < 0: written as −√|ω²| (finite, no NaN) with a warning
sed 's/^bond_coeff 1 0.5 1.0/bond_coeff 1 0.5 1.1/' potential.chain > compressed.chain
"$pdcg" -q atoms2pd --input mu2_0.0/chain.data --potential compressed.chain --dimension 1 --boundary "p f f" -o compressed.h5
out=$("$pdcg" dispersion compressed.h5 --direction 1,0,0 --nk 8 -o unstable.csv 2>&1)
if grep -q "warning: unstable modes" <<<"$out" && /usr/bin/python3 - <<'PY'
import csv, math
rows = list(csv.DictReader(l for l in open("unstable.csv") if not l.startswith("#")))
w1 = [float(r["omega_1"]) for r in rows]
assert all(math.isfinite(float(v)) for r in rows for k, v in r.items())
k = float(rows[-1]["kappa"])
assert abs(w1[-1] + math.sqrt(0.2 * (1 - math.cos(k)))) < 1e-12, (w1[-1], k)  # −√|ω²| at the zone edge
PY
then echo "ok   unstable modes finite (−√|ω²|) with a warning"; else echo "FAIL unstable modes: $out"; fail=1; fi
rm -f unstable.csv
[ ! -e x.csv ] || { echo "FAIL: an output file was written despite the errors"; fail=1; }
[ $fail = 0 ] && echo "dispersion_chain: all passed" || { echo "dispersion_chain: FAILED"; exit 1; }
