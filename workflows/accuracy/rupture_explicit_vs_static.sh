#!/usr/bin/env bash
# Explicit vs quasi-static rupture for the same case (docs/accuracy-cost.md §4b;
# docs/accuracy-cost.md §4b): one pre-cracked plane-stress Neo-Hookean sheet (1 × 1, edge
# crack 0.3, μ = 1, K = 100, ρ = 1, bond stretch 1.15, Δx = SPACING) pulled at its top edge
# to ū = UMAX, once quasi-statically (Newton, staggered rupture, STEPS load steps) and once
# by explicit dynamics (velocity Verlet + dynamic fracture, top velocity ramped to
# V = UMAX/T_END·… with a rise time, see below). Writes OUT/compare.csv (peak load,
# displacement at the peak, critical stretch = 1 + ū at the first break, crack path: tip x
# and the mean distance of damaged points from the crack line, bonds broken, wall time)
# and OUT/compare.png (load-displacement curves, final damage of both).
#   workflows/accuracy/rupture_explicit_vs_static.sh [OUT=build/rupture_compare]
# Environment: SPACING (0.05), STEPS (30), UMAX (0.3), T_END (explicit end time, 12),
#   RISE (velocity rise time, 0.5). ~3 min on the shared 2-core machine at the defaults.
set -uo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
PY=/usr/bin/python3
OUT=${1:-$PDCG_BUILD/rupture_compare}
PDCG=${PDCG:-$PDCG_BUILD/pdcg}
SPACING=${SPACING:-0.05}
STEPS=${STEPS:-30}
UMAX=${UMAX:-0.3}
T_END=${T_END:-12}
RISE=${RISE:-0.5}
[[ -x "$PDCG" ]] || cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target pdcg >/dev/null
mkdir -p "$OUT"
# top velocity V reached with the rise time: u(t) = V (t − RISE (1 − e^{−t/RISE})), V chosen
# so that u(T_END) = UMAX
V=$("$PY" -c "import math; print($UMAX / ($T_END - $RISE * (1 - math.exp(-$T_END / $RISE))))")
common() {
  cat <<Y
dimension: 2
plane: stress
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 1.0], spacing: $SPACING,
           cracks: [{from: [0.0, 0.5], to: [0.3, 0.5]}]}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 100.0, density: 1.0}
Y
}
{ common; cat <<Y
boundary:
  - {name: bottom, region: {y_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: top,    region: {y_min: 1.0}, displacement: {x: 0.0, y: "$UMAX*t"}}
loading: {steps: $STEPS}
effects: [rupture]
rupture: {criterion: bond_stretch, critical: 1.15}
output: {every: $STEPS}
Y
} >"$OUT/static.yaml"
{ common; cat <<Y
boundary:
  - {name: bottom, region: {y_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: top,    region: {y_min: 1.0}, displacement: {x: 0.0, y: "$V*(t - $RISE*(1 - exp(-t/$RISE)))"}}
effects: [inertia, rupture]
inertia: {end_time: $T_END}
rupture: {criterion: bond_stretch, critical: 1.15}
output: {every: 1000000}
Y
} >"$OUT/explicit.yaml"
for c in static explicit; do
  rm -rf "${OUT:?}/$c"
  start=$(date +%s.%N)
  OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} "$PDCG" run "$OUT/$c.yaml" -o "$OUT/$c" >"$OUT/$c.log" 2>&1
  rc=$?
  end=$(date +%s.%N)
  echo "$c $rc $(echo "$end - $start" | bc)" >>"$OUT/walltime.txt.new"
  echo "$c: exit $rc after $(echo "$end - $start" | bc) s"
done
mv "$OUT/walltime.txt.new" "$OUT/walltime.txt"
"$PY" "$HERE/rupture_explicit_vs_static.py" "$OUT" "$UMAX" "$V" "$RISE"
