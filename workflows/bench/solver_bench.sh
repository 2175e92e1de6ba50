#!/usr/bin/env bash
# BA solver benchmark (issue 6): residual+tangent assembly time and linear-solve time per
# Newton iteration versus the number of points, 2D (plane strain, UMFPACK) and 3D, with the
# fitted growth exponent t ∝ N^p. Writes $OUT/solver_bench.csv and prints the fit.
#   workflows/bench/solver_bench.sh [OUT=build/bench]
# Environment: SIZES_2D (points per edge, default "100 200 400" = 10⁴, 4·10⁴, 1.6·10⁵),
#   SIZES_3D (default "10 14 18 22"; 22³ ≈ 10⁴; 37³ ≈ 5·10⁴ only if BENCH_3D_LARGE=1),
#   LINEAR_3D (default bicgstab), OMP_NUM_THREADS (default: all cores).
set -euo pipefail
source "$(dirname "$0")/../lib/setup.sh"
pdcg_build_target() {  # configure once, build only the given targets
  [[ -f "$PDCG_BUILD/CMakeCache.txt" ]] || cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target "$@"
}
pdcg_build_target bench_solver_newton >/dev/null
BIN="$PDCG_BUILD/workflows/bench/bench_solver_newton"
[[ -x "$BIN" ]] || BIN=$(find "$PDCG_BUILD" -name bench_solver_newton -type f | head -1)
OUT=${1:-$PDCG_BUILD/bench}
mkdir -p "$OUT"
CSV="$OUT/solver_bench.csv"
echo "# $(date -u +%FT%TZ) $(uname -n) load: $(cut -d' ' -f1-3 /proc/loadavg) threads: ${OMP_NUM_THREADS:-$(nproc)}" >"$CSV"
echo "dim,n,points,linear,newton_iterations,assembly_s_per_it,solve_s_per_it,peak_rss_mb" >>"$CSV"
run() {
  local line
  line=$("$BIN" "$@")
  echo "$line"
  # key=value pairs → CSV
  /usr/bin/python3 - "$line" >>"$CSV" <<'PY'
import sys
kv = dict(p.split("=") for p in sys.argv[1].split())
print(",".join(kv[k] for k in ["dim", "n", "points", "linear", "newton_iterations",
                               "assembly_s_per_it", "solve_s_per_it", "peak_rss_mb"]))
PY
}
for n in ${SIZES_2D:-100 200 400}; do run 2 "$n" umfpack; done
SIZES=${SIZES_3D:-10 14 18 22}
[[ "${BENCH_3D_LARGE:-0}" == 1 ]] && SIZES="$SIZES 37"
for n in $SIZES; do run 3 "$n" "${LINEAR_3D:-bicgstab}"; done
/usr/bin/python3 - "$CSV" <<'PY'
import sys, numpy as np
rows = [l.strip().split(",") for l in open(sys.argv[1]) if l[0].isdigit()]
for dim in ("2", "3"):
    r = [x for x in rows if x[0] == dim]
    if len(r) < 2:
        continue
    N = np.array([float(x[2]) for x in r])
    for col, name in ((5, "assembly"), (6, "linear solve")):
        t = np.array([float(x[col]) for x in r])
        p, c = np.polyfit(np.log(N), np.log(t), 1)
        print(f"{dim}D {name}: t = {np.exp(c):.3e} N^{p:.2f}  (N = {', '.join(f'{int(v)}' for v in N)})")
PY
echo "wrote $CSV"
