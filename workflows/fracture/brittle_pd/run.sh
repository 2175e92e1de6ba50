#!/usr/bin/env bash
# PD counterpart of the brittle MD references (docs/fracture.md §7.6): the 11 600-atom notched
# lj15 sheet of workflows/fracture/brittle_md (W = 100 a0), coarse-grained as the flagship does
# (workflows/quickstart/pipeline.sh stage 11: perfect lattice -> delta body -> homogenised ->
# rescaled by 2; the Cauchy-Born material of the coarse model is the atoms'), pulled to rupture
# by the BA solver with fracture_energy, G_c = 2 gamma (relaxed edge energy of the close-packed
# row, by LAMMPS: in.surface). Compared with the slow-rate (1e-4/tau) MD rows of
# brittle_md/reference_lj15.csv; no MD is run here.
#
# Usage: workflows/fracture/brittle_pd/run.sh [options]
#   -p PDCG     pdcg executable (default build/pdcg)
#   -o OUT      output directory (default results/brittle_pd); runs in OUT/<case>
#   -c "CASE.." cases, each n:m:notch:rule[:rho] (rule brittle|soft), default "40:3.015:0.2:brittle"
#   -e S        strain at the end of loading (default 0.045), -k K load steps (default 90: 0.0005 each)
#   -s S0       first load step straight to strain S0 (default 0: K equal steps), then K - 1 to S
#   -f F        tip calibration: the rule gets G_c / F (fracture.md §7.6b; default 1: none)
#   -t SEC      wall-time limit per PD run (default 1200 s; the run is stopped there and
#               analysed from what it wrote: the steps before an unstable pass)
# Writes OUT/summary.csv (one row per case in OUT, this call's and earlier ones: pd_sheet.py analyze).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
src=$(cd "$here/../../.." && pwd)
pdcg=$src/build/pdcg
out=$src/results/brittle_pd
cases="40:3.015:0.2:brittle"
smax=0.045
steps=90
start0=0
limit=1200
tipf=1
while getopts "p:o:c:e:k:s:t:f:h" opt; do
  case $opt in
    p) pdcg=$OPTARG ;;
    o) out=$OPTARG ;;
    c) cases=$OPTARG ;;
    e) smax=$OPTARG ;;
    k) steps=$OPTARG ;;
    s) start0=$OPTARG ;;
    t) limit=$OPTARG ;;
    f) tipf=$OPTARG ;;
    *) sed -n '2,20p' "$0"; exit 2 ;;
  esac
done
command -v lmp > /dev/null || { echo "run.sh: LAMMPS executable 'lmp' not found (Debian: apt install lammps)" >&2; exit 2; }
[ -x "$pdcg" ] || { echo "run.sh: pdcg executable '$pdcg' not found (build it, or give -p)" >&2; exit 2; }
py=/usr/bin/python3
pdcg=$(cd "$(dirname "$pdcg")" && pwd)/$(basename "$pdcg")
mkdir -p "$out"
out=$(cd "$out" && pwd)
sys=$out/lj15
mkdir -p "$sys"
# 1. the atoms: zero-stress a0, edge energy gamma (LAMMPS alone, seconds)
if [ ! -s "$sys/gamma.txt" ]; then
  "$py" "$src/workflows/fracture/brittle_md/make_decks.py" --system lj15 "$sys"
  (cd "$sys" && nice -n 10 lmp -in in.relax -var out . -log relax.log -screen none \
    && nice -n 10 lmp -in in.surface -var out . -log surface.log -screen none)
fi
echo "lj15: a0 = $(cat "$sys/a0.txt"); $(tr '\n' ' ' < "$sys/gamma.txt" | cut -d' ' -f1-4)"
# 2. the coarse model, as the flagship (pipeline.sh stage 11)
if [ ! -s "$sys/res.h5" ]; then
  nice -n 10 "$pdcg" -q atoms2pd --input "$sys/perfect.data" --potential "$sys/potential.mod" \
    --dimension 2 --boundary "p p f" -o "$sys/perfect.h5"
  nice -n 10 "$pdcg" -q homogenize "$sys/perfect.h5" --kernel wendland-c2 --width 2.5 --spacing 1.0 -o "$sys/hom.h5"
  nice -n 10 "$pdcg" -q rescale "$sys/hom.h5" --factor 2 -o "$sys/res.h5"
  for k in perfect res; do nice -n 10 "$pdcg" -q elastic "$sys/$k.h5" --json > "$sys/elastic_$k.json"; done
fi
"$py" - "$sys" <<'PY'
import json, sys
e = {k: json.load(open(f"{sys.argv[1]}/elastic_{k}.json")) for k in ("perfect", "res")}
C = {k: e[k]["C_voigt"] for k in e}
d = max(abs(C["res"][i][j] - C["perfect"][i][j]) for i in range(6) for j in range(6)) / C["perfect"][0][0]
print(f"Cauchy-Born C11 {C['perfect'][0][0]:.6g}, C12 {C['perfect'][0][1]:.6g}, C66 {C['perfect'][5][5]:.6g}; coarse model differs by {d:.1e} C11")
PY
# 3. the PD runs
for cs in $cases; do
  IFS=: read -r n m q rule rho <<< "$cs"
  rho=${rho:-0.1}
  name=n${n}_m${m}_a${q}_${rule}$([ "$rule" = soft ] && echo "_rho$rho" || true)$([ "$tipf" = 1 ] || echo "_f$tipf")
  run=$out/$name
  "$py" "$here/pd_sheet.py" scene "$sys" "$run" --n "$n" --m "$m" --notch "$q" --rule "$rule" \
    --rho "$rho" --strain-max "$smax" --steps "$steps" --strain-start "$start0" --tip-factor "$tipf"
  start=$(date +%s)
  rc=0
  (cd "$run" && OMP_NUM_THREADS=${OMP_NUM_THREADS:-2} nice -n 10 "$py" "$src/workflows/quickstart/timed.py" \
    time.json "$run" timeout "$limit" "$pdcg" run sheet.yaml -o pd > pd.log 2>&1) || rc=$?
  echo "$name: pdcg exit $rc after $(( $(date +%s) - start )) s wall$([ $rc = 124 ] && echo " (stopped at the time limit)" || true)"
done
# the table of every case in OUT (this call's and earlier ones)
header=--header
table=$(mktemp "$out/summary.XXXXXX")
for run in "$out"/n*/; do
  [ -e "$run/pd/reactions.csv" ] || continue
  "$py" "$here/pd_sheet.py" analyze "$run" --reference "$src/workflows/fracture/brittle_md/reference_lj15.csv" $header >> "$table"
  header=
done
mv "$table" "$out/summary.csv"  # whole: two runs of run.sh on one OUT do not interleave their rows
column -s, -t < "$out/summary.csv" | cut -c1-250
echo "table: $out/summary.csv"
