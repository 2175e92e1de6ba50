#!/usr/bin/env bash
# BA kernels against the machine's roofline (docs/performance.md, "Memory"):
#  1. STREAM-like triad (GB/s) and FMA peak (GFLOP/s, AVX2+FMA) on 1 and 2 threads, each
#     probe run REPEAT times, the best kept (shared machine: the best is the least disturbed);
#  2. BA residual evaluation and tangent assembly on unit squares (2D plane strain) and cubes
#     (3D), m = 3.015, in BA family terms per second (minimum time over the in-process
#     repetitions), achieved GFLOP/s and GB/s from the analytic counts of ba_roofline.cpp,
#     and the fraction of the roofline bound min(peak, AI × bandwidth) reached;
#  3. the same-process roofline: triad and residual alternating in one process (AVX2 sweep and
#     the portable sweep as the peer), best of the rounds;
#  4. bytes per point and per term held by the Discretization, the Model and the tangent
#     (live heap bytes, counting malloc) against the data they must hold.
# Writes $OUT/roofline.csv (first line: date, CPU, cores, memory, load) and prints the tables.
#   workflows/bench/roofline.sh [OUT=build/bench]
# Environment: SIZES_2D (points per edge, default "100 316 632" ≈ 10⁴, 10⁵, 4·10⁵),
#   SIZES_3D (default "12 22 27" ≈ 1.7·10³, 10⁴, 2·10⁴), TANGENT_2D / TANGENT_3D (largest
#   edge with a tangent run, default 316 / 12), BODY_CELLS (fcc cells per edge of the body
#   memory run, default 12), THREADS (default "1 2"), REPS (residual
#   repetitions, default 5), REPEAT (probe repetitions, default 3), ROOF_ROUNDS (rounds of the
#   same-process triad + residual runs, AVX2 and portable sweep, one thread; 0 skips them;
#   default 5).
set -euo pipefail
source "$(dirname "$0")/../lib/setup.sh"
[[ -f "$PDCG_BUILD/CMakeCache.txt" ]] || cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target bench_ba_roofline bench_body_memory >/dev/null
BIN=$(find "$PDCG_BUILD" -name bench_ba_roofline -type f -perm -u+x | head -1)
BODYBIN=$(find "$PDCG_BUILD" -name bench_body_memory -type f -perm -u+x | head -1)
OUT=${1:-$PDCG_BUILD/bench}
mkdir -p "$OUT"
CSV="$OUT/roofline.csv"
MEM=$(awk '/MemTotal/ {printf "%.1f GB", $2 / 1048576}' /proc/meminfo)
echo "# $(date -u +%FT%TZ) $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores, $MEM, load at start: $(cut -d' ' -f1-3 /proc/loadavg)" >"$CSV"
THREADS=${THREADS:-1 2}
for t in $THREADS; do
  for r in $(seq "${REPEAT:-3}"); do
    "$BIN" triad "$t" 256 | sed 's/^/probe /' >>"$CSV"
    "$BIN" fma "$t" | sed 's/^/probe /' >>"$CSV"
  done
done
OMP_NUM_THREADS=1 "$BODYBIN" "${BODY_CELLS:-12}" 2>/dev/null | grep '^kind=' | sed 's/^/body /' >>"$CSV"
for dim in 2 3; do
  if [[ $dim == 2 ]]; then sizes=${SIZES_2D-100 316 632}; tmax=${TANGENT_2D:-316}; else sizes=${SIZES_3D-12 22 27}; tmax=${TANGENT_3D:-12}; fi
  for n in $sizes; do
    for t in $THREADS; do
      tan=0
      # tangent on one thread only (its rate per thread is what the table compares)
      [[ $n -le $tmax && $t == "${THREADS%% *}" ]] && tan=1
      line=$(OMP_NUM_THREADS=$t "$BIN" ba "$dim" "$n" "${REPS:-5}" "$tan")
      echo "ba load=$(cut -d' ' -f1 /proc/loadavg) $line" | tee -a "$CSV" >&2
    done
  done
done
# Same-process roofline (one thread): triad and residual alternate ROOF_ROUNDS times in one
# process, for the AVX2 sweep and for the portable sweep (PDCG_SOLVER_SCALAR=1, the code
# before the AVX2 kernel) as the peer in the same script.
if [[ ${ROOF_ROUNDS:-5} -gt 0 ]]; then
  for dim in 2 3; do
    if [[ $dim == 2 ]]; then sizes=${SIZES_2D-100 316 632}; else sizes=${SIZES_3D-12 22 27}; fi
    for n in $sizes; do
      for path in avx2 portable; do
        env $([[ $path == portable ]] && echo PDCG_SOLVER_SCALAR=1) OMP_NUM_THREADS=1 \
          "$BIN" roof "$dim" "$n" "${ROOF_ROUNDS:-5}" "${REPS:-5}" | grep '^roof ' |
          sed "s/^roof /roof path=$path load=$(cut -d' ' -f1 /proc/loadavg) /" | tee -a "$CSV" >&2
      done
    done
  done
