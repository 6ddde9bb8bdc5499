#!/usr/bin/env bash
# The speed-accuracy trade of docs/ACCURACY.md: `apparent trade` on the five trade scenes (the
# default flanges, data/scenes/trade/*.json), then scripts/accuracy_report.py turns their CSVs into
# docs/ACCURACY.md (with the adaptive / uniform ratios at equal error) and docs/accuracy.png.
# Usage: scripts/accuracy_report.sh [BUILD_DIR]      needs: python3, gnuplot (apt gnuplot-nox)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
command -v gnuplot >/dev/null || { echo "needs gnuplot (apt-get install gnuplot-nox)" >&2; exit 2; }
cmake --build "$build" --target apparent -j "$(nproc)" >/dev/null
out=$root/docs/trade
mkdir -p "$out"
cd "$root"
for scene in data/scenes/flanges.json data/scenes/trade/box_near.json data/scenes/trade/sphere320.json \
             data/scenes/trade/plate.json data/scenes/trade/sphere20480.json; do
  name=$(basename "$scene" .json)
  echo "== apparent trade $scene"
  "$build/apparent" trade "$scene" --out "$out/$name" --quiet | tee "$out/$name/table.txt"
done
python3 "$root/scripts/accuracy_report.py" "$out" "$root/docs"
(cd "$root/docs" && gnuplot accuracy.gp)
echo "wrote docs/ACCURACY.md, docs/accuracy.png and docs/trade/"
