#!/usr/bin/env bash
# ctest entry: renders the default scene plain, with Draco and with meshopt, then loads them in Google's
# model-viewer in headless Chromium (tests/model_viewer/check.js).
# Usage: run_ctest.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/plain" --model finite,relativistic --quiet
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/draco" --model relativistic --draco --quiet
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/meshopt" --model relativistic --compress meshopt --quiet
sphere="$src/data/scenes/trade/sphere20480.json"
"$apparent" render "$sphere" --out "$out/sphere" --model relativistic --compress meshopt --quiet
grep -q '"targets"' "$out/sphere/relativistic.glb" || { echo "model_viewer: $sphere: no morph targets" >&2; exit 1; }
cd "$src"
node tests/model_viewer/check.js "$out/plain" "$out/draco" "$out/meshopt"
node tests/model_viewer/check.js "$out/sphere" --shot-time 4
