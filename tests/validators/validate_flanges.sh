#!/usr/bin/env bash
# Renders the default flange scene in every model and checks each .glb with the Khronos
# glTF-Validator. Usage: validate_flanges.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$apparent" render "$src/data/scenes/flanges.json" --out "$out" --model all --quiet
cd "$src"
node tests/validators/validate_gltf.js "$out"/*.glb
