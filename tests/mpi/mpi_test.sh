#!/bin/bash
# `mpirun -n 3 apparent render` (pipeline/run/mpi_group.h): every output byte-identical to one process
# (the default scene and a mirrored, clipped one; .glb plain, Draco and meshopt, its frames by
# reference, diff -r also finding any scratch file left; meshopt with attributes; PLY; OBJ, also
# without a .glb, each rank writing its own frames' files;
# raytrace's PNG files and video; figure's sheet and video), a
# failure on any rank ends the job with the one-process code and one line from rank 0 and no
# output, and a rank killed with SIGKILL mid-run ends the job non-zero with no truncated file and
# no temporary (also at a model switch and with 20 ranks: 20 ranks give the one-process bytes too).
# Usage: mpi_test.sh APPARENT SOURCE_DIR   (ctest sets OpenMPI's run-as-root variables for it)
set -u
# Under scripts/sanitize.sh: AddressSanitizer's checks stay on in every rank, its leak report off
# (OpenMPI keeps allocations to its exit that LeakSanitizer reports as leaks).
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
apparent=$1
cd "$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
mpi() { timeout 300 mpirun --oversubscribe -n 3 "$apparent" "$@"; }

# Step: byte-identical outputs.
for scene in data/scenes/flanges.json data/fixtures/scene_mirror_exists.json; do
    for options in "--format glb,ply,obj" "--compress draco --frames 40:160" "--compress meshopt --frames 40:160" \
                   "--compress meshopt --attributes doppler,proper_time --frames 40:160" "--format ply,obj --frames 40:160" \
                   "--tolerance vertex --compress meshopt --model relativistic,finite"; do
        rm -rf "$work/one" "$work/three"
        "$apparent" render "$scene" --out "$work/one" --quiet $options || fail "one process: $scene $options"
        # The summary alone (stdout): mpirun forwards stdout and stderr apart, so a warning may
        # interleave with it in one stream.
        out=$(mpi render "$scene" --out "$work/three" $options 2> "$work/stderr.txt") ||
            fail "mpirun: $scene $options: $out $(cat "$work/stderr.txt")"
        diff -r "$work/one" "$work/three" > /dev/null || fail "outputs differ: $scene $options"
        # The .glb's frames went by reference (the ranks share the folder: no fallback warning).
        ! grep -q "goes through rank 0 instead" "$work/stderr.txt" || fail "frames not by reference: $(cat "$work/stderr.txt")"
        case "$out" in *"3 processes shared the frames"*) ;; *) fail "summary without the process count: $out" ;; esac
        [ "$(echo "$out" | grep -c '^relativistic: ')" = 1 ] || fail "not one summary line (rank 0 alone): $out"
    done
done
# render --verbose states rank 0's work on the frames it did not cut: of frames 40:80 with 3 ranks,
# rank 0 cuts 40, 43, ..., 79 (14 frames) and receives the other 26.
rm -rf "$work/three"
out=$(mpi render data/scenes/flanges.json --out "$work/three" --format ply --frames 40:80 --verbose 2> /dev/null) ||
    fail "mpirun --verbose: $out"
echo "$out" | grep -Eq '^relativistic: loop .*; of the writing, the frames of other ranks [0-9]+ us each \(CPU [0-9]+ us; 26 frames\)$' ||
    fail "render --verbose without rank 0's work on the 26 frames of other ranks: $out"
# From 10 processes meshopt frames that may be morph targets travel by reference too (each rank
# cuts the frame before its own again: pipeline/run/distribute.cpp); below, whole. The same bytes.
for scene in data/scenes/flanges.json data/fixtures/scene_mirror_exists.json; do
    rm -rf "$work/one" "$work/ten"
    "$apparent" render "$scene" --out "$work/one" --quiet --compress meshopt --frames 60:100 || fail "one process: $scene meshopt"
    timeout 300 mpirun --oversubscribe -n 10 "$apparent" render "$scene" --out "$work/ten" --quiet --threads 1 \
        --compress meshopt --frames 60:100 2> "$work/stderr.txt" || fail "mpirun -n 10: $scene $(cat "$work/stderr.txt")"
    diff -r "$work/one" "$work/ten" > /dev/null || fail "outputs differ with 10 processes: $scene meshopt"
