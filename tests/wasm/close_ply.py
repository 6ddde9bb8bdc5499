#!/usr/bin/env python3
"""Two PLY frames of apparent (binary little-endian, tests/wasm/cut.sh): the same header and faces,
every vertex value within REL of the first file's, relative to max(1, |value|).

usage: close_ply.py NATIVE.ply WASM.ply REL   (exit 1 with the first differences; prints the counts)
"""
import struct
import sys


def read(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii")
    lines = header.splitlines()
    count = int(next(l for l in lines if l.startswith("element vertex")).split()[2])
    types = [l.split()[1] for l in lines if l.startswith("property") and "list" not in l]
    fmt = "<" + "".join({"double": "d", "uchar": "B", "ushort": "H", "int": "i"}[t] for t in types)
    size = struct.calcsize(fmt)
    rows = [struct.unpack_from(fmt, data, end + i * size) for i in range(count)]
    return header, rows, data[end + count * size:]


a, b, rel = read(sys.argv[1]), read(sys.argv[2]), float(sys.argv[3])
problems = []
if a[0] != b[0]:
    problems.append("the headers differ")
if a[2] != b[2]:
    problems.append("the faces differ")
if len(a[1]) != len(b[1]):
    problems.append("%d vertices against %d" % (len(a[1]), len(b[1])))
same = numbers = 0
worst = 0.0
for i, (u, v) in enumerate(zip(a[1], b[1])):
    for x, y in zip(u, v):
        numbers += 1
        same += x == y
        d = abs(x - y) / max(1.0, abs(x))
        worst = max(worst, d)
        if d > rel and len(problems) < 5:
            problems.append("vertex %d: %r against %r" % (i, x, y))
print("  %d of %d values the same bits, the largest difference %.3g relative" % (same, numbers, worst))
for p in problems:
    print("  " + p)
sys.exit(1 if problems else 0)
