#!/usr/bin/env bash
# `pdcg elastic`: FCC Cu (EAM Cu_u3) prepared by the `lmp` binary; the CLI's C11,
# C12, C44 against LAMMPS energies of the same crystal under ±Green–Lagrange strain (second
# differences, as in tests/unit/body/test_cauchy_born.cpp), the same constants for the
# homogenised and rescaled model files, and exit code 2 for a bad --F.
# Usage: elastic.sh /path/to/pdcg
set -u
pdcg=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
fail=0
cat > make.in <<'IN'
units metal
lattice fcc 3.615
region box block 0 3 0 3 0 3
create_box 1 box
create_atoms 1 box
mass 1 63.546
write_data cu.data
IN
lmp -log none -screen none -in make.in || { echo "lmp failed"; exit 1; }
printf 'units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n' > cu.pot
"$pdcg" atoms2pd --input cu.data --potential cu.pot -o cu.h5 >/dev/null || exit 1
"$pdcg" homogenize cu.h5 --kernel cubic-bspline --width 4.7 --spacing 3.0 --shift "0.31 -0.17 0.44" -o hom.h5 >/dev/null || exit 1
"$pdcg" rescale hom.h5 --factor 3 -o res.h5 >/dev/null || exit 1
for f in cu hom res; do "$pdcg" elastic $f.h5 --json > $f.json || { echo "elastic $f failed"; fail=1; }; done
# LAMMPS reference: W(E) from `lmp` energies, C11 = W''(E11), C12 mixed, C44 = W''(E23)/4
python3 - <<'PY' || fail=1
import json, math, subprocess
h = 1e-4
def chol_upper(C):
    # C = RᵀR, R upper triangular
    R = [[0.0]*3 for _ in range(3)]
    for i in range(3):
        s = C[i][i] - sum(R[k][i]**2 for k in range(i))
        R[i][i] = math.sqrt(s)
        for j in range(i+1, 3):
            R[i][j] = (C[i][j] - sum(R[k][i]*R[k][j] for k in range(i))) / R[i][i]
    return R
def W(e11, e22, e23):
    C = [[1+2*e11, 0, 0], [0, 1+2*e22, 2*e23], [0, 2*e23, 1]]
    R = chol_upper(C)
    L = 3 * 3.615
    H = [[R[i][j]*L for j in range(3)] for i in range(3)]
    deck = f"""units metal
boundary p p p
read_data cu.data
change_box all triclinic
change_box all x final 0 {H[0][0]!r} y final 0 {H[1][1]!r} z final 0 {H[2][2]!r} xy final {H[0][1]!r} xz final {H[0][2]!r} yz final {H[1][2]!r} remap units box
pair_style eam
pair_coeff 1 1 Cu_u3.eam
thermo_style custom pe
thermo_modify format float %.17g
run 0
print "PE $(pe:%.17g)"
"""
    with open("w.in", "w") as f: f.write(deck)
    out = subprocess.run(["lmp", "-log", "none", "-in", "w.in"], capture_output=True, text=True).stdout
    pe = [l for l in out.splitlines() if l.startswith("PE ")][-1].split()[1]
    return float(pe) / L**3
W0 = W(0, 0, 0)
ref = [(W(h,0,0) - 2*W0 + W(-h,0,0))/h**2,
       (W(h,h,0) - W(h,-h,0) - W(-h,h,0) + W(-h,-h,0))/(4*h*h),
       (W(0,0,h) - 2*W0 + W(0,0,-h))/(4*h*h)]
d = {f: json.load(open(f + ".json")) for f in ("cu", "hom", "res")}
C = d["cu"]["C_voigt"]
pd = [C[0][0], C[0][1], C[3][3]]
ok = True
for name, a, b in zip(("C11", "C12", "C44"), pd, ref):
    rel = abs(a - b) / abs(b)
    print(f"  {name}: pdcg {a:.8g} eV/A^3, LAMMPS {b:.8g}, rel. diff {rel:.2e}")
    ok &= rel < 5e-3  # acceptance: 0.5%