fi
/usr/bin/python3 - "$CSV" <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
print(lines[0])
kv = lambda l: dict(p.split("=", 1) for p in l.split()[1:] if "=" in p)
probes = [kv(l) for l in lines[1:] if l.startswith("probe ")]
bw, peak = {}, {}
for p in probes:
    t = int(p["threads"])
    if p["probe"] == "triad":
        bw[t] = max(bw.get(t, 0.0), float(p["gbs"]))
    elif p["gflops"] != "nan":
        peak[t] = max(peak.get(t, 0.0), float(p["gflops"]))
print("\n| probe | 1 thread | 2 threads |\n|---|---:|---:|")
print(f"| triad a = b + s·c (GB/s, best of runs) | {bw.get(1, float('nan')):.1f} | {bw.get(2, float('nan')):.1f} |")
print(f"| FMA peak, AVX2 (GFLOP/s, best of runs) | {peak.get(1, float('nan')):.1f} | {peak.get(2, float('nan')):.1f} |")
rows = [kv(l) for l in lines[1:] if l.startswith("ba ")]
print("\n| dim | points | terms/point | threads | load | residual s | residual terms/s | GFLOP/s | GB/s | "
      "bound terms/s | fraction of bound | tangent terms/s | tangent member pairs/s |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for r in rows:
    t = int(r["threads"])
    fpt, bpt = float(r["flops_per_term"]), float(r["bytes_per_term"])
    ai = fpt / bpt
    bound_flops = min(peak.get(t, float("inf")), ai * bw.get(t, float("nan")))  # GFLOP/s
    bound_terms = bound_flops * 1e9 / fpt
    rate = float(r["residual_terms_per_s"])
    tan = r["tangent_terms_per_s"]
    tan = "|" if tan in ("nan", "-nan") else f"{float(tan):.3g} | {float(r['tangent_pairs_per_s']):.3g}"
    print(f"| {r['dim']} | {int(r['points']):,} | {float(r['terms_per_point']):.0f} | {t} | {r['load']} | "
          f"{float(r['residual_s']):.4g} | {rate:.3g} | {float(r['residual_gflops']):.2f} | "
          f"{float(r['residual_gbs']):.2f} | {bound_terms:.3g} | {rate / bound_terms:.2f} (1/{bound_terms / rate:.1f}) | {tan} |")
roof = [kv(l) for l in lines[1:] if l.startswith("roof ")]
if roof:
    print("\n| dim | points | sweep | load | best triad GB/s (same process) | residual terms/s (best) | "
          "bound terms/s | fraction of bound | best fraction within a round |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|")
    for r in roof:
        print(f"| {r['dim']} | {int(r['points']):,} | {r['path']} | {r['load']} | {float(r['best_triad_gbs']):.1f} | "
              f"{float(r['best_terms_per_s']):.3g} | {float(r['bound_terms_per_s']):.3g} | "
              f"{float(r['fraction']):.2f} (1/{float(r['one_over']):.1f}) | "
              f"{float(r['best_round_fraction']):.2f} (1/{1 / float(r['best_round_fraction']):.1f}) |")
print("\nMemory (live heap bytes; 'min' = the data that must be held, see ba_roofline.cpp):\n")
print("| dim | points | terms | discretization B/point | B/term | min B/term | ratio | model B/point | "
      "B/term | tangent (K + stencil tangents + row index) B/point | K min B/point | ratio |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
seen = set()
for r in rows:
    key = (r["dim"], r["points"])
    if key in seen:
        continue
    seen.add(key)
    N, T = int(r["points"]), int(r["terms"])
    disc, dmin, model = int(r["disc_bytes"]), float(r["disc_min_bytes"]), int(r["model_bytes"])
    tanb, kmin = int(r["tangent_bytes"]), float(r["k_min_bytes"])
    tcol = f"{tanb / N:.0f} | {kmin / N:.0f} | {tanb / kmin:.2f}" if tanb > 0 else " | | "
    print(f"| {r['dim']} | {N:,} | {T:,} | {disc / N:.0f} | {disc / T:.1f} | {dmin / T:.1f} | {disc / dmin:.2f} | "
          f"{model / N:.0f} | {model / T:.2f} | {tcol} |")
bodies = [kv(l) for l in lines[1:] if l.startswith("body ")]
if bodies:
    print("\nBodies (live heap bytes of the Body; min = data it must hold, see body_memory.cpp):\n")
    print("| kind | atoms | bonds | B/atom | B/bond | min B/atom | ratio | within 2× |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for b in bodies:
        r = float(b["ratio"])
        print(f"| {b['kind']} | {int(b['atoms']):,} | {int(b['bonds']):,} | {float(b['bytes_per_atom']):.0f} | "
              f"{float(b['bytes_per_bond']):.1f} | {float(b['min_per_atom']):.0f} | {r:.2f} | {'yes' if r <= 2 else 'no'} |")
PY
echo "wrote $CSV"
