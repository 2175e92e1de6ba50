#!/usr/bin/env bash
# MD fracture references of the brittle reference system (docs/fracture.md, 'A brittle
# reference system'): notched 2D triangular sheets pulled to rupture by Debian's LAMMPS (`lmp`),
# one serial run at a time (nice 10, one thread), each analysed by analyze.py; a table of all
# runs in OUT/SYSTEM/summary.csv (collect.py).
#
# Usage: workflows/fracture/brittle_md/run.sh [options]
#   -s SYSTEM   pair model of make_decks.py (default lj15, the brittle reference system)
#   -o OUT      output directory (default results/brittle_md); runs in OUT/SYSTEM/W<nx>_a<notch>_r<rate>
#   -n "NX..."  sheet widths in lattice spacings (default "100"); height: ny = round(nx/sqrt(3))
#               hex cells (2 ny rows), i.e. a square sheet; atoms = 2 nx ny
#   -a "Q..."   notch lengths as fractions of the width (default "0.1 0.2 0.3"); a = round(Q nx) a0
#   -r "R..."   strain rates in 1/tau (default "1e-3 1e-4")
#   -T TEMP     bath temperature (default 0.001)
#   -x "ARGS"   extra `-var NAME VALUE` arguments for in.fracture (e.g. "-var damp 10")
#   -f          rerun runs that already have an analysis.json
# Cost (2-core machine, one core): 0.09-0.27 microseconds per atom-step; W = 100 at 1e-4/tau about
# a minute, W = 200 at 1e-4/tau 13 min (docs/fracture.md §7.5).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
src=$(cd "$here/../../.." && pwd)
system=lj15
out=$src/results/brittle_md
widths="100"
notches="0.1 0.2 0.3"
rates="1e-3 1e-4"
temp=0.001
extra=""
force=0
while getopts "s:o:n:a:r:T:x:fh" opt; do
  case $opt in
    s) system=$OPTARG ;;
    o) out=$OPTARG ;;
    n) widths=$OPTARG ;;
    a) notches=$OPTARG ;;
    r) rates=$OPTARG ;;
    T) temp=$OPTARG ;;
    x) extra=$OPTARG ;;
    f) force=1 ;;
    *) sed -n '2,20p' "$0"; exit 2 ;;
  esac
done
command -v lmp > /dev/null || { echo "run.sh: LAMMPS executable 'lmp' not found (Debian: apt install lammps)" >&2; exit 2; }
py=/usr/bin/python3
sysdir=$out/$system
mkdir -p "$sysdir"
"$py" "$here/make_decks.py" --system "$system" "$sysdir"
(cd "$sysdir" && lmp -in in.relax -var out . -log relax.log -screen none \
  && lmp -in in.surface -var out . -log surface.log -screen none)
echo "$system: a0 = $(cat "$sysdir/a0.txt"); $(tr '\n' ' ' < "$sysdir/gamma.txt" | cut -d' ' -f1-4)"
for nx in $widths; do
  ny=$("$py" -c "print(round($nx/3**0.5))")
  # Griffith load of each notched sheet by molecular statics (skipped when already computed)
  list=$(for q in $notches; do "$py" -c "print(round($q*$nx))"; done | tr '\n' ' ')
  if ! "$py" -c "import json,sys; d=json.load(open('$sysdir/griffith_W$nx.json')); sys.exit(0 if all(k in d for k in '$list'.split()) else 1)" 2> /dev/null; then
    "$py" "$here/griffith.py" "$sysdir" --nx "$nx" --ny "$ny" --notch $list
  fi
  for q in $notches; do
    notch=$("$py" -c "print(round($q*$nx))")
    for rate in $rates; do
      run=$sysdir/W${nx}_a${notch}_r${rate}
      if [ $force = 0 ] && [ -e "$run/analysis.json" ]; then echo "skip $run (done)"; continue; fi
      rm -rf "$run"; mkdir -p "$run"
      start=$(date +%s)
      # shellcheck disable=SC2086
      (cd "$sysdir" && OMP_NUM_THREADS=1 nice -n 10 lmp -in in.fracture -var out "$run" -var nx "$nx" \
        -var ny "$ny" -var notch "$notch" -var rate "$rate" -var T "$temp" $extra \
        -log "$run/log.lammps" -screen none)
      echo "wall_seconds $(( $(date +%s) - start ))" >> "$run/meta.txt"
      echo -n "W${nx}_a${notch}_r${rate} ($(( $(date +%s) - start )) s): "
      "$py" "$here/analyze.py" "$run" --png
    done
  done
done
"$py" "$here/collect.py" "$sysdir" > "$sysdir/summary.csv"
echo "table: $sysdir/summary.csv"
