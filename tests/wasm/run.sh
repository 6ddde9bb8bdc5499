#!/usr/bin/env bash
# mesh4d/ compiled to WebAssembly with Emscripten (Debian's emscripten: em++, scripts/build_web.sh's
# objects and flags), from the same sources as the native library, and tests/wasm/parity.cpp run by
# both: the WebAssembly build's cuts are compared with the native ones (docs/DESIGN.md section 14).
# The comparison:
# the same vertex and triangle counts and triangles in every cut, and every number within 1e-12
# relative of the native one; how many are bit for bit the same is printed.
# Usage: run.sh NATIVE_PARITY SOURCE_DIR WORK_DIR   (exit 77: em++ is not installed, the test skips)
set -euo pipefail
native=$1
src=$2
work=$3
command -v em++ > /dev/null || { echo "wasm: em++ not found (scripts/setup.sh installs Debian's emscripten)"; exit 77; }
# Step: the module's objects (scripts/build_web.sh, the same flags), then this program against mesh4d's.
mkdir -p "$work"
bash "$src/scripts/build_web.sh" "$work" > "$work/build.log" 2>&1 || { tail -20 "$work/build.log"; exit 1; }
export NODE_PATH=/usr/share/nodejs${NODE_PATH:+:$NODE_PATH}
mapfile -t flags < "$work/flags.txt"
em++ "${flags[@]}" -c "$src/tests/wasm/parity.cpp" -o "$work/parity.o"
# Node 18 and later have fetch(), which this Emscripten's loader would use for a file path: the
# module is one file, its WebAssembly inside (SINGLE_FILE).
em++ -O2 -fwasm-exceptions "$work"/obj/mesh4d_*.o "$work/parity.o" -o "$work/parity.js" -sENVIRONMENT=node -sSINGLE_FILE=1 \
  -sALLOW_MEMORY_GROWTH=1
"$native" > "$work/native.txt"
node "$work/parity.js" > "$work/wasm.txt"
python3 - "$work/native.txt" "$work/wasm.txt" <<'PY'
import sys
a, b = (open(p).read().splitlines() for p in sys.argv[1:3])
fails, same, numbers, worst = [], 0, 0, 0.0
if len(a) != len(b):
    fails.append("%d lines native, %d WebAssembly" % (len(a), len(b)))
for i, (x, y) in enumerate(zip(a, b)):
    if not x.startswith("v "):
        if x != y:
            fails.append("line %d: %r against %r" % (i + 1, x, y))
        continue
    xs, ys = x.split()[1:], y.split()[1:]
    if len(xs) != len(ys):
        fails.append("line %d: %d numbers against %d" % (i + 1, len(xs), len(ys)))
        continue
    for p, q in zip(xs, ys):
        u, v = float.fromhex(p), float.fromhex(q)
        numbers += 1
        same += p == q
        worst = max(worst, abs(u - v) / max(1.0, abs(u)))
        if abs(u - v) > 1e-12 * max(1.0, abs(u)):
            fails.append("line %d: %r against %r" % (i + 1, u, v))
cuts = sum(1 for x in a if x.startswith("=="))
print("wasm: %d cuts, %d numbers, %d bit for bit the same as native, the largest difference %.3g relative"
      % (cuts, numbers, same, worst))
for f in fails[:5]:
    print("FAIL", f)
sys.exit(1 if fails or numbers == 0 else 0)
PY
