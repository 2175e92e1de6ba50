#!/usr/bin/env bash
# "Only what a scene asks for" (docs/effects.md): per-load-step cost of the same
# pre-cracked sheet (plane stress, mu = 1, K = 100, N x N points, top grip to u_y = 0.1)
#   elastic   the elasticity-only solver (Model + StaticSolver: what a scene without effects runs)
#   rupture   the same with rupture enabled whose criterion is never reached (stretch 10)
#   breaking  rupture with bond stretch 1.5: a few tip bonds break, staggered passes run
# (library level, bench_rupture_cost), and at scene level `pdcg run` of edge.yaml without
# `effects` against the same scene with `effects: [rupture]`, critical 10. Each case REPS times,
# interleaved; the table gives the minimum (least disturbed by the other jobs of the machine),
# the median, and ratios to the elasticity-only case.
#   workflows/rupture/bench_rupture.sh [OUT=build/rupture-bench]   (N=30 REPS=3 STEPS=3)
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
OUT=${1:-$PDCG_BUILD/rupture-bench}
N=${N:-30}
REPS=${REPS:-3}
STEPS=${STEPS:-3}
mkdir -p "$OUT"
cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target bench_rupture_cost pdcg >/dev/null
BIN=$(find "$PDCG_BUILD" -name bench_rupture_cost -type f | head -1)
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
# scene level: the workflow's edge scene, N points per edge, STEPS steps to u_y = 0.1, one output
base=$(sed -e "s/spacing: 0.05/spacing: $(/usr/bin/python3 -c "print(1/$N)")/" \
  -e "s/steps: [0-9]*/steps: $STEPS/" -e 's/"0.1 + 0.25\*t"/"0.1*t"/' -e "s/every: 1/every: $STEPS/" \
  "$HERE/edge.yaml")
printf '%s\n' "$base" | grep -v -e '^effects:' -e '^rupture:' >"$OUT/scene_elastic.yaml"
printf '%s\n' "$base" | sed 's/critical: 2.0/critical: 10.0/' >"$OUT/scene_rupture.yaml"
LOG="$OUT/bench.txt"
echo "# $(date -u +%FT%TZ) $(uname -n) load: $(cut -d' ' -f1-3 /proc/loadavg) threads: $OMP_NUM_THREADS" | tee "$LOG"
for r in $(seq "$REPS"); do
  for c in elastic rupture breaking; do "$BIN" "$c" "$N" "$STEPS" 2>/dev/null | tee -a "$LOG"; done
  for c in elastic rupture; do
    s=$(date +%s.%N)
    "$PDCG_BUILD/pdcg" run "$OUT/scene_$c.yaml" -o "$OUT/run_$c" >"$OUT/run_$c.log" 2>&1
    echo "case=scene_$c n=$N steps=$STEPS s_per_step=$(/usr/bin/python3 -c "print(($(date +%s.%N) - $s) / $STEPS)")" \
      | tee -a "$LOG"
  done
done
/usr/bin/python3 - "$LOG" <<'PY'
import sys, statistics as st
rows = [dict(p.split("=", 1) for p in l.split()) for l in open(sys.argv[1]) if l.startswith("case=")]
cases = {}
for r in rows:
    cases.setdefault(r["case"], []).append(r)
def t(c, f=min):
    return f(float(r["s_per_step"]) for r in cases[c])
print(f"\n| case | s/step (min) | s/step (median) | ratio to elasticity-only (min) | Newton its | "
      f"bonds broken | rupture arrays (bytes) |")
print("|---|---|---|---|---|---|---|")
for c, ref in (("elastic", "elastic"), ("rupture", "elastic"), ("breaking", "elastic"),
               ("scene_elastic", "scene_elastic"), ("scene_rupture", "scene_elastic")):
    if c not in cases:
        continue
    r = cases[c][0]
    arrays = "-" if "broken_flags_bytes" not in r else (
        "none" if r["broken_flags_bytes"] == "0" else
        f"broken {r['broken_flags_bytes']} + ill-posed {r['illposed_flags_bytes']} "
        f"+ criterion {r['criterion_values_bytes_per_pass']} (kept)")
    print(f"| {c} | {t(c):.3f} | {t(c, st.median):.3f} | {t(c) / t(ref):.3f} | "
          f"{r.get('newton_iterations', '-')} | {r.get('broken_bonds', '-')} | {arrays} |")
if "rupture" in cases:
    print(f"\nstaggered check with nothing breaking: {float(cases['rupture'][0]['stagger_s_per_step']):.4f} s/step "
          f"of {t('rupture'):.3f}; peak RSS elastic {cases['elastic'][0]['peak_rss_mb']} MB, "
          f"rupture {cases['rupture'][0]['peak_rss_mb']} MB")
PY
