#!/usr/bin/env bash
# Accuracy against cost of coarse-graining (docs/accuracy-cost.md §2): a Gaussian wave packet in a
# periodic 1D Lennard-Jones chain and in a long FCC LJ bar periodic in y, z (longitudinal, along
# [100]), LAMMPS MD of the atoms as the reference, rescaled models
# (N/ε points, `pdcg atoms2pd` + `pdcg rescale --factor ε`, `pdcg md` with Δt·ε) for ε ∈ {1, 2, 4, 8}:
# displacement error against MD at the same material points, dispersion error at the carrier
# wavenumber κ₀ (pdcg dispersion vs the atoms' and the closed form ω(εκ)/ε), wall times of
# pdcg and LAMMPS for the same simulated time; CSV + PNG (summarised in docs/accuracy-cost.md §2).
#
#   workflows/accuracy/coarse_graining.sh [OUT=results/accuracy/coarse_graining]   (~1.5 min, 1 thread per run)
#   writes OUT/chain/ and OUT/fcc/. PDCG=/path/to/pdcg to skip the build; LATTICES="chain fcc";
#   N, CROSS, EPS, LAM, W, STRAIN, TRAVEL, DT, FRAMES, REPEAT override the problem (coarse_graining.py).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
OUT=${1:-$PDCG_ROOT/results/accuracy/coarse_graining}
if [[ -z "${PDCG:-}" ]]; then
  [[ -f "$PDCG_BUILD/CMakeCache.txt" ]] || cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target pdcg >/dev/null
  PDCG=$PDCG_BUILD/pdcg
fi
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
for lattice in ${LATTICES:-chain fcc}; do
  mkdir -p "$OUT/$lattice"
  PDCG=$PDCG LATTICE=$lattice /usr/bin/python3 "$HERE/coarse_graining.py" "$OUT/$lattice"
done
