#!/usr/bin/env bash
# `solver: {check_stability: true}` in a scene (hard case "buckling-prone slender
# strip"): the perfect strip 1 × 0.1 (40 × 4 points, m = 3, energy form, plane strain, K/μ = 10,
# both end columns clamped) compressed to 9.75% in 20 steps. With the check the run stops at
# the first step past the bifurcation with exit 1 and the loss-of-stability diagnosis, keeping
# the steps before it; without it (key absent = default, or false) every step "converges" on
# the unstable straight path as before (exit 0, 20 steps, lateral deflection ≪ the buckled
# strip's 0.18). Bad values, misspelt keys and the check with the weak formulation are input
# errors (exit 2).
# The same case in C++: tests/unit/validation/test_stability_hard.cpp (docs/validation.md §2).
# Usage: check_stability.sh /path/to/pdcg
set -u
pdcg=$(realpath "$1")
py=${PYTHON:-/usr/bin/python3}  # needs h5py + numpy (Debian python3-h5py)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
fail=0
scene() {  # scene <solver map entries>
  cat <<YAML
units: none
dimension: 2
plane: strain
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 0.1], spacing: 0.025}
horizon: {factor: 3.015}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left,  region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: {x_min: 1.0}, displacement: {x: "-0.0975*t", y: 0.0}}
loading: {steps: 20}
solver: {formulation: energy, linear: cholmod$1}
output: {directory: out, every: 20}
YAML
}
check() {  # check <name> <expected-exit> <regex-on-output> <scene-file> <outdir>
  local name=$1 want=$2 regex=$3 file=$4 dir=$5 out code
  out=$("$pdcg" run "$file" -o "$dir" 2>&1); code=$?
  printf '%s\n' "$out" > "$dir.log"
  if [ "$code" != "$want" ]; then
    echo "FAIL $name: exit $code, expected $want"; echo "$out" | tail -20; fail=1; return
  fi
  if [ -n "$regex" ] && ! grep -Eq -- "$regex" <<<"$out"; then
    echo "FAIL $name: output does not match /$regex/"; echo "$out" | tail -20; fail=1; return
  fi
  echo "ok   $name"
}
scene ", check_stability: true" > on.yaml
scene "" > default.yaml
scene ", check_stability: false" > off.yaml
scene ", check_stability: maybe" > bad.yaml
scene ", check_stabilty: true" > typo.yaml
sed 's/formulation: energy, linear: cholmod/linear: umfpack/' on.yaml > weak.yaml

# on: exit 1 at the first unstable step (t = 0.2; Euler strain for pinned ends 0.0087 < 0.2 ×
# 0.0975 = 0.0195 < clamped 0.0346), the steps before it kept, the key in the resolved scene
check on 1 'loss of stability at load factor 0\.2:.*1 negative eigenvalue' on.yaml on
if [ "$(tail -n 1 on/reactions.csv | cut -d, -f1,2)" != "3,0.15" ]; then
  echo "FAIL on-kept: last row of reactions.csv is '$(tail -n 1 on/reactions.csv)', expected step 3 at t = 0.15"; fail=1
else echo "ok   on-kept"; fi
# the failed run's last progress line shows where it stopped, never 100 %
if grep -q '(100%)' on.log || ! grep -q 'load steps 3/20 (15%).*stopped' on.log; then
  echo "FAIL on-progress: the failed run's progress line:"; grep 'load steps' on.log; fail=1
else echo "ok   on-progress"; fi
if grep -q 'check_stability: true' on/scene.resolved.yaml; then echo "ok   on-resolved"
else echo "FAIL on-resolved: check_stability missing from scene.resolved.yaml"; fail=1; fi

# off (default and explicit): as before — all 20 steps converge on the straight path, silently
check default 0 'done: 20 steps' default.yaml default
if grep -q 'check_stability: false' default/scene.resolved.yaml; then echo "ok   default-resolved"
else echo "FAIL default-resolved: default check_stability: false not written"; fail=1; fi
check off 0 'done: 20 steps' off.yaml off
if cmp -s default/reactions.csv off/reactions.csv; then echo "ok   off-equals-default"
else echo "FAIL off-equals-default: reactions differ"; fail=1; fi
if grep -q 'loss of stability' default.log off.log; then
  echo "FAIL off-silent: a loss-of-stability message without the check"; fail=1
else echo "ok   off-silent"; fi
# the unstable straight path: max |u_y| of the last step 3.7e-3 measured, the buckled strip 0.18
"$py" - off/results_0020.h5 <<'PY' || fail=1
import sys
import h5py
import numpy as np
uy = np.abs(h5py.File(sys.argv[1], "r")["fields/displacement"][:, 1]).max()
ok = uy < 0.018  # 10% of the buckled deflection (0.18, docs/validation.md §2)
print(("ok  " if ok else "FAIL") + f" off-straight-path: max |u_y| = {uy:.2e} (< 0.018)")
sys.exit(0 if ok else 1)
PY

# input errors (exit 2): a non-boolean value, a misspelt key listing the valid ones
check bad 2 'solver.check_stability.*not a boolean|not a boolean.*solver.check_stability' bad.yaml bad
check typo 2 'check_stabilty.*check_stability|check_stability.*check_stabilty' typo.yaml typo
# the weak form (default): its symmetric part is indefinite even at rest, so the check is refused
check weak 2 'check_stability: the stability check needs the energy formulation' weak.yaml weak

if [ $fail -ne 0 ]; then echo "check_stability: FAILED"; exit 1; fi
echo "check_stability: all passed"
