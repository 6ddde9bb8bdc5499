#!/usr/bin/env bash
# The WebAssembly module (exporters/web/module.cpp; docs/WEB.md "The cut in WebAssembly"): mesh4d,
# the scene and glTF readers, the stage and the PLY writer compiled with Emscripten (Debian's
# emscripten: em++) from the same sources as the native program, into one file,
# BUILD/apparent_web.js (its WebAssembly inside), which exporters/web/cut.mjs loads under node.
# The build: no TBB (APPARENT_NO_TBB: serial loops), the scalar forms (APPARENT_NO_LANES), glTF
# meshes only (APPARENT_NO_OPENMESH, APPARENT_NO_DRACO: Debian has no WebAssembly build of
# OpenMesh or Draco), CGAL's exact numbers from Boost.Multiprecision (CGAL_DISABLE_GMP), and
# -ffp-contract=off as the native library.
# Usage: scripts/build_web.sh [BUILD]   (default build/web; objects newer than their source are kept)
set -euo pipefail
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
work=${1:-$src/build/web}
command -v em++ > /dev/null || { echo "build_web: em++ not found (scripts/setup.sh test installs Debian's emscripten)" >&2; exit 77; }
mkdir -p "$work/obj" "$work/include"
# The libraries' headers alone: the rest of /usr/include is the host's C library.
for h in CGAL boost nlohmann tiny_gltf.h eigen3; do ln -sfn "/usr/include/$h" "$work/include/$h"; done
# Debian's emscripten 3.1.6 finds its JavaScript optimizer's parser (node-acorn) here.
export NODE_PATH=/usr/share/nodejs${NODE_PATH:+:$NODE_PATH}
flags=(-std=c++17 -O2 -fno-math-errno -ffp-contract=off -fwasm-exceptions -DAPPARENT_NO_LANES=1 -DAPPARENT_NO_TBB=1
       -DAPPARENT_NO_OPENMESH=1 -DAPPARENT_NO_DRACO=1 -DCGAL_DISABLE_GMP=1 -DCGAL_ALWAYS_ROUND_TO_NEAREST=1
       -DTINYGLTF_NO_STB_IMAGE=1 -DTINYGLTF_NO_STB_IMAGE_WRITE=1 -I "$src" -isystem "$work/include"
       -isystem "$work/include/eigen3")
# The flags, for the tests that link their own programs against these objects (tests/wasm/run.sh).
printf '%s\n' "${flags[@]}" > "$work/flags.txt"
sources=($(cd "$src" && find mesh4d pipeline/stage -name '*.cpp' | sort)
         pipeline/input/{scene,scene_fields,gltf_scene,gltf_reader,gltf_document,gltf_animation,gltf_look,gltf_nodes}.cpp
         pipeline/input/{json_limits,mesh_check,mesh_input,input_file,units}.cpp
         exporters/{ply,frame_files,atomic_file,surface_look,frame_spill,tinygltf_impl}.cpp exporters/web/module.cpp)
# Step: every source, two at a time (an object newer than its source, than every header of the
# repository and than this script is kept).
newest_header=$(cd "$src" && ls -t $(find mesh4d pipeline exporters -name '*.h') scripts/build_web.sh | head -1)
for f in "${sources[@]}"; do
  o="$work/obj/$(echo "$f" | tr / _).o"
  [ "$o" -nt "$src/$f" ] && [ "$o" -nt "$src/$newest_header" ] && continue
  em++ "${flags[@]}" -c "$src/$f" -o "$o" &
  if [ "$(jobs -rp | wc -l)" -ge 2 ]; then wait -n; fi
done
while [ "$(jobs -rp | wc -l)" -gt 0 ]; do wait -n; done
# Step: one file, the WebAssembly inside (SINGLE_FILE), a factory function (MODULARIZE) for node
# and the browser, the module's own in-memory file system for the scene file (and Node.js's file
# system mountable in it, for exporters/web/cut.mjs).
objects=()
for f in "${sources[@]}"; do objects+=("$work/obj/$(echo "$f" | tr / _).o"); done
em++ -O2 -fwasm-exceptions --bind "${objects[@]}" -o "$work/apparent_web.js" -sSINGLE_FILE=1 -sMODULARIZE=1 \
  -sEXPORT_NAME=createApparent -sALLOW_MEMORY_GROWTH=1 -sEXPORTED_RUNTIME_METHODS=FS,NODEFS -lnodefs.js -sENVIRONMENT=web,node
echo "build_web: $work/apparent_web.js ($(stat -c %s "$work/apparent_web.js") bytes)"
