#!/usr/bin/env bash
# Distributed runs of `pdcg run` under mpirun against the serial run (docs/scale-out.md §5).
#
#   run_tests.sh PDCG MPIEXEC CASE [N]
#
# CASE: plate_mumps N   the plate with a hole on N processes (MUMPS) = the serial UMFPACK run
#                       within 1e-10 relative (reactions / load, fields / their max): both are
#                       direct solves, only the summation order differs (measured ≤ 1e-14).
#       plate_gamg N    the same with GMRES + GAMG (relative KSP tolerance 1e-12 per Newton
#                       iteration) within 1e-8, the Newton tolerance of the scene: an inexact
#                       linear solve changes the iterates, not the converged state beyond what the
#                       Newton tolerance admits (measured ≤ 1e-14).
#       block3d N       a 3D block on N processes (MUMPS) = serial UMFPACK within 1e-10 (as above).
#       dynamic N       an explicit dynamic fracture (dynamic_fracture.yaml) on N processes = the
#                       serial run: the same broken-bond count at every step and the same damage
#                       field at every output step (exactly), energies, reactions, displacement
#                       and velocity within 1e-10 relative (only the summation order of the forces
#                       differs; measured ≤ 1e-13, docs/scale-out.md §6).
#       dynamic3d N     the same for a 3D dynamic fracture (dynamic3d.yaml; measured 2.4e-15).
#       dynamic_damped N  damped explicit dynamics with a traction and an initial velocity
#                       (dynamic_damped.yaml) on N processes = the serial run: viscous damping
#                       within 1e-10 (as dynamic; measured 1.7e-14); adaptive dynamic relaxation
#                       within 1e-5: its c_n divides force differences by Δt v_i, so components
#                       with small v_i turn the round-off of f into relative changes of 1e-8..1e-6
#                       — the serial run itself moves 2.3e-6 between 1 and 2 OpenMP threads
#                       (measured 9.2e-8 on 2 processes; docs/scale-out.md §6).
#       too_many        4 points on 5 processes: refused (exit 2), clear message, nothing written.
#       bad_option      an unknown PETSc option: refused (exit 2) naming it, nothing written; for
#                       explicit dynamics, which reads none, too.
#       refused         checkpointing, quasi-static rupture, another effect, the softening law on
#                       2 processes: refused (exit 2) naming the key, nothing written.
# Root (CI): OpenMPI needs OMPI_ALLOW_RUN_AS_ROOT(_CONFIRM), set by ctest (tests/CMakeLists.txt).
set -euo pipefail
PDCG=$1 MPIEXEC=$2 CASE=$3 N=${4:-2}
HERE=$(cd "$(dirname "$0")" && pwd)
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
export OMP_NUM_THREADS=1  # one thread per process: the processes share the cores
mpi() { "$MPIEXEC" --oversubscribe -n "$@"; }
compare() { /usr/bin/python3 "$HERE/compare_runs.py" "$@"; }

expect_refusal() {  # expect_refusal PATTERN DIR -- command...
  local pattern=$1 dir=$2
  shift 3
  set +e
  "$@" >"$W/out" 2>&1
  local rc=$?
  set -e
  cat "$W/out"
  [ "$rc" = 2 ] || { echo "FAIL: exit code $rc, expected 2 (bad input)"; exit 1; }
  grep -q -- "$pattern" "$W/out" || { echo "FAIL: no message matching '$pattern'"; exit 1; }
  [ ! -e "$dir" ] || { echo "FAIL: a refused run wrote $dir"; exit 1; }
  echo "ok: refused with exit 2 and the message"
}

