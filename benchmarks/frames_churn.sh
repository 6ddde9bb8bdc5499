#!/bin/bash
# Frames as a user runs them, whole process (issue 37): a 1M-triangle torus OBJ (ring radius 2, tube
# 0.5, 1000 x 500 vertices) passing 10 ls from the camera at 0.9c, vertex mode (--tolerance vertex),
# --threads 1, rendered to .glb and to PLY for frames 0:1, 0:5 and 0:9, beside gltfpack's whole
# conversion of the same OBJ (`gltfpack -i torus.obj -o x.glb`), every command in turn in one run,
# best of ROUNDS (default 3): each figure the least of its rounds. `/usr/bin/time` gives each run's wall, user and system
# CPU, peak resident memory and minor page faults. Prints a Markdown table of those, then the
# issue's ratios: load plus the first frame against gltfpack, each extra frame ((0:5 - 0:1) / 4)
# against gltfpack, in wall time and (in brackets) in CPU time, user plus system (the figure that
# holds on a machine shared with other work), system against user CPU per extra frame, peak memory
# (of 0:1, and of 0:5 in brackets) against gltfpack's; and the same per frame once the loop holds
# no more frames for its output estimate ((0:9 - 0:5) / 4: the first 4 frames are held).
# With PEER=/path/to/another/apparent (e.g. a build of the commit before a change), its runs join
# the same rounds, rows marked "peer": a before/after measured side by side.
# Usage: [PEER=other/apparent] [ROUNDS=3] benchmarks/frames_churn.sh [build/apparent]
# (needs gltfpack and GNU time: scripts/setup.sh installs them)
set -euo pipefail
apparent=$(realpath "${1:-build/apparent}")
peer=${PEER:+$(realpath "$PEER")}
rounds=${ROUNDS:-3}
command -v gltfpack >/dev/null || { echo "frames_churn.sh: needs gltfpack (scripts/setup.sh installs it)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "frames_churn.sh: needs GNU time as /usr/bin/time (Debian package time)" >&2; exit 2; }
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

# Step: the torus, 1000 x 500 vertices, two triangles per quad (1,000,000 triangles), and its scene.
bash "$root/scripts/torus_obj.sh" 1000 500 torus.obj
cat > torus.json <<'JSON'
{
  "camera": { "position": [0, 0, 0], "look_at": [0, 0, -10], "up": [0, 1, 0], "fov_deg": 60 },
  "frames": { "start": 0, "end": 10, "fps": 10 },
  "model": "relativistic",
  "objects": [ { "name": "torus", "mesh": "torus.obj", "position": [-14, 0, -10], "t0": 0, "velocity": [0.9, 0, 0] } ]
}
JSON

# Step: the runs, in turn, ROUNDS times; each appends "label wall user sys rss_kb minflt" to runs.txt.
measure() {  # LABEL COMMAND...
    local label=$1
    shift
    rm -rf out x.glb
    /usr/bin/time -o time.txt -f '%e %U %S %M %R' "$@" > run.log 2>&1 || { cat run.log time.txt; exit 1; }
    echo "$label $(tail -1 time.txt)" >> runs.txt
}
binaries=("this $apparent")
[ -n "$peer" ] && binaries+=("peer $peer")
for ((round = 0; round < rounds; ++round)); do
    measure gltfpack gltfpack -i torus.obj -o x.glb
    for entry in "${binaries[@]}"; do
        set -- $entry
        for format in glb ply; do
            for frames in 0:1 0:5 0:9; do
                measure "$1/$format/$frames" "$2" render torus.json --out out --tolerance vertex --threads 1 \
                    --frames "$frames" --format "$format"
            done
        done
    done
done

# Step: each figure the least of the rounds, then the table and the ratios.
python3 - runs.txt "${#binaries[@]}" <<'PY'
import sys
best = {}
for line in open(sys.argv[1]):
    label, wall, user, sys_, rss, minflt = line.split()
    row = (float(wall), float(user), float(sys_), int(rss) / 1024, int(minflt))
    best[label] = tuple(min(a, b) for a, b in zip(best[label], row)) if label in best else row
print("| run | wall s | user s | sys s | peak MB | minor faults |")
print("|---|---:|---:|---:|---:|---:|")
for label, (w, u, s, r, f) in best.items():
    print(f"| {label} | {w:.2f} | {u:.2f} | {s:.2f} | {r:.0f} | {f} |")
g = best["gltfpack"]
print()
print("| binary, format | load + frame 0 / gltfpack, wall (CPU) (goal 1.2) | extra frame / gltfpack, wall (CPU) (goal 0.1) "
      "| extra frame: sys / user (goal 0.1) | extra frame: faults | peak / gltfpack, 0:1 (0:5) (goal 2) "
      "| frames 5-8, each: / gltfpack, wall (CPU); sys / user; faults |")
print("|---|---:|---:|---:|---:|---:|---:|")
cpu = lambda row: row[1] + row[2]
for binary in ("this", "peer"):
    for fmt in ("glb", "ply"):
        one, five, nine = (best.get(f"{binary}/{fmt}/{f}") for f in ("0:1", "0:5", "0:9"))
        if not one:
            continue
        extra = [(five[i] - one[i]) / 4 for i in range(5)]
        ratio = extra[2] / extra[1] if extra[1] > 0 else float("nan")
        late = [(nine[i] - five[i]) / 4 for i in range(5)]
        late_ratio = late[2] / late[1] if late[1] > 0 else float("nan")
        print(f"| {binary}, {fmt} | {one[0] / g[0]:.2f} ({cpu(one) / cpu(g):.2f}) "
              f"| {extra[0] / g[0]:.2f} ({(extra[1] + extra[2]) / cpu(g):.2f}) | {ratio:.2f} | {extra[4]:.0f} "
              f"| {one[3] / g[3]:.2f} ({five[3] / g[3]:.2f}) | {late[0] / g[0]:.2f} ({(late[1] + late[2]) / cpu(g):.2f}); "
              f"{late_ratio:.2f}; {late[4]:.0f} |")
PY