done
# A folder rank 0 cannot see from the other ranks (ranks 1 and 2 in a mount namespace of their own
# with a tmpfs over it): one warning, the .glb's frames travel whole, the same bytes.
if unshare -m true 2> /dev/null; then
    rm -rf "$work/one" "$work/apart"
    mkdir -p "$work/apart"
    common=(render data/scenes/flanges.json --frames 40:80 --format glb,ply)
    "$apparent" "${common[@]}" --out "$work/one" --quiet || fail "one process: ${common[*]}"
    printf '#!/bin/sh\nexec unshare -m sh -c '"'"'mount -t tmpfs none "$0" && exec "$@"'"'"' "$@"\n' > "$work/apart.sh"
    chmod +x "$work/apart.sh"
    timeout 300 mpirun --oversubscribe -n 1 "$apparent" "${common[@]}" --out "$work/apart" : \
        -n 2 "$work/apart.sh" "$work/apart" "$apparent" "${common[@]}" --out "$work/apart" > /dev/null 2> "$work/stderr.txt" ||
        fail "mpirun, folder not shared: $(cat "$work/stderr.txt")"
    diff -r "$work/one" "$work/apart" > /dev/null || fail "outputs differ: folder not shared"
    grep -q "is not visible on rank 0.*goes through rank 0 instead" "$work/stderr.txt" ||
        fail "no warning for a folder not shared: $(cat "$work/stderr.txt")"
else
    echo "folder not shared: skipped (unshare -m not permitted here)"
fi

# raytrace splits its frames the same way: the PNG files and the video identical.
"$apparent" raytrace data/scenes/flanges.json --out "$work/rt1" --frames 90:100 --size 160x90 --video "$work/rt1.mp4" \
    --quiet || fail "raytrace, one process"
out=$(mpi raytrace data/scenes/flanges.json --out "$work/rt3" --frames 90:100 --size 160x90 --video "$work/rt3.mp4" \
    2> "$work/stderr.txt") || fail "raytrace under mpirun: $out $(cat "$work/stderr.txt")"
diff -r "$work/rt1" "$work/rt3" > /dev/null || fail "raytrace PNG files differ"
cmp -s "$work/rt1.mp4" "$work/rt3.mp4" || fail "raytrace videos differ"
case "$out" in *"3 processes shared the frames"*) ;; *) fail "raytrace summary without the process count: $out" ;; esac
# figure too: its panels (7 of them: ranks own unequal shares) and its video's frames.
"$apparent" figure data/scenes/flanges.json --out "$work/fig1.png" --columns 7 --models relativistic --size 96x54 \
    --title "Flanges" --quiet || fail "figure, one process"
out=$(mpi figure data/scenes/flanges.json --out "$work/fig3.png" --columns 7 --models relativistic --size 96x54 \
    --title "Flanges" 2> "$work/stderr.txt") || fail "figure under mpirun: $out $(cat "$work/stderr.txt")"
cmp -s "$work/fig1.png" "$work/fig3.png" || fail "figure sheets differ"
case "$out" in *"3 processes shared the frames"*) ;; *) fail "figure summary without the process count: $out" ;; esac
"$apparent" figure data/scenes/flanges.json --video "$work/fig1.mp4" --frames 90:98 --models instant,relativistic \
    --size 96x54 --quiet || fail "figure --video, one process"
out=$(mpi figure data/scenes/flanges.json --video "$work/fig3.mp4" --frames 90:98 --models instant,relativistic \
    --size 96x54 2> "$work/stderr.txt") || fail "figure --video under mpirun: $out $(cat "$work/stderr.txt")"
cmp -s "$work/fig1.mp4" "$work/fig3.mp4" || fail "figure videos differ"
case "$out" in *"3 processes shared the frames"*) ;; *) fail "figure --video summary without the process count: $out" ;; esac

# --quiet silences every rank.
out=$(mpi render data/scenes/flanges.json --out "$work/quiet" --frames 0:20 --quiet 2>&1)
[ -z "$out" ] || fail "--quiet under mpirun printed: $out"

