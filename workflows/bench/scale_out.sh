#!/usr/bin/env bash
# Scale-out measurements (docs/scale-out.md §7): time per explicit step and per Newton iteration
# of `pdcg run` serial, under `mpirun -n 1` and `mpirun -n 2`, the peak memory of the largest
# process, and the entries and bytes the force exchange sends per explicit step (counted by the
# run and logged). One OpenMP thread per process. Prints a markdown table and writes
# $OUT/scale_out.csv with the machine and its load.
#   workflows/bench/scale_out.sh [OUT=build/bench]     (≈ 5 min on the loaded 2-core machine)
# Environment: SPACING_EXPLICIT (default 0.01: a unit square of 10⁴ points, m = 3),
#   STEPS (explicit steps, default 100), SPACING_NEWTON (default 0.025: the plate with a hole of
#   tests/mpi/plate.yaml at 1 317 points), RANKS (default "1 2").
set -euo pipefail
source "$(dirname "$0")/../lib/setup.sh"
PDCG=${PDCG:-$PDCG_BUILD/pdcg}
OUT=${1:-$PDCG_BUILD/bench}
H=${SPACING_EXPLICIT:-0.01} STEPS=${STEPS:-100} HN=${SPACING_NEWTON:-0.025} RANKS=${RANKS:-"1 2"}
mkdir -p "$OUT"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
CORES=$(nproc)  # before OMP_NUM_THREADS, which nproc honours
export OMP_NUM_THREADS=1
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
export OMPI_MCA_btl_vader_single_copy_mechanism=none
CSV="$OUT/scale_out.csv"
echo "# $(date -u +%FT%TZ) $(uname -n) $(lscpu | sed -n 's/^Model name: *//p' | head -1), $CORES cores, load: $(cut -d' ' -f1-3 /proc/loadavg)" >"$CSV"
echo "case,run,points,steps_or_iterations,seconds_per_step_or_iteration,evaluate_ms,evaluate_cpu_ms,exchange_ms,exchange_entries,exchange_kB,peak_rss_mb,wall_s,load1" >>"$CSV"

# explicit: a unit square, bottom clamped, top pulled slowly (no rupture); Δt ≈ 0.73 h (auto)
end=$(python3 -c "print(0.73 * $H * $STEPS)")
cat >"$W/explicit.yaml" <<EOF
units: none
dimension: 2
plane: stress
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 1.0], spacing: $H}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 3.0, density: 1.0}
boundary:
  - {name: bottom, region: {y_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: top,    region: {y_min: 1.0}, displacement: {x: 0.0, y: "0.01*t"}}
effects: [inertia]
inertia: {end_time: $end}
output: {every: 1000000, series_every: 1000000}
EOF
sed -e "s/spacing: 0.05/spacing: $HN/" -e 's/every: 5}/every: 100}/' \
  "$PDCG_ROOT/tests/mpi/plate.yaml" >"$W/newton.yaml"

run() {  # run NAME RUNNER... : the log in $W/NAME.log, /usr/bin/time in $W/NAME.time
  local name=$1
  shift
  /usr/bin/time -f "%M %e" -o "$W/$name.time" "$@" >"$W/$name.log" 2>&1 || {
    cat "$W/$name.log"
    exit 1
  }
}
runner() {  # runner R: the command prefix of R (serial or a rank count)
  if [ "$1" = serial ]; then echo ""; else echo "mpirun --oversubscribe -n $1"; fi
}
printf "| case | run | points | steps / iterations | s per step / iteration | force evaluation ms (CPU ms) | vote + sum ms | entries sent per step | kB per step | peak RSS MB | wall s | load |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n"
for r in serial $RANKS; do
  load=$(cut -d' ' -f1 /proc/loadavg)
  # shellcheck disable=SC2046
  run "explicit_$r" $(runner "$r") "$PDCG" run "$W/explicit.yaml" -o "$W/out_explicit_$r"
  log=$W/explicit_$r.log
  points=$(sed -n 's/.*body: \([0-9]*\) points.*/\1/p' "$log" | head -1)
  steps=$(sed -n 's/.*done: \([0-9]*\) steps.*/\1/p' "$log")
  elapsed=$(grep -o 'elapsed [0-9.]* s' "$log" | tail -1 | awk '{print $2}')
  ev=$(sed -n 's/.*evaluations, \([0-9.e+-]*\) ms each.*/\1/p' "$log")
  evc=$(sed -n 's/.*ms each (\([0-9.e+-]*\) ms of CPU).*/\1/p' "$log")
  xc=$(sed -n 's/.*, \([0-9.e+-]*\) ms for the admissibility vote.*/\1/p' "$log")
  ent=$(sed -n 's/.*evaluation \([0-9]*\) partial sums.*, \([0-9]*\) entries copied.*/\1+\2/p' "$log")
  kb=$(sed -n 's/.*(≈ \([0-9]*\) kB over all processes).*/\1/p' "$log")
  read -r rss wall <"$W/explicit_$r.time"
  per=$(python3 -c "print(f'{$elapsed / $steps:.4g}')")
  echo "explicit,$r,$points,$steps,$per,${ev:-},${evc:-},${xc:-},${ent:-},${kb:-},$((rss / 1024)),$wall,$load" >>"$CSV"
  printf "| explicit | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n" "$r" "$points" "$steps" \
    "$per" "${ev:--} (${evc:--})" "${xc:--}" "${ent:--}" "${kb:--}" "$((rss / 1024))" "$wall" "$load"
done
for r in serial $RANKS; do
  load=$(cut -d' ' -f1 /proc/loadavg)
  # shellcheck disable=SC2046
  run "newton_$r" $(runner "$r") "$PDCG" run "$W/newton.yaml" -o "$W/out_newton_$r"
  log=$W/newton_$r.log
  points=$(sed -n 's/.*body: \([0-9]*\) points.*/\1/p' "$log" | head -1)
  # per iteration: Σ (assembly + linear solve) / Σ iterations over the converged load steps
  read -r its per < <(python3 - "$log" <<'PY'
import re, sys
its = sec = 0
for l in open(sys.argv[1]):
    m = re.search(r"(\d+) Newton iterations.*assembly ([\d.]+) s, linear solve ([\d.]+) s", l)
    if m:
        its += int(m[1]); sec += float(m[2]) + float(m[3])
print(its, f"{sec / its:.4g}")
PY
)
  read -r rss wall <"$W/newton_$r.time"
  echo "newton,$r,$points,$its,$per,,,,,,$((rss / 1024)),$wall,$load" >>"$CSV"
  printf "| newton (MUMPS; serial UMFPACK) | %s | %s | %s | %s | | | | | %s | %s | %s |\n" "$r" \
    "$points" "$its" "$per" "$((rss / 1024))" "$wall" "$load"
done
echo "written $CSV"
