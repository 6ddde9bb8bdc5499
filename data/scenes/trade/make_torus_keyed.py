#!/usr/bin/env python3
"""Writes torus_keyed_cubic.gltf (or the path given as the first argument): keyed_cubic.gltf's scene
and path (its CUBICSPLINE translation and LINEAR rotation, the same bytes) with the box replaced by the
torus of the benchmarks (benchmarks/load_bench.cpp torusOf(20000): 200 x 50 quads, 20 000 triangles,
ring radius 2, tube 0.5, axis +y), and 100 frames: 60 .. 159 at 10 fps, camera times 6 .. 15.9 s, so
that what the camera sees was emitted while the torus is on the keyed path (keys at 0, 8, 16 s; the
torus is about 6 ls away). Issue 31's third target measures a whole render of it at the default
tolerance against --tolerance vertex (docs/ACCURACY.md "Keyed paths"). Not committed (300 kB): made on
demand, deterministic."""
import base64
import json
import math
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def torus(nu, nv, ring, tube):
    """tests/test_meshes.h testmesh::torus: the same points and triangles in the same order."""
    pts = []
    for i in range(nu):
        for j in range(nv):
            u, v = 2 * math.pi * i / nu, 2 * math.pi * j / nv
            pts.append(((ring + tube * math.cos(v)) * math.cos(u), tube * math.sin(v),
                        (ring + tube * math.cos(v)) * math.sin(u)))

    def pid(i, j):
        return ((i + nu) % nu) * nv + (j + nv) % nv

    tris = []
    for i in range(nu):
        for j in range(nv):
            tris.append((pid(i, j), pid(i, j + 1), pid(i + 1, j)))
            tris.append((pid(i + 1, j), pid(i, j + 1), pid(i + 1, j + 1)))
    return pts, tris


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "torus_keyed_cubic.gltf")
    with open(os.path.join(HERE, "..", "keyed_cubic.gltf")) as f:
        gltf = json.load(f)
    prefix = "data:application/octet-stream;base64,"
    blob = bytearray(base64.b64decode(gltf["buffers"][0]["uri"][len(prefix):]))
    pts, tris = torus(200, 50, 2.0, 0.5)

    def add(data, target):
        blob.extend(b"\0" * (-len(blob) % 4))
        gltf["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
        blob.extend(data)
        return len(gltf["bufferViews"]) - 1

    pos = add(b"".join(struct.pack("<3f", *p) for p in pts), 34962)
    idx = add(b"".join(struct.pack("<3H", *t) for t in tris), 34963)
    gltf["accessors"].append({"bufferView": pos, "componentType": 5126, "count": len(pts), "type": "VEC3",
                              "min": [min(p[c] for p in pts) for c in range(3)],
                              "max": [max(p[c] for p in pts) for c in range(3)]})
    gltf["accessors"].append({"bufferView": idx, "componentType": 5123, "count": 3 * len(tris), "type": "SCALAR"})
    n = len(gltf["accessors"])
    gltf["meshes"][0] = {"name": "torus", "primitives": [{"attributes": {"POSITION": n - 2}, "indices": n - 1}]}
    gltf["nodes"][1]["name"] = "torus"
    extras = gltf["scenes"][0]["extras"]
    extras["frames"] = {"start": 6, "end": 16, "fps": 10}
    extras.pop("tolerance", None)  # the default tolerance unless --tolerance says otherwise
    gltf["asset"]["generator"] = "apparent data/scenes/trade/make_torus_keyed.py"
    gltf["buffers"] = [{"byteLength": len(blob), "uri": prefix + base64.b64encode(bytes(blob)).decode()}]
    with open(out, "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