for f in ("hom", "res"):
    Cf = d[f]["C_voigt"]
    dev = max(abs(Cf[i][j] - C[i][j]) for i in range(6) for j in range(6)) / abs(C[0][0])
    print(f"  {f}: max |C - C_delta| / C11 = {dev:.2e} (kind {d[f]['kind']})")
    ok &= dev < 1e-10  # same sums, other order and ε^d scaling: round-off
raise SystemExit(0 if ok else 1)
PY
# bad --F: exit 2 with a message naming the option
"$pdcg" elastic cu.h5 --F "1 0 0 0 -1 0 0 0 1" > bad.out 2>&1
rc=$?
[ $rc -eq 2 ] || { echo "det F < 0: exit $rc, expected 2"; fail=1; }
grep -q -- "--F" bad.out || { echo "message does not name --F"; cat bad.out; fail=1; }
"$pdcg" elastic cu.h5 --fit 1.05 --critical > text.out || fail=1
grep -q "neo-Hookean fit" text.out || { echo "no fit in text output"; fail=1; }
# --quasi-harmonic T (docs/temperature.md §3.1): T = 0 is the static lattice (Bravais: the same
# constants as above); at 300 K the isothermal constants are softer and the JSON says which;
# what it cannot do is exit 2 naming the option or the body
"$pdcg" elastic cu.h5 --quasi-harmonic 0 --json > qh0.json || { echo "elastic --quasi-harmonic 0 failed"; fail=1; }
"$pdcg" elastic cu.h5 --quasi-harmonic 300 --quasi-harmonic-step 1e-2 --json > qh300.json || { echo "elastic --quasi-harmonic 300 failed"; fail=1; }
python3 - <<'PY' || fail=1
import json
c, q0, q = (json.load(open(f))["C_voigt"] for f in ("cu.json", "qh0.json", "qh300.json"))
t = json.load(open("qh300.json"))
dev = max(abs(q0[i][j] - c[i][j]) for i in range(6) for j in range(6)) / c[0][0]
print(f"  quasi-harmonic T = 0 vs static: {dev:.1e}; 300 K C11 {q[0][0]:.6f} vs {c[0][0]:.6f} eV/A^3")
ok = dev < 1e-12  # same analytic static part, no vibrational term at T = 0
ok &= t["free_energy"] == "quasi-harmonic" and t["temperature"] == 300
ok &= t["quasi_harmonic_step"] == 0.01
ok &= q[0][0] < c[0][0] and q[3][3] < c[3][3]  # thermal softening (Cu: ≈ −1 % at 300 K)
raise SystemExit(0 if ok else 1)
PY
# the homogenised and the rescaled models at T are the free energy of their atoms (docs/theory.md
# (2.8)): the same isothermal constants as the delta body
for f in hom res; do
  "$pdcg" elastic $f.h5 --quasi-harmonic 300 --quasi-harmonic-step 1e-2 --json > qh300_$f.json || { echo "elastic $f.h5 --quasi-harmonic 300 failed"; fail=1; }
done
python3 - <<'PY' || fail=1
import json
q = json.load(open("qh300.json"))["C_voigt"]
for f in ("hom", "res"):
    m = json.load(open(f"qh300_{f}.json"))["C_voigt"]
    dev = max(abs(m[i][j] - q[i][j]) for i in range(6) for j in range(6)) / q[0][0]
    print(f"  quasi-harmonic 300 K, {f}.h5 vs cu.h5: {dev:.1e} of C11")
    # the same atoms' Hessians up to the round-off of the rescaled force states, divided by
    # h² = 1e-4 in the second difference
    if not dev < 1e-8:
        raise SystemExit(1)
PY
for args in "cu.h5 --quasi-harmonic 300 --fit 1.05:--fit" \
  "cu.h5 --quasi-harmonic 300 --quasi-harmonic-step 0.05:--quasi-harmonic-step" \
  "cu.h5 --quasi-harmonic-step 0.01:--quasi-harmonic-step" \
  "cu.h5 --quasi-harmonic 300000:beyond melting"; do
  "$pdcg" elastic ${args%%:*} > bad.out 2>&1
  rc=$?
  [ $rc -eq 2 ] && grep -q -- "${args#*:}" bad.out || { echo "elastic ${args%%:*}: exit $rc"; cat bad.out; fail=1; }
done
exit $fail
