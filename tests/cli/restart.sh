#!/usr/bin/env bash
# Checkpoint/restart: a run killed with a real SIGKILL from outside (tests/cli/kill_at.py polls
# the output directory and kills when the K-th checkpoint and then R more results files have
# appeared; K, R random per run from a printed seed) and continued with
# `pdcg run scene.yaml --restart DIR` gives bitwise the same outputs as an uninterrupted run
# on one thread: series/reactions CSV and XDMF byte for byte, every dataset of every
# results_NNNN.h5 exactly equal (the files' command_line attributes differ by design).
# Cases: quasi-static Newton (load steps, no rupture), quasi-static with rupture (broken bonds,
# rebuilt stencils, anchors in the checkpoint; and with the fracture_energy rule, its bond
# work, and with its softening law, the damage), dynamic (inertia + viscous damping, prescribed
# motion, initial velocity), ADR, dynamic fracture; and one run killed while a checkpoint is
# being written (SIGSTOP when its temporary exists, then SIGKILL): the previous checkpoint is
# used and the restart removes the dead run's temporaries.
# Replay a failure: PDCG_KILL_SEED=<printed seed> bash restart.sh PDCG WORK
# Usage: restart.sh /path/to/pdcg /path/to/work
set -u
pdcg=$1
work=$2
here=$(cd "$(dirname "$0")" && pwd)
export OMP_NUM_THREADS=1
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
seed=${PDCG_KILL_SEED:-$(( $(od -An -N2 -tu2 /dev/urandom) ))}
RANDOM=$seed
echo "seed $seed (replay: PDCG_KILL_SEED=$seed)"
fail=0
compare() {  # compare <A> <B> <csv-name>
  local a=$1 b=$2 csv=$3
  cmp "$a/$csv" "$b/$csv" || { echo "FAIL $csv differs"; fail=1; }
  cmp "$a/results.xdmf" "$b/results.xdmf" || { echo "FAIL results.xdmf differs"; fail=1; }
  /usr/bin/python3 - "$a" "$b" <<'PY' || fail=1
import sys, glob, os, h5py, numpy as np
a, b = sys.argv[1], sys.argv[2]
fa = sorted(os.path.basename(p) for p in glob.glob(a + "/results_*.h5"))
fb = sorted(os.path.basename(p) for p in glob.glob(b + "/results_*.h5"))
if fa != fb:
    print("FAIL result files differ:", fa, fb); sys.exit(1)
n = 0
for f in fa:
    with h5py.File(os.path.join(a, f)) as x, h5py.File(os.path.join(b, f)) as y:
        names = []
        x.visit(lambda k: names.append(k) if isinstance(x[k], h5py.Dataset) else None)
        for k in names:
            if not np.array_equal(x[k][()], y[k][()]):
                print("FAIL", f, k, "differs"); sys.exit(1)
            n += 1
        for k in ("step", "time", "load_factor", "residual"):
            if k in x.attrs and x.attrs[k] != y.attrs[k]:
                print("FAIL", f, "attribute", k); sys.exit(1)
print(f"ok   {len(fa)} result files, {n} datasets bitwise equal")
PY
  local left
  left=$(ls -A "$b" | grep '\.tmp\.')
  [ -z "$left" ] || { echo "FAIL temporaries left after the restart: $left"; fail=1; }
}
full() {  # full <name> <scene>: the uninterrupted run
  "$pdcg" -q run "$2" -o "$1.full" || { echo "FAIL $1: uninterrupted run"; fail=1; return 1; }
}
restart_and_compare() {  # <name> <scene> <csv>
  local name=$1 scene=$2 csv=$3
  ls "$name.cut"/checkpoint_*.h5 >/dev/null 2>&1 || { echo "FAIL $name: no checkpoint left"; fail=1; return; }
  "$pdcg" -q run "$scene" --restart "$name.cut" || { echo "FAIL $name: restart"; fail=1; return; }
  compare "$name.full" "$name.cut" "$csv"
}
run_case() {  # run_case <name> <scene> <csv> <checkpoints of a full run>
  local name=$1 scene=$2 csv=$3 nck=$4
  full "$name" "$scene" || return
  local k r msg code attempt
  for attempt in 1 2 3; do  # a run that ends before the kill (last checkpoint) is retried
    k=$(( 1 + RANDOM % (nck - 1) )) r=$(( RANDOM % 3 ))
    rm -rf "$name.cut"
    msg=$(/usr/bin/python3 "$here/kill_at.py" "$name.cut" files $k $r -- "$pdcg" -q run "$scene" -o "$name.cut")
    code=$?
    [ $code = 3 ] || break
    echo "     $name attempt $attempt: $msg"
  done
  [ $code = 0 ] || { echo "FAIL $name: K=$k R=$r: $msg"; fail=1; return; }
  echo "ok   $name: K=$k R=$r $msg"
  restart_and_compare "$name" "$scene" "$csv"
}
cat > static.yaml <<'Y'
dimension: 2
plane: strain
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 0.25], spacing: 0.0625}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0}
boundary:
  - {name: left,  region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: {x_min: 1.0}, displacement: {x: "0.3*t", y: "0.05*t"}}
