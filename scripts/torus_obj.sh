#!/usr/bin/env bash
# Writes a torus OBJ for the benchmarks: N x M vertices (major radius 2, minor 0.5), two triangles
# per quad (2 N M triangles). Usage: scripts/torus_obj.sh N M OUT.obj
set -euo pipefail
[ $# -eq 3 ] || { echo "usage: $0 N M OUT.obj" >&2; exit 2; }
awk -v n="$1" -v m="$2" 'BEGIN {
    R = 2; r = 0.5; pi = atan2(0, -1);
    for (i = 0; i < n; ++i) for (j = 0; j < m; ++j) {
        u = 2 * pi * i / n; v = 2 * pi * j / m;
        printf "v %.12g %.12g %.12g\n", (R + r * cos(v)) * cos(u), r * sin(v), (R + r * cos(v)) * sin(u);
    }
    for (i = 0; i < n; ++i) for (j = 0; j < m; ++j) {
        a = i * m + j + 1; b = ((i + 1) % n) * m + j + 1; c = ((i + 1) % n) * m + (j + 1) % m + 1; d = i * m + (j + 1) % m + 1;
        printf "f %d %d %d\nf %d %d %d\n", a, b, c, a, c, d;
    }
}' > "$3"
