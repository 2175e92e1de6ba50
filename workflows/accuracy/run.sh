#!/usr/bin/env bash
# Accuracy against cost (docs/accuracy-cost.md §1 and §4): one command, CSV + PNG per item, summary in
# docs/accuracy-cost.md.
#   workflows/accuracy/run.sh [OUT=build/accuracy]   (item 1: see docs/accuracy-cost.md §1 for the
#     measured time, dominated by the dx = 1/160 runs; --spacings 0.05 0.025 0.0125 for minutes;
#     item 4: ≈ 6 min at load 15, the sum of the §4 run times; --parts plate | nonlinear for one)
#   SMOKE=1 workflows/accuracy/run.sh OUT               (seconds; what ctest runs)
# Extra arguments after OUT go to accuracy.py (e.g. --spacings 0.05 0.025 --parts plate).
# Needs python3-numpy, python3-scipy (FEM curve), python3-h5py (pdcg fields), python3-matplotlib
# (Debian 12).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
PY=/usr/bin/python3  # Debian's python (numpy/scipy/matplotlib from apt)
OUT=${1:-$PDCG_BUILD/accuracy}
shift || true
PDCG=${PDCG:-$PDCG_BUILD/pdcg}
if [[ ! -x "$PDCG" ]]; then
  [[ -f "$PDCG_BUILD/CMakeCache.txt" ]] || cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target pdcg
fi
extra=()
[[ -n "${SMOKE:-}" ]] && extra+=(--smoke)
mkdir -p "$OUT"
"$PY" "$HERE/accuracy.py" --pdcg "$PDCG" --out "$OUT" "${extra[@]}" "$@" | tee "$OUT/accuracy.log"
echo "results in $OUT"
