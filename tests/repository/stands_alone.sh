#!/usr/bin/env bash
# The repository stands on its own (CONTRIBUTING.md "Conventions"): no tracked file outside docs/ may
# refer to the folder beside the checkout that held shared notes and data during development, nor
# to the development machine's absolute work folders. docs/ may tell that history. Run from ctest (tests/CMakeLists.txt) with the source folder.
# The searched text is assembled from two parts, so that this file does not match itself.
set -euo pipefail
src=${1:?usage: stands_alone.sh SOURCE_DIR}
cd "$src"
needles=('..''/shared' '/wo''rk/')
if ! git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  echo "error: $src is not a git checkout (the check reads the tracked files)" >&2
  exit 1
fi
# Tracked files outside docs/, as they are in the working tree (deleted ones skipped).
status=0
for needle in "${needles[@]}"; do
  hits=$(git ls-files -z -- . ':!:docs/**' | xargs -0 -r grep -n -F -I -e "$needle" -- 2>/dev/null || true)
  if [ -n "$hits" ]; then
    echo "error: tracked files outside docs/ refer to '$needle' (copy what they need into the repository):" >&2
    echo "$hits" >&2
    status=1
  else
    echo "ok: no tracked file outside docs/ refers to '$needle'"
  fi
done
exit $status
