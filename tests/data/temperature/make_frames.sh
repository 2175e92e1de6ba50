#!/usr/bin/env bash
# Makes the frame set of tests/unit/body/test_temperature.cpp with the temperature workflow's
# LAMMPS deck (workflows/temperature/md.in): fcc LJ (lj/cut 2.5, shifted), 2×2×2 cells
# (32 atoms) relaxed at T = 0, NVT at T* = 0.2 for 5000 steps, then 5000 steps sampled with a
# frame every 100 (51 frames). Writes here: frames.dump.gz (id type x y z c_pe, 17 digits),
# frames.txt (per frame: step, pe per atom, virial-only pressure tensor of LAMMPS) and
# lattice.dump (the relaxed T = 0 lattice). ~2 s.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../../.." && pwd)
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
lmp -in "$ROOT/workflows/temperature/md.in" -var T 0.2 -var seed 4711 -var cells 2 \
  -var equil 5000 -var sample 5000 -var every 100 -var out "$TMP" -log none -screen none
gzip -9 -n -c "$TMP/frames.dump" >"$HERE/frames.dump.gz"
cp "$TMP/frames.txt" "$TMP/lattice.dump" "$HERE/"
