#!/usr/bin/env bash
# Installs what is missing (Debian, as root), builds, and runs every test.
# Exit code 0 only when all tests pass. Extra arguments go to ctest
# (e.g. ./tests/run.sh -L core, ./tests/run.sh -LE slow).
set -euo pipefail
source "$(dirname "$0")/../workflows/lib/setup.sh"
pdcg_install_dependencies
pdcg_build
cd "$PDCG_BUILD"
ctest --output-on-failure -j"${PDCG_JOBS:-2}" --timeout 1200 "$@"
