#!/usr/bin/env bash
# Install pdcg into a prefix, move the prefix elsewhere (the package must be
# relocatable), then configure, build and run a separate consumer project that
# uses find_package(pdcg) and pdcg::pdcg.
# Usage: consumer_test.sh <pdcg-build-dir> <consumer-source-dir> <scratch-dir>
set -euo pipefail
build=$1 consumer=$2 scratch=$3
rm -rf "$scratch"; mkdir -p "$scratch"
cmake --install "$build" --prefix "$scratch/prefix-a" > "$scratch/install.log"
mv "$scratch/prefix-a" "$scratch/prefix-b"      # relocate
gen=()
command -v ninja >/dev/null && gen=(-G Ninja)
cmake -S "$consumer" -B "$scratch/build" "${gen[@]}" -DCMAKE_PREFIX_PATH="$scratch/prefix-b" \
      -DCMAKE_BUILD_TYPE=Release > "$scratch/configure.log"
cmake --build "$scratch/build" -j2 > "$scratch/build.log"
out=$("$scratch/build/consumer")
echo "$out"
grep -q "consumer: pdcg $(cat "$build/VERSION" 2>/dev/null || echo '')" <<<"$out"
grep -q "round trip ok" <<<"$out"
# the installed executable runs from the moved prefix too
"$scratch/prefix-b/bin/pdcg" version | grep -q '^pdcg '
# nothing installed points back into the source tree: no PDCG_SOURCE_DIR in the installed
# configuration header, and the CLI's helper script is in the prefix
if grep -q PDCG_SOURCE_DIR "$scratch/prefix-b/include/pdcg/config.hpp"; then
  echo "install.consumer: the installed pdcg/config.hpp names the source tree"; exit 1
fi
test -f "$scratch/prefix-b/share/pdcg/plot_dispersion.py"
echo "install.consumer: passed"
