#!/bin/bash
# Under `mpirun -n 3 apparent render` every rank must render the same thing.
# Rank 1 given another copy of the scene (one velocity changed), another --model, or another
# --tolerance: every rank stops before any frame, exit 2, one line naming rank 1 and what differs
# (scene, option), and nothing is written. The same three ranks agreeing render as before.
# Usage: mpi_agree_test.sh APPARENT SOURCE_DIR   (ctest sets OpenMPI's run-as-root variables for it)
set -u
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
apparent=$1
cd "$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
# Two copies of the default scene, each in a folder with the meshes (mesh paths "meshes/..."):
# the second with the first flange at 0.5c instead of 0.866c.
for copy in a b; do
    mkdir -p "$work/$copy"
    cp -r data/meshes "$work/$copy/meshes"
done
sed 's#"\.\./meshes/#"meshes/#' data/scenes/flanges.json > "$work/a/flanges.json"
sed 's/"velocity": \[0.866, 0, 0\]/"velocity": [0.5, 0, 0]/' "$work/a/flanges.json" > "$work/b/flanges.json"
cmp -s "$work/a/flanges.json" "$work/b/flanges.json" && fail "the second copy does not differ"
common=(--frames 0:12 --quiet)
# RANK1_SCENE RANK1_OPTIONS... ; EXPECTED text: rank 1 differs from ranks 0 and 2.
check() {
    local expected=$1 scene1=$2
    shift 2
    rm -rf "$work/out"
    timeout 300 mpirun --oversubscribe -n 1 "$apparent" render "$work/a/flanges.json" --out "$work/out" "${common[@]}" : \
        -n 1 "$apparent" render "$scene1" --out "$work/out" "${common[@]}" "$@" : \
        -n 1 "$apparent" render "$work/a/flanges.json" --out "$work/out" "${common[@]}" \
        > "$work/stdout.txt" 2> "$work/stderr.txt"
    local code=$?
    [ "$code" = 2 ] || fail "$expected: exit $code, not 2: $(cat "$work/stderr.txt")"
    # One line from apparent (mpirun adds its own report of the non-zero exit).
    [ "$(grep -c '^error: ' "$work/stderr.txt")" = 1 ] || fail "$expected: not one line: $(cat "$work/stderr.txt")"
    grep -q "^error: rank 1 $expected" "$work/stderr.txt" || fail "$expected: $(cat "$work/stderr.txt")"
    [ -z "$(ls -A "$work/out" 2> /dev/null)" ] || fail "$expected: written: $(ls -A "$work/out")"
    echo "refused: $(grep '^error: ' "$work/stderr.txt")"
}
check "read another scene than rank 0" "$work/b/flanges.json"
check "has another output option than rank 0: 'models finite'" "$work/a/flanges.json" --model finite
check "has another output option than rank 0: 'tolerance 0" "$work/a/flanges.json" --tolerance vertex
# Agreeing ranks: rendered as before.
rm -rf "$work/out"
timeout 300 mpirun --oversubscribe -n 3 "$apparent" render "$work/a/flanges.json" --out "$work/out" "${common[@]}" \
    2> "$work/stderr.txt" || fail "agreeing ranks: $(cat "$work/stderr.txt")"
[ -f "$work/out/relativistic.glb" ] || fail "agreeing ranks wrote no .glb"
if [ "$failures" = 0 ]; then echo "mpi_agree_test: all passed"; exit 0; fi
echo "mpi_agree_test: $failures failed"
exit 1
