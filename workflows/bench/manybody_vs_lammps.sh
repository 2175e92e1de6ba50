#!/usr/bin/env bash
# Native three-body and bond-order styles against LAMMPS on the same machine, in the same
# script: diamond Si with Stillinger–Weber (Si.sw) and Tersoff (Si.tersoff), Debian's `lmp`
# (one thread: the Debian build has no OPENMP package, and the OPT package has no sw/tersoff).
#   1. one force evaluation of 216 atoms from the command line: `pdcg forces` on a body built
#      by `pdcg atoms2pd` vs `lmp` `run 0` (whole processes, wall seconds, best of REPEAT);
#   2. fixed-family NVE dynamics (`pdcg md`, families 2 r_c + skin) vs `lmp` `fix nve`, the
#      integration loops only (pdcg: its md loop; LAMMPS: "Loop time"), atom-steps/s, best of
#      REPEAT, pdcg's many-body kernel on 1 and 2 threads and its general evaluator
#      (`--kernels general`, the path before the kernel) on 1; ratio pdcg/lmp (> 1: pdcg faster);
#   3. with CALLGRIND=1, instructions per atom-step of the loops on one thread (valgrind
#      --tool=callgrind: pdcg VelocityVerlet::step, kernel and general path; LAMMPS
#      Verlet::run), CG_CELLS (default 4: 512 atoms), CG_STEPS (default 5) steps: robust on a
#      loaded machine.
# Trajectories are checked against LAMMPS by tests/unit/dynamics (DynamicsVsLammps.Diamond*),
# forces and per-atom energies by tests/unit/atomistic/test_manybody.cpp.
# Usage: workflows/bench/manybody_vs_lammps.sh [PDCG]   (CELLS="3 10", STEPS=20, REPEAT=3)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
PDCG=$(realpath "${1:-$root/build/pdcg}")
STEPS=${STEPS:-20}
CELLS=${CELLS:-3 10}
REPEAT=${REPEAT:-3}
POT=${LAMMPS_POTENTIALS:-/usr/share/lammps/potentials}
load_start=$(cut -d' ' -f1-3 /proc/loadavg)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
best() { python3 -c "import sys; print(min(float(v) for v in sys.argv[1:]))" "$@"; }
wall() {  # wall seconds of a command (stdout/stderr discarded)
  python3 -c "import subprocess, sys, time
t = time.perf_counter()
subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
print(time.perf_counter() - t)" "$@"
}
make_crystal() {  # style file cells: c.data, v.dump (300 K velocities), in.run, pot.in
  local style=$1 file=$2 cells=$3
  cat > in.make <<LMP
units metal
atom_style atomic
lattice diamond 5.431
region box block 0 $cells 0 $cells 0 $cells
create_box 1 box
create_atoms 1 box
mass 1 28.0855
pair_style $style
pair_coeff * * $POT/$file Si
velocity all create 300 87287 loop geom
write_data c.data
write_dump all custom v.dump id type x y z vx vy vz modify format float %.17g
LMP
  lmp -in in.make -log none -screen none
  printf 'units metal\nmass 1 28.0855\npair_style %s\npair_coeff * * %s/%s Si\n' "$style" "$POT" "$file" > pot.in
  cat > in.run <<LMP
units metal
atom_style atomic
pair_style $style
read_data c.data
pair_coeff * * $POT/$file Si
timestep 0.001
fix 1 all nve
thermo $STEPS
run $STEPS
LMP
}
# family cutoff: 2 r_c (sw: 2 a σ = 7.54 Å; tersoff: 2 (R + D) = 6.4 Å) and a skin
fc_of() { [ "$1" = sw ] && echo 8.0 || echo 6.9; }

forces_rows=() md_rows=() cg_rows=()
for sys in "sw Si.sw" "tersoff Si.tersoff"; do
  set -- $sys
  style=$1 file=$2
  # 1. one force evaluation, 216 atoms, perturbed
  cat > in.one <<LMP
