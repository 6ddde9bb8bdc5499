#!/usr/bin/env bash
# Renders the default flange scene in every model, plain, with Draco, with meshopt and with
# --shade doppler (COLOR_0), and checks each .glb
# with the Khronos glTF-Validator (0 errors and 0 warnings required; the validator does not
# decode Draco or meshopt, which it reports as INFO: the Draco round trip is tested in cli_test.cpp,
# meshopt's in tests/web/meshopt_roundtrip.js); then the Vienna cube's, whose camera is orthographic.
# Usage: validate_flanges.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/plain" --model all --quiet
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/draco" --model all --draco --quiet
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/meshopt" --model all --compress meshopt --quiet
"$apparent" render "$src/data/scenes/flanges.json" --out "$out/shaded" --model all --shade doppler --quiet
"$apparent" render "$src/data/scenes/vienna_cube.json" --out "$out/ortho" --model all --quiet
cd "$src"
node tests/validators/validate_gltf.js "$out"/plain/*.glb "$out"/draco/*.glb "$out"/meshopt/*.glb "$out"/shaded/*.glb "$out"/ortho/*.glb
