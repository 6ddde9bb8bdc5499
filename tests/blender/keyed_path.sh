#!/usr/bin/env bash
# ctest entry: a keyframed path authored in Blender (docs/MOTION.md "Keyframed paths"). make_keyed_scene.py
# keys a cube from (-2, 0, 0) at frame 0 to (2, 0, 0) at frame 100 at 10 fps (0.4 ls/s for 10 s,
# turning a quarter turn) and exports it with Blender's glTF exporter, animations on. apparent renders
# it with no warning; in the instant model (no light delay) the cube's vertex mean at frame k
# (t = k / 10 s) is the keyed centre, x = -2 + 0.4 t (before the first key: -2, after the last: 2),
# and the relativistic model renders every frame.
# Usage: keyed_path.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
apparent=$1
src=$2
blender="${BLENDER:-blender}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$blender" -b --factory-startup --python-exit-code 1 --python "$src/tests/blender/make_keyed_scene.py" -- \
  "$tmp/keyed.glb" > "$tmp/make.log" 2>&1 || { cat "$tmp/make.log"; exit 1; }
"$apparent" render "$tmp/keyed.glb" --model instant --format obj --out "$tmp/instant" --quiet 2> "$tmp/instant.err"
"$apparent" render "$tmp/keyed.glb" --out "$tmp/rel" --quiet 2> "$tmp/rel.err"
if [ -s "$tmp/instant.err" ] || [ -s "$tmp/rel.err" ]; then
  echo "keyed_path.sh: FAIL: warnings:" >&2; cat "$tmp/instant.err" "$tmp/rel.err" >&2; exit 1
fi
[ -f "$tmp/rel/relativistic.glb" ] || { echo "keyed_path.sh: FAIL: no relativistic.glb" >&2; exit 1; }
python3 - "$tmp/instant/instant" <<'PY'
import glob, os, sys
worst = 0.0
files = sorted(glob.glob(os.path.join(sys.argv[1], "frame_*.obj")))
assert len(files) == 200, len(files)  # the default frames: 0 .. 20 s at 10 fps
for path in files:
    k = int(path[-9:-4])
    t = k / 10
    v = [tuple(map(float, line.split()[1:4])) for line in open(path) if line.startswith("v ")]
    mean_x = sum(p[0] for p in v) / len(v)
    expected = -2 + 0.4 * min(max(t, 0), 10)
    worst = max(worst, abs(mean_x - expected))
print(f"keyed_path: {len(files)} frames, the cube's centre within {worst:.2e} ls of the keyed path")
sys.exit(0 if worst < 1e-5 else 1)
PY
