#!/usr/bin/env bash
# Edge energy γ of the close-packed row of the 2D triangular sheets (docs/fracture.md, 'A brittle
# reference system'): `pdcg surface` against LAMMPS alone.
#   LAMMPS: workflows/fracture/brittle_md/make_decks.py writes the decks; `lmp` relaxes the 2D
#   lattice (box/relax -> a0) and computes γ_2D = (E_edge − E_bulk)/(2 L_x) of an 8 × 10 hex-cell
#   cell made non-periodic in y, unrelaxed and minimised (in.surface).
#   pdcg surface takes 3-D crystals, so the sheet is stacked: layers of the same 2D lattice c apart
#   along z, c = 2 r_c + 0.5 (no interaction between layers), a 3-D periodic cell of 2 atoms
#   (a0 × √3 a0 × c); `pdcg surface --normal "0 1 0"` cuts it parallel to the rows, with the same
#   slab height as LAMMPS (20 rows). Per unit length of edge γ_2D = γ_3D c.
#   Tolerances: unrelaxed 1e-10 relative (the same atoms: round-off of two lattice sums whose
#   difference is a few % of each), relaxed 1e-8 (both minimisers stop at |f| ≤ 1e-10 resp.
#   1e-12; the energy error of a minimum found to |f| is ~|f|²/k ≪ 1e-12).
# Systems: lj15 (the brittle reference system; nearest neighbours only, so its edge does
# not relax and relaxed = unrelaxed; its γ is also the closed form (ε − |φ(r_c)|)/a0, a0 = 2^(1/6)σ:
# two bonds per a0 of edge, each of energy −(ε − |φ(r_c)|), cut per two edges) and lj25 (the
# flagship's model; its edge relaxes).
# Usage: brittle_surface.sh /path/to/pdcg SOURCE_DIR
set -u
pdcg=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
fail=0
for sys in lj15 lj25; do
  /usr/bin/python3 "$src/workflows/fracture/brittle_md/make_decks.py" --system $sys $sys > /dev/null || { echo "FAIL: make_decks $sys"; exit 1; }
  (cd $sys && lmp -in in.relax -var out . -log none -screen none > /dev/null \
    && lmp -in in.surface -var out . -log none -screen none > /dev/null) || { echo "FAIL: lmp $sys"; fail=1; continue; }
  rc=$(awk '{print $2}' $sys/system.txt)
  /usr/bin/python3 - $sys "$rc" <<'PY' || { fail=1; continue; }
import math, sys
s, rc = sys.argv[1], float(sys.argv[2])
a0 = float(open(f"{s}/a0.txt").read())
c = 2 * rc + 0.5
ly = math.sqrt(3) * a0
with open(f"{s}/layers.data", "w") as f:
    f.write(f"stacked 2D triangular layers of {s}\n\n2 atoms\n3 atom types\n\n"
            f"0 {a0!r} xlo xhi\n0 {ly!r} ylo yhi\n0 {c!r} zlo zhi\n\nMasses\n\n1 1\n2 1\n3 1\n\n"
            f"Atoms # atomic\n\n1 1 0 0 0\n2 1 {0.5 * a0!r} {0.5 * ly!r} 0\n")
with open(f"{s}/layers.mod", "w") as f:
    f.write("units lj\nboundary p p p\n" + open(f"{s}/potential.mod").read())
open(f"{s}/thickness.txt", "w").write(repr(10 * ly) + "\n")
PY
  "$pdcg" atoms2pd --input $sys/layers.data --potential $sys/layers.mod -o $sys/layers.h5 > /dev/null 2> err.txt \
    || { echo "FAIL: atoms2pd $sys"; cat err.txt; fail=1; continue; }
  "$pdcg" surface $sys/layers.h5 --normal "0 1 0" --thickness "$(cat $sys/thickness.txt)" --json > $sys/pd.json 2> err.txt \
    || { echo "FAIL: pdcg surface $sys"; cat err.txt; fail=1; continue; }
  /usr/bin/python3 - $sys "$rc" <<'PY' || fail=1
import json, sys
s, rc = sys.argv[1], float(sys.argv[2])
c = 2 * rc + 0.5
pd = json.load(open(f"{s}/pd.json"))
ref = dict(l.split()[:2] for l in open(f"{s}/gamma.txt") if l.startswith("gamma"))
gu, gr = float(ref["gamma_unrelaxed"]), float(ref["gamma_relaxed"])
pu, pr = pd["unrelaxed"]["gamma"] * c, pd["relaxed"]["gamma"] * c
u, r = abs(pu - gu) / gu, abs(pr - gr) / gr
ok = pd["cell"]["layers"] == 20 and u < 1e-10 and r < 1e-8  # reasons in the header
if s == "lj15":  # closed form; 1e-13: one division and a few products in double precision
    a0 = 2 ** (1 / 6)
    closed = (1 + 4 * (1.5**-12 - 1.5**-6)) / a0
    ok &= abs(pu - closed) / closed < 1e-13 and abs(gu - closed) / closed < 1e-13
    print(f"  lj15 closed form {closed:.15g}: pdcg rel {abs(pu - closed) / closed:.1e}, LAMMPS rel {abs(gu - closed) / closed:.1e}")
print(f"  {s}: {pd['cell']['layers']} rows; gamma unrelaxed {pu:.15g} vs LAMMPS {gu:.15g} "
      f"(rel {u:.1e}); relaxed {pr:.15g} vs {gr:.15g} (rel {r:.1e}); G_c = 2 gamma = {2 * pr:.10g}"
      f"{'' if ok else '  <-- FAIL'}")
raise SystemExit(0 if ok else 1)
PY
done
exit $fail