# Step: failures end the job with the one-process code and line, and write nothing.
expect_failure() {  # CODE OUTDIR ARGS...: the code, our line exactly once, no output folder
    local code=$1 dir=$2
    shift 2
    "$apparent" "$@" --out "$dir.one" > "$work/one.txt" 2>&1
    local one=$?
    mpi "$@" --out "$dir" > /dev/null 2> "$work/mpi.txt"
    local got=$?
    local line
    line=$(grep '^error: ' "$work/one.txt")
    [ "$one" = "$code" ] || fail "one process gave $one, not $code: $*"
    [ "$got" = "$code" ] || fail "mpirun gave $got, not $code: $* ($(cat "$work/mpi.txt"))"
    [ "$(grep -cxF -- "$line" "$work/mpi.txt")" = 1 ] || fail "not the one-process line once: $* ($(cat "$work/mpi.txt"))"
    [ "$(grep -c '^error: ' "$work/mpi.txt")" = 1 ] || fail "more than one error line: $*"
    [ ! -e "$dir" ] || fail "$dir left behind: $*"
}
expect_failure 2 "$work/e1" render data/scenes/flanges.json --max-triangles 100
expect_failure 2 "$work/e2" render data/fixtures/scene_mirror_not_planar.json
expect_failure 3 "$work/e3" render data/scenes/flanges.json --format ply,glb --max-output-bytes 100000
expect_failure 2 "$work/e4" raytrace data/scenes/flanges.json --model all --video "$work/e4.mp4"
expect_failure 2 "$work/e5" figure data/scenes/flanges.json --times 1000
# figure: rank 0 fails to write the sheet after every rank sent its panels: the one-process code and line.
touch "$work/blocker"
"$apparent" figure data/scenes/flanges.json --columns 4 --size 32x18 --out "$work/blocker/sheet.png" > "$work/one.txt" 2>&1
one=$?
mpi figure data/scenes/flanges.json --columns 4 --size 32x18 --out "$work/blocker/sheet.png" > /dev/null 2> "$work/mpi.txt"
got=$?
[ "$one" = 3 ] && [ "$got" = 3 ] || fail "figure write failure: one process $one, mpirun $got (3 expected)"
[ "$(grep -cxF -- "$(grep '^error: ' "$work/one.txt")" "$work/mpi.txt")" = 1 ] && [ "$(grep -c '^error: ' "$work/mpi.txt")" = 1 ] ||
    fail "figure write failure: not the one-process line once ($(cat "$work/mpi.txt"))"

# A write failing on ranks 1 and 2 alone (a file size limit there; PLY frames, which each rank
# writes itself): the job ends with code 3 and one line naming the file of frame 1, the first
# frame of rank 1, as one process with that limit names its frame 0's; frame 0 (rank 0's) is
# complete, nothing else is left (no temporary file).
printf '#!/bin/sh\nulimit -f 64\nexec "$@"\n' > "$work/limited.sh"
chmod +x "$work/limited.sh"
limited=(render data/scenes/flanges.json --format ply --frames 40:160 --tolerance 1e-4x --quiet)
"$apparent" "${limited[@]}" --out "$work/unlimited" || fail "one process, no limit"
"$work/limited.sh" "$apparent" "${limited[@]}" --out "$work/limited1" > /dev/null 2> "$work/one.txt"
one=$?
timeout 300 mpirun --oversubscribe -n 1 "$apparent" "${limited[@]}" --out "$work/limited3" : \
    -n 2 "$work/limited.sh" "$apparent" "${limited[@]}" --out "$work/limited3" > /dev/null 2> "$work/mpi.txt"
got=$?
[ "$one" = 3 ] && [ "$got" = 3 ] || fail "a rank's write failure: one process $one, mpirun $got (3 expected)"
grep -q "^error: $work/limited1/relativistic/frame_00040.ply: cannot write (" "$work/one.txt" ||
    fail "a rank's write failure, one process: $(cat "$work/one.txt")"
[ "$(grep -c '^error: ' "$work/mpi.txt")" = 1 ] &&
    grep -q "^error: $work/limited3/relativistic/frame_00041.ply: cannot write (.*File too large" "$work/mpi.txt" ||
    fail "a rank's write failure: not one line naming frame 41 ($(cat "$work/mpi.txt"))"
left=$(cd "$work/limited3/relativistic" && ls -A)
[ "$left" = frame_00040.ply ] || fail "a rank's write failure left: $left"
cmp -s "$work/limited3/relativistic/frame_00040.ply" "$work/unlimited/relativistic/frame_00040.ply" ||
    fail "a rank's write failure: frame 40 not complete"

# Step: SIGKILL to rank 1 mid-run: mpirun exits non-zero; every file present is complete (the
# one-process run's bytes for it), no temporary is left beside them.
long=(render data/scenes/flanges.json --format ply,glb --tolerance 1e-4x --model all --quiet)
"$apparent" "${long[@]}" --out "$work/reference" || fail "reference run"
mpi "${long[@]}" --out "$work/killed" > "$work/killed.txt" 2>&1 &
launcher=$!
victim=""
for _ in $(seq 1 600); do
    for pid in $(pgrep -P "$launcher" 2>/dev/null) $(pgrep -f "$apparent render" 2>/dev/null); do
        if tr '\0' '\n' < "/proc/$pid/environ" 2>/dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=1'; then victim=$pid; fi
    done
    [ -n "$victim" ] && [ "$(ls "$work/killed/relativistic" 2>/dev/null | wc -l)" -gt 20 ] && break
    sleep 0.05
