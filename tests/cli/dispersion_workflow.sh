#!/usr/bin/env bash
# The dispersion workflow (workflows/dispersion/run.sh) end to end into a temporary
# directory, then its numbers: every model curve of the chain bodies (delta, homogenised with
# each kernel, rescaled ε = 2 and 4, homogenised + rescaled) within 1e-12 of the closed form
# (same formula, round-off only), the measured ridges of the LAMMPS MD and of the `pdcg md` run
# of the ε = 2 body within one frequency bin (the transform's resolution), FCC LJ within 1e-5
# of ω_max of LAMMPS lattice dynamics (central-difference step), and the PNG.
# Usage: dispersion_workflow.sh /path/to/pdcg <source-dir>
set -euo pipefail
pdcg=$1 src=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
PDCG=$pdcg bash "$src/workflows/dispersion/run.sh" "$tmp/out" | grep -v '^md:'
/usr/bin/python3 - "$tmp/out" <<'PY'
import json, math, sys
import matplotlib.image as mpimg
out = sys.argv[1]
rows = json.load(open(f"{out}/acceptance.json"))
assert len(rows) == 26, len(rows)  # per chain 8 bodies, 2 quoted values, 2 ridges; FCC 2
fail = [r for r in rows if not (math.isfinite(r["worst"]) and r["worst"] <= r["tolerance"])]
for r in fail: print("FAIL", r)
def get(prefix):
    return [r for r in rows if r["case"].startswith(prefix)]
# the acceptance tolerances themselves, not only what the script chose
assert all(r["tolerance"] == 1e-12 for r in get("chain") if "measured" not in r["case"])
assert all(r["tolerance"] == 1.0 and r["unit"] == "bins" for r in rows if "measured" in r["case"])
assert len([r for r in rows if "homogenised" in r["case"]]) == 10  # 4 kernels + hom+rescaled, 2 chains
assert get("FCC LJ delta")[0]["tolerance"] == 1e-5
img = mpimg.imread(f"{out}/dispersion.png")
assert img.shape[0] > 400 and img.shape[1] > 1200, img.shape
print(f"dispersion_workflow: {len(rows)} checks, worst model error "
      f"{max(r['worst'] for r in rows if r['unit'] == 'abs'):.2e}, worst ridge "
      f"{max(r['worst'] for r in rows if r['unit'] == 'bins'):.3f} bins, FCC {get('FCC LJ delta')[0]['worst']:.2e}")
sys.exit(1 if fail else 0)
PY