loading: {steps: 16}
output: {checkpoint_every: 2}
Y
run_case static static.yaml reactions.csv 8
cat > dyn.yaml <<'Y'
dimension: 2
plane: strain
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 0.25], spacing: 0.0625}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left,  region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: {x_min: 1.0}, displacement: {x: "0.01*sin(3*t)"}}
initial: {velocity: {y: "0.01*sin(pi*x)"}}
effects: [inertia, damping]
inertia: {end_time: 3.0}
damping: {type: viscous, coefficient: 0.1}
output: {every: 25, checkpoint_every: 20}
Y
run_case dynamic dyn.yaml series.csv 7
# killed while a checkpoint is being written: stopped while the K-th checkpoint's temporary
# exists (K >= 2: an earlier complete checkpoint exists), then SIGKILL; the restart uses the
# previous checkpoint and removes the temporary. A miss (renamed before the stop) retries.
hit=0
for attempt in 1 2 3 4 5 6 7 8 9 10; do
  k=$(( 2 + RANDOM % 5 ))
  rm -rf mid.cut
  msg=$(/usr/bin/python3 "$here/kill_at.py" mid.cut ckpt-tmp $k 0 -- "$pdcg" -q run dyn.yaml -o mid.cut)
  code=$?
  if [ $code = 3 ] || [ $code = 4 ]; then echo "     attempt $attempt K=$k: missed: $(cut -c1-90 <<<"$msg")"; continue; fi
  if [ $code != 0 ]; then echo "FAIL mid-checkpoint K=$k: $msg"; fail=1; break; fi
  echo "ok   mid-checkpoint K=$k: $msg"
  tmp=$(ls -A mid.cut | grep '^\.checkpoint_.*\.tmp\.')
  [ -n "$tmp" ] || { echo "FAIL mid-checkpoint: no temporary after the kill"; fail=1; }
  cp -r dynamic.full mid.full
  restart_and_compare mid dyn.yaml series.csv
  hit=1
  break
done
[ $hit = 1 ] || { echo "FAIL mid-checkpoint: never caught a checkpoint being written in 10 runs"; fail=1; }
cat > adr.yaml <<'Y'
dimension: 2
plane: strain
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 0.25], spacing: 0.0625}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left,  region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: {x_min: 1.0}, displacement: {x: 0.01}}
effects: [inertia, damping]
inertia: {end_time: 3.0}
damping: {type: adaptive-dynamic-relaxation}
output: {every: 30, checkpoint_every: 20}
Y
run_case adr adr.yaml series.csv 7
cat > rup.yaml <<'Y'
dimension: 2
plane: stress
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 1.0], spacing: 0.1,
           cracks: [{from: [0.0, 0.5], to: [0.3, 0.5]}]}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 100.0}
boundary:
  - {name: bottom, region: {y_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: top,    region: {y_min: 1.0}, displacement: {x: 0.0, y: "0.15*t"}}
loading: {steps: 3}
effects: [rupture]
rupture: {criterion: bond_stretch, critical: 1.15}
output: {checkpoint_every: 1}
Y
run_case rupture rup.yaml reactions.csv 3
# the energy-based rule: bonds break at steps 3 and 4, so a checkpoint after step 3 carries
# work integrals of rebuilt (renormalised) stencils, restored with the broken pairs
sed -e 's/steps: 3/steps: 4/' \
    -e 's/criterion: bond_stretch, critical: 1.15/criterion: fracture_energy, surface_energy: 0.004/' \
    rup.yaml > rupfe.yaml
run_case rupture_fe rupfe.yaml reactions.csv 4
# the softening law (docs/fracture.md §6): damage history and damage in the checkpoint, the
# weights and lenses of the damaged pairs rebuilt from them on restart
sed -e 's/surface_energy: 0.004/surface_energy: 0.004, softening: linear, elastic_limit: 0.3/' \
    rupfe.yaml > rupsoft.yaml
run_case rupture_soft rupsoft.yaml reactions.csv 4
# dynamic fracture (inertia + rupture): bonds break before and after the checkpoint; the
# broken pairs, the switched-off point stencils and the (shrunk) time step are restored
cat > dynrup.yaml <<'Y'
dimension: 2
plane: stress
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 1.0], spacing: 0.1,
           cracks: [{from: [0.0, 0.5], to: [0.3, 0.5]}]}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 100.0, density: 1.0}
