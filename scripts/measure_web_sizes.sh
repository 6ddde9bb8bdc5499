#!/usr/bin/env bash
# Measures the web file's size (render --format web, docs/GLTF.md "The web file") against its input
# .glb: the glTF models of data/ (each .gltf packed into a .glb with the same JSON and buffer bytes,
# tests/web_file/pack_glb.py, so the two are compared as binary files), the glTF scenes of data/scenes,
# and Khronos's 2CylinderEngine and BoxTextured .glb from Debian's assimp-testmodels (read where they
# are installed, never committed). A model that is not a scene is placed in a one-object scene
# moving at 0.9c; the web file is written for 1 and for 120 frames (--frames does not change it).
# Prints a Markdown table. Usage: scripts/measure_web_sizes.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
models=/usr/share/assimp/models/glTF2
echo "| input | input .glb bytes | web file bytes | ratio |"
echo "|---|---|---|---|"
row() {  # label, input .glb, scene
  local label=$1 glb=$2 scene=$3
  "$build/apparent" render "$scene" --format web --out "$tmp/web1" --frames 0:1 --quiet
  "$build/apparent" render "$scene" --format web --out "$tmp/web" --quiet
  cmp -s "$tmp/web1/scene.web.glb" "$tmp/web/scene.web.glb" || { echo "$label: the web file depends on --frames" >&2; exit 1; }
  local a b
  a=$(stat -c %s "$glb")
  b=$(stat -c %s "$tmp/web/scene.web.glb")
  echo "| $label | $a | $b | $(python3 -c "print(f'{$b / $a:.3f}')") |"
}
model() {  # label, .glb: a one-object scene at 0.9c, 120 frames
  local scene
  scene="$tmp/$(basename "$2" .glb).json"
  cat > "$scene" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]}, "frames": {"start": 0, "end": 12, "fps": 10},
 "objects": [{"name": "model", "mesh": "$(basename "$2")", "position": [-4, 0, -10], "velocity": [0.9, 0, 0]}]}
JSON
  row "$1" "$2" "$scene"
}
for m in clock_face clock_hand; do
  python3 "$root/tests/web_file/pack_glb.py" "$root/data/meshes/$m.gltf" "$tmp/$m.glb"
  model "data/meshes/$m.gltf" "$tmp/$m.glb"
done
for s in flanges keyed keyed_cubic; do
  python3 "$root/tests/web_file/pack_glb.py" "$root/data/scenes/$s.gltf" "$tmp/$s.glb"
  row "data/scenes/$s.gltf (the scene)" "$tmp/$s.glb" "$tmp/$s.glb"
done
for m in 2CylinderEngine-glTF-Binary/2CylinderEngine BoxTextured-glTF-Binary/BoxTextured; do
  if [ -f "$models/$m.glb" ]; then
    cp "$models/$m.glb" "$tmp/"
    model "$(basename "$m").glb (assimp-testmodels)" "$tmp/$(basename "$m").glb"
  fi
done
