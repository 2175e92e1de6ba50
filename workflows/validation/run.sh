#!/usr/bin/env bash
# Plate-with-hole validation (docs/validation.md §1): the independent FEM reference, then pdcg on the same
# plate at several spacings, the comparison table and plot for docs/validation.md.
#   workflows/validation/run.sh [OUT=build/validation]   (FEM_LEVELS=5 by default; ~20 min,
#   SPACINGS="0.05 0.025 0.0125" by default: + ~10 min for the finest)
# Plane stress / other bulk moduli: plate_hole_fem.py --plane stress --bulk K (references in
# tests/data/plate_hole_fem_{strain,stress}_K*.csv; docs/validation.md §1).
# Needs python3-numpy, python3-scipy, python3-matplotlib (Debian 12); installed when run as
# root, else the apt-get line is printed.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
need=()
for p in python3-numpy python3-scipy python3-matplotlib; do
  [[ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)" == "install ok installed" ]] || need+=("$p")
done
if ((${#need[@]})); then
  if [[ $(id -u) == 0 ]]; then
    apt-get install -y "${need[@]}"
  else
    echo "missing packages; run: sudo apt-get install -y ${need[*]}" >&2
    exit 1
  fi
fi
PY=/usr/bin/python3  # Debian's python (numpy/scipy/matplotlib from apt)
OUT=${1:-$PDCG_BUILD/validation}
mkdir -p "$OUT"
"$PY" "$HERE/plate_hole_fem.py" --levels "${FEM_LEVELS:-5}" --base 6 --csv "$OUT/plate_hole_fem.csv" | tee "$OUT/fem.log"
pdcg_build_target() {  # configure once, build only the given targets
  [[ -f "$PDCG_BUILD/CMakeCache.txt" ]] || cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target "$@"
}
pdcg_build_target test_validation_acceptance >/dev/null
# Δx = 0.0125 takes minutes, 0.00625 (22 k points) hours on a loaded 2-core machine.
for h in ${SPACINGS:-0.05 0.025 0.0125}; do
  PDCG_PLATE_SPACING=$h "$PDCG_BUILD/test_validation_acceptance" \
    | grep -E '^step|max relative' >"$OUT/pdcg_$h.txt" || true
done
"$PY" "$HERE/plot_plate_hole.py" "$OUT/plate_hole_fem.csv" "$OUT" "$OUT"/pdcg_*.txt
echo "results in $OUT (copy plate_hole_fem.csv to tests/data/ to update the test reference)"
