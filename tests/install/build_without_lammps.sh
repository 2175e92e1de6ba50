#!/usr/bin/env bash
# PDCG_ENABLE_LAMMPS=OFF must still build everything that does not need LAMMPS,
# and `pdcg version` must say LAMMPS is not enabled.
# Usage: build_without_lammps.sh <source-dir> <scratch-build-dir>
set -euo pipefail
src=$1 build=$2
gen=()
command -v ninja >/dev/null && gen=(-G Ninja)
# -O0: this test checks that everything builds (and warning-free) without LAMMPS; optimised
# code is built and tested by the main build. -O0 compiles Eigen-heavy code about 3x faster.
# PDCG_PYTHON=OFF: the module's source has no LAMMPS-dependent code (only the atomistic
# library and the CLI do), and its pybind11 compile is the costliest file of this build.
cmake -S "$src" -B "$build" "${gen[@]}" -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS=-O0 -DPDCG_ENABLE_LAMMPS=OFF \
      -DPDCG_PYTHON=OFF \
      -DPDCG_ENABLE_TESTING=OFF -DPDCG_ENABLE_BENCHMARKS=OFF > "$build.configure.log" 2>&1 \
  || { tail -30 "$build.configure.log"; exit 1; }
cmake --build "$build" -j2 > "$build.build.log" 2>&1 || { grep -E 'error|Error' "$build.build.log" | head -30; exit 1; }
if grep -q 'warning:' "$build.build.log"; then
  grep 'warning:' "$build.build.log" | head; echo "warnings in our code"; exit 1; fi
"$build/pdcg" version | grep -q 'LAMMPS .*not enabled'
echo "build_without_lammps: passed"
