#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build of the test suite, which is also the
# build of the libFuzzer harnesses (tests/fuzz/run.sh): one clang-14 tree, build-checks/,
# configured with -DPDCG_FUZZ=ON (every target -fsanitize=address,undefined
# -fno-sanitize-recover=all, the libraries also -fsanitize=fuzzer-no-link, the harnesses
# linked with -fsanitize=fuzzer), -O1 -gline-tables-only (line numbers in the reports, a
# fraction of the compile time of -g). Then ctest there with every sanitizer report fatal.
# Exit code 0 only when every selected test passes with no report (docs/testing.md
# "Sanitizers and fuzzing").
#
#   tests/sanitize.sh                 the CI selection: ctest -LE "$PDCG_ASAN_EXCLUDE", default
#                                     'slow|cli' (see docs/testing.md for what that leaves out)
#   PDCG_ASAN_EXCLUDE=slow tests/sanitize.sh    every test but the slow ones
#   tests/sanitize.sh -R dump         extra arguments go to ctest (replace the selection)
#   tests/sanitize.sh --build [target...]   configure and build only (tests/fuzz/run.sh uses
#                                     this with fuzz_all)
#   PDCG_CHECKS_BUILD=DIR             the build tree (default build-checks/)
#
# Suppressions (third-party libraries only, each with its reason): tests/sanitizers/*.supp.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
export PDCG_CHECKS=1
source "$HERE/../workflows/lib/setup.sh"
pdcg_install_dependencies
B=${PDCG_CHECKS_BUILD:-$PDCG_ROOT/build-checks}
if [ ! -f "$B/CMakeCache.txt" ]; then
  launcher=()
  if command -v ccache >/dev/null && [ "${CCACHE_DISABLE:-0}" != 1 ]; then
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  fi
  # Benchmarks off (not tests). LAMMPS stays on: the unit tests take LAMMPS as their
  # reference; the fuzz harnesses refuse non-native styles themselves (fuzz_potential.hpp).
  cmake -S "$PDCG_ROOT" -B "$B" -G Ninja "${launcher[@]}" \
    -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
    -DPDCG_FUZZ=ON -DPDCG_ENABLE_BENCHMARKS=OFF >/dev/null
fi
if [ "${1:-}" = --build ]; then  # --build [target...]: only build (default: everything)
  shift
  targets=()
  [ $# -gt 0 ] && targets=(--target "$@")
  cmake --build "$B" -j"${PDCG_JOBS:-2}" "${targets[@]}"
  exit 0
fi
cmake --build "$B" -j"${PDCG_JOBS:-2}"

S=$HERE/sanitizers
# file:line in the reports (llvm-14; ASan looks for a plain llvm-symbolizer in PATH otherwise)
[ -x /usr/lib/llvm-14/bin/llvm-symbolizer ] &&
  export ASAN_SYMBOLIZER_PATH=${ASAN_SYMBOLIZER_PATH:-/usr/lib/llvm-14/bin/llvm-symbolizer}
# halt_on_error: the first report ends the process (the test fails); detect_leaks: on, with
# the third-party leaks of lsan.supp suppressed.
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:abort_on_error=0:print_stacktrace=1:detect_leaks=1:detect_stack_use_after_return=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1:suppressions=$S/ubsan.supp}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$S/lsan.supp:print_suppressions=0}
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-PASSIVE}
cd "$B"
args=("$@")
[ ${#args[@]} = 0 ] && args=(-LE "${PDCG_ASAN_EXCLUDE:-slow|cli}")
ctest --output-on-failure -j"${PDCG_JOBS:-2}" --timeout 1800 "${args[@]}"
