#!/usr/bin/env bash
# Installs what is missing (Debian, as root), builds, and runs every test.
# Exit code 0 only when all tests pass. Extra arguments go to ctest
# (e.g. ./tests/run.sh -L core, ./tests/run.sh -LE slow).
# Then, unless PDCG_CHECKS=0, the sanitizer and fuzzing checks (docs/testing.md "Sanitizers
# and fuzzing", with their cost in the CI budget): tests/sanitize.sh (one clang-14 ASan +
# UBSan build, build-checks/, and the suite there without the labels slow and cli) and
# tests/fuzz/run.sh (every libFuzzer harness, built in that same tree, PDCG_FUZZ_SECONDS (3)
# each after its corpus replay). CI (.ci/run) runs them; PDCG_CHECKS=0 ./tests/run.sh skips
# them locally. The extra ctest arguments apply to the Release tests only.
set -euo pipefail
export PDCG_CHECKS=${PDCG_CHECKS:-1}
export PDCG_TESTS=1  # the test suite's own packages too (ParaView, Xvfb: setup.sh)
source "$(dirname "$0")/../workflows/lib/setup.sh"
pdcg_install_dependencies
pdcg_build
cd "$PDCG_BUILD"
# ctest -j2 runs two tests at once, each with OpenMP threads, on a 2-core machine: idle
# OpenMP threads must sleep, not spin, or they steal the cores of the other test.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-PASSIVE}
pdcg_seed_test_costs "$PDCG_BUILD"  # long tests first (setup.sh)
ctest --output-on-failure -j"${PDCG_JOBS:-2}" --timeout 1200 "$@"
if [ "$PDCG_CHECKS" = 1 ]; then
  t0=$SECONDS
  "$PDCG_ROOT/tests/sanitize.sh"
  t1=$SECONDS
  PDCG_FUZZ_SECONDS=${PDCG_FUZZ_SECONDS:-3} "$PDCG_ROOT/tests/fuzz/run.sh"
  echo "checks: sanitizer build + suite $((t1 - t0)) s, fuzzing $((SECONDS - t1)) s"
fi
