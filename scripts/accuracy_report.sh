#!/usr/bin/env bash
# The speed-accuracy trade of docs/ACCURACY.md: `apparent trade` on the five trade scenes (the
# default flanges, data/scenes/trade/*.json), then scripts/accuracy_report.py fills the generated blocks
# of docs/ACCURACY.md from them (the adaptive / uniform ratios at equal error, the tables; the text
# outside the blocks' markers is kept) and makes docs/accuracy.png;
# scripts/trade_end_to_end.py times whole renders at equal error (docs/trade/end_to_end.md); then
# the other motions (keyframed, accelerated, spinning, rolling: docs/trade/motions/).
# Usage: scripts/accuracy_report.sh [--motions] [BUILD_DIR]      needs: python3, gnuplot (apt gnuplot-nox)
#   --motions  measures only the other motions (a few minutes) and regenerates the page from what
#              docs/trade/ holds (the other blocks keep their last measurement and its date)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
only_motions=0
if [ "${1:-}" = "--motions" ]; then only_motions=1; shift; fi
build=${1:-$root/build}
command -v gnuplot >/dev/null || { echo "needs gnuplot (apt-get install gnuplot-nox)" >&2; exit 2; }
cmake --build "$build" --target apparent -j "$(nproc)" >/dev/null
out=$root/docs/trade
mkdir -p "$out"
cd "$root"
stamp() { echo "$(date -u '+%Y-%m-%d %H:%M UTC'), source at $(git rev-parse --short HEAD 2>/dev/null || echo 'an unknown commit')$(git diff --quiet HEAD -- 2>/dev/null || echo ' with local changes')"; }
if [ "$only_motions" = 0 ]; then
# The method paragraph of docs/ACCURACY.md says when and from which source this was measured.
stamp > "$out/measured.txt"
# A finer ladder than trade's default (about 1.5x apart instead of 3x): the comparison at equal error
# interpolates between the two tolerances that bracket each uniform level's error.
ladder=1e-1,5e-2,3e-2,2e-2,1e-2,7e-3,5e-3,3e-3,2e-3,1.4e-3,1e-3,7e-4,5e-4,3e-4,2e-4,1.4e-4,1e-4
for scene in data/scenes/flanges.json data/scenes/trade/box_near.json data/scenes/trade/sphere320.json \
             data/scenes/trade/plate.json data/scenes/trade/sphere20480.json; do
  name=$(basename "$scene" .json)
  mkdir -p "$out/$name"
  echo "== apparent trade $scene"
  "$build/apparent" trade "$scene" --out "$out/$name" --quiet --tolerances "$ladder" | tee "$out/$name/table.txt"
done
echo "== where nothing needs refining: the cut at T = 1e-3 x size against vertex mode (performance_bench)"
cmake --build "$build" --target performance_bench -j "$(nproc)" >/dev/null
"$build/benchmarks/performance_bench" --benchmark_filter='BM_Cut(VertexMode|Tolerance)/' --benchmark_min_time=0.3 \
  --benchmark_format=json > "$out/cheap_path.json"
echo "== cost per output triangle: tolerance mode against vertex mode (refine_bench)"
cmake --build "$build" --target refine_bench -j "$(nproc)" >/dev/null
"$build/benchmarks/refine_bench" --benchmark_min_time=0.5 --benchmark_format=json > "$out/per_triangle.json"
echo "== instructions per output triangle (callgrind: repeatable on a shared machine)"
if command -v valgrind >/dev/null; then
  echo "scene,k,tolerance_triangles,tolerance_instructions,vertex_triangles,vertex_instructions" > "$out/instructions.csv"
  for k in 3 4 5; do
    for scene in 0 1 2; do
      counts=()
      for fn in countTolerance countVertex; do
        log=$(mktemp)
        valgrind --tool=callgrind --callgrind-out-file=/dev/null --toggle-collect="*$fn*" \
          "$build/benchmarks/refine_bench" --count "$scene" "$k" > "$log.out" 2> "$log"
        counts+=("$(sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$log")")
        tris=$(cat "$log.out")
        rm -f "$log" "$log.out"
      done
      tt=$(echo "$tris" | awk '/tolerance_triangles/ {print $2}')
      vt=$(echo "$tris" | awk '/vertex_triangles/ {print $2}')
      echo "$scene,$k,$tt,${counts[0]},$vt,${counts[1]}" >> "$out/instructions.csv"
    done
  done
else
  echo "valgrind not found (scripts/setup.sh installs it): no instruction counts" >&2
  rm -f "$out/instructions.csv"
fi
echo "== end to end at equal error (apparent render, every frame)"
count=$(command -v valgrind >/dev/null && echo --count || true)
python3 "$root/scripts/trade_end_to_end.py" "$build" $count | tee "$out/end_to_end.md"
fi
echo "== the other motions: keyframed (LINEAR, CUBICSPLINE), accelerated, spinning, rolling"
mkdir -p "$out/motions"
stamp > "$out/motions/measured.txt"
# Issue 31's tolerances; the rolling wheel on its middle frame only and down to 1e-3 x size (its
# finer rows cost minutes per frame: 9.8 s of cut per frame at 1e-4 before any measuring).
for run in "keyed.gltf" "keyed_cubic.gltf" "rocket.json" "spinning_wheel.json" \
           "rolling_wheel.json --frames 8:9 --tolerances 1e-2,3e-3,1e-3"; do
  scene=data/scenes/${run%% *}
  extra=""; [ "$run" != "${run%% *}" ] && extra=${run#* }
  name=$(basename "${scene%.*}")
  mkdir -p "$out/motions/$name"
  echo "== apparent trade $scene --levels 4 ${extra:---tolerances 1e-2,1e-3,1e-4}"
  # shellcheck disable=SC2086
  "$build/apparent" trade "$scene" --out "$out/motions/$name" --quiet --levels 4 ${extra:---tolerances 1e-2,1e-3,1e-4} \
    | tee "$out/motions/$name/table.txt"
done
python3 "$root/scripts/accuracy_report.py" "$out" "$root/docs"
(cd "$root/docs" && gnuplot accuracy.gp)
echo "wrote docs/ACCURACY.md, docs/accuracy.png and docs/trade/"
