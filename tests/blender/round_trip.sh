#!/usr/bin/env bash
# ctest entry: the Blender round trip (docs/VIEWERS.md "Blender"). A scene authored in Blender (a cube with the custom
# property velocity = [0, 0.5, 0], "into the screen" in Blender's Z-up axes, and the scene property up = "z")
# is exported by Blender's glTF exporter, rendered by apparent (instant model, frames 0..10, 1 s apart at the
# ends), imported back with scripts/blender_import.py and saved; the saved file must have the .glb's fps,
# timeline and camera, and the cube must have moved 0.5 along Blender's +Y, as its author meant.
# Usage: round_trip.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
blender="${BLENDER:-blender}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$blender" -b --factory-startup --python-exit-code 1 --python "$src/tests/blender/make_zup_scene.py" -- \
  "$tmp/scene.glb" 0 0.5 0 > "$tmp/make.log" 2>&1 || { cat "$tmp/make.log"; exit 1; }
"$apparent" render "$tmp/scene.glb" --model instant --tolerance vertex --frames 0:11 --out "$tmp/out" --quiet
"$blender" -b --factory-startup --python-exit-code 1 --python "$src/scripts/blender_import.py" -- \
  "$tmp/out/instant.glb" --save "$tmp/round.blend" 2>&1 | grep 'blender_import'
[ -f "$tmp/round.blend" ] || { echo "round_trip.sh: FAIL: scripts/blender_import.py saved nothing" >&2; exit 1; }
"$blender" -b --factory-startup "$tmp/round.blend" --python-exit-code 1 \
  --python "$src/tests/blender/check_round_trip.py" -- "$tmp/out/instant.glb" 0 0.5 0 10 2>&1 | grep 'check_round_trip'
exit "${PIPESTATUS[0]}"
