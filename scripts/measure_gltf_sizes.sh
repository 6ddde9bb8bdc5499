#!/usr/bin/env bash
# Measures the .glb sizes quoted in docs/GLTF.md: the default flange scene, a
# 20k-triangle torus passing at 0.8c (the one of benchmarks/performance_bench.cpp, BM_Frames) over
# 100 and 1000 frames, and the Khronos/Collada Duck (from Debian's assimp-testmodels, converted to
# OBJ by assimp-utils at run time, never committed) passing the camera at 0.9c; each plain, with
# --compress draco, with --compress meshopt, and the plain file through Debian's `gltfpack -cc`
# beside them; every apparent file checked with the Khronos glTF-Validator. Prints a Markdown
# table. Usage: scripts/measure_gltf_sizes.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
command -v assimp >/dev/null || { echo "needs assimp-utils (apt-get install assimp-utils)" >&2; exit 2; }
command -v gltfpack >/dev/null || { echo "needs gltfpack (apt-get install meshoptimizer)" >&2; exit 2; }
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

# The torus of BM_Frames: 200 x 50 segments (20000 triangles), ring radius 2, tube 0.5.
python3 - "$tmp/torus.obj" <<'PY'
import math, sys
nu, nv, R, r = 200, 50, 2.0, 0.5
with open(sys.argv[1], "w") as f:
    for i in range(nu):
        for j in range(nv):
            u, v = 2 * math.pi * i / nu, 2 * math.pi * j / nv
            f.write("v %.17g %.17g %.17g\n" % ((R + r * math.cos(v)) * math.cos(u), r * math.sin(v), (R + r * math.cos(v)) * math.sin(u)))
    idx = lambda i, j: (i % nu) * nv + (j % nv) + 1
    for i in range(nu):
        for j in range(nv):
            f.write("f %d %d %d\n" % (idx(i, j), idx(i, j + 1), idx(i + 1, j)))
            f.write("f %d %d %d\n" % (idx(i + 1, j), idx(i, j + 1), idx(i + 1, j + 1)))
PY
for n in 100 1000; do
  cat > "$tmp/torus$n.json" <<JSON
{ "camera": { "position": [0, 0, 0], "look_at": [0, 0, -1] },
  "frames": { "start": 0, "end": $((n / 10)), "fps": 10 },
  "model": "relativistic",
  "objects": [ { "mesh": "torus.obj", "position": [-4, 0, -10], "velocity": [0.8, 0, 0] } ] }
JSON
done

row() {  # name scene tolerance
  local name=$1 scene=$2 tol=$3 args=()
  [ "$tol" = scene ] || args=(--tolerance "$tol")
  local d="$tmp/$name"
  "$build/apparent" render "$scene" --out "$d/plain" --model relativistic "${args[@]}" --quiet
  "$build/apparent" render "$scene" --out "$d/draco" --model relativistic "${args[@]}" --compress draco --quiet
  "$build/apparent" render "$scene" --out "$d/meshopt" --model relativistic "${args[@]}" --compress meshopt --quiet
  gltfpack -cc -i "$d/plain/relativistic.glb" -o "$d/gltfpack.glb" >/dev/null 2>&1
  local plain draco meshopt packed frames verdict
  plain=$(stat -c %s "$d/plain/relativistic.glb")
  draco=$(stat -c %s "$d/draco/relativistic.glb")
  meshopt=$(stat -c %s "$d/meshopt/relativistic.glb")
  packed=$(stat -c %s "$d/gltfpack.glb")
  frames=$(python3 -c "import json,struct,sys; b=open(sys.argv[1],'rb').read(); n=struct.unpack('<I',b[12:16])[0]; print(len(json.loads(b[20:20+n])['scenes'][0]['extras']['frame_times']))" "$d/plain/relativistic.glb")
  verdict=$(cd "$root" && node tests/validators/validate_gltf.js "$d/plain/relativistic.glb" "$d/draco/relativistic.glb" "$d/meshopt/relativistic.glb" | \
            sed -E 's/.*: ([0-9]+) errors, ([0-9]+) warnings.*/\1+\2/' | paste -sd ';' -)
  rm -rf "$d"
  printf '| %s | %s | %s | %d | %d | %d | %d | %.1f x | %s |\n' "$name" "$tol" "$frames" "$plain" "$draco" "$meshopt" \
    "$packed" "$(echo "$plain / $meshopt" | bc -l)" "$verdict"
}
echo "| sequence (relativistic) | tolerance (ls) | frames | plain .glb bytes | --compress draco | --compress meshopt | gltfpack -cc of the plain file | plain / meshopt | validator errors+warnings (plain; draco; meshopt) |"
echo "|---|---|---|---|---|---|---|---|---|"
row flanges "$root/data/scenes/flanges.json" scene
row flanges "$root/data/scenes/flanges.json" 0.001
row flanges "$root/data/scenes/flanges.json" vertex
row torus-20k "$tmp/torus100.json" vertex
row torus-20k "$tmp/torus1000.json" vertex
row duck "$tmp/duck.json" vertex
row duck "$tmp/duck.json" 0.01
