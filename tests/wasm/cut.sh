#!/usr/bin/env bash
# exporters/web/cut.mjs (the WebAssembly module under Node.js, scripts/build_web.sh) against the
# native program: frames of shipped glTF scenes cut by both, in vertex mode and at tolerances, must
# be the same PLY files byte for byte (positions, emission times, Doppler factors, proper times,
# faces, header); hostile scene files must be refused by both with the same one line and exit code 2,
# never a hang. Prints the module's size.
# Usage: cut.sh APPARENT SOURCE_DIR WORK_DIR   (exit 77: em++ is not installed, the test skips)
set -euo pipefail
apparent=$1
src=$2
work=$3
command -v em++ > /dev/null || { echo "wasm_cut: em++ not found (scripts/setup.sh installs Debian's emscripten)"; exit 77; }
mkdir -p "$work"
bash "$src/scripts/build_web.sh" "$work" > "$work/build.log" 2>&1 || { tail -20 "$work/build.log"; exit 1; }
module=$work/apparent_web.js
echo "wasm_cut: module and loader $(stat -c %s "$module") bytes (one file)"
cd "$src"
fails=0
# Step: frames cut by both (the scene path as given: the PLY names it).
# `compare` asks for the same bytes; `close=1 compare` (a body that spins: sines and cosines from
# each build's own C library) for the same header and faces and every double within 1e-12 relative
# (of max(1, |value|)), printing how many are the same bits.
close=0
compare() {  # scene tolerance frames...
  local scene=$1 tolerance=$2; shift 2
  rm -rf "$work/native"
  "$apparent" render "$scene" --format ply --tolerance "$tolerance" --out "$work/native" --quiet
  for k in "$@"; do
    local native
    native=$(ls "$work"/native/*/frame_$(printf %05d "$k").ply)
    node exporters/web/cut.mjs "$scene" --frame "$k" --tolerance "$tolerance" --module "$module" --out "$work/wasm.ply"
    if cmp -s "$native" "$work/wasm.ply"; then
      echo "same bytes: $scene frame $k, tolerance $tolerance ($(stat -c %s "$native") bytes)"
    elif [ "$close" = 1 ] && python3 "$src/tests/wasm/close_ply.py" "$native" "$work/wasm.ply" 1e-12; then
      echo "  (close: $scene frame $k, tolerance $tolerance)"
    else
      echo "FAIL: $scene frame $k, tolerance $tolerance: the PLY files differ"; fails=$((fails + 1))
    fi
  done
}
compare data/scenes/flanges.gltf vertex 0 7 19
compare data/scenes/flanges.gltf 0.01 0 3 10 19
compare data/scenes/flanges.gltf 1e-3x 12
compare data/scenes/keyed.gltf 1e-3x 4 9
compare data/scenes/keyed_cubic.gltf 1e-2x 5 11
compare data/scenes/clocks.json 1e-3x 0 8
# Step: the default scene (OBJ meshes) through its web file (apparent render --format web).
rm -rf "$work/webfile"
"$apparent" render data/scenes/flanges.json --format web --out "$work/webfile" --quiet
compare "$(realpath --relative-to="$src" "$work/webfile/scene.web.glb")" vertex 0 10
compare "$(realpath --relative-to="$src" "$work/webfile/scene.web.glb")" 1e-3x 4 17
# Step: a moving camera (flyby.json) and a spinning, rolling body, through their web files.
for scene in flyby rolling_wheel; do
  rm -rf "$work/webfile"
  "$apparent" render data/scenes/$scene.json --format web --out "$work/webfile" --quiet
  [ "$scene" = rolling_wheel ] && close=1
  compare "$(realpath --relative-to="$src" "$work/webfile/scene.web.glb")" vertex 0 5
  compare "$(realpath --relative-to="$src" "$work/webfile/scene.web.glb")" 1e-2x 3
  close=0
done
# Step: --time gives the frame at that camera time (frame 3 of flanges is at 0.3 s).
rm -rf "$work/native"
"$apparent" render data/scenes/flanges.gltf --format ply --frames 3:4 --out "$work/native" --quiet
node exporters/web/cut.mjs data/scenes/flanges.gltf --time 0.3 --module "$module" --out "$work/wasm.ply"
cmp -s "$work"/native/*/frame_00003.ply "$work/wasm.ply" && echo "same bytes: --time 0.3" ||
  { echo "FAIL: --time 0.3 differs from frame 3"; fails=$((fails + 1)); }
# Step: hostile and unsupported files: the same line as the native program, exit code 2.
head -c 3000 data/scenes/flanges.gltf > "$work/truncated.gltf"
head -c 1000 /dev/urandom > "$work/noise.glb"
printf 'glTF\002\000\000\000\377\377\377\377' > "$work/short_header.glb"
for f in data/fixtures/gltf/scene_superluminal.gltf data/fixtures/gltf/scene_no_objects.gltf \
         data/fixtures/gltf/scene_duplicate_names.gltf "$work/truncated.gltf" "$work/noise.glb" "$work/short_header.glb"; do
  set +e
  want=$("$apparent" render "$f" --format ply --out "$work/refused" --quiet 2>&1 | grep '^error: ')
  got=$(timeout 120 node exporters/web/cut.mjs "$f" --frame 0 --module "$module" --out "$work/refused.ply" 2>&1)
  code=$?
  set -e
  if [ "$code" = 2 ] && [ -n "$want" ] && [ "$got" = "$want" ]; then
    echo "refused alike: $f: $got"
  else
    echo "FAIL: $f: exit $code, '$got' (native: '$want')"; fails=$((fails + 1))
  fi
done
set +e
got=$(node exporters/web/cut.mjs data/fixtures/scene_tetra.json --frame 0 --module "$module" --out "$work/refused.ply" 2>&1)
code=$?
set -e
if [ "$code" = 2 ] && [[ "$got" == *"only glTF meshes"* ]]; then echo "refused: an OBJ mesh: $got"
else echo "FAIL: scene_tetra.json: exit $code, '$got'"; fails=$((fails + 1)); fi
[ ! -e "$work/refused.ply" ] || { echo "FAIL: a refused cut left $work/refused.ply"; fails=$((fails + 1)); }
echo "wasm_cut: $fails failures"
[ "$fails" = 0 ]