done
if [ -z "$victim" ]; then
    fail "rank 1 not found"
else
    kill -KILL "$victim"
fi
wait "$launcher"
code=$?
[ "$code" != 0 ] || fail "mpirun exited 0 after a rank was killed"
written=0
while IFS= read -r -d '' f; do
    rel=${f#"$work/killed/"}
    case "$rel" in
        *.tmp-*) fail "temporary file left: $rel" ;;
        *) cmp -s "$f" "$work/reference/$rel" || fail "not complete: $rel"; written=$((written + 1)) ;;
    esac
done < <(find "$work/killed" -type f -print0 2>/dev/null)
echo "killed run: mpirun exit $code, $written complete files, none truncated"

# Step: a rank killed at a frame chosen here (APPARENT_KILL_AFTER_WRITING, exporters/frame_files.h:
# the rank that writes that frame's file sends itself SIGKILL once the file's temporary is
# written, before sending it): mpirun exits non-zero, the frame's temporary is gone (rank 0
# removes the run's temporaries by their names' pattern when mpirun ends it), every file present is
# complete. Two cases: the first frame of the second model, made by rank 1 after the first
# model's end (`--model A,B`: the model switch); and with 20 ranks the first frame of rank 19,
# 19 frames of other ranks under way at once (rank 0 once registered 16 names at most).
kill_at() {  # RANKS FRAME_FILE (relative to the output folder) ARGS...
    local ranks=$1 victim=$2
    shift 2
    rm -rf "$work/chosen" "$work/chosen.one"
    "$apparent" "$@" --out "$work/chosen.one" --quiet || fail "one process: $*"
    APPARENT_KILL_AFTER_WRITING="$work/chosen/$victim" timeout 300 mpirun --oversubscribe -n "$ranks" \
        -x APPARENT_KILL_AFTER_WRITING "$apparent" "$@" --out "$work/chosen" --quiet --threads 1 > /dev/null 2>&1
    local code=$? files=0
    [ "$code" != 0 ] || fail "killed at $victim, $ranks ranks: mpirun exited 0"
    [ ! -e "$work/chosen/$victim" ] || fail "killed at $victim, $ranks ranks: the frame was renamed into place"
    while IFS= read -r -d '' f; do
        rel=${f#"$work/chosen/"}
        case "$rel" in
            *.tmp-*) fail "killed at $victim, $ranks ranks: temporary file left: $rel" ;;
            *) cmp -s "$f" "$work/chosen.one/$rel" || fail "killed at $victim: not complete: $rel"; files=$((files + 1)) ;;
        esac
    done < <(find "$work/chosen" -type f -print0 2>/dev/null)
    echo "killed at $victim with $ranks ranks: mpirun exit $code, $files complete files, no temporary"
}
kill_at 3 instant/frame_00041.ply render data/scenes/flanges.json --format ply --frames 40:100 --model relativistic,instant
kill_at 3 instant/frame_00041.obj render data/scenes/flanges.json --format obj,glb --frames 40:100 --model relativistic,instant
kill_at 20 relativistic/frame_00059.ply render data/scenes/flanges.json --format ply,glb --frames 40:100

# More ranks than rank 0 once kept names for (16 per sink): 20 processes, the same bytes, also
# with fewer frames than processes (ranks without a frame).
for frames in 40:100 40:50; do
    rm -rf "$work/one" "$work/twenty"
    "$apparent" render data/scenes/flanges.json --out "$work/one" --quiet --format ply,obj,glb --frames $frames ||
        fail "one process: frames $frames"
    timeout 300 mpirun --oversubscribe -n 20 "$apparent" render data/scenes/flanges.json --out "$work/twenty" --quiet \
        --threads 1 --format ply,obj,glb --frames $frames 2> "$work/stderr.txt" ||
        fail "mpirun -n 20, frames $frames: $(cat "$work/stderr.txt")"
    diff -r "$work/one" "$work/twenty" > /dev/null || fail "outputs differ with 20 processes, frames $frames"
done

[ "$failures" = 0 ] && echo "mpi_test: all passed"
exit $((failures > 0))
