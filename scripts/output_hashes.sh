#!/usr/bin/env bash
# The bytes a build writes for every shipped scene, as one line per output file: "md5  path".
# Two builds that should agree (a reshaping commit and its parent, APPARENT_NO_LANES=ON and the
# default) print the same lines; scripts/compare_builds.sh diffs them.
#   scripts/output_hashes.sh BUILD/apparent OUT_DIR [quick]
# Every scene in data/scenes (and data/scenes/trade), each model apart, glb + ply + obj, in vertex
# mode and at the scene's default tolerance; `quick` renders the first 3 frames of each
# (the default: all frames up to 12).
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 APPARENT_BINARY OUT_DIR [quick]" >&2; exit 2; }
bin=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
out=$2
frames=0:12
[ "${3:-}" = quick ] && frames=0:3
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
rm -rf "$out"
mkdir -p "$out"
cd "$root"
for scene in data/scenes/*.json data/scenes/*.gltf data/scenes/trade/*.json; do
  name=$(echo "${scene#data/scenes/}" | tr '/' '_')
  for tol in vertex default; do
   # One model at a time: a scene one model refuses (the rolling wheel is faster than light
   # under Galilean carry) still renders in the others.
   for model in instant finite relativistic contracted; do
    dir="$out/${name%.*}.$tol.$model"
    args=(render "$scene" --out "$dir" --model "$model" --format glb,ply,obj --frames "$frames" --threads 2 --quiet)
    [ "$tol" = vertex ] && args+=(--tolerance vertex)
    # A scene the program refuses (say, too large at the default) is recorded by its exit code.
    code=0
    "$bin" "${args[@]}" > "$dir.log" 2>&1 || code=$?
    echo "exit $code" > "$dir.exit"
   done
  done
done
cd "$out"
find . -type f ! -name '*.log' | LC_ALL=C sort | xargs md5sum
