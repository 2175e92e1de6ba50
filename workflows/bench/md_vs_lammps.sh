#!/usr/bin/env bash
# Benchmark: fixed-family dynamics of a delta body (`pdcg md`) vs LAMMPS MD (`lmp`,
# Debian build: no OPENMP package, so LAMMPS runs on one thread; its best serial styles are the
# OPT package's, `-sf opt`: lj/cut/opt, eam/opt) on the same atoms: FCC LJ (lj/cut 2.5, lj units,
# dt 0.005) and FCC Cu (eam Cu_u3, metal, dt 0.001), 32k and 256k atoms, NVE, same steps, pdcg
# on 1 and 2 threads (OMP_NUM_THREADS). Rates are the integration loops only (pdcg: the md loop;
# LAMMPS: "Loop time"), atom-steps/s, the best of REPEAT runs each (default 3: the machine is
# shared; the minimum time is the least disturbed run); the ratio is against the faster of
# `lmp` and `lmp -sf opt`. With CALLGRIND=1, also counts instructions (valgrind
# --tool=callgrind, Ir of the integration loop only: pdcg VelocityVerlet::step, LAMMPS
# Verlet::run) on a small crystal (CG_CELLS, default 10: 4000 atoms, CG_STEPS 20 steps, one
# thread): robust on a loaded machine. SYSTEMS="lj eam" selects the systems. With CPU=1, also
# one-thread rates in CPU time (on-CPU seconds of the loop, which a loaded machine does not
# stretch by descheduling): LAMMPS "Loop time" × its "% CPU use", pdcg the process CPU time
# (getrusage of the child) of a CPU_STEPS-step run (default 100: the setup's own spread must
# be small against the loop) minus that of a 0-step run (setup), best of REPEAT each.
# Trajectories (same forces, 100 steps) are checked against lmp by tests/cli/md.sh and
# tests/unit/dynamics (ctest -L dynamics).
# Usage: workflows/bench/md_vs_lammps.sh [PDCG] [--write-docs]   (a few minutes)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
PDCG=$(realpath "${1:-$root/build/pdcg}")
write_docs=${2:-}
STEPS=${STEPS:-30}
CELLS=${CELLS:-20 40}
REPEAT=${REPEAT:-3}
SYSTEMS=${SYSTEMS:-lj eam}
load_start=$(cut -d' ' -f1-3 /proc/loadavg)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
rows=()
bench() {  # name units lattice-args pair-commands mass dt cells family-cutoff [callgrind]
  local name=$1 units=$2 lat=$3 pair=$4 mass=$5 dt=$6 cells=$7 fc=$8 cg=${9:-}
  cat > in.make <<LMP
units $units
atom_style atomic
lattice $lat
region box block 0 $cells 0 $cells 0 $cells
create_box 1 box
create_atoms 1 box
mass 1 $mass
$pair
velocity all create $( [ "$units" = lj ] && echo 0.3 || echo 300 ) 87287 loop geom
write_data c.data
write_dump all custom v.dump id type x y z vx vy vz modify format float %.17g
LMP
  lmp -in in.make -log none -screen none
  local natoms=$((4 * cells * cells * cells))
  cat > in.run <<LMP
units $units
atom_style atomic
$(echo "$pair" | head -1)
read_data c.data
$(echo "$pair" | tail -n +2)
timestep $dt
fix 1 all nve
thermo $STEPS
run $STEPS
LMP
  if [ -n "$cg" ]; then
    printf '%s\n' "$pair" | grep -v '^$' > pot.in
    echo "units $units" >> pot.in
    echo "mass 1 $mass" >> pot.in
    "$PDCG" atoms2pd --input c.data --potential pot.in --family-cutoff "$fc" -o b.h5 >/dev/null 2>&1
    OMP_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=cg.pdcg \
      --toggle-collect='pdcg::dynamics::VelocityVerlet::step(bool)' \
      "$PDCG" md b.h5 --steps "$STEPS" --dt "$dt" --velocities v.dump >/dev/null 2>&1
    OMP_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=cg.lmp \
      --toggle-collect='LAMMPS_NS::Verlet::run(int)' lmp -in in.run -screen none -log none >/dev/null 2>&1
    OMP_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=cg.opt \
      --toggle-collect='LAMMPS_NS::Verlet::run(int)' lmp -sf opt -in in.run -screen none -log none >/dev/null 2>&1
    local ip il io
    ip=$(sed -n 's/^summary: //p' cg.pdcg)
    il=$(sed -n 's/^summary: //p' cg.lmp)
    io=$(sed -n 's/^summary: //p' cg.opt)
    cgrows+=("| $name | $natoms | $(python3 -c "a=$natoms*$STEPS; print(f'{$ip/a:.0f} | {$il/a:.0f} | {$io/a:.0f} | {$il/$ip:.2f} | {$io/$ip:.2f}')") |")
    echo "${cgrows[-1]}"
    rm -f b.h5 c.data v.dump cg.pdcg cg.lmp cg.opt
    return
  fi
  local lt=1e30 ot=1e30 lc=1e30 oc=1e30 t_ c_ i
  for ((i = 0; i < REPEAT; i++)); do
    t_=$(OMP_NUM_THREADS=1 lmp -in in.run -screen none -log lmp.log >/dev/null 2>&1; grep "^Loop time" lmp.log | awk '{print $4}')
    c_=$(python3 -c "print($t_ * $(sed -n 's/^\([0-9.]*\)% CPU use.*/\1/p' lmp.log) / 100)")
    lt=$(python3 -c "print(min($lt, $t_))")
    lc=$(python3 -c "print(min($lc, $c_))")
    t_=$(OMP_NUM_THREADS=1 lmp -sf opt -in in.run -screen none -log lmp.log >/dev/null 2>&1; grep "^Loop time" lmp.log | awk '{print $4}')
    c_=$(python3 -c "print($t_ * $(sed -n 's/^\([0-9.]*\)% CPU use.*/\1/p' lmp.log) / 100)")
    ot=$(python3 -c "print(min($ot, $t_))")
    oc=$(python3 -c "print(min($oc, $c_))")
  done
  local lrate orate best
  lrate=$(python3 -c "print(f'{$natoms*$STEPS/$lt:.4g}')")
  orate=$(python3 -c "print(f'{$natoms*$STEPS/$ot:.4g}')")
  best=$(python3 -c "print(max($lrate, $orate))")
  printf '%s\n' "$pair" | grep -v '^$' > pot.in
  echo "units $units" >> pot.in
  echo "mass 1 $mass" >> pot.in
  "$PDCG" atoms2pd --input c.data --potential pot.in --family-cutoff "$fc" -o b.h5 >/dev/null 2>&1
  for t in 1 2; do
    local r=0 r_
    for ((i = 0; i < REPEAT; i++)); do
      r_=$(OMP_NUM_THREADS=$t "$PDCG" md b.h5 --steps "$STEPS" --dt "$dt" --velocities v.dump 2>&1 | sed -n 's/.* \([0-9.e+]*\) atom-steps\/s.*/\1/p')
      r=$(python3 -c "print(f'{max($r, $r_):.4g}')")
    done
    local ratio
    ratio=$(python3 -c "print(f'{$r/$best:.2f}')")
    rows+=("| $name | $natoms | $t | $r | $lrate | $orate | $ratio | $(cut -d' ' -f1 /proc/loadavg) |")
    echo "${rows[-1]}"
  done
  if [ "${CPU:-0}" = 1 ]; then
    local c0=1e30 c1=1e30
    for ((i = 0; i < REPEAT; i++)); do
      c_=$(cputime "$PDCG" md b.h5 --steps 0 --dt "$dt" --velocities v.dump)
      c0=$(python3 -c "print(min($c0, $c_))")
      c_=$(cputime "$PDCG" md b.h5 --steps "${CPU_STEPS:-100}" --dt "$dt" --velocities v.dump)
      c1=$(python3 -c "print(min($c1, $c_))")
    done
    cpurows+=("| $name | $natoms | $(python3 -c "a=$natoms*$STEPS; p=$natoms*${CPU_STEPS:-100}/($c1-$c0); l=a/$lc; o=a/$oc; print(f'{p:.4g} | {l:.4g} | {o:.4g} | {p/max(l, o):.2f}')") | $(cut -d' ' -f1 /proc/loadavg) |")
    echo "CPU: ${cpurows[-1]}"
  fi
  rm -f b.h5 c.data v.dump
}
# on-CPU seconds of a one-thread command (getrusage of the child: user + system)
cputime() {
  OMP_NUM_THREADS=1 python3 -c "import resource, subprocess, sys
subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
r = resource.getrusage(resource.RUSAGE_CHILDREN)
print(r.ru_utime + r.ru_stime)" "$@"
}
cgrows=()
cpurows=()
if [ "${CALLGRIND:-0}" = 1 ]; then
  STEPS_SAVED=$STEPS
  STEPS=${CG_STEPS:-20}
  echo "| system | atoms | pdcg Ir/atom-step | lmp Ir/atom-step | lmp -sf opt Ir/atom-step | ratio lmp/pdcg | ratio opt/pdcg |"
  echo "|---|---|---|---|---|---|---|"
  for cells in ${CG_CELLS:-10}; do
    if [[ " $SYSTEMS " == *" lj "* ]]; then bench "FCC LJ lj/cut 2.5" lj "fcc 0.8442" "pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0" 1.0 0.005 $cells 2.8 cg; fi
    if [[ " $SYSTEMS " == *" eam "* ]]; then bench "FCC Cu eam Cu_u3" metal "fcc 3.615" "pair_style eam
