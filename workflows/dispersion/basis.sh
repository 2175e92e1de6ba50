#!/usr/bin/env bash
# Crystals with a basis (docs/dispersion.md "Crystals with a basis"): the 6 branches (3
# acoustic, 3 optical) of diamond Si, Stillinger–Weber, along Setyawan–Curtarolo's fcc path,
# for the delta body; also the ε = 2 rescaled body's CSV (ω_ε(κ) = ω(εκ)/ε: the same curves
# over half the path length at half the frequency; not drawn, its path ticks differ).
#
#   workflows/dispersion/basis.sh [OUT=results/dispersion_basis]     (~5 s; PDCG=/path/to/pdcg optional)
#
# Writes si.data (LAMMPS), si.h5, si_eps2.h5, si.csv, si_eps2.csv and si_dispersion.png (the
# picture in docs/dispersion.md). The numbers are checked against LAMMPS force constants by
# ctest (cli.dispersion_basis, CrystalDispersion.*), not here.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/../lib/setup.sh"
OUT=${1:-$PDCG_ROOT/results/dispersion_basis}
if [[ -z "${PDCG:-}" ]]; then
  [[ -f "$PDCG_BUILD/CMakeCache.txt" ]] || cmake -S "$PDCG_ROOT" -B "$PDCG_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build "$PDCG_BUILD" -j"${PDCG_JOBS:-2}" --target pdcg >/dev/null
  PDCG=$PDCG_BUILD/pdcg
fi
export LAMMPS_POTENTIALS=${LAMMPS_POTENTIALS:-/usr/share/lammps/potentials}
mkdir -p "$OUT"
cd "$OUT"
cat > si.in <<'IN'
units metal
boundary p p p
lattice diamond 5.431
region b block 0 3 0 3 0 3
create_box 1 b
create_atoms 1 region b
mass 1 28.0855
write_data si.data
IN
lmp -in si.in -log none -screen none -nocite
printf 'units metal\nmass 1 28.0855\npair_style sw\npair_coeff * * Si.sw Si\n' > sw.pot
"$PDCG" -q atoms2pd --input si.data --potential sw.pot -o si.h5
"$PDCG" -q rescale si.h5 --factor 2 -o si_eps2.h5
"$PDCG" -q dispersion si.h5 --path auto --nk 30 -o si.csv
"$PDCG" -q dispersion si_eps2.h5 --path auto --nk 30 -o si_eps2.csv
/usr/bin/python3 "$HERE/../lib/plot_dispersion.py" si_dispersion.png \
  "diamond Si (Stillinger–Weber): 3 acoustic + 3 optical branches" si.csv:"delta body"
echo "dispersion of diamond Si -> $OUT/si_dispersion.png"
