#!/usr/bin/env bash
# Whether two builds write the same bytes for every shipped scene (scripts/output_hashes.sh).
#   scripts/compare_builds.sh BUILD_A/apparent BUILD_B/apparent [quick]
# Exit 0 when every output file (and every exit code) is identical, 1 with the differing files
# listed otherwise. Used before and after each reshaping commit, and by CI for the
# APPARENT_NO_LANES=ON build against the default one.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 APPARENT_A APPARENT_B [quick]" >&2; exit 2; }
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
bash "$here/output_hashes.sh" "$1" "$work/a" ${3:-} > "$work/a.md5"
bash "$here/output_hashes.sh" "$2" "$work/b" ${3:-} > "$work/b.md5"
n=$(wc -l < "$work/a.md5")
if diff "$work/a.md5" "$work/b.md5" > "$work/diff"; then
  echo "compare_builds: $n output files identical"
else
  echo "compare_builds: outputs differ:"
  cat "$work/diff"
  exit 1
fi
