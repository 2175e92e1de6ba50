#!/usr/bin/env bash
# ParaView opens a rupture run's results.xdmf: the time steps, the point fields at every
# step bit for bit against the HDF5 files, damage, and a rendered PNG
# (tests/paraview/check_results.py). Usage: results_in_paraview.sh PDCG WORKDIR [PNG [MPIEXEC]]
# With MPIEXEC: the output of a distributed run instead (the plate with a hole of tests/mpi on 2
# processes, every step written), opened by ParaView and compared with the serial run's files.
# Needs Debian's paraview, python3-paraview and xvfb (tests/run.sh installs them): without
# them the test is skipped (exit 77) on a developer's machine and fails under CI.
set -euo pipefail
pdcg=$1 work=$2
here=$(cd "$(dirname "$0")" && pwd)
png=${3:-$work/rupture_damage.png}
mpiexec=${4:-}
if ! command -v pvbatch >/dev/null || ! command -v Xvfb >/dev/null; then
  msg="pvbatch or Xvfb not found: apt-get install --no-install-recommends paraview python3-paraview xvfb"
  if [ "${CI:-}" = true ]; then echo "FAIL $msg" >&2; exit 1; fi
  echo "SKIP $msg" >&2
  exit 77
fi
rm -rf "$work"
mkdir -p "$work"
cd "$work"
# an edge-cracked Neo-Hookean sheet pulled until the crack runs (the rupture workflow's
# scene at half its resolution): 4 output steps, damage growing from the tip
cat >sheet.yaml <<'YAML'
dimension: 2
plane: stress
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 1.0], spacing: 0.1,
           cracks: [{from: [0.0, 0.5], to: [0.3, 0.5]}]}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 100.0}
boundary:
  - {name: bottom, region: {y_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: top,    region: {y_min: 1.0}, displacement: {x: 0.0, y: "0.2*t"}}
loading: {steps: 4}
effects: [rupture]
rupture: {criterion: bond_stretch, critical: 1.15}
YAML
serial=()
if [ -z "$mpiexec" ]; then
  "$pdcg" run sheet.yaml -o run >run.log 2>&1 || { tail -20 run.log; exit 1; }
else
  # the plate with a hole of the distributed-run tests, a result file at each of its 5 steps;
  # OpenMPI refuses root unless told (CI runs as root); one thread per process
  sed 's/every: 5}/every: 1}/' "$here/../mpi/plate.yaml" >plate.yaml
  grep -q 'every: 1}' plate.yaml
  "$pdcg" -q run plate.yaml -o serial >serial.log 2>&1 || { tail -20 serial.log; exit 1; }
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1 \
    "$mpiexec" --oversubscribe -n 2 "$pdcg" -q run plate.yaml -o run >run.log 2>&1 ||
    { tail -20 run.log; exit 1; }
  serial=(serial)
fi
# pvbatch renders through OpenGL on an X display: a private Xvfb on a free display number
display=""
for n in $(seq 90 120); do
  if [ ! -e "/tmp/.X$n-lock" ] && [ ! -e "/tmp/.X11-unix/X$n" ]; then display=:$n; break; fi
done
[ -n "$display" ] || { echo "no free X display number in :90-:120" >&2; exit 1; }
# Xvfb signals readiness with SIGUSR1 to its parent when it inherits SIGUSR1 ignored (as
# xvfb-run does); -noreset: no server reset between clients (a client connecting during one
# got "bad X server connection" here)
trap : USR1
(trap '' USR1; exec Xvfb "$display" -screen 0 1024x1024x24 -nolisten tcp -noreset) >xvfb.log 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null || true' EXIT
wait "$xvfb" || true # returns on USR1 (ready), or when Xvfb exits (failed: the render says so)
status=0
DISPLAY=$display pvbatch "$here/check_results.py" run "$png" "${serial[@]}" >pvbatch.log 2>pvbatch.err || status=$?
cat pvbatch.log
if [ "$status" != 0 ]; then
  grep -v '^ *[0-9]* *0x' pvbatch.err | tail -20 >&2
  tail -5 xvfb.log >&2
  exit 1
fi
grep -q '^paraview check: 0 failures$' pvbatch.log
echo "results_in_paraview: passed ($png)"
