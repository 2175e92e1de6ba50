#!/usr/bin/env bash
# BA solver benchmark (docs/performance.md "BA solver"): per Newton iteration, residual+tangent assembly,
# factorisation, and the rest of the linear solve (reduction + triangular solves / Krylov
# iterations), and peak memory, versus the number of points; 2D (plane strain) and 3D unit
# square / cube, m = 3.015, weak form (UMFPACK) plus, at the comparison sizes, the symmetric
# energy form with CHOLMOD, the weak form with GMRES preconditioned by the lattice (Q1)
# stiffness (linear: gmres) and BiCGSTAB + ILUT. Writes $OUT/solver_bench.csv (one row per
# run, with the 1-minute load average at its start), prints a markdown table and the fitted
# growth t ∝ N^p.
#   workflows/bench/solver_bench.sh [OUT=build/bench]          (minutes)
#   BIG=1 workflows/bench/solver_bench.sh                       (adds the big cases: ≈ 1 h
#     on a quiet 2-core machine, ≈ 15 GB peak: 2D 400² = 1.6·10⁵ points with UMFPACK and
#     GMRES, 3D 22³ ≈ 10⁴ points with UMFPACK, GMRES and matrix-free GMRES, GMRES on
#     BIG_GMRES_3D and matrix-free GMRES on BIG_MF_3D)
#   MF_3D="10 22 37" workflows/bench/solver_bench.sh            (only the matrix-free 3D rows
#     when SIZES_2D="" SIZES_3D="" are also set; 37³ = 50 653 points: 12.4 GB peak, ≈ 20 min)
# Environment: SIZES_2D (points per edge, default "50 100 200"), SIZES_3D (default
#   "8 10 14 18"), COMPARE_2D (default "100"), COMPARE_3D (default "10"): sizes at which
#   CHOLMOD (energy), GMRES and BiCGSTAB+ILUT also run (COMPARE_SOLVERS, default
#   "cholmod gmres bicgstab gmres-mf", selects among them; gmres-mf = GMRES with
#   matrix-free products); BIG_GMRES_3D (default "28": the largest 3D cube that fits this
#   23 GB machine with the assembled GMRES; 37³ ≈ 5·10⁴ does not, see docs/performance.md),
#   BIG_MF_3D (default "37": matrix-free GMRES, 5·10⁴ points), MF_3D (default "": extra 3D
#   sizes run with matrix-free GMRES only), TOL (Newton tolerance, default 1e-8),
#   OMP_NUM_THREADS (default: all cores). An empty list (SIZES_2D="") skips that part.
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
BLAS=$(readlink -f /usr/lib/x86_64-linux-gnu/libblas.so.3 2>/dev/null || echo unknown)
echo "# $(date -u +%FT%TZ) $(uname -n) $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores, load: $(cut -d' ' -f1-3 /proc/loadavg), threads: ${OMP_NUM_THREADS:-$(nproc)}, BLAS: $BLAS" >"$CSV"
KEYS="dim n points linear form newton_iterations krylov_iterations products product_s product_s_per_it operator_mb assembly_s_per_it factor_s_per_it solve_s_per_it rss_before_newton_mb peak_rss_mb load1 history"
echo "${KEYS// /,}" >>"$CSV"
run() {
  local line
  # (CHOLMOD prints its warnings on stdout: keep the result line only)
  # (a failed run — out of memory, a NumericalError — is reported and skipped)
  line=$("$BIN" "$@" "${TOL:-1e-8}" | grep '^dim=') || { echo "run $* failed" >&2; return 0; }
  echo "$line"
  /usr/bin/python3 - "$line" "$KEYS" >>"$CSV" <<'PY'
import sys
kv = dict(p.split("=") for p in sys.argv[1].split())
print(",".join(kv[k] for k in sys.argv[2].split()))
PY
}
for n in ${SIZES_2D-50 100 200}; do
  run 2 "$n" umfpack weak
  if [[ " ${COMPARE_2D-100} " == *" $n "* ]]; then
    for ls in ${COMPARE_SOLVERS-cholmod gmres bicgstab gmres-mf}; do
      if [[ $ls == cholmod ]]; then run 2 "$n" cholmod energy; else run 2 "$n" "$ls" weak; fi
    done
  fi
done
for n in ${SIZES_3D-8 10 14 18}; do
  run 3 "$n" umfpack weak
  if [[ " ${COMPARE_3D-10} " == *" $n "* ]]; then
    for ls in ${COMPARE_SOLVERS-cholmod gmres bicgstab gmres-mf}; do
      if [[ $ls == cholmod ]]; then run 3 "$n" cholmod energy; else run 3 "$n" "$ls" weak; fi
    done
  fi
done
for n in ${MF_3D-}; do run 3 "$n" gmres-mf weak; done
if [[ "${BIG:-0}" == 1 ]]; then
  run 2 400 umfpack weak
  run 2 400 gmres weak
  run 3 22 umfpack weak
  run 3 22 gmres weak
  run 3 22 gmres-mf weak
  for n in ${BIG_GMRES_3D-28}; do run 3 "$n" gmres weak; done
  for n in ${BIG_MF_3D-37}; do run 3 "$n" gmres-mf weak; done
fi
/usr/bin/python3 - "$CSV" <<'PY'
import sys, numpy as np
lines = open(sys.argv[1]).read().splitlines()
print(lines[0])
head = lines[1].split(",")
rows = [dict(zip(head, l.split(","))) for l in lines[2:] if l and l[0].isdigit()]
print("| dim | points | linear (form) | Newton its | Krylov its | products (s each) | assembly s/it | factorisation s/it | rest of solve s/it | of which products s/it | RSS before Newton MB | peak RSS MB | kB/point | load |")
print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for r in rows:
    print(f"| {r['dim']} | {int(r['points']):,} | {r['linear']} ({r['form']}) | {r['newton_iterations']} | "
          f"{r['krylov_iterations']} | {r['products']} ({float(r['product_s']):.3g}) | "
          f"{float(r['assembly_s_per_it']):.3g} | {float(r['factor_s_per_it']):.3g} | "
          f"{float(r['solve_s_per_it']):.3g} | {float(r['product_s_per_it']):.3g} | "
          f"{float(r['rss_before_newton_mb']):.0f} | {float(r['peak_rss_mb']):.0f} | "
          f"{1024 * float(r['peak_rss_mb']) / int(r['points']):.0f} | {r['load1']} |")
fits = [("umfpack", (("assembly_s_per_it", "assembly"), ("factor_s_per_it", "factorisation"))),
        ("gmres-mf", (("assembly_s_per_it", "residual + stencil tangents"),
                      ("product_s", "one product"), ("peak_rss_mb", "peak RSS")))]
for dim in ("2", "3"):
    for ls, cols in fits:
        r = [x for x in rows if x["dim"] == dim and x["linear"] == ls]
        if len(r) < 2:
            continue
        N = np.array([float(x["points"]) for x in r])
        for col, name in cols:
            t = np.array([float(x[col]) for x in r])
            p, c = np.polyfit(np.log(N), np.log(t), 1)
            print(f"{dim}D {name} ({ls} rows): t = {np.exp(c):.3e} N^{p:.2f}  (N = {', '.join(f'{int(v)}' for v in N)})")
PY
echo "wrote $CSV"
