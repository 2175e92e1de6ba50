#!/usr/bin/env bash
# Issue 5 acceptance through the CLI: LAMMPS MD of a 1D chain (atomistics/chain1d), measured
# with `pdcg dispersion --trajectory`, compared with the closed form
# ω² = 2[μ₁(1 − cos κ) + μ₂(1 − cos 2κ)] written by Python (independent of pdcg): every ridge
# point within one frequency-resolution bin (the transform's resolution; reason for the tolerance).
# Then the bad inputs of the issue.  Usage: dispersion_chain.sh /path/to/pdcg <source-dir>
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
rows = list(csv.DictReader(open("measured.csv")))
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
expect_error too-few-frames   'too few frames'                      --trajectory $d --dt 0.01 --frames 0:1 -o x.csv
expect_error resolution       'too short for the requested frequency resolution.*at least' --trajectory $d --dt 0.01 --resolution 0.001 -o x.csv
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
[ ! -e x.csv ] || { echo "FAIL: an output file was written despite the errors"; fail=1; }
[ $fail = 0 ] && echo "dispersion_chain: all passed" || { echo "dispersion_chain: FAILED"; exit 1; }