boundary:
  - {name: bottom, region: {y_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: top,    region: {y_min: 1.0}, displacement: {x: 0.0, y: "0.15*(t - 0.5*(1 - exp(-t/0.5)))"}}
effects: [inertia, rupture]
inertia: {end_time: 4.0}
rupture: {criterion: bond_stretch, critical: 1.15}
output: {every: 10, checkpoint_every: 15}
Y
run_case dynrup dynrup.yaml series.csv 7
b_cut=$(awk -F, 'NR > 1 && $1 == 30 {print $NF}' dynrup.full/series.csv)
b_end=$(tail -1 dynrup.full/series.csv | awk -F, '{print $NF}')
if [ "${b_cut:-0}" -gt 0 ] && [ "$b_end" -gt "$b_cut" ]; then echo "ok   dynrup: $b_cut bonds broken at step 30, $b_end at the end"; else echo "FAIL dynrup: bonds broken $b_cut at step 30, $b_end at the end (want 0 < step 30 < end)"; fail=1; fi
out=$("$pdcg" run dynrup.yaml -o progress.dynrup 2>&1)
if grep -Eq "steps [0-9]+/[0-9]+ .*t = 4, $b_end bonds broken" <<<"$out"; then echo "ok   progress (dynamic fracture)"; else echo "FAIL progress (dynamic fracture): $out" | tail -3; fail=1; fi
# a restart needs a checkpoint of the same scene
out=$("$pdcg" run dyn.yaml --restart rupture.cut 2>&1); code=$?
if [ $code = 2 ] && grep -q "another scene" <<<"$out"; then echo "ok   other scene refused"; else echo "FAIL other scene: exit $code: $out"; fail=1; fi
mkdir -p empty
out=$("$pdcg" run dyn.yaml --restart empty 2>&1); code=$?
if [ $code = 2 ] && grep -q "no checkpoint" <<<"$out"; then echo "ok   no checkpoint refused"; else echo "FAIL no checkpoint: exit $code: $out"; fail=1; fi
out=$("$pdcg" run dyn.yaml --restart dynamic.cut -o x 2>&1); code=$?
if [ $code = 2 ] && grep -q "restart" <<<"$out"; then echo "ok   --restart with -o refused"; else echo "FAIL --restart -o: exit $code: $out"; fail=1; fi
# progress line (stderr not a terminal: the final line): steps, time, rate, bonds broken
out=$("$pdcg" run dyn.yaml -o progress.dyn 2>&1)
if grep -Eq "steps ([0-9]+)/\1 \(100%\) [0-9.e+]+/s elapsed [0-9.]+ s t = 3" <<<"$out"; then echo "ok   progress (dynamic)"; else echo "FAIL progress (dynamic): $out" | tail -3; fail=1; fi
out=$("$pdcg" run rup.yaml -o progress.rup 2>&1)
b_rup=$(tail -1 progress.rup/reactions.csv | awk -F, '{print $NF}')  # the run's own count
if [ "${b_rup:-0}" -gt 0 ] && grep -Eq "load steps 3/3 \(100%\) .*t = 1, $b_rup bonds broken" <<<"$out"; then echo "ok   progress (rupture)"; else echo "FAIL progress (rupture): $out" | tail -3; fail=1; fi
# the stable step from the command line: refused above the limit (exit 2); forced, the run
# diverges and exits 1 with the ratio to the limit (the limit of this bar is 0.0300)
sed 's/inertia: {end_time: 3.0}/inertia: {time_step: 0.04, end_time: 3.0}/' dyn.yaml > fast.yaml
out=$("$pdcg" run fast.yaml -o fast 2>&1); code=$?
if [ $code = 2 ] && grep -q "above the stable limit" <<<"$out"; then echo "ok   time_step above the limit refused"; else echo "FAIL refuse: exit $code: $out" | tail -3; fail=1; fi
# forced at 2× the limit (the limit is a bound: with the force-balanced weak form this bar
# still runs at 1.33× it, and diverges from 1.67× on, within 6 steps)
sed 's/inertia: {end_time: 3.0}/inertia: {time_step: 0.06, end_time: 3.0, allow_unstable: true}/' dyn.yaml > forced.yaml
out=$("$pdcg" run forced.yaml -o forced 2>&1); code=$?
if [ $code = 1 ] && grep -Eq "diverged|inadmissible" <<<"$out"; then echo "ok   forced unstable step diverges (exit 1)"; else echo "FAIL forced: exit $code: $out" | tail -3; fail=1; fi
if [ $fail -ne 0 ]; then echo "restart: FAILED"; exit 1; fi
echo "restart: all passed"
