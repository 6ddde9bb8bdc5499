#!/usr/bin/env bash
# Measures the .glb sizes quoted in the README: the default flange scene, and the Khronos/Collada
# Duck (from Debian's assimp-testmodels, converted to OBJ by assimp-utils at run time, never
# committed) passing the camera at 0.9c; each with and without Draco, each checked with the
# Khronos glTF-Validator. Prints a Markdown table. Usage: scripts/measure_gltf_sizes.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
command -v assimp >/dev/null || { echo "needs assimp-utils (apt-get install assimp-utils)" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

assimp export /usr/share/assimp/models/Collada/duck.dae "$tmp/duck.obj" >/dev/null
# The duck is about 1.65 units long; scaled to 2 light-seconds it passes 10 light-seconds in
# front of the camera at 0.9c, crossing the line of sight at t = 0 (seen about 10 s later).
cat > "$tmp/duck.json" <<'JSON'
{ "camera": { "position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0], "fov_deg": 60 },
  "frames": { "start": 0, "end": 20, "fps": 10 },
  "model": "relativistic",
  "objects": [ { "name": "duck", "mesh": "duck.obj", "position": [0, -1, -10], "t0": 0,
                 "velocity": [0.9, 0, 0], "scale": 1.2 } ] }
JSON

row() {  # name scene tolerance
  local name=$1 scene=$2 tol=$3
  "$build/apparent" render "$scene" --out "$tmp/$name-plain" --model relativistic --tolerance "$tol" --quiet
  "$build/apparent" render "$scene" --out "$tmp/$name-draco" --model relativistic --tolerance "$tol" --draco --quiet
  local plain draco verdict tris
  plain=$(stat -c %s "$tmp/$name-plain/relativistic.glb")
  draco=$(stat -c %s "$tmp/$name-draco/relativistic.glb")
  verdict=$(cd "$root" && node tests/validators/validate_gltf.js "$tmp/$name-plain/relativistic.glb" "$tmp/$name-draco/relativistic.glb" | \
            sed -E 's/.*: ([0-9]+ errors, [0-9]+ warnings).*/\1/' | paste -sd ';' -)
  tris=$("$build/apparent" render "$scene" --out "$tmp/$name-count" --model relativistic --tolerance "$tol" 2>&1 | \
         grep -o "up to [0-9]* triangles")
  rm -rf "$tmp/$name-plain" "$tmp/$name-draco" "$tmp/$name-count"
  printf '| %s | %s | %s | %d | %d | %.1f x | %s |\n' "$name" "$tol" "$tris" "$plain" "$draco" \
    "$(echo "$plain / $draco" | bc -l)" "$verdict"
}
echo "| sequence (200 frames, relativistic) | tolerance (ls) | per frame | .glb bytes | with --draco (14 bits) | ratio | glTF-Validator (plain; Draco) |"
echo "|---|---|---|---|---|---|---|"
row flanges "$root/data/scenes/flanges.json" vertex
row flanges "$root/data/scenes/flanges.json" 0.01
row duck "$tmp/duck.json" vertex
row duck "$tmp/duck.json" 0.01
