#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build of the test suite: builds into
# build-asan/ (GCC, -DPDCG_SANITIZE=address,undefined, -O1 -g -fno-omit-frame-pointer) and
# runs ctest there with every sanitizer report fatal (GCC: float-cast-overflow is not part of
# -fsanitize=undefined, it is added; clang has it in undefined). Exit code 0 only when every test
# passes with no report (docs/testing.md "Sanitizers and fuzzing").
#
#   tests/sanitize.sh                 the CI selection: ctest -LE "$PDCG_ASAN_EXCLUDE", default
#                                     'slow|cli' (see docs/testing.md for what that leaves out)
#   PDCG_ASAN_EXCLUDE=slow tests/sanitize.sh    every test but the slow ones
#   tests/sanitize.sh -R dump         extra arguments go to ctest (replace the selection)
#
# Suppressions (third-party libraries only, each with its reason): tests/sanitizers/*.supp.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../workflows/lib/setup.sh"
pdcg_install_dependencies
B=${PDCG_ASAN_BUILD:-$PDCG_ROOT/build-asan}
if [ ! -f "$B/CMakeCache.txt" ]; then
  launcher=()
  command -v ccache >/dev/null &&
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  cmake -S "$PDCG_ROOT" -B "$B" -G Ninja "${launcher[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
    -DPDCG_SANITIZE=address,undefined,float-cast-overflow -DPDCG_ENABLE_BENCHMARKS=OFF
fi
cmake --build "$B" -j"${PDCG_JOBS:-2}"
S=$HERE/sanitizers
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
