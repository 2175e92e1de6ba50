#!/usr/bin/env bash
# `pdcg run` refuses bad scenes before it writes anything, and a run that fails later never
# looks finished:
#  - a negative horizon value (the old pdcg ran it silently with the default factor), a region
#    that selects no point and a time step above the stable limit: exit 2, the message names
#    file:line and the key, no output directory and no scene.resolved.yaml;
#  - a run whose second load step fails: exit 1 with the diagnosis, the outputs of step 1 kept,
#    the last progress line "stopped" at 1/2, never 100 %.
# Usage: scene_checks.sh /path/to/pdcg
set -u
pdcg=$(realpath "$1")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
fail=0
scene() {  # scene <horizon> <right region> <right x>
  cat <<YAML
dimension: 2
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 0.5], spacing: 0.1}
horizon: $1
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0}
boundary:
  - {name: left, region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: $2, displacement: {x: $3}}
loading: {steps: 2}
solver: {max_cutbacks: 0}
output: {directory: out}
YAML
}
refused() {  # refused <name> <scene-file> <regex>
  local name=$1 file=$2 regex=$3 out code
  out=$("$pdcg" run "$file" -o "$name.out" 2>&1); code=$?
  if [ "$code" != 2 ]; then
    echo "FAIL $name: exit $code, expected 2 (input error)"; echo "$out" | tail -5; fail=1
  elif ! grep -Eq -- "$regex" <<<"$out"; then
    echo "FAIL $name: message does not match /$regex/:"; echo "$out" | tail -5; fail=1
  elif [ -e "$name.out" ]; then
    echo "FAIL $name: the refused scene left $name.out/ ($(ls "$name.out" | tr '\n' ' '))"; fail=1
  else
    echo "ok   $name"
  fi
}
scene "{value: -0.3}" "{x_min: 1.0}" '"0.01*t"' > negative_horizon.yaml
refused negative-horizon negative_horizon.yaml \
  "negative_horizon\.yaml:3: horizon\.value: out of range: got '-0\.3', expected a horizon > 0"
scene "{factor: 3.015}" "{x_min: 1.5}" '"0.01*t"' > empty_region.yaml
refused no-point empty_region.yaml \
  "empty_region\.yaml:7: boundary\[right\]\.region: the region selects no point"
cat > unstable.yaml <<'YAML'
dimension: 2
geometry: {size: [1.0, 0.5], spacing: 0.1}
material: {shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left, region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
effects: [inertia]
inertia: {time_step: 10.0, end_time: 100.0}
YAML
refused unstable-step unstable.yaml \
  "unstable\.yaml:7: inertia\.time_step: time step above the stable limit"

# Step 2 compresses the bar to a tenth of its length (u = -0.9 at t = 1; 1e-6 at t = 0.5): the
# material refuses the inverted state and, without cutbacks, the run stops at step 2.
scene "{factor: 3.015}" "{x_min: 1.0}" '"-0.9*t^20"' > fails.yaml
out=$("$pdcg" run fails.yaml -o fails.out 2>&1); code=$?
if [ "$code" != 1 ]; then
  echo "FAIL failed-run: exit $code, expected 1 (numerical failure)"; echo "$out" | tail -5; fail=1
elif grep -q '(100%)' <<<"$out" || ! grep -q 'load steps 1/2 (50%).*stopped' <<<"$out"; then
  echo "FAIL failed-run: progress line:"; grep 'load steps' <<<"$out"; fail=1
elif [ "$(grep -v '^#' fails.out/reactions.csv | tail -n 1 | cut -d, -f1,2)" != "1,0.5" ] ||
  [ ! -e fails.out/results_0001.h5 ] || [ ! -e fails.out/scene.resolved.yaml ]; then
  echo "FAIL failed-run: the outputs of step 1 are not all there"; ls fails.out; fail=1
else
  echo "ok   failed-run (exit 1, step 1 kept, progress stopped at 1/2)"
fi
exit $fail
