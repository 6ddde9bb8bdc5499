#!/usr/bin/env bash
# A textured, three-material box with vertex colours (make_textured_box.py) rendered at 0.9c: at the
# default tolerance, in vertex mode, and at rest in the instant model; each .glb passes the Khronos
# glTF-Validator and check_textured.py (every vertex's TEXCOORD_0 and COLOR_0 equal the closed form
# at its rest point, the materials and the image are the input's, the image once). With --compress
# the look is dropped with a warning; across processes (--shard) it is refused.
# Usage: run.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
python3 "$src/tests/looks/make_textured_box.py" "$out/box.glb" "$out/texture.png"
scene() {  # velocity x, model, frames start
  cat > "$out/scene_$2.json" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_deg": 60},
 "frames": {"start": $3, "end": $(($3 + 2)), "fps": 2}, "model": "$2",
 "objects": [{"name": "box", "mesh": "box.glb", "position": [-2, 0.3, -4], "velocity": [$1, 0, 0],
              "rotation_deg": [20, 30, 0]}]}
JSON
}
scene 0.9 relativistic 16
scene 0 instant 0
"$apparent" render "$out/scene_relativistic.json" --out "$out/refined" --quiet
"$apparent" render "$out/scene_relativistic.json" --out "$out/vertex" --tolerance vertex --quiet
"$apparent" render "$out/scene_instant.json" --out "$out/rest" --tolerance vertex --quiet
python3 "$src/tests/looks/check_textured.py" "$out/refined/relativistic.glb" "$out/box.glb" -2 0.3 -4 0.9 0 0 20 30 0
python3 "$src/tests/looks/check_textured.py" "$out/vertex/relativistic.glb" "$out/box.glb" -2 0.3 -4 0.9 0 0 20 30 0
python3 "$src/tests/looks/check_textured.py" "$out/rest/instant.glb" "$out/box.glb" -2 0.3 -4 0 0 0 20 30 0
(cd "$src" && node tests/validators/validate_gltf.js "$out/refined/relativistic.glb" "$out/vertex/relativistic.glb" \
  "$out/rest/instant.glb")
"$apparent" render "$out/scene_relativistic.json" --out "$out/meshopt" --compress meshopt 2> "$out/meshopt.err"
grep -q "object 'box': its materials, textures" "$out/meshopt.err" || { echo "FAIL: no warning with --compress"; exit 1; }
if "$apparent" render "$out/scene_relativistic.json" --out "$out/shard" --shard 0/2 2> "$out/shard.err"; then
  echo "FAIL: --shard accepted a textured object"; exit 1
fi
grep -q "do not carry yet" "$out/shard.err" || { echo "FAIL: unclear --shard message"; cat "$out/shard.err"; exit 1; }
echo "looks: ok"
