#!/usr/bin/env bash
# Surface energies of docs/fracture.md §4: every row of the table, pdcg against slabs built and
# minimised by LAMMPS alone (surface_lammps.py). Prints one line per plane.
# Usage: workflows/fracture/run.sh [path/to/pdcg]   (default: build/pdcg of this checkout)
set -u
here=$(cd "$(dirname "$0")" && pwd)
src=$(cd "$here/../.." && pwd)
pdcg=${1:-$src/build/pdcg}
status=0
bash "$src/tests/cli/surface_lammps.sh" "$pdcg" "$src" fast || status=1
bash "$src/tests/cli/surface_lammps.sh" "$pdcg" "$src" slow || status=1
exit $status
