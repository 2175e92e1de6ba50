#!/usr/bin/env bash
# Accuracy against cost (issue 9 §1 items 1 and 4): one command, CSV + PNG per item, summary in
# docs/accuracy-cost.md.
#   workflows/accuracy/run.sh [OUT=build/accuracy]   (~33 min measured at load 15-20 on the shared
#     2-core machine, 10 of them the three dx = 0.0125 runs; --spacings 0.05 0.025 for < 15 min)
#   SMOKE=1 workflows/accuracy/run.sh OUT               (seconds; what ctest runs)
# Extra arguments after OUT go to accuracy.py (e.g. --spacings 0.05 0.025 --parts plate).
# Needs python3-numpy, python3-scipy (FEM curve), python3-matplotlib (Debian 12).
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
