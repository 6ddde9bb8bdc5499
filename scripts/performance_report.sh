#!/usr/bin/env bash
# Runs benchmarks/performance_bench (Google Benchmark) and the peak-memory runs of `apparent render`,
# then writes docs/PERFORMANCE.md and docs/performance.json. Run it on an otherwise idle machine.
# Usage: scripts/performance_report.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
cmake --build "$build" --target performance_bench apparent -j "$(nproc)" >/dev/null
"$build/benchmarks/performance_bench" --benchmark_format=json \
  --benchmark_out="$root/docs/performance.json" --benchmark_out_format=json >/dev/null
python3 "$root/scripts/performance_report.py" "$root/docs/performance.json" "$build/apparent" "$root/docs/PERFORMANCE.md"
"$root/scripts/load_report.sh" "$build"  # its own section, appended to the file just written
echo "wrote docs/PERFORMANCE.md, docs/performance.json"
