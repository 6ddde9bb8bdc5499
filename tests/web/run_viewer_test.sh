#!/usr/bin/env bash
# Renders the default scene (plain, Draco, meshopt, and Draco with --shade doppler) and checks each with three.js in headless
# Chromium (tests/web/viewer_test.js).
# Usage: run_viewer_test.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/plain" --model instant,finite,relativistic --quiet
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/draco" --model instant,finite,relativistic --draco --quiet
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/meshopt" --model instant,finite,relativistic --compress meshopt --quiet
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/doppler" --model instant,finite,relativistic --draco --shade doppler --quiet
cd "$src"
node tests/web/viewer_test.js "$out/plain"
node tests/web/viewer_test.js "$out/draco"
node tests/web/viewer_test.js "$out/meshopt"
node tests/web/viewer_test.js "$out/doppler"
