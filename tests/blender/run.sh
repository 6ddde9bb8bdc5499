#!/usr/bin/env bash
# Imports apparent's animated .glb files into headless Blender and checks objects, animation and visibility over
# time (tests/blender/check_glb.py has the list of checks).
#
#   tests/blender/run.sh [--draco-shim] [--scene-fps N] [--frames 0,50,100,199] FILE.glb [FILE.glb ...]
#
# --draco-shim  Debian's blender ships the glTF importer without Blender's Draco library (libextern_draco.so), so
#               a KHR_draco_mesh_compression file FAILS to import there. With this flag the script builds a
#               stand-in (tests/blender/extern_draco_shim.cpp, on Debian's libdraco; needs g++ and libdraco-dev)
#               into a temporary directory and gives it to the importer via BLENDER_EXTERN_DRACO_LIBRARY_PATH.
#               Ignored when BLENDER_EXTERN_DRACO_LIBRARY_PATH is already set.
# BLENDER=PATH  the blender binary (default: blender on PATH).
#
# Needs: apt-get install -y --no-install-recommends blender python3-numpy
# (Debian's blender package does not pull in numpy, which its glTF importer imports.)
# Exit status: 0 all checks passed, 1 a check failed (or Blender did not finish), 2 setup or usage problem.
set -uo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
blender="${BLENDER:-blender}"
shim=0
args=()
files=()
usage() {
  echo "usage: tests/blender/run.sh [--draco-shim] [--scene-fps N] [--frames K,K,...] FILE.glb [FILE.glb ...]" >&2
  exit 2
}
while [ $# -gt 0 ]; do
  case "$1" in
    --draco-shim) shim=1; shift ;;
    --scene-fps|--frames) [ $# -ge 2 ] || usage; args+=("$1" "$2"); shift 2 ;;
    -h|--help) usage ;;
    -*) echo "run.sh: unknown option $1" >&2; usage ;;
    *) files+=("$1"); shift ;;
  esac
done
[ ${#files[@]} -gt 0 ] || usage
for f in "${files[@]}"; do
  if [ ! -f "$f" ]; then
    echo "run.sh: SETUP ERROR: $f does not exist (make one with: build/apparent render data/scenes/flanges.json" \
         "--out DIR --model instant,finite,relativistic [--draco])" >&2
    exit 2
  fi
done

if ! command -v "$blender" >/dev/null 2>&1; then
  echo "run.sh: SETUP ERROR: Blender not found ('$blender'). Install Debian's: " \
       "apt-get install -y --no-install-recommends blender python3-numpy   (or set BLENDER=/path/to/blender)" >&2
  exit 2
fi

tmp="$(mktemp -d "${TMPDIR:-/tmp}/apparent-blender-XXXXXX")"
trap 'rm -rf "$tmp"' EXIT

if [ "$shim" = 1 ] && [ -z "${BLENDER_EXTERN_DRACO_LIBRARY_PATH:-}" ]; then
  cxx="${CXX:-g++}"
  if ! command -v "$cxx" >/dev/null 2>&1 || [ ! -f /usr/include/draco/compression/decode.h ]; then
    echo "run.sh: SETUP ERROR: --draco-shim needs a C++ compiler ($cxx) and Debian's libdraco-dev" \
         "(apt-get install -y g++ libdraco-dev)" >&2
    exit 2
  fi
  if ! "$cxx" -std=c++17 -O2 -shared -fPIC "$here/extern_draco_shim.cpp" -o "$tmp/libextern_draco.so" -ldraco \
       >"$tmp/shim.log" 2>&1; then
    cat "$tmp/shim.log" >&2
    echo "run.sh: SETUP ERROR: building the Draco stand-in failed" >&2
    exit 2
  fi
  export BLENDER_EXTERN_DRACO_LIBRARY_PATH="$tmp/libextern_draco.so"
  echo "run.sh: Draco: using the stand-in $BLENDER_EXTERN_DRACO_LIBRARY_PATH (Debian's libdraco), not Blender's own library"
fi

"$blender" -b --factory-startup --python-exit-code 1 --python "$here/check_glb.py" -- "${files[@]}" \
  ${args[@]+"${args[@]}"} 2>&1 | grep -v 'INFO: Draco Decoder: Decode primitive' | tee "$tmp/out.log"
rc=${PIPESTATUS[0]}
# check_glb.py ends Blender with its own status; a Blender that ended otherwise (crash, script not run) has not
# printed the summary line
if [ "$rc" != 2 ] && ! grep -Eq '^check_glb: [0-9]+ passed, [0-9]+ failed$' "$tmp/out.log"; then
  echo "run.sh: FAIL: Blender exited with status $rc without the check summary" >&2
  exit 1
fi
exit "$rc"