pair_coeff 1 1 /usr/share/lammps/potentials/Cu_u3.eam" 63.55 0.001 $cells 5.45 cg; fi
  done
  STEPS=$STEPS_SAVED
fi
hdr="| system | atoms | pdcg threads | pdcg atom-steps/s | lmp atom-steps/s | lmp -sf opt atom-steps/s | ratio pdcg/best lmp | load |"
echo "$hdr"
echo "|---|---|---|---|---|---|---|---|"
for cells in $CELLS; do
  if [[ " $SYSTEMS " == *" lj "* ]]; then bench "FCC LJ lj/cut 2.5" lj "fcc 0.8442" "pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0" 1.0 0.005 $cells 2.8; fi
  if [[ " $SYSTEMS " == *" eam "* ]]; then bench "FCC Cu eam Cu_u3" metal "fcc 3.615" "pair_style eam
pair_coeff 1 1 /usr/share/lammps/potentials/Cu_u3.eam" 63.55 0.001 $cells 5.45; fi
done
if [ ${#cpurows[@]} -gt 0 ]; then
  echo "| system | atoms | pdcg CPU atom-steps/s (1 thread) | lmp CPU atom-steps/s | lmp -sf opt CPU atom-steps/s | ratio pdcg/best lmp (CPU) | load |"
  echo "|---|---|---|---|---|---|---|"
  printf '%s\n' "${cpurows[@]}"
fi
machine=$(lscpu | grep -E "^Model name|^CPU\(s\)|^Thread|^L2|^L3" | sed 's/  */ /g' | paste -sd ';' -)
echo "machine: $machine; load average at start: $load_start, at end: $(cut -d' ' -f1-3 /proc/loadavg)"
if [ "$write_docs" = "--write-docs" ]; then
  {
    echo
    echo "## Fixed-family dynamics (benchmark 1, \`workflows/bench/md_vs_lammps.sh\`)"
    echo
    echo "Generated $(date -u +%Y-%m-%dT%H:%MZ), $STEPS NVE steps, machine: $machine; load average at start $load_start, at end $(cut -d' ' -f1-3 /proc/loadavg)."
    echo
    echo "$hdr"
    echo "|---|---|---|---|---|---|---|---|"
    printf '%s\n' "${rows[@]}"
    if [ ${#cpurows[@]} -gt 0 ]; then
      echo
      echo "| system | atoms | pdcg CPU atom-steps/s (1 thread) | lmp CPU atom-steps/s | lmp -sf opt CPU atom-steps/s | ratio pdcg/best lmp (CPU) | load |"
      echo "|---|---|---|---|---|---|---|"
      printf '%s\n' "${cpurows[@]}"
    fi
    if [ ${#cgrows[@]} -gt 0 ]; then
      echo
      echo "| system | atoms | pdcg Ir/atom-step | lmp Ir/atom-step | lmp -sf opt Ir/atom-step | ratio lmp/pdcg | ratio opt/pdcg |"
      echo "|---|---|---|---|---|---|---|"
      printf '%s\n' "${cgrows[@]}"
    fi
  } >> "$root/docs/performance.md"
fi
