#!/usr/bin/env bash
# Quasi-static rupture to separation (docs/effects.md §2, "Unstable passes", "Free
# fragments", "Factor reuse"): the 50 x 50 edge-cracked sheet of
# workflows/rupture/edge_2500.yaml (50 load steps, top grip to u_y = 0.5) run twice
# with the same binary:
#   pseudo_transient  the default: a staggered pass that Newton cannot re-equilibrate
#                     falls back to pseudo-transient continuation, then ADR
#   anchor            as pseudo_transient, free fragments parked (rupture.fragments: anchor)
#   reuse             as anchor, and the Newton solves of the staggered passes reuse the
#                     last factorisation as a GMRES preconditioner
#                     (rupture.factorisations: reuse)
#   relaxation        ADR only as the fallback (the scheme before the continuation)
# each under a time limit. Per run: exit status, CPU (user + system) and wall seconds, load
# steps written, bonds broken, staggered passes, Newton / pseudo-transient / ADR iterations,
# the passes that needed a fallback, and CPU seconds per broken bond. The machine's load
# average is printed: wall times on a shared machine scale with it; CPU times much less.
#   workflows/bench/bench_separation.sh [OUT=build/rupture-separation]
# Environment: SPACING (default 0.02; 0.01 gives the 10^4-point sheet), LIMIT seconds per
# run (default 1200), CASES (default "pseudo_transient reuse"), OMP_NUM_THREADS (1).
set -uo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
OUT=${1:-$PDCG_BUILD/rupture-separation}
SPACING=${SPACING:-0.02}
LIMIT=${LIMIT:-1200}
mkdir -p "$OUT"
cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target pdcg >/dev/null
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
LOG="$OUT/bench.txt"
echo "# $(date -u +%FT%TZ) $(uname -n) spacing $SPACING limit $LIMIT s threads $OMP_NUM_THREADS" | tee "$LOG"
for c in ${CASES:-pseudo_transient reuse}; do
  case $c in
    anchor) keys="fallback: pseudo_transient, fragments: anchor" ;;
    reuse) keys="fallback: pseudo_transient, fragments: anchor, factorisations: reuse" ;;
    *) keys="fallback: $c" ;;
  esac
  sed -e "s/spacing: 0.02/spacing: $SPACING/" -e "s/critical: 2.0}/critical: 2.0, $keys}/" \
    "$HERE/../rupture/edge_2500.yaml" >"$OUT/$c.yaml"
  rm -rf "${OUT:?}/$c"
  load0=$(cut -d' ' -f1 /proc/loadavg)
  /usr/bin/time -f "%U %S %e" -o "$OUT/$c.time" timeout "$LIMIT" \
    "$PDCG_BUILD/pdcg" run "$OUT/$c.yaml" -o "$OUT/$c" >"$OUT/$c.log" 2>&1
  rc=$?
  /usr/bin/python3 - "$OUT" "$c" "$rc" "$load0" "$(cut -d' ' -f1 /proc/loadavg)" <<'PY' | tee -a "$LOG"
import re, sys
out, c, rc, l0, l1 = sys.argv[1:]
user, sys_, wall = (float(x) for x in open(f"{out}/{c}.time").read().split()[-3:])
rows = [l.strip().split(",") for l in open(f"{out}/{c}/reactions.csv") if not l.startswith("#")]
last = rows[-1]
log = open(f"{out}/{c}.log").read()
s = dict(passes=0, newton=0, failed=0, ptc=0, adr=0, stagger_s=0.0)
for m in re.finditer(r"after (\d+) passes .*?; (\d+) Newton iterations \((\d+) in failed solves\), "
                     r"(\d+) pseudo-transient and (\d+) ADR iterations, ([\d.]+) s", log):
    for k, v in zip(("passes", "newton", "failed", "ptc", "adr"), m.groups()[:5]):
        s[k] += int(v)
    s["stagger_s"] += float(m.group(6))
ptc_ok = len(re.findall(r"pseudo-transient continuation: converged", log))
ptc_fail = len(re.findall(r"pseudo-transient continuation: FAILED", log))
adr = len(re.findall(r"adaptive dynamic relaxation: (?:converged|FAILED)", log))
broken = int(last[-1])
cpu = user + sys_
print(f"case={c} exit={rc} cpu_s={cpu:.1f} wall_s={wall:.1f} load={l0}->{l1} "
      f"steps={last[0]} t={last[1]} top_fy={last[-2]} broken_bonds={broken} "
      f"passes_finished_steps={s['passes']} newton_its={s['newton']} failed_newton_its={s['failed']} "
      f"ptc_its={s['ptc']} adr_its={s['adr']} ptc_resolved={ptc_ok} ptc_failed={ptc_fail} "
      f"adr_passes={adr} cpu_s_per_broken_bond={cpu / max(broken, 1):.3f}")
PY
done
echo "results in $OUT (bench.txt, <case>.log, <case>/reactions.csv)"
