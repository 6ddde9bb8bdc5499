#!/usr/bin/env bash
# The WebAssembly cut against the native one (issue 36's speed target: at most 2x on one thread),
# in one run: the same scene, frames and tolerance cut by the module under Node.js
# (benchmarks/wasm_cut.mjs) and by the native program's code (benchmarks/cut_time.cpp, one TBB
# thread), each cut timed alone (the same FrameCutter::cut), the median of N. Scenes: flanges.gltf (the default scene in glTF) and a 100k-triangle torus (.glb,
# scripts/torus_obj.sh through gltfpack -noq) at 0.9c; vertex mode and the default tolerance.
# Usage: benchmarks/wasm_cut.sh [N]   (needs build/web/apparent_web.js and build/benchmarks/cut_time)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
n=${1:-40}
mkdir -p build; work=$(mktemp -d -p "$root/build" wasm_cut.XXXXXX)  # below the root: the module mounts the working folder
trap 'rm -rf "$work"' EXIT
cd "$root"
bash scripts/torus_obj.sh 250 200 "$work/torus.obj"
gltfpack -noq -i "$work/torus.obj" -o "$work/torus.glb" > /dev/null
cat > "$work/torus.json" <<'JSON'
{ "camera": { "position": [0, 0, 0], "look_at": [0, 0, -1], "fov_deg": 60 },
  "frames": { "start": 134.7, "end": 136.7, "fps": 20 },
  "objects": [ { "name": "torus", "mesh": "torus.glb", "position": [-14, 0, -10], "t0": 0, "velocity": [0.9, 0, 0] } ] }
JSON
native() {  # scene tolerance
  build/benchmarks/cut_time "$1" "$2" "$n"
}
printf '%-28s %-10s %12s %12s %10s %8s\n' scene tolerance "native ms" "wasm ms" triangles ratio
for row in "data/scenes/flanges.gltf|vertex" "data/scenes/flanges.gltf|" "$work/torus.json|vertex" "$work/torus.json|"; do
  scene=${row%|*}; tol=${row#*|}
  read -r _ nat _ tri < <(native "$scene" "$tol")
  rel=$scene; [[ "$scene" = /* ]] && rel=$(realpath --relative-to="$root" "$scene")
  read -r _ was _ wtri < <(node benchmarks/wasm_cut.mjs build/web/apparent_web.js "$rel" "$tol" "$n")
  printf '%-28s %-10s %12s %12s %10s %8.2f\n' "$(basename "$scene")" "${tol:-scene}" "$nat" "$was" "$tri/$wtri" \
    "$(python3 -c "print($was / $nat)")"
done
