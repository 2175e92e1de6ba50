#!/usr/bin/env bash
# Dispersion workflow (docs/dispersion.md): atomistic, homogenised and rescaled curves in one PNG.
#
#   workflows/dispersion/run.sh [OUT=results/dispersion]        (~30 s; PDCG=/path/to/pdcg optional)
#
# 1D harmonic chains (atomistics/chain1d, μ₁ = M = h = 1, μ₂ ∈ {0, 0.25}):
#   LAMMPS writes the chain (data file with its bonds) and an NVE trajectory;
#   pdcg atoms2pd → delta body; pdcg homogenize with every kernel; pdcg rescale ε = 2, 4
#   (of the delta body and of a homogenised one); pdcg dispersion of each body;
#   pdcg dispersion --trajectory of the LAMMPS run and of a `pdcg md` run of the ε = 2 body.
# FCC Lennard-Jones (atomistics/lj_fcc, perfect lattice): pdcg dispersion of the delta body
#   along G-X-W-L-G-K against lattice dynamics from LAMMPS forces (central differences in
#   lattice_dynamics.py, through the LAMMPS Python module).
# check_and_plot.py compares everything with the closed forms (written there, independent of
# pdcg), writes errors.csv + acceptance.json, draws dispersion.png and exits 1 if an
# acceptance tolerance is missed.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
OUT=${1:-$PDCG_ROOT/results/dispersion}
PY=/usr/bin/python3
if [[ -z "${PDCG:-}" ]]; then
  [[ -f "$PDCG_BUILD/CMakeCache.txt" ]] || cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target pdcg >/dev/null
  PDCG=$PDCG_BUILD/pdcg
fi
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
pdcg() { "$PDCG" -q "$@" >/dev/null; }
KERNELS="top-hat gaussian cubic-bspline wendland-c2"
PI=3.141592653589793

for mu2 in 0 0.25; do
  d=$OUT/chain_mu2_$mu2
  mkdir -p "$d"
  echo "== chain μ₂ = $mu2: LAMMPS (data file + NVE trajectory, 1024 frames)"
  (cd "$d" && lmp -in "$PDCG_ROOT/atomistics/chain1d/in.chain" -var out . -var mu2 "$mu2" -log none -screen none)
  # the same springs as the deck, for pdcg (bond_style harmonic: E = K (r − r0)², K = μ/2)
  cat >"$d/potential.chain" <<EOF
units lj
mass 1 1.0
pair_style zero 2.5
pair_coeff * *
bond_style harmonic
bond_coeff 1 0.5 1.0
bond_coeff 2 $($PY -c "print($mu2/2)") 2.0
special_bonds lj/coul 0.0 1.0 1.0
EOF
  cd "$d"
  pdcg atoms2pd --input chain.data --potential potential.chain --dimension 1 --boundary "p f f" -o delta.h5
  pdcg dispersion delta.h5 --direction 1,0,0 --kmax $PI --nk 64 -o model_delta.csv
  for k in $KERNELS; do
    w=2.0; [[ $k == gaussian ]] && w=0.8  # gaussian width is σ (support 3σ)
    pdcg homogenize delta.h5 --kernel $k --width $w --spacing 0.8 -o hom_$k.h5
    pdcg dispersion hom_$k.h5 --direction 1,0,0 --kmax $PI --nk 64 -o model_hom_$k.csv
  done
  for eps in 2 4; do
    pdcg rescale delta.h5 --factor $eps -o res_$eps.h5
    pdcg dispersion res_$eps.h5 --direction 1,0,0 --kmax $PI --nk 64 -o model_res_$eps.csv
  done
  pdcg rescale hom_wendland-c2.h5 --factor 4 -o hom_res_4.h5
  pdcg dispersion hom_res_4.h5 --direction 1,0,0 --kmax $PI --nk 64 -o model_hom_res_4.csv
  echo "== chain μ₂ = $mu2: measured (LAMMPS trajectory; pdcg md of the ε = 2 body)"
  pdcg dispersion --trajectory chain.dump --dt 0.01 -o measured_lammps.csv
  pdcg md res_2.h5 --steps 10230 --dt 0.02 --temperature 0.01 --seed 7 --dump md_res_2.dump --every 10
  pdcg dispersion --trajectory md_res_2.dump --dt 0.02 -o measured_md_res_2.csv
  rm -f md_res_2.dump chain.dump
  cd "$OUT"
done

echo "== FCC LJ (perfect 4×4×4 lattice): delta body along G-X-W-L-G-K vs LAMMPS lattice dynamics"
d=$OUT/fcc_lj
mkdir -p "$d"
(cd "$PDCG_ROOT/atomistics/lj_fcc" && lmp -in in.lj_fcc -var out "$d" -var perturb 0 -var name perfect -log none -screen none)
cd "$d"
rm -f perfect.dump
pdcg atoms2pd --input perfect.data --potential "$PDCG_ROOT/atomistics/lj_fcc/potential.lj" -o delta.h5
pdcg dispersion delta.h5 --path G-X-W-L-G-K --nk 20 -o model_delta.csv
pdcg rescale delta.h5 --factor 16 -o res_16.h5
pdcg dispersion res_16.h5 --path G-X-W-L-G-K --nk 20 -o model_res_16.csv
$PY "$HERE/lattice_dynamics.py" perfect.data "$PDCG_ROOT/atomistics/lj_fcc/potential.lj" model_delta.csv lammps_ld.csv
cd "$OUT"
rm -f "$OUT"/*/*.h5

$PY "$HERE/check_and_plot.py" "$OUT"