units metal
lattice diamond 5.431
region b block 0 3 0 3 0 3
create_box 1 b
create_atoms 1 region b
mass 1 28.0855
pair_style $style
pair_coeff * * $POT/$file Si
displace_atoms all random 0.1 0.1 0.1 4242 units box
write_dump all custom one.dump id type x y z modify format float %.17g
LMP
  lmp -in in.one -log none -screen none
  printf 'units metal\nmass 1 28.0855\npair_style %s\npair_coeff * * %s/%s Si\n' "$style" "$POT" "$file" > one.pot
  sed 's/^write_dump.*/run 0/' in.one > in.one0
  "$PDCG" atoms2pd --input one.dump --potential one.pot -o one.h5 >/dev/null 2>&1
  tp=() tl=()
  for ((i = 0; i < REPEAT; i++)); do
    tp+=("$(wall "$PDCG" forces one.h5 -o f.csv)")
    tl+=("$(wall lmp -in in.one0 -log none -screen none)")
  done
  p=$(best "${tp[@]}") l=$(best "${tl[@]}")
  forces_rows+=("| $style ($file) | 216 | $(printf '%.3f' "$p") | $(printf '%.3f' "$l") | $(cut -d' ' -f1 /proc/loadavg) |")
  echo "${forces_rows[-1]}"
  # 2. dynamics
  for cells in $CELLS; do
    make_crystal "$style" "$file" "$cells"
    natoms=$((8 * cells * cells * cells))
    lt=()
    for ((i = 0; i < REPEAT; i++)); do
      OMP_NUM_THREADS=1 lmp -in in.run -screen none -log lmp.log >/dev/null 2>&1
      lt+=("$(grep "^Loop time" lmp.log | awk '{print $4}')")
    done
    lrate=$(python3 -c "print(f'{$natoms * $STEPS / $(best "${lt[@]}"):.4g}')")
    "$PDCG" atoms2pd --input c.data --potential pot.in --family-cutoff "$(fc_of "$style")" -o b.h5 >/dev/null 2>&1
    for run in "1 auto" "2 auto" "1 general"; do
      set -- $run
      t=$1 kern=$2
      r=0
      for ((i = 0; i < REPEAT; i++)); do
        r_=$(OMP_NUM_THREADS=$t "$PDCG" md b.h5 --steps "$STEPS" --dt 0.001 --velocities v.dump --kernels "$kern" 2>&1 | sed -n 's/.* \([0-9.e+]*\) atom-steps\/s.*/\1/p')
        r=$(python3 -c "print(f'{max($r, $r_):.4g}')")
      done
      md_rows+=("| $style ($file) | $natoms | $kern | $t | $r | $lrate | $(python3 -c "print(f'{$r / $lrate:.2f}')") | $(cut -d' ' -f1 /proc/loadavg) |")
      echo "${md_rows[-1]}"
    done
  done
  # 3. instruction counts
  if [ "${CALLGRIND:-0}" = 1 ]; then
    cells=${CG_CELLS:-4}
    STEPS_SAVED=$STEPS
    STEPS=${CG_STEPS:-5}
    make_crystal "$style" "$file" "$cells"
    natoms=$((8 * cells * cells * cells))
    "$PDCG" atoms2pd --input c.data --potential pot.in --family-cutoff "$(fc_of "$style")" -o b.h5 >/dev/null 2>&1
    for kern in auto general; do
      OMP_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=cg.pdcg.$kern \
        --toggle-collect='pdcg::dynamics::VelocityVerlet::step(bool)' \
        "$PDCG" md b.h5 --steps "$STEPS" --dt 0.001 --velocities v.dump --kernels $kern >/dev/null 2>&1
    done
    OMP_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=cg.lmp \
      --toggle-collect='LAMMPS_NS::Verlet::run(int)' lmp -in in.run -screen none -log none >/dev/null 2>&1
    ip=$(sed -n 's/^summary: //p' cg.pdcg.auto)
    ig=$(sed -n 's/^summary: //p' cg.pdcg.general)
    il=$(sed -n 's/^summary: //p' cg.lmp)
    cg_rows+=("| $style ($file) | $natoms | $(python3 -c "a = $natoms * $STEPS; print(f'{$ip / a:.0f} | {$ig / a:.0f} | {$il / a:.0f} | {$il / $ip:.2f} | {$il / $ig:.2f}')") |")
    echo "${cg_rows[-1]}"
    STEPS=$STEPS_SAVED
  fi
done
machine=$(lscpu | grep -E "^Model name|^CPU\(s\)" | sed 's/  */ /g' | paste -sd ';' -)
echo
echo "One force evaluation (whole commands, wall s, best of $REPEAT):"
echo "| system | atoms | pdcg forces | lmp run 0 | load |"
echo "|---|---|---|---|---|"
printf '%s\n' "${forces_rows[@]}"
echo
echo "Fixed-family NVE, $STEPS steps (integration loops):"
echo "| system | atoms | pdcg kernels | pdcg threads | pdcg atom-steps/s | lmp atom-steps/s (1 thread) | ratio pdcg/lmp | load |"
echo "|---|---|---|---|---|---|---|---|"
printf '%s\n' "${md_rows[@]}"
if [ ${#cg_rows[@]} -gt 0 ]; then
  echo
  echo "| system | atoms | pdcg kernel Ir/atom-step | pdcg general Ir/atom-step | lmp Ir/atom-step | ratio lmp/kernel | ratio lmp/general |"
  echo "|---|---|---|---|---|---|---|"
  printf '%s\n' "${cg_rows[@]}"
fi
echo "machine: $machine; load average at start: $load_start, at end: $(cut -d' ' -f1-3 /proc/loadavg)"
