#!/usr/bin/env bash
# ctest entry: renders the default scene in every model, plain and with --compress meshopt (at the
# scene's tolerance, at a finer one, in vertex mode, and with --attributes doppler,proper_time
# --shade doppler), and the 20480-face icosphere (normals through the OCTAHEDRAL filter; in vertex
# mode its frames after the first are morph targets of the first's mesh), and
# decodes each meshopt file with the decoder three.js uses (npm meshoptimizer) against the plain
# one (tests/web/meshopt_roundtrip.js).
# Usage: run_meshopt_roundtrip.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
scene="$src/data/scenes/flanges.json"
# "attributes": the scene's tolerance with --attributes doppler,proper_time --shade doppler.
for tol in scene 0.002 vertex attributes; do
  args=()
  case "$tol" in
    scene) ;;
    attributes) args=(--attributes doppler,proper_time --shade doppler) ;;
    *) args=(--tolerance "$tol") ;;
  esac
  "$apparent" render "$scene" --out "$out/$tol-plain" --model all "${args[@]}" --quiet
  "$apparent" render "$scene" --out "$out/$tol-meshopt" --model all "${args[@]}" --compress meshopt --quiet
done
cd "$src"
for tol in scene 0.002 vertex attributes; do
  for m in instant finite relativistic contracted; do
    node tests/web/meshopt_roundtrip.js "$out/$tol-plain/$m.glb" "$out/$tol-meshopt/$m.glb"
  done
done
# The 20480-face icosphere: frames large enough that the normals get their own OCTAHEDRAL view
# (the flanges' small frames keep them in the vertex record), with and without the attributes.
sphere=data/scenes/trade/sphere20480.json
for extra in plain attributes; do
  args=(--model relativistic --frames 0:3)
  [ "$extra" = attributes ] && args+=(--attributes doppler,proper_time --shade doppler)
  "$apparent" render "$sphere" --out "$out/sphere-$extra-plain" "${args[@]}" --quiet
  "$apparent" render "$sphere" --out "$out/sphere-$extra-meshopt" "${args[@]}" --compress meshopt --quiet
  grep -q '"OCTAHEDRAL"' "$out/sphere-$extra-meshopt/relativistic.glb" || {
    echo "meshopt_roundtrip: $sphere: no OCTAHEDRAL view, the filter path is not exercised" >&2
    exit 1
  }
  # Frame coherence (exporters/gltf.h): in vertex mode the frames after the first are morph targets
  # of its mesh; with --attributes / --shade doppler every frame keeps its own vertex stream.
  if [ "$extra" = plain ]; then
    grep -q '"targets"' "$out/sphere-$extra-meshopt/relativistic.glb" || {
      echo "meshopt_roundtrip: $sphere: no morph targets, frame coherence is not exercised" >&2
      exit 1
    }
  fi
  node tests/web/meshopt_roundtrip.js "$out/sphere-$extra-plain/relativistic.glb" "$out/sphere-$extra-meshopt/relativistic.glb"
done
