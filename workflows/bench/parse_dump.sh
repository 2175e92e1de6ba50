#!/usr/bin/env bash
# Benchmark (not a test): parse a >= 1 GB LAMMPS text dump with pdcg and with
# LAMMPS's own read_dump, in the same run, on the same file.
#
# Usage: workflows/bench/parse_dump.sh [BUILD_DIR] [WORK_DIR]
#   BUILD_DIR  pdcg build tree with `pdcg` and `bench_parse_dump` (default: build)
#   WORK_DIR   where the dump is generated (default: /tmp/pdcg-bench-dump); kept for reruns
# Env: FRAMES (default 15) frames of CELLS^3 fcc cells (default 63 -> 1,000,188 atoms),
#      columns `id type x y z` printed with %20.15g: ~74 MB per frame.
#      GZ=1 also times the gzip -1 compressed copy (pdcg and LAMMPS read_dump, which
#      reads .gz through a `gzip -dc` pipe).
#
# Measured (wall clock, file already in the page cache — it is read once before timing):
#   pdcg inspect        index all frames + parse frame 0 (what `pdcg inspect` does)
#   pdcg open + frame 0 a fresh DumpReader, frame(0): the lazy index stops after frame 0
#   pdcg index          one pass over the file recording every frame (nframes())
#   pdcg frame 0 / last parse one frame (random access through the index)
#   pdcg all frames     parse every frame into Atoms
#   LAMMPS read_dump    `read_dump FILE <first step> x y z box yes add keep` (parses frame 0)
#                       and `read_dump FILE <last step> ...` (LAMMPS scans all earlier frames);
#                       LAMMPS start-up (same script without read_dump) is subtracted.
set -euo pipefail
build=$(realpath "${1:-build}")
work=${2:-/tmp/pdcg-bench-dump}
frames=${FRAMES:-15}
cells=${CELLS:-63}
mkdir -p "$work"
cd "$work"
dump=big.dump

now() { date +%s.%N; }
elapsed() { python3 -c "print(f'{$2 - $1:.3f}')"; }

if [ ! -s "$dump" ] || [ "$(cat frames.txt 2>/dev/null)" != "$frames $cells" ]; then
  echo "generating $dump ($frames frames of $((4 * cells * cells * cells)) atoms) with LAMMPS ..."
  rm -f "$dump"
  cat > gen.in <<LMP
units lj
atom_style atomic
atom_modify map yes
lattice fcc 0.8442
region box block 0 $cells 0 $cells 0 $cells
create_box 2 box
create_atoms 1 box
mass * 1.0
set type 1 type/fraction 2 0.5 1
variable i loop $frames
label loop
displace_atoms all random 0.1 0.1 0.1 \${i}
reset_timestep \${i}
write_dump all custom $dump id type x y z modify format float %20.15g append yes
next i
jump SELF loop
LMP
  lmp -in gen.in -log none -screen none -nocite
  echo "$frames $cells" > frames.txt
fi
bytes=$(stat -c %s "$dump")
mb=$(python3 -c "print($bytes / 1e6)")
cat "$dump" > /dev/null  # into the page cache, for every reader alike

t0=$(now); "$build/pdcg" inspect "$dump" > inspect.txt; t1=$(now)
t_inspect=$(elapsed "$t0" "$t1")
"$build/bench_parse_dump" "$dump" > pdcg.txt
get() { awk -v k="$1" '$1 == k { print $2 }' pdcg.txt; }
frame0_bytes=$(get frame0_bytes)

lammps_time() {  # lammps_time <read_dump line or empty>
  cat > rd.in <<LMP
units lj
atom_style atomic
atom_modify map yes
region box block 0 1 0 1 0 1
create_box 2 box
mass * 1.0
$1
LMP
  local a b
  a=$(now); lmp -in rd.in -log none -screen none -nocite; b=$(now)
  elapsed "$a" "$b"
}
t_lmp_base=$(lammps_time "")
t_lmp_first=$(lammps_time "read_dump $dump 1 x y z box yes add keep")
t_lmp_last=$(lammps_time "read_dump $dump $frames x y z box yes add keep")

