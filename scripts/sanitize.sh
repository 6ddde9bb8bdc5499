#!/usr/bin/env bash
# The whole GoogleTest suite and the kill test under AddressSanitizer (with LeakSanitizer) and
# UndefinedBehaviorSanitizer, g++ (CONTRIBUTING.md "Tests, fuzzing and sanitizers"): a Debug build with -DAPPARENT_SANITIZE=ON
# in build-asan, then ctest without the third-party viewers (Chromium, MeshLab, Blender and the
# glTF-Validator check outputs, not our memory safety) and without the WebAssembly comparisons
# (their module is Emscripten's build, which these sanitizers do not instrument; they run in the
# plain suite). Any sanitizer report fails its test.
# Environment: BUILD_DIR (default build-asan), JOBS (default 2).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
build=${BUILD_DIR:-build-asan}
jobs=${JOBS:-2}
start=$(date +%s)
echo "== building in $build (Debug, ASan + UBSan)"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DAPPARENT_SANITIZE=ON -DAPPARENT_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target apparent_tests apparent >/dev/null
built=$(date +%s)
echo "== running the test suite under the sanitizers"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
cd "$build"
ctest --output-on-failure -j "$jobs" -E '^(gltf_validator_flanges|threejs_viewer_chromium|meshlab_ply|blender_import|model_viewer_chromium|wasm_parity|wasm_cut)$'
echo "sanitize.sh: build $(( built - start )) s, tests $(( $(date +%s) - built )) s"
