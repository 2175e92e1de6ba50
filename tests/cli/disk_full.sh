#!/usr/bin/env bash
# Output into a full file system, beyond the file size limit, into a read-only or impossible
# directory. Every failure is a clear error (which file, the OS error, the fix), leaves every
# earlier output complete and readable, and no partial file under a final name (no temporary
# either); a damaged checkpoint is refused by --restart.
#  1. `ulimit -f` (RLIMIT_FSIZE) with SIGXFSZ *not* ignored by this shell: pdcg ignores it
#     itself (main()), so the write fails with EFBIG and becomes the error; for a results file,
#     a checkpoint, model files (atoms2pd, homogenize, rescale) and a CSV (forces).
#  2. a small tmpfs that fills up (ENOSPC) in the middle of a quasi-static and of a dynamic
#     run (half the space an uninterrupted run needs); after it is enlarged,
#     `--restart` finishes the run with results bitwise equal to an uninterrupted run.
#  3. a read-only tmpfs and a path through a regular file: exit 2 before any computation.
#  4. a truncated and a bit-flipped checkpoint: --restart refuses them (exit 2), naming it.
# Every final-named file left is checked independently with h5py: each dataset read, its crc32
# attribute recomputed with zlib. Parts 2 and 3 need `mount` (root); without it they print skip.
# Usage: disk_full.sh /path/to/pdcg /path/to/work
set -u
pdcg=$1
work=$2
export OMP_NUM_THREADS=1
mnt=$work/mnt
ro=$work/ro
cleanup() {
  mountpoint -q "$mnt" 2>/dev/null && umount "$mnt"
  mountpoint -q "$ro" 2>/dev/null && umount "$ro"
}
trap cleanup EXIT
cleanup
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail=0
ok() { echo "ok   $*"; }
bad() { echo "FAIL $*"; fail=1; }

# intact DIR: no temporary; every .h5 reads completely and matches its crc32 (zlib, here);
# every .csv ends with a newline and has the header's column count on every line
intact() {
  /usr/bin/python3 - "$1" <<'PY'
import os, sys, zlib, h5py, numpy as np
d = sys.argv[1]
bad = [f"temporary left: {n}" for n in os.listdir(d) if ".tmp." in n]
nh5 = nset = ncsv = 0
for n in sorted(os.listdir(d)):
    p = os.path.join(d, n)
    if n.endswith(".h5"):
        try:
            with h5py.File(p, "r") as f:
                sets = []
                f.visititems(lambda k, o: sets.append(k) if isinstance(o, h5py.Dataset) else None)
                for k in sets:
                    o = f[k]
                    v = o[()]
                    if o.dtype.kind == "O" or h5py.check_string_dtype(o.dtype):
                        vals = [v] if o.shape == () else list(v)
                        bs = [x if isinstance(x, bytes) else x.encode() for x in vals]
                        crc = zlib.crc32(bs[0]) if o.shape == () else zlib.crc32(b"".join(b + b"\0" for b in bs))
                    else:
                        crc = zlib.crc32(np.ascontiguousarray(v).tobytes())
                    if "crc32" not in o.attrs or int(o.attrs["crc32"]) != crc:
                        bad.append(f"{n}:{k} crc32 mismatch or missing")
                    nset += 1
            nh5 += 1
        except Exception as e:
            bad.append(f"{n}: unreadable: {e}")
    elif n.endswith(".csv"):
        t = open(p).read()
        # '#' lines (the units line) are comments; every other line has the header's columns
        lines = [l for l in t.split("\n") if not l.startswith("#")]
        if not t.endswith("\n") or any(l.count(",") != lines[0].count(",") for l in lines[:-1]):
            bad.append(f"{n}: incomplete")
        ncsv += 1
for b in bad:
    print("FAIL", b)
print(f"     {d}: {nh5} HDF5 files ({nset} datasets, crc32 checked), {ncsv} CSV complete; no temporary" if not bad else "")
sys.exit(1 if bad else 0)
PY
}
# says <text> <pattern>...: every pattern (grep -E) in text
says() {
  local t=$1; shift
  for p in "$@"; do grep -Eq -- "$p" <<<"$t" || { echo "     missing '$p' in: $t"; return 1; }; done
}

cat > static.yaml <<'Y'
dimension: 2
plane: strain
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 0.25], spacing: 0.03125}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0}
boundary:
  - {name: left,  region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: {x_min: 1.0}, displacement: {x: "0.2*t"}}