python3 - "$bytes" "$frame0_bytes" "$t_inspect" "$t_lmp_base" "$t_lmp_first" "$t_lmp_last" pdcg.txt <<'PY'
import sys
nbytes, f0, t_inspect, base, first, last = map(float, sys.argv[1:7])
p = {l.split()[0]: float(l.split()[1]) for l in open(sys.argv[7])}
lf, ll = first - base, last - base
mbs = lambda b, t: b / 1e6 / t
print(f"file: {nbytes/1e9:.2f} GB, {int(p['frames'])} frames, frame 0 = {f0/1e6:.1f} MB")
print(f"{'what':48s} {'seconds':>8s} {'MB/s':>8s}")
rows = [
    ("pdcg inspect (index all + parse frame 0)", t_inspect, nbytes),
    ("pdcg open + frame 0 (lazy index: frame 0 only)", p["open_frame0_seconds"], f0),
    ("pdcg index (one pass over the file)", p["index_seconds"], nbytes),
    ("pdcg parse frame 0", p["frame0_seconds"], f0),
    ("pdcg parse last frame (random access)", p["last_seconds"], f0),
    ("pdcg parse all frames", p["all_seconds"], nbytes),
    ("pdcg index + parse last frame", p["index_seconds"] + p["last_seconds"], nbytes),
    ("LAMMPS read_dump frame 0", lf, f0),
    ("LAMMPS read_dump last frame (scans all)", ll, nbytes),
]
for name, t, b in rows:
    print(f"{name:48s} {t:8.3f} {mbs(b, t):8.1f}")
print(f"ratio frame 0:    LAMMPS read_dump / pdcg (open + frame 0) = {lf / p['open_frame0_seconds']:.1f}x")
print(f"ratio last frame: LAMMPS read_dump / pdcg (index + parse) = "
      f"{ll / (p['index_seconds'] + p['last_seconds']):.1f}x")
print(f"(LAMMPS start-up {base:.3f} s subtracted)")
PY

if [ "${GZ:-0}" = 1 ]; then
  [ -s "$dump.gz" ] && [ "$dump.gz" -nt "$dump" ] || gzip -1 -k -f "$dump"
  gzbytes=$(stat -c %s "$dump.gz")
  cat "$dump.gz" > /dev/null
  "$build/bench_parse_dump" "$dump.gz" > pdcg_gz.txt
  t_lmp_gz_first=$(lammps_time "read_dump $dump.gz 1 x y z box yes add keep")
  t_lmp_gz_last=$(lammps_time "read_dump $dump.gz $frames x y z box yes add keep")
  python3 - "$bytes" "$gzbytes" "$frame0_bytes" "$t_lmp_base" "$t_lmp_gz_first" "$t_lmp_gz_last" pdcg_gz.txt <<'PY'
import sys
nbytes, gz, f0, base, first, last = map(float, sys.argv[1:7])
p = {l.split()[0]: float(l.split()[1]) for l in open(sys.argv[7])}
lf, ll = first - base, last - base
mbs = lambda b, t: b / 1e6 / t
print(f"\ngzip -1 copy: {gz/1e9:.2f} GB compressed (MB/s below are of uncompressed text)")
rows = [
    ("pdcg open + frame 0 (lazy index: frame 0 only)", p["open_frame0_seconds"], f0),
    ("pdcg index (decompress all, access points)", p["index_seconds"], nbytes),
    ("pdcg parse frame 0 (after index)", p["frame0_seconds"], f0),
    ("pdcg parse last frame (random access)", p["last_seconds"], f0),
    ("pdcg parse all frames", p["all_seconds"], nbytes),
    ("pdcg index + parse last frame", p["index_seconds"] + p["last_seconds"], nbytes),
    ("LAMMPS read_dump .gz frame 0", lf, f0),
    ("LAMMPS read_dump .gz last frame", ll, nbytes),
]
for name, t, b in rows:
    print(f"{name:48s} {t:8.3f} {mbs(b, t):8.1f}")
print(f"ratio frame 0:    LAMMPS / pdcg (open + frame 0) = {lf / p['open_frame0_seconds']:.2f}x")
print(f"ratio last frame: LAMMPS / pdcg (index + parse last) = "
      f"{ll / (p['index_seconds'] + p['last_seconds']):.2f}x")
PY
fi
