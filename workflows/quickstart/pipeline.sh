#!/usr/bin/env bash
# The pdcg stages of the quickstart (called by ../quickstart.sh after the LAMMPS step).
# Usage: pipeline.sh <pdcg> <case-dir> <out-dir>
set -euo pipefail
pdcg=$1 case_dir=$2 out=$3
here=$(cd "$(dirname "$0")" && pwd)
py=/usr/bin/python3
cd "$out"
t0=$(date +%s.%N)
stamp() { /usr/bin/python3 -c "import time,sys; print(f'{time.time()-float(sys.argv[1]):.2f}')" "$t0"; }

echo "== 3. pdcg inspect: what LAMMPS wrote"
"$pdcg" inspect lj_fcc.dump --json > inspect.json
"$pdcg" inspect lj_fcc.dump | sed 's/^/   /'

echo "== 4. pdcg atoms2pd: the delta body (points at the atoms, families from the cutoff)"
"$pdcg" -q atoms2pd --input lj_fcc.data --potential "$case_dir/potential.lj" --density delta -o body.h5
"$pdcg" info body.h5 | head -3 | sed 's/^/   /'

echo "== 5. pdcg forces: PD internal forces f_k = Σ_j (t_kj − t_jk) vs the MD forces of LAMMPS"
"$pdcg" -q forces body.h5 -o forces.csv
$py "$here/compare_forces.py" forces.csv lj_fcc.dump > forces_check.json
$py -c "import json; d=json.load(open('forces_check.json')); print(f\"   max |f_PD − f_LAMMPS| / max |f_LAMMPS| = {d['max_norm_relative_error']:.2e} over {d['atoms']} atoms; |Σ f| = {d['net_force']:.1e}\")"

echo "== 6. homogenise (Wendland C2 kernel on a grid) and rescale the horizon (ε = 4)"
F="1.02 0.01 0 0 0.99 0 0 0 1.01"
"$pdcg" -q energy body.h5 --F "$F" --json > energy_delta.json
"$pdcg" -q homogenize body.h5 --kernel wendland-c2 --width 2.0 --spacing 0.8 -o hom.h5
"$pdcg" -q energy hom.h5 --F "$F" --json > energy_hom.json
"$pdcg" -q rescale hom.h5 --factor 4 -o res.h5
"$pdcg" -q energy res.h5 --F "$F" --json > energy_res.json
$py - <<'PY'
import json
d, h, r = (json.load(open(f"energy_{k}.json")) for k in ("delta", "hom", "res"))
print(f"   energy density under F: atoms {d['energy_density']:.12g}, homogenised {h['energy_density']:.12g}, rescaled {r['energy_density']:.12g}")
print(f"   relative differences: {abs(h['energy_density']/d['energy_density']-1):.1e}, {abs(r['energy_density']/d['energy_density']-1):.1e} (§2.3-2.4: must vanish)")
PY

echo "== 7. dispersion: perfect lattice (LAMMPS), its delta body, rescaled by ε = 2 and 4"
(cd "$case_dir" && lmp -in in.lj_fcc -var out "$out" -var perturb 0 -var name perfect -log none -screen none)
"$pdcg" -q atoms2pd --input perfect.data --potential "$case_dir/potential.lj" -o perfect.h5
"$pdcg" -q dispersion perfect.h5 --path G-X-W-L-G-K --nk 30 -o dispersion_atoms.csv
for eps in 2 4; do
  "$pdcg" -q rescale perfect.h5 --factor $eps -o perfect_eps$eps.h5
  "$pdcg" -q dispersion perfect_eps$eps.h5 --direction 1,0,0 --kmax 3.9582 --nk 60 -o dispersion_eps$eps.csv
done
"$pdcg" -q dispersion perfect.h5 --direction 1,0,0 --kmax 3.9582 --nk 60 -o dispersion_atoms_100.csv
$py "$here/../lib/plot_dispersion.py" dispersion.png "FCC LJ along [100]: atoms and rescaled models" \
    dispersion_atoms_100.csv:"atoms (delta body)" dispersion_eps2.csv:"rescaled ε = 2" dispersion_eps4.csv:"rescaled ε = 4"
$py "$here/../lib/plot_dispersion.py" dispersion_path.png "FCC LJ delta body, G-X-W-L-G-K" dispersion_atoms.csv:"atoms"
echo "   dispersion.png (atoms vs rescaled along [100]), dispersion_path.png (high-symmetry path)"

if "$pdcg" --help | grep -q '^  run '; then
  echo "== 8. BA correspondence solver: a plate with a hole pulled to 1.5× its length"
  "$pdcg" -q run "$here/plate.yaml" -o plate > plate.log 2>&1 || { tail -20 plate.log; exit 1; }
  tail -3 plate/reactions.csv | sed 's/^/   /'
fi

$py "$here/report.py" "$out" "$(stamp)"
echo "   report: $out/report.md"