loading: {steps: 12}
output: {checkpoint_every: 1}
Y
"$pdcg" -q run static.yaml -o full || { bad "uninterrupted run"; exit 1; }
R=$(stat -c %s full/results_0001.h5)
C=$(stat -c %s full/checkpoint_00000012.h5)
echo "     sizes: results file $R bytes, last checkpoint $C bytes"

# ---- 1. file size limit (EFBIG), SIGXFSZ left at its default in this shell
limit_run() {  # limit_run <KiB> <dir> <pdcg args...>: pdcg under ulimit -f; sets out, code
  local kib=$1 dir=$2; shift 2
  out=$( (ulimit -f "$kib"; exec "$pdcg" "$@") 2>&1); code=$?
}
limit_run $(( R / 2048 )) fsz_results -q run static.yaml -o fsz_results
if [ $code = 1 ] && says "$out" "results_0001\.h5" "File too large" "ulimit -f" "-o"; then
  ok "results file beyond ulimit -f: exit 1, names the file, EFBIG, the fix"
else bad "results file beyond ulimit -f: exit $code (153 = killed by SIGXFSZ): $out"; fi
[ -d fsz_results ] && { intact fsz_results || fail=1; }
[ ! -e fsz_results/results_0001.h5 ] || bad "a results_0001.h5 exists after its write failed"
# a checkpoint beyond the limit: fields only at the last step, so the checkpoint of step 1 is
# the first file larger than the limit (half its size)
sed 's/output: {checkpoint_every: 1}/output: {every: 100, checkpoint_every: 1}/' static.yaml > ck.yaml
limit_run $(( C / 2048 )) fsz_ckpt -q run ck.yaml -o fsz_ckpt
if [ $code = 1 ] && says "$out" "checkpoint_00000001\.h5" "File too large" "ulimit -f"; then
  ok "checkpoint beyond ulimit -f: exit 1, names it"
