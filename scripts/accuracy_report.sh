#!/usr/bin/env bash
# Runs benchmarks/accuracy_bench (Google Benchmark) and writes docs/ACCURACY.md, docs/accuracy.json
# and docs/accuracy.png (gnuplot: measured error against time per frame).
# Usage: scripts/accuracy_report.sh [BUILD_DIR]      needs: python3, gnuplot (apt gnuplot-nox)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
command -v gnuplot >/dev/null || { echo "needs gnuplot (apt-get install gnuplot-nox)" >&2; exit 2; }
cmake --build "$build" --target accuracy_bench -j "$(nproc)" >/dev/null
"$build/benchmarks/accuracy_bench" --benchmark_min_time=0.5 --benchmark_format=json \
  --benchmark_out="$root/docs/accuracy.json" --benchmark_out_format=json >/dev/null
python3 "$root/scripts/accuracy_report.py" "$root/docs/accuracy.json" "$root/docs"
gnuplot "$root/docs/accuracy.gp"
echo "wrote docs/ACCURACY.md, docs/accuracy.json, docs/accuracy.png"
