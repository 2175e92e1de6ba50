#!/usr/bin/env bash
# `pdcg dispersion --path` on crystals with a basis (docs/dispersion.md "Crystals with a basis"):
#  1. diamond Si (sw), 2×2×2 cubic cells from LAMMPS: --path G-X-W-K-G-L gives 6 branches, a
#     '# path labels:' line; at Γ, X, W and L (commensurate with the box) the CSV equals the
#     eigenvalues of a dynamical matrix built here from LAMMPS forces (lammps Python module,
#     central differences with Richardson extrapolation), within 1e-6 of ω_max; Γ acoustic = 0.
#  2. the rescaled body (ε = 2): ω_ε(X/ε) = ω(X)/ε, 6 branches; the homogenised body: 3 branches
#     and an info line saying why.
#  3. hcp (LJ) --path auto: 6 branches along G-M-K-G-A-L-H-A|L-M|K-H; --path G-X lists the hcp
#     labels.
#  4. bad input: a vacancy, a random two-species alloy → exit 2, the reason and the fix, no CSV.
#  5. FCC Cu (one basis atom): the ω columns equal the pre-change pdcg's (when given).
# On the old code (before primitive-cell dispersion) 1 and 3 fail: --path on a crystal with a
# basis was refused.
# Usage: dispersion_basis.sh PDCG PDCG_SOURCE_DIR [OLD_PDCG]
set -u
pdcg=$1
old=${3:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
export LAMMPS_POTENTIALS=${LAMMPS_POTENTIALS:-/usr/share/lammps/potentials}
fail=0
lmprun() { lmp -in "$1" -log none -screen none -nocite || { echo "lmp $1 failed"; exit 1; }; }
expect_error() {  # expect_error <name> <regex> <args...>
  local name=$1 regex=$2; shift 2
  local out code
  rm -f x.csv
  out=$("$pdcg" dispersion "$@" 2>&1) && code=0 || code=$?
  if [ "$code" = 2 ] && grep -Eq -- "$regex" <<<"$out" && [ ! -e x.csv ]; then echo "ok   $name"
  else echo "FAIL $name (exit $code): $out"; fail=1; fi
}

cat > si.in <<'IN'
units metal
boundary p p p
lattice diamond 5.431
region b block 0 2 0 2 0 2
create_box 2 b
create_atoms 1 region b
mass * 28.0855
write_data si.data
IN
cat > hcp.in <<'IN'
units lj
boundary p p p
lattice hcp 1.12
region b block 0 4 0 3 0 3
create_box 1 b
create_atoms 1 box
mass 1 1.0
write_data hcp.data
IN
for f in si hcp; do lmprun $f.in; done
printf 'units metal\nmass * 28.0855\npair_style sw\npair_coeff * * Si.sw Si Si\n' > sw.pot
printf 'units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n' > hcp.pot
"$pdcg" -q atoms2pd --input si.data --potential sw.pot -o si.h5 || exit 1
"$pdcg" -q atoms2pd --input hcp.data --potential hcp.pot -o hcp.h5 || exit 1

# --- 1. diamond Si against LAMMPS ------------------------------------------------------------
"$pdcg" dispersion si.h5 --path G-X-W-K-G-L --nk 4 -o si.csv > si.out 2>&1 || { cat si.out; exit 1; }
grep -q "primitive cell of 2 basis atoms (6 branches" si.out || { echo "no 6-branch line"; cat si.out; fail=1; }
/usr/bin/python3 - <<'PY' || fail=1
import csv, math
import numpy as np
from lammps import lammps

lines = open("si.csv").read().splitlines()
assert lines[0].startswith("# pdcg dispersion: units metal"), lines[0]
assert lines[1].startswith("# path labels: G@0 X@"), lines[1]
labels = {t.split("@")[0]: float(t.split("@")[1]) for t in lines[1].split(":", 1)[1].split()}
rows = list(csv.DictReader(lines[2:]))
assert [c for c in rows[0] if c.startswith("omega")] == [f"omega_{i}" for i in range(1, 7)], rows[0].keys()
def at(label):  # the row of a labelled corner (first occurrence)
    r = next(r for r in rows if abs(float(r["kappa"]) - labels[label]) < 1e-12)
    return np.array([float(r[f"omega_{i}"]) for i in range(1, 7)]), np.array([float(r[c]) for c in ("kx", "ky", "kz")])

# LAMMPS: Φ(jα, sβ) = −∂F_jα/∂u_sβ for s = the two basis atoms (ids 1 and the one at a/4(1,1,1))
lmp = lammps(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
lmp.commands_string("""units metal
atom_modify map array
read_data si.data
pair_style sw
pair_coeff * * Si.sw Si Si
""")
n = lmp.get_natoms()
x0 = np.array(lmp.gather_atoms("x", 1, 3)).reshape(n, 3)
box = np.array([lmp.extract_box()[1][i] - lmp.extract_box()[0][i] for i in range(3)])
def forces(x):
    lmp.scatter_atoms("x", 1, 3, (len(x.ravel()) * __import__("ctypes").c_double)(*x.ravel()))
    lmp.command("run 0")
    return np.array(lmp.gather_atoms("f", 1, 3)).reshape(n, 3)
a = 5.431
s0 = int(np.argmin(np.linalg.norm(x0, axis=1)))
s1 = int(np.argmin(np.linalg.norm(x0 - a / 4, axis=1)))
rel = (x0[:, None, :] - x0[None, [s0, s1], :]) / a  # class by the offset from a basis atom
cls = np.array([0 if np.allclose(np.round(2 * rel[j, 0]) / 2, rel[j, 0]) else 1 for j in range(n)])
assert (cls == 0).sum() == (cls == 1).sum() == n // 2
def column(s, beta, h):
    xp, xm = x0.copy(), x0.copy()
    xp[s, beta] += h; xm[s, beta] -= h
    return -(forces(xp) - forces(xm)) / (2 * h)
h = 1e-2
phi = {}
for c, s in enumerate((s0, s1)):
    phi[c] = [(4 * column(s, b, h / 2) - column(s, b, h)) / 3 for b in range(3)]  # Richardson
forces(x0)
m, mvv2e = 28.0855, 1.0364269e-4
def omega(k):
    D = np.zeros((6, 6), complex)
    for c, s in enumerate((s0, s1)):
        for l in range(n):
            ph = np.exp(1j * k.dot(x0[l] - x0[s]))
            for al in range(3):
                for be in range(3):
                    D[3 * c + al, 3 * cls[l] + be] += phi[c][al][l, be] * ph / (m * mvv2e)
    w2 = np.linalg.eigvalsh(0.5 * (D + D.conj().T))
    return np.sign(w2) * np.sqrt(np.abs(w2))
worst, wmax = 0.0, 0.0
for label in ("G", "X", "W", "L"):
    w, k = at(label)
    assert all(abs(math.remainder(k[i] * box[i], 2 * math.pi)) < 1e-9 for i in range(3)), (label, k)
    r = omega(k)
    wmax = max(wmax, r.max())
    worst = max(worst, np.abs(w - r).max())
    print(f"  {label}: pdcg {np.round(w, 6)}\n     LAMMPS {np.round(r, 6)}")
w, _ = at("G")
assert (w[:3] == 0).all() and w[3] > 100, w  # acoustic exactly 0 at Γ, optical Γ25' ≈ 112 rad/ps
print(f"  diamond Si (sw) vs LAMMPS: max |Δω| = {worst:.3g} = {worst / wmax:.3g} of ω_max {wmax:.6g}")
# acceptance 1e-6 of ω_max; the reference's own error (Richardson, O(h⁴)) is ~1e-8 off Γ and
# √(round-off of ω²) ≈ 2e-6 rad/ps at Γ's acoustic modes
assert worst < 1e-6 * wmax, worst
PY

# --- 2. rescaled and homogenised bodies ------------------------------------------------------
"$pdcg" -q rescale si.h5 --factor 2 -o si_r2.h5 || exit 1
"$pdcg" -q dispersion si_r2.h5 --path G-X --nk 4 -o r2.csv || fail=1
"$pdcg" -q homogenize si.h5 --kernel wendland-c2 --width 6 --spacing 5.431 -o si_h.h5 || exit 1
"$pdcg" dispersion si_h.h5 --path G-X --nk 4 -o h.csv > h.out 2>&1 || { cat h.out; fail=1; }
grep -q "homogenised body: the model has 3 degrees of freedom per point, so 3 branches" h.out ||
  { echo "homogenised: no info line"; cat h.out; fail=1; }
/usr/bin/python3 - <<'PY' || fail=1
import csv
def rows(p):
    return list(csv.DictReader(l for l in open(p) if not l.startswith("#")))
d, r, h = rows("si.csv"), rows("r2.csv"), rows("h.csv")
wx = [float(d[4][f"omega_{i}"]) for i in range(1, 7)]   # X: 4th step of G-X
wr = [float(r[-1][f"omega_{i}"]) for i in range(1, 7)]  # X of the ε = 2 lattice = X/2
assert max(abs(a / 2 - b) for a, b in zip(wx, wr)) < 1e-12 * max(wx), (wx, wr)
assert "omega_4" not in h[0] and "omega_3" in h[0], h[0].keys()
print("  rescaled ε = 2: ω(X)/2 to 1e-12; homogenised: 3 branches")
PY

# --- 3. hcp: auto path, labels ---------------------------------------------------------------
"$pdcg" dispersion hcp.h5 --path auto --nk 3 -o hcp.csv > hcp.out 2>&1 || { cat hcp.out; fail=1; }
grep -q "hcp lattice, a = 1.08.*, c = 1.76.*2 basis atoms" hcp.out || { echo "hcp not classified"; cat hcp.out; fail=1; }
sed -n 2p hcp.csv | grep -q '^# path labels: G@0 M@.* K@.* G@.* A@.* L@.* H@.* A|L@.* M|K@.* H@' ||
  { echo "hcp labels"; sed -n 2p hcp.csv; fail=1; }
sed -n 3p hcp.csv | grep -q '^kappa,omega_1,omega_2,omega_3,omega_4,omega_5,omega_6,kx,ky,kz$' ||
  { echo "hcp header"; sed -n 3p hcp.csv; fail=1; }
expect_error hcp-label-X "path label unknown for this lattice.*'X'.*one of G, M, K, A, L, H for lattice hcp" hcp.h5 --path G-X -o x.csv

# --- 4. not a perfect crystal ----------------------------------------------------------------
cat > defects.in <<'IN'
units metal
boundary p p p
read_data si.data
group last id 64
delete_atoms group last
write_data vac.data
clear
units metal
boundary p p p
read_data si.data
set type 1 type/fraction 2 0.5 12345
write_data alloy.data
IN
lmprun defects.in
"$pdcg" -q atoms2pd --input vac.data --potential sw.pot -o vac.h5 || exit 1
"$pdcg" -q atoms2pd --input alloy.data --potential sw.pot -o alloy.h5 || exit 1
expect_error vacancy "vac.h5.*--path needs a perfect crystal.*unequal population.*vacancies.*--cell" vac.h5 --path auto -o x.csv
# 64 atoms, every one its own environment (the box has no inner translation)
expect_error random-alloy "alloy.h5.*--path needs a perfect crystal.*64 atoms, 64 different environments.*random alloy.*--cell" alloy.h5 --path G-X -o x.csv

# --- 5. FCC Cu: same ω as before ------------------------------------------------------------
cat > cu.in <<'IN'
units metal
boundary p p p
lattice fcc 3.615
region b block 0 3 0 3 0 3
create_box 1 b
create_atoms 1 box
mass 1 63.55
write_data cu.data
IN
lmprun cu.in
printf 'units metal\nmass 1 63.55\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n' > cu.pot
"$pdcg" -q atoms2pd --input cu.data --potential cu.pot -o cu.h5 || exit 1
"$pdcg" -q dispersion cu.h5 --path G-X-W-K-G-L --nk 4 -o cu.csv || fail=1
sed -n 3p cu.csv | grep -q '^kappa,omega_1,omega_2,omega_3,kx,ky,kz$' || { echo "cu header"; fail=1; }
if [ -n "$old" ] && [ -x "$old" ]; then
  "$old" -q dispersion cu.h5 --path G-X-W-K-G-L --nk 4 -o cu_old.csv || fail=1
  # identical numbers; the new file has the labels line
  diff <(grep -v '^#' cu.csv) <(grep -v '^#' cu_old.csv) > /dev/null &&
    echo "ok   FCC Cu identical to the pre-change pdcg" || { echo "FCC Cu differs from the old pdcg"; fail=1; }
fi
exit $fail
