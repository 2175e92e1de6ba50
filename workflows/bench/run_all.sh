#!/usr/bin/env bash
# All performance benchmarks in one command: prints every table and writes them,
# with the machine and the load, into the generated block at the end of docs/performance.md
# (between the `<!-- bench:generated:begin -->` and `<!-- bench:generated:end -->` markers;
# the hand-written analysis above the block is left alone). The block is replaced as a whole,
# through a temporary file renamed over docs/performance.md: an interrupted run leaves the
# old file.
#
#   workflows/bench/run_all.sh            quick sizes (≈ 3 min on a quiet 2-core machine, longer under load)
#   FULL=1 workflows/bench/run_all.sh     the sizes of docs/performance.md (hours; ≈ 15 GB peak)
#   NO_DOCS=1 …                           print only, do not touch docs/performance.md
#
# Runs, each with its own peer in the same script:
#   1. md_vs_lammps.sh   pdcg md vs lmp / lmp -sf opt, FCC LJ and FCC Cu EAM, 1 and 2 threads
#   2. roofline.sh       BA residual/tangent vs the machine's triad and FMA probes; memory
#   3. solver_bench.sh   Newton iteration split (assembly, factorisation, solve), memory
#   4. parse_dump.sh     dump parsing vs LAMMPS read_dump (MB/s)
#   5. bench_delta_body  body building, seconds and bytes per atom
#   6. manybody_vs_lammps.sh  native sw/tersoff: one force evaluation and pdcg md vs lmp
# Environment passed through to the scripts (see each script's header for the sizes).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
source "$here/../lib/setup.sh"
[[ -f "$PDCG_BUILD/CMakeCache.txt" ]] ||
  cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" >/dev/null
OUT=${OUT:-$PDCG_BUILD/bench}
mkdir -p "$OUT"
report="$OUT/run_all.md"
: >"$report"

full=${FULL:-0}
if [[ $full == 1 ]]; then
  md_cells="20 40" md_repeat=3
  roof_env=()
  solver_env=(BIG=1)
  dump_env=()
  body_cells=63
  mb_cells="3 10 20"
else
  md_cells="20 40" md_repeat=1
  roof_env=(SIZES_2D="100 316" SIZES_3D="12" TANGENT_2D=100 TANGENT_3D=8 ROOF_ROUNDS=2 REPEAT=1)
  solver_env=(SIZES_2D="50 100" SIZES_3D="8 10" COMPARE_SOLVERS="cholmod gmres gmres-mf")
  dump_env=(FRAMES=3 CELLS=40)
  body_cells=32
  mb_cells="3 10"
fi

section() {  # title, then the command's stdout goes to the terminal and the report
  local title=$1
  shift
  echo
  echo "=== $title"
  {
    echo
    echo "### $title"
    echo
    echo "Started $(date -u +%Y-%m-%dT%H:%MZ), load $(cut -d' ' -f1-3 /proc/loadavg)."
    echo
  } >>"$report"
  # stderr (progress) to the terminal only; the raw key=value rows the scripts also print
  # (their tables are made from them) stay out of the report
  local raw="$OUT/run_all.raw"
  "$@" | tee "$raw"
  grep -v -E '^(dim=|ba |roof |probe |round=)' "$raw" >>"$report" || true
}

machine=$(lscpu | sed -n 's/^Model name: *//p' | head -1)
mem=$(awk '/MemTotal/ {printf "%.1f GB", $2 / 1048576}' /proc/meminfo)
started=$(date -u +%Y-%m-%dT%H:%MZ)

section "1. Fixed-family dynamics vs LAMMPS (md_vs_lammps.sh)" \
  env CELLS="$md_cells" REPEAT="$md_repeat" bash "$here/md_vs_lammps.sh" "$PDCG_BUILD/pdcg"
section "2. BA kernels against the roofline (roofline.sh)" \
  env "${roof_env[@]}" bash "$here/roofline.sh" "$OUT"
section "3. Newton iteration of the BA solver (solver_bench.sh)" \
  env "${solver_env[@]}" bash "$here/solver_bench.sh" "$OUT"
section "4. Dump parsing vs LAMMPS read_dump (parse_dump.sh)" \
  env "${dump_env[@]}" bash "$here/parse_dump.sh" "$PDCG_BUILD" "$OUT/dump"
delta_bin=$(find "$PDCG_BUILD" -name bench_delta_body -type f -perm -u+x | head -1)
section "5. Body building (bench_delta_body $body_cells)" "$delta_bin" "$body_cells"
section "6. Native sw and tersoff vs LAMMPS (manybody_vs_lammps.sh)" \
  env CELLS="$mb_cells" REPEAT="$md_repeat" bash "$here/manybody_vs_lammps.sh" "$PDCG_BUILD/pdcg"

if [[ ${NO_DOCS:-0} == 1 ]]; then
  echo "tables in $report (docs/performance.md not touched: NO_DOCS=1)"
  exit 0
fi
doc="$PDCG_ROOT/docs/performance.md"
begin='<!-- bench:generated:begin -->'
end='<!-- bench:generated:end -->'
tmp=$(mktemp "$doc.XXXXXX")
chmod --reference="$doc" "$tmp"
trap 'rm -f "$tmp"' EXIT
/usr/bin/python3 - "$doc" "$report" "$tmp" "$begin" "$end" "$started" "$machine" "$mem" "$full" <<'PY'
import sys
doc, report, tmp, begin, end, started, machine, mem, full = sys.argv[1:]
text = open(doc).read()
block = (f"{begin}\n## Generated tables (`workflows/bench/run_all.sh`)\n\n"
         f"Written by `workflows/bench/run_all.sh` ({'FULL=1, the documented sizes' if full == '1' else 'quick sizes'}), "
         f"started {started} on {machine}, {mem}; each script prints its machine line and load. "
         "Everything above this block is the hand-written analysis of earlier runs.\n"
         + open(report).read() + f"\n{end}\n")
if begin in text and end in text:
    head = text[:text.index(begin)]
    tail = text[text.index(end) + len(end):].lstrip("\n")
    text = head + block + tail
else:
    text = text.rstrip("\n") + "\n\n" + block
open(tmp, "w").write(text)
PY
mv "$tmp" "$doc"
trap - EXIT
echo "wrote the generated block of $doc (tables also in $report)"
