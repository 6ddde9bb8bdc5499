#!/usr/bin/env bash
# Runs benchmarks/load_bench (loading against gltfpack on the same files, cut and PLY/OBJ export per
# frame, 1e3..1e6 triangles) and writes its section of docs/PERFORMANCE.md and docs/load.json.
# Needs gltfpack (scripts/setup.sh installs it). Usage: scripts/load_report.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
cmake --build "$build" --target load_bench -j "$(nproc)" >/dev/null
"$build/benchmarks/load_bench" --benchmark_format=json \
  --benchmark_out="$root/docs/load.json" --benchmark_out_format=json >/dev/null
python3 "$root/scripts/load_report.py" "$root/docs/load.json" "$root/docs/PERFORMANCE.md"
echo "wrote its section of docs/PERFORMANCE.md, docs/load.json"
