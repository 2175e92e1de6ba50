#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang-14, -DPDCG_FUZZ=ON: ASan + UBSan + coverage) in the
# build tree of tests/sanitize.sh (build-checks/, one build for both checks) and runs each one
# for a short time, one after the other, from its seed corpus tests/fuzz/corpus/<name>/ plus
# what earlier runs added. Exit code 0 only when no harness found a crash, a leak, undefined
# behaviour or a non-pdcg exception (docs/testing.md "Sanitizers and fuzzing").
#
#   tests/fuzz/run.sh                 every harness, PDCG_FUZZ_SECONDS (default 20) s each
#   tests/fuzz/run.sh eam scene       only those harnesses
#   PDCG_FUZZ_RUNS=1000000 tests/fuzz/run.sh dump_text    a fixed number of executions
#   PDCG_FUZZ_RUNS=1000000 PDCG_FUZZ_SECONDS=3600 ...      whichever comes first
#
# New inputs go to build-checks/fuzz/corpus/<name>/ (kept between runs, never into the source
# tree); a crashing input is saved as build-checks/fuzz/artifacts/<name>-crash-<sha1>.
# Reproduce one: build-checks/fuzz_<name> <file>.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
export PDCG_CHECKS=1
source "$HERE/../../workflows/lib/setup.sh"
B=${PDCG_CHECKS_BUILD:-$PDCG_ROOT/build-checks}
export PDCG_CHECKS_BUILD=$B
"$HERE/../sanitize.sh" --build fuzz_all
X=$B  # CMAKE_RUNTIME_OUTPUT_DIRECTORY: every executable at the top of the tree

names=("$@")
if [ ${#names[@]} = 0 ]; then
  for f in "$HERE"/*.cpp; do names+=("$(basename "$f" .cpp)"); done
fi
S=$HERE/../sanitizers
# file:line in the reports (llvm-14; ASan looks for a plain llvm-symbolizer in PATH otherwise)
[ -x /usr/lib/llvm-14/bin/llvm-symbolizer ] &&
  export ASAN_SYMBOLIZER_PATH=${ASAN_SYMBOLIZER_PATH:-/usr/lib/llvm-14/bin/llvm-symbolizer}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1:print_stacktrace=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1:suppressions=$S/ubsan.supp}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$S/lsan.supp:print_suppressions=0}
export OMP_NUM_THREADS=1
# HDF5 harnesses: mutating an HDF5 file crashes HDF5 1.10.8 itself (Debian 12's libhdf5:
# H5HG_read SEGV, H5C_protect asking malloc for 2^63 bytes) within seconds, inside the library
# and before pdcg sees any data, so they only replay their corpus (-runs=0: every seed and
# saved input read clean); h5_struct fuzzes pdcg's own checks of valid HDF5 files instead.
# PDCG_FUZZ_SEED_ONLY= (empty) fuzzes the byte-level HDF5 harnesses too.
seed_only=" ${PDCG_FUZZ_SEED_ONLY-model_file h5_result} "
failed=()
for n in "${names[@]}"; do
  work=$B/fuzz/corpus/$n
  # scratch files of the harness (readers take paths): per harness, since two harnesses may
  # run at once; on tmpfs when there is one: ext4 writes back a truncated-and-rewritten file
  # at close, which made a dump harness spend most of its time in the kernel
  tmp=$B/fuzz/tmp/$n
  [ -d /dev/shm ] && [ -w /dev/shm ] && tmp=/dev/shm/pdcg-fuzz-$$/$n
  mkdir -p "$work" "$B/fuzz/artifacts" "$tmp"
  # PDCG_FUZZ_RUNS alone: that many executions; with PDCG_FUZZ_SECONDS too: whichever
  # comes first (a campaign with a deadline)
  limit=()
  [ -n "${PDCG_FUZZ_RUNS:-}" ] && limit=(-runs="$PDCG_FUZZ_RUNS")
  [ -z "${PDCG_FUZZ_RUNS:-}" ] || [ -n "${PDCG_FUZZ_SECONDS:-}" ] &&
    limit+=(-max_total_time="${PDCG_FUZZ_SECONDS:-20}")
  [[ "$seed_only" == *" $n "* ]] && limit=(-runs=0)
  echo "== fuzz_$n ${limit[*]}"
  # -timeout: one input taking > 10 s is a finding (a hang); -rss_limit_mb: an input that
  # makes a reader allocate > 2 GiB is a finding.
  if TMPDIR=$tmp "$X/fuzz_$n" "${limit[@]}" -timeout=10 -rss_limit_mb=2048 \
      -print_final_stats=1 -artifact_prefix="$B/fuzz/artifacts/$n-" \
      "$work" "$HERE/corpus/$n" 2>"$B/fuzz/$n.log"; then
    grep -E '^(stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb)|cov: ' \
      "$B/fuzz/$n.log" | tail -4
  else
    echo "FAIL fuzz_$n (log: $B/fuzz/$n.log)"
    grep -E 'ERROR|SUMMARY|exception|Test unit written' "$B/fuzz/$n.log" | head -5
    failed+=("$n")
  fi
  rm -rf "$tmp"
done
rmdir "/dev/shm/pdcg-fuzz-$$" 2>/dev/null || true
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in ${failed[*]}" >&2
  exit 1
fi
echo "fuzz: ${#names[@]} harnesses, no findings"
