#!/bin/sh
# Builds the diagnosis driver against a configured pdcg build dir (default ../../../build).
set -e
HERE=$(cd "$(dirname "$0")" && pwd)
B=${1:-$HERE/../../../build}
B=$(cd "$B" && pwd)
cmd=$(python3 -c "import json,sys; c=json.load(open('$B/compile_commands.json')); print([x['command'] for x in c if x['file'].endswith('src/scene/scene.cpp')][0])")
flags=$(echo "$cmd" | tr ' ' '\n' | grep -E '^-(I|D|std|O|f)' | tr '\n' ' ')
isys=$(echo "$cmd" | grep -o -- '-isystem [^ ]*' | tr '\n' ' ')
libdirs=$(ls -d "$B"/src/*/)
g++ $flags $isys -c "$HERE/hole_surface.cpp" -o "$B/hole_surface.o"
g++ "$B/hole_surface.o" -o "$B/hole_surface" -fopenmp $(for d in $libdirs; do echo "-L$d"; done) \
  -Wl,-rpath,$(echo $libdirs | tr ' ' ':') \
  $(ls "$B"/src/*/*.so | sed 's|.*/lib\(.*\)\.so|-l\1|' | sort -u) -lfmt -lspdlog
echo "built $B/hole_surface"
