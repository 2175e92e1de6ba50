#!/usr/bin/env bash
# pdcg tried as a new user would, on 20 systems made from scratch with LAMMPS (Debian's `lmp`
# and potential files): each is built by a deck (lattice/create_atoms or read_data), `lmp`
# writes the reference (run 0 dump with forces and pe/atom at %.17g, thermo pe/pressure), and
# pdcg runs on it through the CLI only (inspect, atoms2pd, forces, energy, elastic, homogenize,
# rescale, dispersion, md, run). Prints the table
#   system | how made | commands | max rel. force error | energy error | other | outcome
# and exits 1 when any row is WRONG or CRASH (or the trial itself failed).
# Usage: workflows/trial/run.sh [PDCG] [WORKDIR]   (PDCG default: build/pdcg; WORKDIR: a
#        temporary directory, removed afterwards unless given). ONLY=name,name selects systems.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
pdcg=${1:-$here/../../build/pdcg}
[ -x "$pdcg" ] || { echo "run.sh: no pdcg executable at $pdcg (build first, or pass its path)" >&2; exit 2; }
command -v lmp >/dev/null || { echo "run.sh: needs LAMMPS's lmp (Debian package lammps)" >&2; exit 2; }
/usr/bin/python3 -c "import lammps, numpy" 2>/dev/null ||
  { echo "run.sh: needs python3-lammps and python3-numpy for /usr/bin/python3" >&2; exit 2; }
if [ $# -ge 2 ]; then
  work=$2
  mkdir -p "$work"
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
# the python module `lammps` is Debian's, for /usr/bin/python3
/usr/bin/python3 "$here/trial.py" --pdcg "$pdcg" --work "$work" ${ONLY:+--only "$ONLY"}
