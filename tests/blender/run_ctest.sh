#!/usr/bin/env bash
# ctest entry: renders the default scene plain and with Draco, then imports both into headless
# Blender (tests/blender/run.sh; Draco through the build's library for Blender, build/blender/).
# Usage: run_ctest.sh APPARENT_BINARY SOURCE_DIR DRACO_LIBRARY
set -euo pipefail
apparent=$1
src=$2
draco=$3
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/plain" --model instant,finite,relativistic --quiet
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/draco" --model relativistic --draco --quiet
bash "$src/tests/blender/run.sh" --draco-library "$draco" "$out"/plain/*.glb "$out"/draco/*.glb
