#!/usr/bin/env bash
# Renders the default scene (plain, Draco, meshopt, and Draco with --shade doppler) and checks each with three.js in headless
# Chromium (tests/web/viewer_test.js); then the 20480-face icosphere in vertex mode with --compress meshopt, whose frames
# are morph targets (exporters/gltf.h), against its plain export (--plain: the shown frame's bounds as three.js draws it);
# then the Vienna cube through its orthographic camera (docs/PICTURES.md, "The orthographic camera").
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
# ?t is camera time: frames 50..119 are camera times 5.0 .. 11.9 s; t=8 opens at camera time 8, and t=2, outside
# them, is an older link's animation time (camera time 5 + 2).
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/late" --model relativistic --frames 50:120 --quiet
node tests/web/viewer_test.js "$out/late" --models relativistic --frames 0,30,69 --shot-time 3 --open-time 8 --expect-camera-time 8
node tests/web/viewer_test.js "$out/late" --models relativistic --frames 0,69 --shot-time 3 --open-time 2 --expect-camera-time 7
# A scene in metres (units: m) lasts 300 ns: its times read in ns.
"$apparent" render "$src/data/fixtures/scene_metres.json" --out "$out/metres" --model relativistic --quiet
node tests/web/viewer_test.js "$out/metres" --models relativistic --frames 0,15,29 --shot-time 2e-7 --expect-time-unit ns
sphere="$src/data/scenes/trade/sphere20480.json"
"$apparent" render "$sphere" --out "$out/sphere-plain" --model relativistic --quiet
"$apparent" render "$sphere" --out "$out/sphere-meshopt" --model relativistic --compress meshopt --quiet
grep -q '"targets"' "$out/sphere-meshopt/relativistic.glb" || { echo "run_viewer_test: $sphere: no morph targets" >&2; exit 1; }
node tests/web/viewer_test.js "$out/sphere-meshopt" --models relativistic --frames 0,1,2,20,39 --shot-time 4 --plain "$out/sphere-plain"
"$apparent" render "$src/data/scenes/vienna_cube.json" --out "$out/ortho" --model relativistic --quiet
grep -q '"orthographic"' "$out/ortho/relativistic.glb" || { echo "run_viewer_test: vienna_cube: no orthographic camera" >&2; exit 1; }
node tests/web/viewer_test.js "$out/ortho" --models relativistic --frames 0,10,20,39 --shot-time 2
