#!/usr/bin/env bash
# `pdcg inspect` on a triclinic gzip dump and a data file: JSON keys and
# values (box converted from the dump's bounding box by the rules of
# https://docs.lammps.org/Howto_triclinic.html, worked out by hand below), the
# text form, and exit code 2 with file:line for a bad file.
# Usage: inspect.sh /path/to/pdcg
set -u
pdcg=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
# Bounding box: x [-1, 12] with xy = 2, xz = -1  -> xlo = -1 - min(0,2,-1,1) = 0,  xhi = 12 - max(0,2,-1,1) = 10
#               y [0, 8.5] with yz = 0.5         -> ylo = 0 - min(0,0.5) = 0,      yhi = 8.5 - 0.5 = 8
cat > "$tmp/t.dump" <<'DUMP'
ITEM: TIMESTEP
5
ITEM: NUMBER OF ATOMS
3
ITEM: BOX BOUNDS xy xz yz pp pp ff
-1 12 2
0 8.5 -1
0 6 0.5
ITEM: ATOMS id type mass xs ys zs c_pe
1 1 12.0 0.1 0.2 0.3 -1.5
2 2 16.0 0.5 0.5 0.5 -2.5
3 2 16.0 0.9 0.9 0.9 -3.5
ITEM: TIMESTEP
10
ITEM: NUMBER OF ATOMS
3
ITEM: BOX BOUNDS xy xz yz pp pp ff
-1 12 2
0 8.5 -1
0 6 0.5
ITEM: ATOMS id type mass xs ys zs c_pe
3 2 16.0 0.9 0.9 0.9 -3.5
1 1 12.0 0.1 0.2 0.3 -1.5
2 2 16.0 0.5 0.5 0.5 -2.5
DUMP
gzip "$tmp/t.dump"
cat > "$tmp/s.data" <<'DATA'
hand-written system

2 atoms
3 atom types

0 4 xlo xhi
0 5 ylo yhi
0 6 zlo zhi

Masses

1 1.5
2 2.5
3 3.5

Atoms # atomic

2 3 1 1 1
1 1 2 2 2
DATA

json=$("$pdcg" inspect "$tmp/t.dump.gz" --json) || { echo "FAIL dump-json: exit $?"; fail=1; }
python3 - "$json" <<'PY' || fail=1
import json, sys
d = json.loads(sys.argv[1])
want = {"kind": "dump", "compressed": True, "natoms": 3, "nframes": 2, "timesteps": [5, 10],
        "columns": ["id", "type", "mass", "xs", "ys", "zs", "c_pe"]}
ok = all(d[k] == v for k, v in want.items())
b = d["box"]
ok &= b["lo"] == [0, 0, 0] and b["hi"] == [10, 8, 6] and b["tilt"] == [2, -1, 0.5]
ok &= b["periodic"] == [True, True, False] and b["triclinic"] is True
ok &= d["types"] == [{"type": 1, "count": 1, "mass": 12.0}, {"type": 2, "count": 2, "mass": 16.0}]
print("ok   dump-json" if ok else "FAIL dump-json: " + json.dumps(d))
sys.exit(0 if ok else 1)
PY

json=$("$pdcg" inspect "$tmp/s.data" --json) || { echo "FAIL data-json: exit $?"; fail=1; }
python3 - "$json" <<'PY' || fail=1
import json, sys
d = json.loads(sys.argv[1])
ok = d["kind"] == "data" and d["natoms"] == 2 and d["nframes"] == 1 and d["atom_style"] == "atomic"
ok &= d["box"]["lo"] == [0, 0, 0] and d["box"]["hi"] == [4, 5, 6] and d["box"]["tilt"] == [0, 0, 0]
ok &= d["columns"] == ["id", "type", "x", "y", "z"]
ok &= d["types"] == [{"type": 1, "count": 1, "mass": 1.5}, {"type": 2, "count": 0, "mass": 2.5},
                     {"type": 3, "count": 1, "mass": 3.5}]
print("ok   data-json" if ok else "FAIL data-json: " + json.dumps(d))
sys.exit(0 if ok else 1)
PY

out=$("$pdcg" inspect "$tmp/t.dump.gz" 2>&1)
if grep -q "2 frames" <<<"$out" && grep -q "periodic: p p f" <<<"$out" && grep -q "xy 2  xz -1  yz 0.5" <<<"$out"; then
  echo "ok   dump-text"; else echo "FAIL dump-text"; echo "$out"; fail=1; fi

printf 'ITEM: TIMESTEP\n1\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\nITEM: ATOMS id x y z\n' > "$tmp/bad.dump"
out=$("$pdcg" inspect "$tmp/bad.dump" 2>&1); code=$?
if [ $code = 2 ] && grep -q "bad.dump:7: missing 'ITEM: NUMBER OF ATOMS'" <<<"$out"; then
  echo "ok   bad-file"; else echo "FAIL bad-file: exit $code"; echo "$out"; fail=1; fi

out=$("$pdcg" inspect --help 2>&1)
if grep -q "pdcg inspect system.data --json" <<<"$out"; then echo "ok   help"; else echo "FAIL help"; fail=1; fi

if [ $fail -ne 0 ]; then echo "inspect: FAILED"; exit 1; fi
echo "inspect: all passed"
