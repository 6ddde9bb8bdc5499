#!/usr/bin/env bash
# ctest entry: scripts/blender_import.py refuses a .glb whose scene extras it
# reads are bad ("fps" 0, null, negative, Infinity, a string, true; "frame_times" not a list; "light"
# not an object, an ambient outside [0, 1], neither or a zero direction, a position with a string,
# a key weight without its direction) with
# one line and exit status 1, as it documents, instead of a Python traceback after which Blender
# exits 0. The files are the default scene's .glb with only those extras changed.
# Usage: bad_extras.sh APPARENT_BINARY SOURCE_DIR
set -uo pipefail
apparent=$1
src=$2
blender="${BLENDER:-blender}"
command -v "$blender" >/dev/null 2>&1 || { echo "bad_extras.sh: SETUP ERROR: Blender not found" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$apparent" render "$src/data/scenes/flanges.json" --out "$tmp/out" --frames 0:4 --quiet || exit 2
# The .glb with scenes[0].extras[KEY] set to VALUE (JSON text), its JSON chunk re-padded.
alter() {
  python3 - "$tmp/out/relativistic.glb" "$1" "$2" "$3" <<'PY'
import json, struct, sys
src, key, value, dst = sys.argv[1:5]
data = open(src, 'rb').read()
length = struct.unpack('<I', data[12:16])[0]
doc = json.loads(data[20:20 + length])
doc['scenes'][doc.get('scene', 0)]['extras'][key] = json.loads(value)
text = json.dumps(doc).encode()
text += b' ' * (-len(text) % 4)
rest = data[20 + length:]
body = struct.pack('<II', len(text), 0x4E4F534A) + text + rest
open(dst, 'wb').write(b'glTF' + struct.pack('<II', 2, 12 + len(body)) + body)
PY
}
failed=0
check() {  # KEY VALUE: exit status 1 and one line naming the key
  local key=$1 value=$2 f="$tmp/bad.glb"
  alter "$key" "$value" "$f" || exit 2
  "$blender" -b --factory-startup --python "$src/scripts/blender_import.py" -- "$f" >"$tmp/out.log" 2>"$tmp/err.log"
  local rc=$?
  local lines
  lines=$(grep -c '' "$tmp/err.log")
  if [ "$rc" = 1 ] && grep -q "^blender_import: .*scene extras \"$key\"" "$tmp/err.log" && [ "$lines" = 1 ] &&
     ! grep -q Traceback "$tmp/out.log" "$tmp/err.log"; then
    echo "bad_extras.sh: ok: $key = $value: $(cat "$tmp/err.log")"
  else
    echo "bad_extras.sh: FAIL: $key = $value: exit $rc, stderr:" >&2
    cat "$tmp/err.log" >&2
    failed=1
  fi
}
for v in 0 null -24 Infinity '"24"' true; do check fps "$v"; done
check frame_times 3
for v in 5 '{"ambient": 2, "direction": [0, 1, 0]}' '{"ambient": 0.2}' '{"direction": [0, 0, 0]}' \
         '{"position": [0, "a", 0]}' '{"direction": [0, 1, 0], "key_weight": 0.7}'; do
  check light "$v"
done
# The unaltered file still imports (exit 0).
"$blender" -b --factory-startup --python "$src/scripts/blender_import.py" -- "$tmp/out/relativistic.glb" \
  >"$tmp/out.log" 2>&1 || { echo "bad_extras.sh: FAIL: the unaltered file did not import" >&2; cat "$tmp/out.log" >&2; failed=1; }
[ "$failed" = 0 ] && echo "bad_extras.sh: all refused with one line and exit 1"
exit "$failed"
