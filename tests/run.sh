#!/usr/bin/env bash
# Installs what is missing (Debian, as root), builds, and runs every test.
# Exit code 0 only when all tests pass. Extra arguments go to ctest
# (e.g. ./tests/run.sh -L core, ./tests/run.sh -LE slow).
# With PDCG_CHECKS=1 the sanitizer and fuzzing checks follow the tests: tests/sanitize.sh
# (ASan + UBSan build of the suite) and tests/fuzz/run.sh (short libFuzzer runs of every
# reader). They are off by default until their cost on a fresh 2-core machine is measured
# against the CI budget (docs/testing.md).
set -euo pipefail
source "$(dirname "$0")/../workflows/lib/setup.sh"
pdcg_install_dependencies
pdcg_build
cd "$PDCG_BUILD"
# ctest -j2 runs two tests at once, each with OpenMP threads, on a 2-core machine: idle
# OpenMP threads must sleep, not spin, or they steal the cores of the other test.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-PASSIVE}
ctest --output-on-failure -j"${PDCG_JOBS:-2}" --timeout 1200 "$@"
if [ "${PDCG_CHECKS:-0}" = 1 ]; then
  "$PDCG_ROOT/tests/sanitize.sh"
  "$PDCG_ROOT/tests/fuzz/run.sh"
fi
