#!/usr/bin/env bash
# Imports apparent's animated .glb files into headless Blender and checks objects, animation and visibility over
# time (tests/blender/check_glb.py has the list of checks).
#
#   tests/blender/run.sh [--draco-library PATH] [--scene-fps N] [--frames 0,50,100,199] FILE.glb [FILE.glb ...]
#
# --draco-library PATH  the Draco library for Blender that the build makes (default build/blender/libextern_draco.so,
#               CMakeLists.txt target blender_draco; Debian's blender ships the glTF importer without it, so a
#               KHR_draco_mesh_compression file FAILS to import when it is missing).
# BLENDER=PATH  the blender binary (default: blender on PATH).
#
# Needs: apt-get install -y --no-install-recommends blender python3-numpy
# (Debian's blender package does not pull in numpy, which its glTF importer imports.)
# Exit status: 0 all checks passed, 1 a check failed (or Blender did not finish), 2 setup or usage problem.
set -uo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
blender="${BLENDER:-blender}"
args=()
files=()
usage() {
  echo "usage: tests/blender/run.sh [--draco-library PATH] [--scene-fps N] [--frames K,K,...] FILE.glb [FILE.glb ...]" >&2
  exit 2
}
while [ $# -gt 0 ]; do
  case "$1" in
    --draco-library|--scene-fps|--frames) [ $# -ge 2 ] || usage; args+=("$1" "$2"); shift 2 ;;
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
