#!/usr/bin/env bash
# Statistical bodies against MD at a temperature (docs/temperature.md).
#
#   workflows/temperature/run.sh [OUT=results/temperature] [T ...]     (~2 min on 2 busy cores)
#   env: PDCG=/path/to/pdcg, SYSTEM (lj | cu), CELLS (4: 256 atoms), EQUIL (10000),
#        SAMPLE (20000), EVERY (100),
#        ELASTIC=1 (isothermal stiffness, §3), DISPERSION=1 (phonons at T, §3.2)
#
# For each T* (default 0.05 0.2 0.4; k_B T/ε, units lj): LAMMPS (md.in) relaxes fcc LJ
# (lj/cut 2.5, shifted) at T = 0, holds that volume, equilibrates with Nosé–Hoover NVT and
# samples NVT, writing every 10 steps pe and the pressure tensor with and without its kinetic
# part, and every EVERY steps a frame with the same quantities. analyse.py then builds
# statistical bodies of those frames with pdcg (Gaussian fit, empirical, decorrelated frames,
# --temperature, static lattices), evaluates `pdcg energy --stress`, and writes
# table.csv / table.md (block-average error bars) and timing.csv; qha.py the quasi-harmonic
# pressure from LAMMPS's Hessian (qha.txt).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
OUT=${1:-$PDCG_ROOT/results/temperature}
shift || true
TEMPS=("$@")
# SYSTEM=lj (md.in, T* = 0.05 0.2 0.4) or cu (md_cu.in, Cu EAM, T = 300 600 900 K; §2.1)
export SYSTEM=${SYSTEM:-lj}
DECK=md.in
[[ $SYSTEM = cu ]] && DECK=md_cu.in
if [[ ${#TEMPS[@]} -eq 0 ]]; then
  if [[ $SYSTEM = cu ]]; then TEMPS=(300 600 900); else TEMPS=(0.05 0.2 0.4); fi
fi
CELLS=${CELLS:-4}
EQUIL=${EQUIL:-10000}
SAMPLE=${SAMPLE:-20000}
EVERY=${EVERY:-100}
if [[ -z "${PDCG:-}" ]]; then
  [[ -f "$PDCG_BUILD/CMakeCache.txt" ]] || cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target pdcg >/dev/null
  PDCG=$PDCG_BUILD/pdcg
fi
export PDCG
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
echo "T,md_wall_s,md_cpu_s,atoms,steps" >"$OUT/timing.csv"
for T in "${TEMPS[@]}"; do
  d=$OUT/T_$T
  mkdir -p "$d"
  echo "== T* = $T: LAMMPS NVT ($EQUIL + $SAMPLE steps, $((4 * CELLS ** 3)) atoms)"
  t0=$(date +%s.%N)
  c0=$(awk '{print $14 + $15 + $16 + $17}' /proc/$$/stat)
  (cd /usr/share/lammps/potentials && lmp -in "$HERE/$DECK" -var T "$T" -var seed 4711 \
    -var cells "$CELLS" -var equil "$EQUIL" -var sample "$SAMPLE" -var every "$EVERY" \
    -var out "$d" -log "$d/log.lammps" -screen none)
  t1=$(date +%s.%N)
  c1=$(awk '{print $14 + $15 + $16 + $17}' /proc/$$/stat)
  tck=$(getconf CLK_TCK)
  echo "$T,$(/usr/bin/python3 -c "print(f'{$t1 - $t0:.1f}')"),$(/usr/bin/python3 -c "print(f'{($c1 - $c0) / $tck:.1f}')"),$((4 * CELLS ** 3)),$((EQUIL + SAMPLE))" >>"$OUT/timing.csv"
done
/usr/bin/python3 "$HERE/analyse.py" "$OUT" "${TEMPS[@]}"
# quasi-harmonic pressure at the T = 0 volume from LAMMPS's Hessian (docs/temperature.md §3)
if [[ $SYSTEM = lj ]]; then
  A0=$(grep -h "^LATTICE a0" "$OUT"/T_*/log.lammps | head -1 | awk '{print $4}')
  /usr/bin/python3 "$HERE/qha.py" "$A0" "$CELLS" "${TEMPS[@]}" | tee "$OUT/qha.txt"
fi
# isothermal stiffness C11, C12, C44 (MD at strains ±0.01 vs pdcg's quasi-harmonic free
# energy; 12 more MD runs, ~50 s CPU): ELASTIC=1
if [[ "${ELASTIC:-0}" = 1 ]]; then
  /usr/bin/python3 "$HERE/elastic.py" "$OUT" "${TEMPS[@]}"
  (cd "$OUT" && /usr/bin/python3 "$HERE/cutoff_crossings.py")
fi
# phonons at T (docs/temperature.md §3.2): measured dispersion of NVE MD (8×4×4 cells, at the
# T = 0 volume and at zero pressure) against the static and quasi-harmonic model dispersions;
# 12 MD runs of 512 atoms, ~5 min CPU in all: DISPERSION=1 (or dispersion.py OUT [lj|cu] alone)
if [[ "${DISPERSION:-0}" = 1 ]]; then
  /usr/bin/python3 "$HERE/dispersion.py" "$OUT/dispersion" ${DISPERSION_SYSTEMS:-lj cu}
fi