else bad "checkpoint beyond ulimit -f: exit $code: $out"; fi
[ -d fsz_ckpt ] && { intact fsz_ckpt || fail=1; }
[ "$(grep -vc "^#" fsz_ckpt/reactions.csv)" = 3 ] || bad "reactions.csv of the failed run: want header + steps 0, 1 (after the # units line)"
[ ! -e fsz_ckpt/checkpoint_00000001.h5 ] || bad "a checkpoint_00000001.h5 exists after its write failed"

# model files and CSV
cat > make.in <<'IN'
units metal
lattice fcc 3.615
region box block 0 3 0 3 0 3
create_box 1 box
create_atoms 1 box
mass 1 63.546
write_data cu.data
IN
if lmp -log none -screen none -in make.in >/dev/null 2>&1; then
  printf 'units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n' > cu.pot
  "$pdcg" -q atoms2pd --input cu.data --potential cu.pot -o cu.h5 >/dev/null || bad "atoms2pd"
  "$pdcg" -q homogenize cu.h5 --kernel cubic-bspline --width 4.7 --spacing 3.0 -o hom.h5 >/dev/null || bad "homogenize"
  printf 'units metal\npair_style lj/cut 5.0\npair_coeff * * 0.4 2.3\n' > lj.pot
  "$pdcg" -q atoms2pd --input cu.data --potential lj.pot -o lj.h5 >/dev/null || bad "atoms2pd lj"
  mkdir -p lim
  check_limited() {  # <label> <KiB> <final file> <args...>
    local label=$1 kib=$2 file=$3; shift 3
    limit_run "$kib" lim "$@"
    if [ $code = 1 ] && says "$out" "$file" "File too large" "ulimit -f" && [ ! -e "$file" ]; then
      ok "$label beyond ulimit -f $kib: exit 1, names $file, no file under that name"
    else bad "$label beyond ulimit -f $kib: exit $code: $out"; fi
  }
  # 64 KiB: above the EAM file the model embeds (36.6 kB, rewritten to a temporary directory
  # when the model is read), below the model files (~350 kB)
  check_limited atoms2pd 64 lim/cu.h5 -q atoms2pd --input cu.data --potential cu.pot -o lim/cu.h5
  check_limited homogenize 64 lim/hom.h5 -q homogenize cu.h5 --kernel cubic-bspline --width 4.7 --spacing 3.0 -o lim/hom.h5
  check_limited rescale 64 lim/res.h5 -q rescale hom.h5 --factor 3 -o lim/res.h5
  check_limited "forces CSV" 4 lim/f.csv -q forces lj.h5 -o lim/f.csv  # 7.9 kB of CSV
  # the embedded EAM file itself beyond the limit: its write error, not "potential file ends early"
  limit_run 16 lim -q forces cu.h5 -o lim/f.csv
  if [ $code = 1 ] && says "$out" "pdcg-potential-.*Cu_u3\.eam" "File too large" && ! grep -q "ends early" <<<"$out"; then
    ok "embedded potential beyond ulimit -f 16: exit 1, its write error"
  else bad "embedded potential beyond ulimit -f 16: exit $code: $out"; fi
  intact lim || fail=1
else
  echo "skip model files: lmp not available"
fi

# ---- 2. a small tmpfs that fills up (ENOSPC)
mkdir -p "$mnt"
total=$(du -sk full | cut -f1)
size=$(( total / 2 ))
if mount -t tmpfs -o size=${size}k tmpfs "$mnt" 2>/dev/null; then
  out=$("$pdcg" -q run static.yaml -o "$mnt/out" 2>&1); code=$?
  if [ $code = 1 ] && says "$out" "No space left on device" "df -h" "-o"; then
    ok "tmpfs of ${size} KiB full: exit 1: $(grep -o 'cannot write [^:]*' <<<"$out")"
  else bad "full tmpfs: exit $code: $out"; fi
  intact "$mnt/out" || fail=1
  nres=$(ls "$mnt/out"/results_*.h5 2>/dev/null | wc -l)
  ck=$(ls "$mnt/out"/checkpoint_*.h5 2>/dev/null)
  [ "$nres" -ge 1 ] && [ -n "$ck" ] || bad "nothing left to restart from ($nres results files, checkpoint '$ck')"
  mount -o remount,size=64m "$mnt"
  if "$pdcg" -q run static.yaml --restart "$mnt/out"; then
    cmp full/reactions.csv "$mnt/out/reactions.csv" && cmp full/results.xdmf "$mnt/out/results.xdmf" \
      || bad "restart after the full disk: CSV/XDMF differ"
    /usr/bin/python3 - full "$mnt/out" "$nres" <<'PY' || fail=1
import glob, os, sys, h5py, numpy as np
a, b = sys.argv[1:3]
fa = sorted(os.path.basename(p) for p in glob.glob(a + "/results_*.h5"))
fb = sorted(os.path.basename(p) for p in glob.glob(b + "/results_*.h5"))
assert fa == fb, (fa, fb)
n = 0
for f in fa:
    with h5py.File(os.path.join(a, f)) as x, h5py.File(os.path.join(b, f)) as y:
        for k in ("points/reference", "fields/displacement", "fields/first_piola_kirchhoff",
                  "fields/cauchy_stress", "fields/energy_density"):
            if not np.array_equal(x[k][()], y[k][()]):
                print("FAIL", f, k, "differs after the restart"); sys.exit(1)
            n += 1
print(f"ok   after freeing space, --restart: {n} datasets of {len(fa)} results files bitwise "
      f"equal to the uninterrupted run ({sys.argv[3]} were written before the disk was full)")
PY
  else bad "restart after the full disk"; fi
  umount "$mnt"
  # dynamic: the disk fills up while a results file or a checkpoint is written
  cat > dyn.yaml <<'Y'
dimension: 2
plane: strain
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 0.25], spacing: 0.0625}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left,  region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: {x_min: 1.0}, displacement: {x: "0.01*sin(3*t)"}}
initial: {velocity: {y: "0.01*sin(pi*x)"}}
effects: [inertia, damping]
inertia: {end_time: 3.0}
damping: {type: viscous, coefficient: 0.1}
output: {every: 25, checkpoint_every: 20}
Y
  "$pdcg" -q run dyn.yaml -o dynfull || bad "dynamic: uninterrupted run"
  size=$(( $(du -sk dynfull | cut -f1) / 2 ))
  mount -t tmpfs -o size=${size}k tmpfs "$mnt"
  out=$("$pdcg" -q run dyn.yaml -o "$mnt/out" 2>&1); code=$?
  if [ $code = 1 ] && says "$out" "No space left on device" "df -h"; then
    ok "dynamic, tmpfs of ${size} KiB full: exit 1: $(grep -o 'cannot write [^:]*' <<<"$out")"
  else bad "dynamic, full tmpfs: exit $code: $out"; fi
  intact "$mnt/out" || fail=1
  mount -o remount,size=64m "$mnt"
  if "$pdcg" -q run dyn.yaml --restart "$mnt/out" && cmp dynfull/series.csv "$mnt/out/series.csv" \
    && cmp dynfull/results.xdmf "$mnt/out/results.xdmf"; then
    ok "dynamic: after freeing space, --restart gives series.csv and results.xdmf byte-identical"
  else bad "dynamic: restart after the full disk"; fi
  umount "$mnt"
