#!/bin/bash
# Frames across processes, measured (docs/PERFORMANCE.md "Frames across processes"): a 200k-triangle
# torus (ring radius 2, tube 0.5) passing 10 ls from the camera at 0.9c, 100 frames, relativistic,
# default tolerance, to a plain .glb; one process with 1 and 2 threads, then mpirun -n 1, 2 and 4
# with one thread per rank, side by side in one run. Prints a Markdown table: wall time, speed-up
# against one process with one thread, rank 0's writing time and share, and the per-frame costs
# (`render --verbose`; with MPI also rank 0's work on each frame another rank cut, in microseconds),
# and checks that every run's outputs (the .glb, or with --format ply the PLY
# frames) are byte-identical to the one-process run's.
# With PEER=/path/to/another/apparent (e.g. a build of the commit before a change), every run is
# made with both binaries in turn, rows marked "this" and "peer": a ratio measured side by side.
# Usage: [PEER=other/apparent] scripts/mpi_report.sh [build/apparent] [render options, e.g. --compress draco
# or --format ply]
# (needs mpirun: scripts/setup.sh installs it)
set -euo pipefail
apparent=$(realpath "${1:-build/apparent}")
peer=${PEER:+$(realpath "$PEER")}
shift || true
options="$*"
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# Step: the torus, 500 x 200 vertices, two triangles per quad (200,000 triangles).
bash "$root/scripts/torus_obj.sh" 500 200 "$work/torus.obj"
cat > "$work/torus.json" <<'JSON'
{
  "camera": { "position": [0, 0, 0], "look_at": [0, 0, -10], "up": [0, 1, 0], "fov_deg": 60 },
  "frames": { "start": 0, "end": 10, "fps": 10 },
  "model": "relativistic",
  "objects": [ { "name": "torus", "mesh": "torus.obj", "position": [-14, 0, -10], "t0": 0, "velocity": [0.9, 0, 0] } ]
}
JSON
cd "$work"

# Step: the runs. "time" is the wall clock of the whole command, start-up and loading included.
run() {  # LABEL OUTDIR COMMAND...
    local label=$1 out=$2
    shift 2
    local start end
    start=$(date +%s.%N)
    "$@" torus.json --out "$out" --verbose --max-output-bytes 0 $options > "$out.log" 2>&1
    end=$(date +%s.%N)
    local line
    line=$(grep -E '^relativistic: loop ' "$out.log") || { cat "$out.log"; exit 1; }
    # "relativistic: loop L s; per frame: cut and encode C ms (CPU c ms; F frames cut here), write W ms
    #  (CPU w ms; F frames, P% of the loop[ on rank 0]); of the writing, the files' assembly A ms (CPU
    #  a ms)[; rank 0 waited T s for other ranks][; of the writing, the frames of other ranks R us each
    #  (CPU r us; K frames)]"
    field() { echo "$line" | sed -E "s/$1/\\1/"; }
    local cut cut_cpu write write_cpu share assembly="-" received="-"
    cut=$(field '.*cut and encode ([0-9.]+) ms.*')
    cut_cpu=$(field '.*cut and encode [0-9.]+ ms \(CPU ([0-9.]+) ms.*')
    write=$(field '.*, write ([0-9.]+) ms.*')
    write_cpu=$(field '.*, write [0-9.]+ ms \(CPU ([0-9.]+) ms.*')
    share=$(field '.*frames, ([0-9.]+)% of the loop.*')
    if echo "$line" | grep -q "files' assembly"; then
        assembly="$(field ".*files' assembly ([0-9.]+) ms.*") ($(field ".*files' assembly [0-9.]+ ms \\(CPU ([0-9.]+) ms.*"))"
    fi
    if echo "$line" | grep -q "frames of other ranks"; then
        received="$(field ".*frames of other ranks ([0-9]+) us.*") ($(field ".*frames of other ranks [0-9]+ us each \\(CPU ([0-9]+) us.*"))"
    fi
    [ "$out" = one1 ] || diff -r "$out" one1 > /dev/null || { echo "$label: outputs differ"; exit 1; }
    printf '| %s | %.2f | %s (%s) | %s (%s) | %s | %s | %s |\n' "$label" "$(echo "$end - $start" | bc)" "$cut" "$cut_cpu" \
        "$write" "$write_cpu" "$assembly" "$received" "$share" >> table.md
}
: > table.md
# Each run with this binary, then (PEER set) with the peer, in turn.
both() {  # LABEL OUTDIR COMMAND... (the binary as the word APPARENT)
    local label=$1 out=$2
    shift 2
    run "$label${peer:+, this}" "$out" "${@/#APPARENT/$apparent}"
    if [ -n "$peer" ]; then run "$label, peer" "$out-peer" "${@/#APPARENT/$peer}"; fi
}
both "1 process, 1 thread" one1 APPARENT render --threads 1
both "1 process, 2 threads" one2 APPARENT render --threads 2
for n in 1 2 4; do
    both "mpirun -n $n, 1 thread each" "mpi$n" mpirun --oversubscribe -n "$n" APPARENT render --threads 1
done
echo "| run | wall (s) | cut + encode per frame, ms (CPU) | write per frame on rank 0, ms (CPU) | of which the assembly at the end, ms (CPU) | of which per frame of another rank, us (CPU) | writing share of rank 0's loop (%) |"
echo "|---|---:|---:|---:|---:|---:|---:|"
cat table.md
echo
echo "Outputs $(du -sm one1 | cut -f1) MiB, every run's byte-identical to the one-process run's. $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), $(date -u +%Y-%m-%dT%H:%M:%SZ)."
