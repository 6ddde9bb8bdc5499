#!/usr/bin/env bash
# Fuzzes every input reader (docs/HOSTILE_INPUT.md): builds the libFuzzer harnesses of tests/fuzz
# with clang (-fsanitize=fuzzer,address,undefined) in build-fuzz, writes the seed corpora
# (tests/fuzz/make_corpus.py: data/, tests/data/gltf-samples, assimp-testmodels) and runs each
# target for a fixed number of inputs with a fixed seed. Exits non-zero on any crash, leak,
# timeout or out-of-memory; the reproducer is left in build-fuzz/fuzz-artifacts/<target>/.
#   scripts/fuzz.sh                 the CI step: every target, FUZZ_RUNS inputs each
#   scripts/fuzz.sh ply glb         some targets only
# Environment: FUZZ_RUNS (inputs per target, default per target below), FUZZ_SEED (default 1),
# BUILD_DIR (default build-fuzz), JOBS (default 2).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
build=${BUILD_DIR:-build-fuzz}
jobs=${JOBS:-2}
seed=${FUZZ_SEED:-1}
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scene obj ply gltf glb shard)
# Inputs per target: sized so that build plus all runs take about 6 minutes on 2 cores (the glTF
# harnesses run about 5 times slower than the others: tinygltf and Draco per input).
declare -A runs=([scene]=300000 [obj]=200000 [ply]=300000 [gltf]=50000 [glb]=60000 [shard]=200000)
# The JSON readers take inputs up to 1 MiB (deep nesting needs room: 100 000 levels are 200 KB)
# with a dictionary of nesting tokens; the mesh text formats up to 64 KiB.
declare -A max_len=([scene]=1048576 [obj]=65536 [ply]=65536 [gltf]=1048576 [glb]=1048576 [shard]=65536)
declare -A dict=([scene]=json_nesting.dict [gltf]=json_nesting.dict [glb]=json_nesting.dict)

# Debian 12's clang-14 (the package installs clang++-14; the `clang` package adds the clang++ link).
cxx=$(command -v clang++-14 || command -v clang++ || true)
[ -n "$cxx" ] || { echo "fuzz.sh: needs clang and libFuzzer (apt-get install clang-14 libclang-rt-14-dev)" >&2; exit 2; }
echo "== building the fuzz harnesses in $build ($cxx, libFuzzer + ASan + UBSan)"
# A build folder configured with another compiler or without APPARENT_FUZZ starts afresh.
if [ -f "$build/CMakeCache.txt" ] && ! { grep -q "^CMAKE_CXX_COMPILER:[A-Z]*=$cxx\$" "$build/CMakeCache.txt" &&
     grep -q "^APPARENT_FUZZ:BOOL=ON\$" "$build/CMakeCache.txt"; }; then
  rm -rf "$build"
fi
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAPPARENT_FUZZ=ON -DCMAKE_CXX_COMPILER="$cxx" >/dev/null
cmake --build "$build" -j "$jobs" --target $(printf 'fuzz_%s ' "${targets[@]}") >/dev/null

rm -rf "$build/fuzz-seeds" "$build/fuzz-work"
python3 tests/fuzz/make_corpus.py "$build/fuzz-seeds" 65536
# Shards: the committed shards of the tetra fixture (plain, Draco, meshopt with attributes) and of
# tests/looks' textured box (meshopt: a look with materials, an image and TEXCOORD_1).
mkdir -p "$build/fuzz-seeds/shard"
cp tests/fuzz/shard_seeds/*.shard "$build/fuzz-seeds/shard/"

status=0
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
for t in "${targets[@]}"; do
  n=${FUZZ_RUNS:-${runs[$t]}}
  mkdir -p "$build/fuzz-work/$t" "$build/fuzz-artifacts/$t"
  log="$build/fuzz-$t.log"
  start=$(date +%s)
  # -max_len: see max_len above; -timeout: one input may take 10 s; -rss_limit_mb and
  # -malloc_limit_mb: a reader that allocates what a header asks for is reported as a bug.
  dict_arg=()
  [ -z "${dict[$t]:-}" ] || dict_arg=(-dict="tests/fuzz/${dict[$t]}")
  if "$build/tests/fuzz/fuzz_$t" -runs="$n" -seed="$seed" -max_len="${max_len[$t]}" "${dict_arg[@]}" -timeout=10 -rss_limit_mb=2048 \
       -malloc_limit_mb=1024 -print_final_stats=1 -artifact_prefix="$build/fuzz-artifacts/$t/" \
       "$build/fuzz-work/$t" "$build/fuzz-seeds/$t" >"$log" 2>&1; then
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
    echo "fuzz_$t: $execs inputs in $(( $(date +%s) - start )) s, no crash, leak or timeout"
  else
    status=1
    echo "fuzz_$t: FAILED after $(( $(date +%s) - start )) s; reproducer in $build/fuzz-artifacts/$t/, log $log:"
    grep -E "ERROR|SUMMARY|runtime error" "$log" | head -5
  fi
done
exit $status
