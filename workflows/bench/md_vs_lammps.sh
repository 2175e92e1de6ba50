#!/usr/bin/env bash
# Benchmark 1 (issue 10): fixed-family dynamics of a delta body (`pdcg md`) vs LAMMPS MD (`lmp`,
# Debian serial build: no OPENMP package, so LAMMPS always runs on one thread) on the same
# atoms: FCC LJ (lj/cut 2.5, lj units, dt 0.005) and FCC Cu (eam Cu_u3, metal, dt 0.001),
# 32k and 256k atoms, NVE, same steps, pdcg on 1 and 2 threads (OMP_NUM_THREADS).
# Rates are the integration loops only (pdcg: the md loop; LAMMPS: "Loop time"), atom-steps/s.
# With CALLGRIND=1, also counts instructions (valgrind --tool=callgrind, Ir of the
# integration loop only: pdcg VelocityVerlet::step, LAMMPS Verlet::run) on a small crystal
# (CG_CELLS, default 10: 4000 atoms, CG_STEPS 20 steps, one thread): robust on a loaded machine.
# Usage: workflows/bench/md_vs_lammps.sh [PDCG] [--write-docs]   (a few minutes)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
PDCG=$(realpath "${1:-$root/build/pdcg}")
write_docs=${2:-}
STEPS=${STEPS:-30}
CELLS=${CELLS:-20 40}
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
    local ip il
    ip=$(sed -n 's/^summary: //p' cg.pdcg)
    il=$(sed -n 's/^summary: //p' cg.lmp)
    cgrows+=("| $name | $natoms | $(python3 -c "print(f'{$ip/($natoms*$STEPS):.0f} | {$il/($natoms*$STEPS):.0f} | {$il/$ip:.2f}')") |")
    echo "${cgrows[-1]}"
    rm -f b.h5 c.data v.dump cg.pdcg cg.lmp
    return
  fi
  local lt
  lt=$(OMP_NUM_THREADS=1 lmp -in in.run -screen none -log lmp.log >/dev/null 2>&1; grep "^Loop time" lmp.log | awk '{print $4}')
  local lrate
  lrate=$(python3 -c "print(f'{$natoms*$STEPS/$lt:.4g}')")
  printf '%s\n' "$pair" | grep -v '^$' > pot.in
  echo "units $units" >> pot.in
  echo "mass 1 $mass" >> pot.in
  "$PDCG" atoms2pd --input c.data --potential pot.in --family-cutoff "$fc" -o b.h5 >/dev/null 2>&1
  for t in 1 2; do
    local r
    r=$(OMP_NUM_THREADS=$t "$PDCG" md b.h5 --steps "$STEPS" --dt "$dt" --velocities v.dump 2>&1 | sed -n 's/.* \([0-9.e+]*\) atom-steps\/s.*/\1/p')
    local ratio
    ratio=$(python3 -c "print(f'{$r/$lrate:.2f}')")
    rows+=("| $name | $natoms | $t | $r | $lrate | $ratio |")
    echo "${rows[-1]}"
  done
  rm -f b.h5 c.data v.dump
}
cgrows=()
if [ "${CALLGRIND:-0}" = 1 ]; then
  STEPS_SAVED=$STEPS
  STEPS=${CG_STEPS:-20}
  echo "| system | atoms | pdcg Ir/atom-step | lmp Ir/atom-step | ratio lmp/pdcg |"
  echo "|---|---|---|---|---|"
  for cells in ${CG_CELLS:-10}; do
    bench "FCC LJ lj/cut 2.5" lj "fcc 0.8442" "pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0" 1.0 0.005 $cells 2.8 cg
    bench "FCC Cu eam Cu_u3" metal "fcc 3.615" "pair_style eam
pair_coeff 1 1 /usr/share/lammps/potentials/Cu_u3.eam" 63.55 0.001 $cells 5.45 cg
  done
  STEPS=$STEPS_SAVED
fi
echo "| system | atoms | pdcg threads | pdcg atom-steps/s | lmp atom-steps/s (1 thread) | ratio |"
echo "|---|---|---|---|---|---|"
for cells in $CELLS; do
  bench "FCC LJ lj/cut 2.5" lj "fcc 0.8442" "pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0" 1.0 0.005 $cells 2.8
  bench "FCC Cu eam Cu_u3" metal "fcc 3.615" "pair_style eam
pair_coeff 1 1 /usr/share/lammps/potentials/Cu_u3.eam" 63.55 0.001 $cells 5.45
done
machine=$(lscpu | grep -E "^Model name|^CPU\(s\)|^Thread|^L2|^L3" | sed 's/  */ /g' | paste -sd ';' -)
echo "machine: $machine; load average at start: $load_start, at end: $(cut -d' ' -f1-3 /proc/loadavg)"
if [ "$write_docs" = "--write-docs" ]; then
  {
    echo
    echo "## Fixed-family dynamics (benchmark 1, \`workflows/bench/md_vs_lammps.sh\`)"
    echo
    echo "Generated $(date -u +%Y-%m-%dT%H:%MZ), $STEPS NVE steps, machine: $machine; load average at start $load_start, at end $(cut -d' ' -f1-3 /proc/loadavg)."
    echo
    echo "| system | atoms | pdcg threads | pdcg atom-steps/s | lmp atom-steps/s (1 thread) | ratio |"
    echo "|---|---|---|---|---|---|"
    printf '%s\n' "${rows[@]}"
    if [ ${#cgrows[@]} -gt 0 ]; then
      echo
      echo "| system | atoms | pdcg Ir/atom-step | lmp Ir/atom-step | ratio lmp/pdcg |"
      echo "|---|---|---|---|---|"
      printf '%s\n' "${cgrows[@]}"
    fi
  } >> "$root/docs/performance.md"
fi
