#!/usr/bin/env bash
# make_textured_box.py's box as an OBJ with a .mtl and a PNG (make_textured_obj.py: 8 shared corners,
# so every corner is split by its texture coordinates) rendered at 0.9c, at the default tolerance, in
# vertex mode and at rest: each .glb passes the Khronos glTF-Validator, and check_textured.py finds the
# .mtl's materials as docs/INPUT.md maps them, the PNG's bytes once, and every vertex's TEXCOORD_0 equal
# to the closed form at its rest point. Shards merged give the one process's bytes; --compress draco and
# meshopt keep the look, decoded as three.js decodes them, within the codecs' stated bounds.
# Usage: run_obj.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
python3 "$src/tests/looks/make_textured_obj.py" "$out/in"
scene() {  # velocity x, model, frames start
  cat > "$out/in/scene_$2.json" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_deg": 60},
 "frames": {"start": $3, "end": $(($3 + 2)), "fps": 2}, "model": "$2",
 "objects": [{"name": "box", "mesh": "box.obj", "position": [-2, 0.3, -4], "velocity": [$1, 0, 0],
              "rotation_deg": [20, 30, 0]}]}
JSON
}
scene 0.9 relativistic 16
scene 0 instant 0
"$apparent" render "$out/in/scene_relativistic.json" --out "$out/refined" --quiet
"$apparent" render "$out/in/scene_relativistic.json" --out "$out/vertex" --tolerance vertex --quiet
"$apparent" render "$out/in/scene_instant.json" --out "$out/rest" --tolerance vertex --quiet
expected="$out/in/EXPECTED.json"
python3 "$src/tests/looks/check_textured.py" "$out/refined/relativistic.glb" "$expected" -2 0.3 -4 0.9 0 0 20 30 0
python3 "$src/tests/looks/check_textured.py" "$out/vertex/relativistic.glb" "$expected" -2 0.3 -4 0.9 0 0 20 30 0
python3 "$src/tests/looks/check_textured.py" "$out/rest/instant.glb" "$expected" -2 0.3 -4 0 0 0 20 30 0
(cd "$src" && node tests/validators/validate_gltf.js "$out/refined/relativistic.glb" "$out/vertex/relativistic.glb" \
  "$out/rest/instant.glb")
for i in 0 1; do
  "$apparent" render "$out/in/scene_relativistic.json" --out "$out/shard" --shard $i/2 --quiet
done
"$apparent" merge "$out/shard" --quiet
cmp "$out/refined/relativistic.glb" "$out/shard/relativistic.glb" || { echo "FAIL: shards differ from one process"; exit 1; }
# The OBJ's look through both codecs, decoded as three.js decodes them, within the codecs' bounds.
for c in draco meshopt; do
  "$apparent" render "$out/in/scene_relativistic.json" --out "$out/$c" --compress $c --quiet
  (cd "$src" && node tests/looks/decode_glb.js "$out/$c/relativistic.glb" "$out/$c/decoded.glb" &&
    node tests/validators/validate_gltf.js "$out/$c/relativistic.glb")
done
python3 "$src/tests/looks/check_textured.py" "$out/draco/decoded.glb" "$expected" -2 0.3 -4 0.9 0 0 20 30 0 \
  draco 14 12 "$out/refined/relativistic.glb"
python3 "$src/tests/looks/check_textured.py" "$out/meshopt/decoded.glb" "$expected" -2 0.3 -4 0.9 0 0 20 30 0 \
  meshopt "$out/refined/relativistic.glb"
echo "looks (OBJ): ok"