else
  echo "skip tmpfs (mount -t tmpfs not permitted)"
fi

# ---- 3. read-only directory, a path through a regular file: refused before any computation
mkdir -p "$ro"
if mount -t tmpfs -o ro,size=64k tmpfs "$ro" 2>/dev/null; then
  out=$("$pdcg" -v run static.yaml -o "$ro/out" 2>&1); code=$?
  if [ $code = 2 ] && says "$out" "Read-only file system" "--output" && ! grep -q "body:" <<<"$out"; then
    ok "run -o read-only: exit 2 before the body is built"
  else bad "run -o read-only: exit $code: $out"; fi
  if [ -e cu.h5 ]; then
    out=$("$pdcg" -v forces cu.h5 -o "$ro/f.csv" 2>&1); code=$?
    if [ $code = 2 ] && says "$out" "Read-only file system" && [ "$(wc -l <<<"$out")" = 1 ]; then
      ok "forces -o read-only: exit 2, the error is the only line"
    else bad "forces -o read-only: exit $code: $out"; fi
    out=$("$pdcg" -v atoms2pd --input cu.data --potential cu.pot -o "$ro/cu.h5" 2>&1); code=$?
    if [ $code = 2 ] && says "$out" "Read-only file system" && [ "$(wc -l <<<"$out")" = 1 ]; then
      ok "atoms2pd -o read-only: exit 2, the error is the only line (no LAMMPS run)"
    else bad "atoms2pd -o read-only: exit $code: $out"; fi
    for c in "homogenize cu.h5 --kernel cubic-bspline --width 4.7 --spacing 3.0 -o $ro/hom.h5" \
             "rescale cu.h5 --factor 3 -o $ro/res.h5" \
             "dispersion cu.h5 --direction 1,0,0 -o $ro/d.csv" \
             "md cu.h5 --steps 10 --dt 0.001 --thermo $ro/thermo.csv"; do
      out=$("$pdcg" -v $c 2>&1); code=$?
      if [ $code = 2 ] && says "$out" "Read-only file system" && [ "$(wc -l <<<"$out")" = 1 ]; then
        ok "${c%% *} into read-only: exit 2, the error is the only line"
      else bad "${c%% *} into read-only: exit $code: $out"; fi
    done
  fi
  umount "$ro"
else
  echo "skip read-only tmpfs (mount not permitted)"
fi
echo "a file" > plain
out=$("$pdcg" -v run static.yaml -o plain/out 2>&1); code=$?
if [ $code = 2 ] && says "$out" "plain/out" "Not a directory|File exists" && ! grep -q "body:" <<<"$out"; then
  ok "run -o through a regular file: exit 2 before the body is built"
else bad "run -o plain/out: exit $code: $out"; fi
out=$("$pdcg" -q run static.yaml -o new/deeper/out 2>&1); code=$?
[ $code = 0 ] && [ -e new/deeper/out/reactions.csv ] && ok "run -o into missing directories creates them" \
  || bad "run -o new/deeper/out: exit $code: $out"

# ---- 4. damaged checkpoints are refused by --restart
for how in truncated flipped; do
  rm -rf dmg && cp -r full dmg
  ck=$(ls dmg/checkpoint_*.h5)
  if [ $how = truncated ]; then
    truncate -s $(( $(stat -c %s "$ck") * 2 / 3 )) "$ck"
  else
    /usr/bin/python3 - "$ck" <<'PY'
import sys, h5py
p = sys.argv[1]
with h5py.File(p, "r") as f:
    off = f["state/u"].id.get_offset()
with open(p, "r+b") as f:
    f.seek(off + 8 * 10 + 5)
    b = f.read(1)
    f.seek(off + 8 * 10 + 5)
    f.write(bytes([b[0] ^ 0x10]))
PY
  fi
  out=$("$pdcg" -q run static.yaml --restart dmg 2>&1); code=$?
  if [ $code = 2 ] && says "$out" "truncated or corrupt" "$(basename "$ck")"; then
    ok "$how checkpoint refused (exit 2): $(cut -c1-150 <<<"$out")..."
  else bad "$how checkpoint: exit $code: $out"; fi
done

if [ $fail -ne 0 ]; then echo "disk_full: FAILED"; exit 1; fi
echo "disk_full: all passed"
