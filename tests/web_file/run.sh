#!/usr/bin/env bash
# The web file (`render --format web`, pipeline/run/web_file.h) carries everything the cut needs: for
# every shipped scene, rendering its web file gives the scene's own PLY frames. Scenes whose meshes
# are glTF, or OBJ files whose numbers are float32 already, give them byte for byte but the header
# line `comment scene:` (it names the file rendered); the icosphere and wheel OBJ files, whose
# vertices float32 moves (up to 1e-8 of the mesh's size, the writer's note), give the same faces
# and every value within 1e-6 (compare_ply.py). The byte-for-byte scenes' .glb are the scene's too,
# but the extras' scene_file (compare_glb.py: frames, camera, light, materials, images). The file's size does not depend on the frames
# rendered (--frames 0:1 and every frame give the same bytes). The Khronos glTF-Validator finds no
# error in the web files of the default scene, of the textured box and of the keyframed spline (make_textured_box.py: three
# materials, an image, TEXCOORD_0/1 and COLOR_0), and the box rendered from its web file passes
# check_textured.py's closed forms as the box does. A metre scene and two objects of one name are
# refused with exit code 2.
# Usage: run.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cd "$src"
frames=0:3
roundtrip() {  # scene, mode (exact or within), label, extra options...
  local scene=$1 mode=$2 name=$3
  shift 3
  "$apparent" render "$scene" --format web --out "$out/$name/web" --quiet "$@"
  "$apparent" render "$scene" --format ply,glb --frames $frames --out "$out/$name/scene" --quiet "$@"
  "$apparent" render "$out/$name/web/scene.web.glb" --format ply,glb --frames $frames --out "$out/$name/web_frames" --quiet "$@"
  echo -n "$name: "
  if [ "$mode" = exact ]; then
    python3 tests/web_file/compare_ply.py "$out/$name/scene" "$out/$name/web_frames" exact
    echo -n "$name: "
    python3 tests/web_file/compare_glb.py "$out/$name/scene" "$out/$name/web_frames"
  else
    python3 tests/web_file/compare_ply.py "$out/$name/scene" "$out/$name/web_frames" within 1e-6
  fi
}
for s in clocks flanges flyby orbit_ring rocket terrell_cube vienna_cube; do roundtrip data/scenes/$s.json exact $s; done
roundtrip data/scenes/flanges.gltf exact flanges.gltf
frames=0:160 roundtrip data/scenes/keyed.gltf exact keyed.gltf
frames=0:160 roundtrip data/scenes/keyed_cubic.gltf exact keyed_cubic.gltf
# Every object field, and a glTF scene whose object nodes turn and scale (their matrix), with an
# exact speed, exists, a distant light and a moving camera.
frames=0:3 roundtrip tests/web_file/every_field.json exact "every field, every model" --model all
python3 - data/scenes/flanges.gltf "$out/turned.gltf" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["nodes"][1].update(rotation=[0.2, 0.3, 0.1, 0.927], scale=[1.5, 0.7, 1.1])
d["nodes"][2]["rotation"] = [0, 0.7071067811865476, 0, 0.7071067811865476]
d["nodes"][3]["extras"] = {"direction": [1, 1, 0.3], "gamma": 2.5, "t0": 0.5, "exists": [None, 12.5]}
d["scenes"][0]["extras"]["light"] = {"direction": [0.3, 1, 0.2], "ambient": 0.25}
d["nodes"][0]["extras"]["velocity"] = [0.1, 0.05, -0.2]
json.dump(d, open(sys.argv[2], "w"))
PY
roundtrip "$out/turned.gltf" exact "turned glTF nodes"
for s in penrose_sphere rolling_wheel spinning_wheel vienna_sphere; do roundtrip data/scenes/$s.json within $s; done
# The default scene in every model and in vertex mode.
frames=0:20 roundtrip data/scenes/flanges.json exact "flanges, every model" --model all
frames=0:20 roundtrip data/scenes/flanges.json exact "flanges, vertex mode" --tolerance vertex

# The size does not grow with the frames.
"$apparent" render data/scenes/flanges.json --format web --frames 0:1 --out "$out/one" --quiet
"$apparent" render data/scenes/flanges.json --format web --out "$out/all" --quiet
cmp "$out/one/scene.web.glb" "$out/all/scene.web.glb"
echo "web file of 1 and of 200 frames: the same $(stat -c %s "$out/all/scene.web.glb") bytes"

# A textured box: its look through the web file.
mkdir -p "$out/box"
python3 tests/looks/make_textured_box.py "$out/box/box.glb" "$out/box/texture.png"
cat > "$out/box/scene.json" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_deg": 60},
 "frames": {"start": 16, "end": 18, "fps": 2}, "model": "relativistic",
 "objects": [{"name": "box", "mesh": "box.glb", "position": [-2, 0.3, -4], "velocity": [0.9, 0, 0],
              "rotation_deg": [20, 30, 0]}]}
JSON
frames=0:4 roundtrip "$out/box/scene.json" exact "textured box"
"$apparent" render "$out/textured box/web/scene.web.glb" --out "$out/box/from_web" --quiet
python3 tests/looks/check_textured.py "$out/box/from_web/relativistic.glb" "$out/box/box.glb" -2 0.3 -4 0.9 0 0 20 30 0
# The same box as an OBJ with a .mtl (tests/looks/make_textured_obj.py): its three materials meet at
# shared corners, so the web file's primitives share one set of vertex accessors (gltf_reader.h).
python3 tests/looks/make_textured_obj.py "$out/obj"
sed 's#box.glb#box.obj#' "$out/box/scene.json" > "$out/obj/scene.json"
frames=0:4 roundtrip "$out/obj/scene.json" exact "textured OBJ box"
node tests/validators/validate_gltf.js "$out/flanges/web/scene.web.glb" "$out/textured box/web/scene.web.glb" \
  "$out/keyed_cubic.gltf/web/scene.web.glb" "$out/textured OBJ box/web/scene.web.glb"

# What the web file cannot carry: exit code 2, one line naming the field.
refused() {  # scene, expected text of the message
  set +e
  message=$("$apparent" render "$1" --format web --out "$out/refused" 2>&1)
  code=$?
  set -e
  [ $code -eq 2 ] && echo "$message" | grep -qF "$2" || { echo "$1: exit code $code, expected 2 naming $2: $message"; exit 1; }
  [ ! -e "$out/refused/scene.web.glb" ] || { echo "$1: a web file was written"; exit 1; }
}
mkdir -p "$out/metres/scenes"
cp data/meshes/box.obj "$out/metres/scenes/"
sed -e 's/"model"/"units": "m", "model"/' -e 's#../meshes/box.obj#box.obj#' data/scenes/terrell_cube.json > "$out/metres/scenes/terrell_m.json"
refused "$out/metres/scenes/terrell_m.json" ": units: a metre scene"
sed -e 's/"name": "lab twin"/"name": "cube"/' -e 's#../meshes/box.obj#box.obj#' data/scenes/vienna_cube.json > "$out/metres/scenes/twins.json"
refused "$out/metres/scenes/twins.json" "objects[1].name: 'cube' names two objects"
echo "refusals: exit code 2 naming the field"
