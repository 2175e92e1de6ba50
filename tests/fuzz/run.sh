#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang, -DPDCG_FUZZ=ON: ASan + UBSan + coverage) into
# build-fuzz/ and runs each one for a short time, one after the other, starting from its seed
# corpus tests/fuzz/corpus/<name>/. Exit code 0 only when no harness found a crash, a leak,
# undefined behaviour or a non-pdcg exception (docs/testing.md "Sanitizers and fuzzing").
#
#   tests/fuzz/run.sh                 every harness, PDCG_FUZZ_SECONDS (default 20) s each
#   tests/fuzz/run.sh eam scene       only those harnesses
#   PDCG_FUZZ_RUNS=1000000 tests/fuzz/run.sh dump_text    a fixed number of executions
#
# New inputs go to build-fuzz/fuzz/corpus/<name>/ (kept between runs, never into the source
# tree); a crashing input is saved as build-fuzz/fuzz/artifacts/<name>-crash-<sha1>.
# Reproduce one: build-fuzz/fuzz_<name> <file>.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
export PDCG_CHECKS=1
source "$HERE/../../workflows/lib/setup.sh"
pdcg_install_dependencies
B=${PDCG_FUZZ_BUILD:-$PDCG_ROOT/build-fuzz}
if [ ! -f "$B/CMakeCache.txt" ]; then
  launcher=()
  command -v ccache >/dev/null &&
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  # LAMMPS off: the harnesses run native readers only (a LAMMPS style is refused with an
  # InputError, as in a build without LAMMPS); tests and benchmarks are not needed here.
  cmake -S "$PDCG_ROOT" -B "$B" -G Ninja "${launcher[@]}" \
    -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
    -DPDCG_FUZZ=ON -DPDCG_ENABLE_LAMMPS=OFF -DPDCG_ENABLE_TESTING=OFF \
    -DPDCG_ENABLE_BENCHMARKS=OFF -DBUILD_SHARED_LIBS=OFF
fi
cmake --build "$B" --target fuzz_all -j"${PDCG_JOBS:-2}"

names=("$@")
if [ ${#names[@]} = 0 ]; then
  for f in "$HERE"/*.cpp; do names+=("$(basename "$f" .cpp)"); done
fi
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1:print_stacktrace=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
export OMP_NUM_THREADS=1
# HDF5 harnesses: mutating an HDF5 file crashes HDF5 1.10.8 itself (Debian 12's libhdf5:
# H5HG_read SEGV, H5C_protect asking malloc for 2^63 bytes) within seconds, inside the library
# and before pdcg sees any data, so in CI they only replay their corpus (-runs=0: every seed
# and saved input read clean). PDCG_FUZZ_SEED_ONLY= (empty) fuzzes them too.
seed_only=" ${PDCG_FUZZ_SEED_ONLY-model_file h5_result} "
failed=()
for n in "${names[@]}"; do
  work=$B/fuzz/corpus/$n
  mkdir -p "$work" "$B/fuzz/artifacts" "$B/fuzz/tmp"
  limit=(-max_total_time="${PDCG_FUZZ_SECONDS:-20}")
  [ -n "${PDCG_FUZZ_RUNS:-}" ] && limit=(-runs="$PDCG_FUZZ_RUNS")
  [[ "$seed_only" == *" $n "* ]] && limit=(-runs=0)
  echo "== fuzz_$n ${limit[*]}"
  # -timeout: one input taking > 10 s is a finding (a hang); -rss_limit_mb: an input that
  # makes a reader allocate > 2 GiB is a finding. Scratch files go to build-fuzz/fuzz/tmp.
  if TMPDIR=$B/fuzz/tmp "$B/fuzz_$n" "${limit[@]}" -timeout=10 -rss_limit_mb=2048 \
      -print_final_stats=1 -artifact_prefix="$B/fuzz/artifacts/$n-" \
      "$work" "$HERE/corpus/$n" 2>"$B/fuzz/$n.log"; then
    grep -E '^(stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb)|cov: ' \
      "$B/fuzz/$n.log" | tail -4
  else
    echo "FAIL fuzz_$n (log: $B/fuzz/$n.log)"
    grep -E 'ERROR|SUMMARY|exception|Test unit written' "$B/fuzz/$n.log" | head -5
    failed+=("$n")
  fi
done
rm -rf "$B/fuzz/tmp"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in ${failed[*]}" >&2
  exit 1
fi
echo "fuzz: ${#names[@]} harnesses, no findings"
