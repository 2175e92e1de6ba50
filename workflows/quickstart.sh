#!/usr/bin/env bash
# The main job of pdcg: from LAMMPS atoms to a peridynamic model, checked against LAMMPS.
#
#   ./workflows/quickstart.sh            (as root on Debian 12: installs what is missing)
#
# Steps (each prints what it did; results in results/quickstart/):
#   1. install missing Debian packages, configure and build into build/
#   2. LAMMPS: a perturbed FCC Lennard-Jones crystal (atomistics/lj_fcc), its forces and energies
#   3. pdcg: inspect, delta body (forces vs LAMMPS), homogenise, rescale, dispersion, BA plate
#   4. flagship (docs/flagship.md): 2D triangular LJ sheet relaxed by LAMMPS, its delta body
#      (forces vs LAMMPS), coarse model (homogenised + rescaled), dispersion atoms vs coarse, a
#      notched coarse sheet pulled to rupture by the BA solver with the Cauchy–Born material,
#      and LAMMPS MD fracture of the same sheet; report.md + PNGs + a summary on stdout
set -euo pipefail
source "$(dirname "$0")/lib/setup.sh"
pdcg_install_dependencies
mkdir -p "$PDCG_BUILD"  # a fresh clone has no build/ yet: the log goes there
pdcg_build > "$PDCG_BUILD/quickstart-build.log" 2>&1 || { tail -40 "$PDCG_BUILD/quickstart-build.log"; exit 1; }

out="$PDCG_ROOT/results/quickstart"
mkdir -p "$out"
pdcg="$PDCG_BUILD/pdcg"
case_dir="$PDCG_ROOT/atomistics/lj_fcc"

echo "== 1. pdcg $("$pdcg" version | head -1 | awk '{print $2}') built in $PDCG_BUILD"
echo "== 2. LAMMPS: perturbed FCC Lennard-Jones crystal (256 atoms)"
(cd "$case_dir" && lmp -in in.lj_fcc -var out "$out" -log "$out/lammps.log" -screen none)
echo "   wrote $out/lj_fcc.data and $out/lj_fcc.dump (LAMMPS forces and per-atom energies)"

if [ -x "$PDCG_ROOT/workflows/quickstart/pipeline.sh" ]; then
  "$PDCG_ROOT/workflows/quickstart/pipeline.sh" "$pdcg" "$case_dir" "$out"
else
  echo "== 3. pdcg versions of the libraries in use:"
  "$pdcg" version | sed 's/^/   /'
fi
echo
echo "Results are in $out"
