#!/usr/bin/env bash
# `pdcg md` end to end against the lmp binary: an FCC LJ crystal with LAMMPS velocities, 100
# NVE steps in both; the pdcg dump must match LAMMPS's dump (same forces, same integrator),
# be readable by `pdcg inspect` and `pdcg dispersion --trajectory`; bad input exits 2.
set -euo pipefail
PDCG=$1
command -v lmp >/dev/null || { echo "lmp not found: skipped"; exit 0; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"
cat > in.fcc <<'LMP'
units lj
atom_style atomic
lattice fcc 1.0
region box block 0 4 0 4 0 4
create_box 1 box
create_atoms 1 box
mass 1 1.0
displace_atoms all random 0.02 0.02 0.02 4711
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0
velocity all create 0.3 87287 loop geom
write_data fcc.data
write_dump all custom nov.dump id type x y z
write_dump all custom v.dump id type x y z vx vy vz modify format float %.17g
timestep 0.005
fix 1 all nve
run 100
write_dump all custom end.dump id type xu yu zu vx vy vz modify format float %.17g
LMP
lmp -in in.fcc -log none -screen none
printf 'units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n' > lj.in
"$PDCG" atoms2pd --input fcc.data --potential lj.in --family-cutoff 2.9 -o b.h5
"$PDCG" md b.h5 --steps 100 --dt 0.005 --velocities v.dump --dump run.dump --every 50 --thermo th.csv
"$PDCG" inspect run.dump > /dev/null
python3 - <<'PY'
def frames(path):
    out, lines = [], open(path).read().split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("ITEM: NUMBER OF ATOMS"):
            n = int(lines[i + 1])
            box = [list(map(float, lines[i + 3 + k].split()[:2])) for k in range(3)]
            cols = lines[i + 6].split()[2:]
            rows = {}
            for l in lines[i + 7:i + 7 + n]:
                r = dict(zip(cols, map(float, l.split())))
                rows[int(r["id"])] = r
            out.append((rows, box))
            i += 7 + n
        else:
            i += 1
    return out
p, box = frames("run.dump")[-1]
l, _ = frames("end.dump")[0]
L = [b[1] - b[0] for b in box]
ex = max(abs(p[i][c] + p[i]["i" + c] * L[k] - l[i][c + "u"]) for i in l for k, c in enumerate("xyz"))
vmax = max(abs(l[i]["v" + c]) for i in l for c in "xyz")
ev = max(abs(p[i]["v" + c] - l[i]["v" + c]) for i in l for c in "xyz") / vmax
print(f"md vs lmp after 100 steps: max position difference {ex:.2e}, velocity {ev:.2e}")
# same forces and integrator; the dump's 17 digits and summation order: round-off (1e-10)
assert ex < 1e-10 and ev < 1e-10, (ex, ev)
rows = open("th.csv").read().split()
assert len(rows) == 102 and rows[0] == "step,time,kinetic,potential,total,temperature", len(rows)
PY
set +e
"$PDCG" md b.h5 --steps 10 --dt 1 2> err.txt; rc=$?
[ $rc -eq 2 ] && grep -q "stable limit" err.txt || { echo "dt above the limit: rc=$rc"; cat err.txt; exit 1; }
"$PDCG" md b.h5 --steps -1 --dt 0.005 2> /dev/null; [ $? -eq 2 ] || { echo "negative steps accepted"; exit 1; }
"$PDCG" md b.h5 --steps 1 --dt 0.005 --velocities nov.dump 2> err.txt; rc=$?
[ $rc -eq 2 ] && grep -q "velocities" err.txt || { echo "no velocities: rc=$rc"; cat err.txt; exit 1; }
"$PDCG" md b.h5 --steps 1 --dt 0.005 --dump x.dump 2> /dev/null; [ $? -eq 2 ] || { echo "--dump without --every accepted"; exit 1; }
"$PDCG" md b.h5 --steps 1 --dt 0.005 --temperature 0.1 --velocities v.dump 2> /dev/null; [ $? -eq 2 ] || { echo "both velocity sources accepted"; exit 1; }
echo "md.sh: ok"
