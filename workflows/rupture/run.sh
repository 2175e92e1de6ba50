#!/usr/bin/env bash
# Rubber-sheet rupture study (docs/validation.md "Rubber sheet rupture"):
#   edge pre-crack (c = 0.3) and centre pre-crack (2c = 1/3) under displacement-controlled
#   tension, plus edge cracks c = 0.2 and 0.4 for the Rivlin-Thomas comparison; then the
#   tables (OUT/summary.txt) and plots (docs/img/rupture_*.png).
#   workflows/rupture/run.sh [OUT=build/rupture]
# Environment: SPACING (default 0.05), STEPS (default 25), RUN_TIMEOUT seconds per run
#   (default 150: a run whose re-equilibrium falls back to adaptive dynamic relaxation can
#   spend long there; the analysis uses every step written before), IMG (default docs/img),
#   CASES (default "edge centre edge_c200 edge_c400"; also edge_path2, see below).
# Each run's HDF5 + XDMF damage series is in OUT/<case>/results.xdmf (ParaView: open it,
# colour by "damage").
set -uo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
PY=/usr/bin/python3  # Debian's python (numpy, h5py, matplotlib from apt)
OUT=${1:-$PDCG_BUILD/rupture}
IMG=${IMG:-$PDCG_ROOT/docs/img}
SPACING=${SPACING:-0.05}
STEPS=${STEPS:-25}
mkdir -p "$OUT"
[[ -x "$PDCG_BUILD/pdcg" ]] || cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target pdcg >/dev/null
scene() {  # scene <template> <name> [crack tip x]: writes OUT/<name>.yaml
  local s
  s=$(sed -e "s/spacing: 0.05/spacing: $SPACING/" -e "s/steps: [0-9]*/steps: $STEPS/" \
    "$HERE/$1.yaml")
  [[ -n "${3:-}" ]] && s=${s//"to: [0.3, 0.5]"/"to: [$3, 0.5]"}
  printf '%s\n' "$s" >"$OUT/$2.yaml"
}
scene edge edge
scene centre centre
scene edge edge_c200 0.2
scene edge edge_c400 0.4
# the edge scene on another load path: 0.02 per step from 0 (reaches the running crack at
# u_y = 0.34 after one ADR rescue at 0.28, ~5 min here; not in the default CASES)
sed -e 's/"0.1 + 0.25\*t"/"0.5*t"/' "$OUT/edge.yaml" >"$OUT/edge_path2.yaml"
for c in ${CASES:-edge centre edge_c200 edge_c400}; do
  rm -rf "${OUT:?}/$c"
  start=$(date +%s)
  OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} timeout "${RUN_TIMEOUT:-150}" \
    "$PDCG_BUILD/pdcg" run "$OUT/$c.yaml" -o "$OUT/$c" >"$OUT/$c.log" 2>&1
  rc=$?
  echo "$c: exit $rc after $(($(date +%s) - start)) s, $(($(grep -vc '^#' "$OUT/$c/reactions.csv") - 2)) steps written" \
    | tee -a "$OUT/runs.txt"
  grep -E "numerical failure|adaptive dynamic relaxation:" "$OUT/$c.log" | cut -c1-300 | tail -3
done
# the c = 0.3 point of the Rivlin-Thomas study is the main edge run
ln -sfn edge "$OUT/edge_c300"
"$PY" "$HERE/analyse.py" "$OUT" "$IMG"
echo "results in $OUT (summary.txt, <case>/results.xdmf), plots in $IMG"
