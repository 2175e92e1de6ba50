#!/usr/bin/env bash
# Accuracy against cost of statistical densities (docs/accuracy-cost.md §3): the expected energy of an
# FCC Lennard-Jones crystal with Gaussian atoms, by Gauss–Hermite cubature (order n) and by
# sampling (S joint draws, several seeds), against a converged reference (cubature order 16),
# with the wall time of each evaluation; CSV + PNG (summarised in docs/accuracy-cost.md §3).
#
#   workflows/accuracy/statistical.sh [OUT=results/accuracy/statistical]    (~4 min on 1 core)
#   PDCG=/path/to/pdcg to skip the build; ORDERS, SAMPLES, SEEDS, MC_SAMPLES override the sweep.
#
# Crystal: fcc 4×4×4 cells (256 atoms, periodic), ρ* = 1 (a = 1.5874σ), every atom an isotropic
# Gaussian. Two cases: lj/cut 2.5σ shifted (atomistics/lj_fcc/potential.lj) with σ = 0.06σ, and
# lj/cut 2.38σ shifted (cutoff between shells) with σ = 0.02σ. Each reference (high order) is
# checked against a plain NumPy Monte-Carlo estimate written in statistical.py (independent of pdcg).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
OUT=${1:-$PDCG_ROOT/results/accuracy/statistical}
if [[ -z "${PDCG:-}" ]]; then
  [[ -f "$PDCG_BUILD/CMakeCache.txt" ]] || cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target pdcg >/dev/null
  PDCG=$PDCG_BUILD/pdcg
fi
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
cat >"$OUT/in.fcc" <<EOF2
units lj
atom_style atomic
lattice fcc 1.0
region box block 0 4 0 4 0 4
create_box 1 box
create_atoms 1 box
mass 1 1.0
write_data $OUT/fcc256.data
EOF2
lmp -in "$OUT/in.fcc" -log none -screen none
PDCG=$PDCG /usr/bin/python3 "$HERE/statistical.py" "$OUT"
