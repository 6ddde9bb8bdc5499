#!/usr/bin/env python3
"""Writes the meshes of the trade scenes (docs/ACCURACY.md) into data/meshes/:
box.obj (a cube of edge 1, 12 triangles), plate.obj (a 2 x 4 quad of 4 triangles about its centre,
facing +z) and icosphere320.obj / icosphere20480.obj (unit icospheres: the icosahedron split
4-to-1 two and five times, points pushed onto the sphere). Positions with 17 significant digits."""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
MESHES = os.path.normpath(os.path.join(HERE, "..", "..", "meshes"))


def write(name, points, faces, about):
    with open(os.path.join(MESHES, name), "w") as f:
        f.write(f"# {about}\n# made by data/scenes/trade/make_meshes.py\n")
        for p in points:
            f.write("v %.17g %.17g %.17g\n" % p)
        for a, b, c in faces:
            f.write(f"f {a + 1} {b + 1} {c + 1}\n")


def icosphere(levels):
    t = (1 + math.sqrt(5)) / 2
    pts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
           (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    pts = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in pts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        mid = {}

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = [(pts[a][k] + pts[b][k]) / 2 for k in range(3)]
                n = math.sqrt(sum(x * x for x in p))
                pts.append(tuple(x / n for x in p))
                mid[key] = len(pts) - 1
            return mid[key]

        nxt = []
        for a, b, c in faces:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nxt += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = nxt
    return pts, faces


def main():
    h = 0.5
    box = [(x, y, z) for z in (-h, h) for y in (-h, h) for x in (-h, h)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    write("box.obj", box, [t for q in quads for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))],
          "a cube of edge 1 centred on the origin, 12 triangles, outward normals")
    plate = [(-1, -2, 0), (1, -2, 0), (1, 2, 0), (-1, 2, 0), (0, 0, 0)]
    write("plate.obj", plate, [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)],
          "a flange-like plate, 2 x 4 light-seconds, facing +z, 4 triangles about its centre")
    for levels, name in ((2, "icosphere320.obj"), (5, "icosphere20480.obj")):
        pts, faces = icosphere(levels)
        write(name, pts, faces, f"a unit icosphere, {len(faces)} triangles")


if __name__ == "__main__":
    main()
