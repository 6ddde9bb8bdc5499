#!/usr/bin/env python3
"""Compares the PLY frames two renders wrote (the scene's and its web file's, tests/web_file/run.sh).

usage: compare_ply.py A_DIR B_DIR exact
       compare_ply.py A_DIR B_DIR within REL

A_DIR and B_DIR hold <model>/frame_NNNNN.ply; both must hold the same frames. `exact`: every byte
equal except the header line `comment scene: ...` (it names the file rendered). `within REL`: the
same header (but that line), the same faces and `object` values, every position within REL times
the frame's bounding-box diagonal and every other double (quality, doppler, proper_time) within REL
relative (absolute below 1).
Prints the largest difference found.
"""
import glob
import os
import struct
import sys


def read(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    vertex_props, faces, vertices = [], 0, 0
    element = None
    for line in header:
        w = line.split()
        if w[0] == "element":
            element = w[1]
            if element == "vertex":
                vertices = int(w[2])
            else:
                faces = int(w[2])
        elif w[0] == "property" and element == "vertex":
            vertex_props.append((w[1], w[2]))
    fmt = "<" + "".join({"double": "d", "uchar": "B", "int": "i", "uint": "I"}[t] for t, _ in vertex_props)
    size = struct.calcsize(fmt)
    rows = [struct.unpack_from(fmt, data, end + i * size) for i in range(vertices)]
    return [l for l in header if not l.startswith("comment scene:")], vertex_props, rows, data[end + vertices * size:]


def main():
    a_dir, b_dir, mode = sys.argv[1], sys.argv[2], sys.argv[3]
    rel = float(sys.argv[4]) if mode == "within" else 0.0
    files = sorted(glob.glob(os.path.join(a_dir, "*", "frame_*.ply")))
    if not files:
        sys.exit("no PLY frames in " + a_dir)
    worst = 0.0
    for fa in files:
        fb = os.path.join(b_dir, os.path.relpath(fa, a_dir))
        ha, props, ra, faces_a = read(fa)
        hb, _, rb, faces_b = read(fb)
        name = os.path.relpath(fa, a_dir)
        if ha != hb:
            sys.exit(f"{name}: headers differ:\n{ha}\n{hb}")
        if faces_a != faces_b:
            sys.exit(f"{name}: faces differ")
        if mode == "exact":
            if ra != rb:
                sys.exit(f"{name}: vertex values differ")
            continue
        xyz = [r[:3] for r in ra]
        diag = sum((max(p[c] for p in xyz) - min(p[c] for p in xyz)) ** 2 for c in range(3)) ** 0.5 if xyz else 1.0
        for i, (va, vb) in enumerate(zip(ra, rb)):
            for c, (t, prop) in enumerate(props):
                if t == "uchar":
                    if va[c] != vb[c]:
                        sys.exit(f"{name}: vertex {i} {prop} {va[c]} != {vb[c]}")
                    continue
                d = abs(va[c] - vb[c]) / (diag if c < 3 else max(1.0, abs(va[c])))
                worst = max(worst, d)
                if d > rel:
                    sys.exit(f"{name}: vertex {i} {prop} {va[c]!r} != {vb[c]!r} ({d:.3g} > {rel})")
    print(f"{len(files)} frames {'identical (but the scene line)' if mode == 'exact' else f'within {rel}: largest {worst:.3g}'}")


main()
