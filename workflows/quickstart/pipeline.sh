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
print(f"   relative differences: {abs(h['energy_density']/d['energy_density']-1):.1e}, {abs(r['energy_density']/d['energy_density']-1):.1e} (docs/theory.md §3-4: must vanish)")
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

# ---- flagship: a notched triangular Lennard-Jones sheet, from atoms to rupture (docs/flagship.md)
sheet_dir="$case_dir/../lj_sheet"
mkdir -p sheet
echo "== 9. LAMMPS: relax the 2D triangular LJ sheet (dimension 2, lj/cut 2.5σ)"
(cd "$sheet_dir" && lmp -in in.relax -var out "$out/sheet" -log "$out/sheet/relax.log" -screen none)
a0=$(cat sheet/a0.txt)
echo "   zero-stress nearest-neighbour distance a0 = $a0 σ"

echo "== 10. sheet delta body (dimension 2) and its forces vs LAMMPS"
"$pdcg" -q atoms2pd --input sheet/sheet.data --potential "$sheet_dir/potential.lj" --dimension 2 --boundary "p p f" -o sheet/body.h5
"$pdcg" -q forces sheet/body.h5 -o sheet/forces.csv
$py "$here/compare_forces.py" sheet/forces.csv sheet/sheet.dump > sheet/forces_check.json
$py -c "import json; d=json.load(open('sheet/forces_check.json')); print(f\"   max |f_PD − f_LAMMPS| / max |f_LAMMPS| = {d['max_norm_relative_error']:.2e} over {d['atoms']} atoms\")"

echo "== 11. coarse sheet: homogenise (Wendland C2) and rescale by ε = 2; Cauchy–Born constants"
"$pdcg" -q atoms2pd --input sheet/sheet_perfect.data --potential "$sheet_dir/potential.lj" --dimension 2 --boundary "p p f" -o sheet/perfect.h5
"$pdcg" -q homogenize sheet/perfect.h5 --kernel wendland-c2 --width 2.5 --spacing 1.0 -o sheet/hom.h5
"$pdcg" -q rescale sheet/hom.h5 --factor 2 -o sheet/res.h5
for k in perfect hom res; do "$pdcg" -q elastic sheet/$k.h5 --json --critical > sheet/elastic_$k.json; done
$py - <<'PY'
import json
e = {k: json.load(open(f"sheet/elastic_{k}.json")) for k in ("perfect", "hom", "res")}
C = {k: e[k]["C_voigt"] for k in e}
d = max(abs(C[k][i][j] - C["perfect"][i][j]) for k in ("hom", "res") for i in range(6) for j in range(6)) / C["perfect"][0][0]
print(f"   C11 {C['perfect'][0][0]:.6g}, C12 {C['perfect'][0][1]:.6g}, C66 {C['perfect'][5][5]:.6g} (ε/σ²); homogenised/rescaled differ by {d:.1e}·C11")
print(f"   LJ bond inflection: r_infl/r_min = {e['perfect']['bond_inflection_stretch']:.6f}")
PY

echo "== 12. dispersion along x: atoms vs the coarse (rescaled) sheet"
echo "   (an 'unstable modes' warning here is the out-of-plane branch ω₁ of the 2D body, ω₁² ≈ −1e-5·ω²_LA:"
echo "    a flat sheet with a pair potential has no bending stiffness; the in-plane model never uses it)"
kx=$($py -c "import math; print(4*math.pi/(3*$a0))")  # the K point (zone edge along x)
"$pdcg" -q dispersion sheet/perfect.h5 --direction 1,0,0 --kmax "$kx" --nk 60 -o sheet/dispersion_atoms.csv
for eps in 2 4; do
  "$pdcg" -q rescale sheet/perfect.h5 --factor $eps -o sheet/perfect_eps$eps.h5
  "$pdcg" -q dispersion sheet/perfect_eps$eps.h5 --direction 1,0,0 --kmax "$kx" --nk 60 -o sheet/dispersion_eps$eps.csv
done
"$pdcg" -q dispersion sheet/res.h5 --direction 1,0,0 --kmax "$kx" --nk 60 -o sheet/dispersion_res.csv
echo "   sheet_dispersion.png: in-plane branches, atoms vs coarse models (drawn by report.py)"

echo "== 13. BA solver: the notched coarse sheet pulled to rupture (Cauchy–Born material of res.h5)"
$py "$here/sheet_scene.py" sheet > sheet/scene_info.json
$py "$here/timed.py" sheet/pd_time.json "$out" "$pdcg" -q run sheet/sheet.yaml -o sheet/pd > sheet/pd.log 2>&1 \
  || { tail -20 sheet/pd.log; exit 1; }
echo "   PD: $(tail -1 sheet/pd/reactions.csv | awk -F, '{print $NF}') broken bonds at the last step; $($py -c "import json; t=json.load(open('sheet/pd_time.json')); print(f\"{t['wall']:.1f} s wall, {t['cpu']:.1f} s CPU\")")"

echo "== 14. LAMMPS MD fracture of the same notched sheet (atomistic size, 1 core)"
OMP_NUM_THREADS=1 $py "$here/timed.py" sheet/md_time.json "$sheet_dir" lmp -in in.fracture -var out "$out/sheet" -log "$out/sheet/md.log" -screen none
$py "$sheet_dir/md_fracture.py" sheet "$($py -c "import json; print(json.load(open('sheet/md_time.json'))['wall'])")" > /dev/null
echo "   MD: $($py -c "import json; t=json.load(open('sheet/md_time.json')); print(f\"{t['wall']:.1f} s wall, {t['cpu']:.1f} s CPU\")")"

$py "$here/report.py" "$out" "$(stamp)"
echo "   report: $out/report.md"
