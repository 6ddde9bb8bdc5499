#!/usr/bin/env bash
# ctest entry: a Draco .glb opened in Blender exactly as docs/VIEWERS.md "Blender" says,
# then rendered headless and checked not dark (tests/blender/check_render.py). No environment variable:
# scripts/blender_import.py finds the build's Draco library itself (build/blender/libextern_draco.so); only a
# build directory other than SOURCE_DIR/build is named with --draco-library. Blender runs with
# --factory-startup, so that no user preferences of the machine change the result.
# Then a textured box's look through Draco: its UVs, colours and materials in Blender, its texture in a render.
# Then the refusals: a Draco file without the library, and a meshopt file (Blender 3.4 reads no
# EXT_meshopt_compression), each one line and exit status 1.
# Usage: render.sh APPARENT_BINARY SOURCE_DIR DRACO_LIBRARY [KEEP_DIR: the rendered pictures are copied there]
set -uo pipefail
apparent=$1
src=$2
draco=$3
keep=${4:-}
blender="${BLENDER:-blender}"
command -v "$blender" >/dev/null 2>&1 || { echo "render.sh: SETUP ERROR: Blender not found" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
unset BLENDER_EXTERN_DRACO_LIBRARY_PATH
"$apparent" render "$src/data/scenes/flanges.json" --out "$tmp/out" --model relativistic --compress draco --quiet || exit 2
"$apparent" render "$src/data/scenes/flanges.json" --out "$tmp/meshopt" --model relativistic --compress meshopt \
  --frames 0:3 --quiet || exit 2
option=()
if [ "$(realpath "$draco")" != "$(realpath -m "$src/build/blender/libextern_draco.so")" ]; then
  option=(--draco-library "$draco")
  echo "render.sh: the build is not in $src/build: --draco-library $draco"
fi
failed=0

# Step: the import as a user runs it, saved, then rendered.
"$blender" -b --factory-startup --python-exit-code 1 --python "$src/scripts/blender_import.py" -- \
  "$tmp/out/relativistic.glb" --save "$tmp/out/relativistic.blend" ${option[@]+"${option[@]}"} 2>&1 \
  | grep '^blender_import'
[ -f "$tmp/out/relativistic.blend" ] || { echo "render.sh: FAIL: scripts/blender_import.py saved nothing" >&2; exit 1; }
"$blender" -b "$tmp/out/relativistic.blend" --python-exit-code 1 --python "$src/tests/blender/check_render.py" -- \
  "$tmp/out/render.png" 2>&1 | grep '^check_render'
[ "${PIPESTATUS[0]}" = 0 ] || failed=1
[ -n "$keep" ] && mkdir -p "$keep" && cp "$tmp"/out/render*.png "$keep"/

# Step: a textured model's look through Draco: make_textured_box.py's box with COLOR_0 at 0.9c imported
# with its UVs, colours and three materials (check_look.py); the box without COLOR_0 near the camera rendered, its
# texture's red, green and blue texels in the picture (tests/looks/texels.js).
python3 "$src/tests/looks/make_textured_box.py" "$tmp/box.glb" "$tmp/texture.png" || exit 2
python3 "$src/tests/looks/make_textured_box.py" "$tmp/plain_box.glb" "$tmp/texture2.png" --no-colors || exit 2
cat > "$tmp/look.json" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_deg": 60},
 "frames": {"start": 16, "end": 18, "fps": 2},
 "objects": [{"name": "box", "mesh": "box.glb", "position": [-2, 0.3, -4], "velocity": [0.9, 0, 0],
              "rotation_deg": [20, 30, 0]}]}
JSON
cat > "$tmp/near.json" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_deg": 40},
 "frames": {"start": 9.5, "end": 10.5, "fps": 4},
 "objects": [{"name": "box", "mesh": "plain_box.glb", "position": [-5.2, 0, -2.5], "velocity": [0.9, 0, 0],
              "rotation_deg": [20, 30, 0]}]}
JSON
for scene in look near; do
  "$apparent" render "$tmp/$scene.json" --out "$tmp/$scene" --model relativistic --compress draco --quiet || exit 2
  "$blender" -b --factory-startup --python-exit-code 1 --python "$src/scripts/blender_import.py" -- \
    "$tmp/$scene/relativistic.glb" --save "$tmp/$scene/relativistic.blend" ${option[@]+"${option[@]}"} 2>&1 \
    | grep '^blender_import: saved'
done
"$blender" -b "$tmp/look/relativistic.blend" --python-exit-code 1 --python "$src/tests/blender/check_look.py" 2>&1 \
  | grep '^check_look'
[ "${PIPESTATUS[0]}" = 0 ] || failed=1
"$blender" -b "$tmp/near/relativistic.blend" --python-exit-code 1 --python "$src/tests/blender/check_render.py" -- \
  "$tmp/near/render_textured.png" 1 2>&1 | grep '^check_render'
[ "${PIPESTATUS[0]}" = 0 ] || failed=1
node "$src/tests/looks/texels.js" "$tmp/near/render_textured.png" || failed=1
[ -n "$keep" ] && cp "$tmp/near/render_textured.png" "$keep"/

# Step: the refusals, one line each and exit status 1.
refusal() {  # NAME FILE EXPECTED-TEXT [ARGS...]
  local name=$1 file=$2 expected=$3
  shift 3
  local log="$tmp/$name.log" code=0
  "$blender" -b --factory-startup --python-exit-code 1 --python "$src/scripts/blender_import.py" -- "$file" "$@" \
    > "$log" 2>&1 || code=$?
  local lines
  lines=$(grep -c '^blender_import:' "$log")
  if [ "$code" = 1 ] && [ "$lines" = 1 ] && grep -q "^blender_import: .*$expected" "$log"; then
    echo "render.sh: ok: $name: $(grep '^blender_import:' "$log")"
  else
    echo "render.sh: FAIL: $name: exit status $code, $lines blender_import lines, expected one with '$expected'" >&2
    cat "$log" >&2
    failed=1
  fi
}
refusal no_draco_library "$tmp/out/relativistic.glb" "the Draco library for Blender is not at" \
  --draco-library "$tmp/missing/libextern_draco.so"
refusal meshopt "$tmp/meshopt/relativistic.glb" "uses EXT_meshopt_compression"
exit "$failed"