case "$CASE" in
  plate_mumps | plate_gamg | block3d)
    scene=$HERE/plate.yaml
    [ "$CASE" = block3d ] && scene=$HERE/block3d.yaml
    "$PDCG" -q run "$scene" -o "$W/serial"
    if [ "$CASE" = plate_gamg ]; then
      sed 's/linear: umfpack/linear: gamg/' "$scene" >"$W/scene.yaml"
      scene=$W/scene.yaml
      tol=1e-8
    else
      tol=1e-10
    fi
    mpi "$N" "$PDCG" -q run "$scene" -o "$W/mpi"
    compare "$W/serial" "$W/mpi" "$tol"
    ;;
  dynamic | dynamic3d)
    scene=$HERE/dynamic_fracture.yaml
    [ "$CASE" = dynamic3d ] && scene=$HERE/dynamic3d.yaml
    "$PDCG" -q run "$scene" -o "$W/serial"
    mpi "$N" "$PDCG" -q run "$scene" -o "$W/mpi"
    /usr/bin/python3 "$HERE/compare_dynamic.py" "$W/serial" "$W/mpi" 1e-10
    ;;
  dynamic_damped)
    sed 's/type: viscous, coefficient: 0.2/type: adaptive-dynamic-relaxation/' \
      "$HERE/dynamic_damped.yaml" >"$W/adr.yaml"
    grep -q adaptive "$W/adr.yaml"
    for run in "$HERE/dynamic_damped.yaml 1e-10" "$W/adr.yaml 1e-5"; do
      read -r scene tol <<<"$run"
      rm -rf "$W/serial" "$W/mpi"
      echo "== $(basename "$scene")"
      "$PDCG" -q run "$scene" -o "$W/serial"
      mpi "$N" "$PDCG" -q run "$scene" -o "$W/mpi"
      /usr/bin/python3 "$HERE/compare_dynamic.py" "$W/serial" "$W/mpi" "$tol"
    done
    ;;
  too_many)
    expect_refusal "partition would leave a process without points" "$W/out5" -- \
      mpi 5 "$PDCG" -q run "$HERE/four_points.yaml" -o "$W/out5"
    ;;
  bad_option)
    expect_refusal "PETSc option not used by the solver: -ksp_no_such_option" "$W/bad" -- \
      mpi 2 "$PDCG" -q run "$HERE/plate.yaml" -o "$W/bad" --petsc-options "-ksp_no_such_option 3"
    # explicit dynamics reads no PETSc option: any (but a viewer) is refused
    expect_refusal "PETSc option not used by the solver: -ksp_no_such_option.*explicit dynamics" \
      "$W/bad_dyn" -- mpi 2 "$PDCG" -q run "$HERE/dynamic_fracture.yaml" -o "$W/bad_dyn" \
      --petsc-options "-ksp_no_such_option 3"
    ;;
  refused)
    # checkpointing, rupture and explicit dynamics on 2 processes: refused before any work,
    # naming the key
    sed 's/output: {directory: plate, every: 5}/output: {directory: plate, every: 5, checkpoint_every: 1}/' \
      "$HERE/plate.yaml" >"$W/ck.yaml"
    grep -q checkpoint_every "$W/ck.yaml"
    expect_refusal "output.checkpoint_every: checkpointing is not implemented on several MPI processes" \
      "$W/ck" -- mpi 2 "$PDCG" -q run "$W/ck.yaml" -o "$W/ck"
    { cat "$HERE/plate.yaml"; echo "effects: [rupture]"
      echo "rupture: {criterion: bond_stretch, critical: 1.15}"; } >"$W/rup.yaml"
    expect_refusal "effects: rupture of a quasi-static run is not implemented on several MPI processes" \
      "$W/rup" -- mpi 2 "$PDCG" -q run "$W/rup.yaml" -o "$W/rup"
    # explicit dynamics runs on several processes, but not the softening law of its rupture
    sed 's/rupture: {criterion: bond_stretch, critical: 1.15}/rupture: {criterion: fracture_energy, G_c: 0.01, softening: linear}/' \
      "$HERE/dynamic_fracture.yaml" >"$W/soft.yaml"
    grep -q softening "$W/soft.yaml"
    expect_refusal "rupture.softening: the softening failure law is not implemented on several MPI processes" \
      "$W/soft" -- mpi 2 "$PDCG" -q run "$W/soft.yaml" -o "$W/soft"
    ;;
  *)
    echo "unknown case $CASE"
    exit 2
    ;;
esac
