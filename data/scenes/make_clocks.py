#!/usr/bin/env python3
"""Writes clocks.json and its meshes ../meshes/clock_face.gltf (a disc of radius 1 ls, 0.05 ls
thick, facing +z, light grey) and ../meshes/clock_hand.gltf (a bar 0.1 x 0.8 x 0.04 ls from the
origin along +y, in front of the face, dark red): two clocks, one passing the camera at 0.8c and
one at rest, each with a hand that jumps one hour per second of the clock's own time (docs/PICTURES.md
"Gallery"). Run from this folder; the outputs are committed. The colours are the glTF materials'
(the only way a mesh brings its own colour), the buffers base64 data URIs."""
import base64
import json
import math
import struct


def write_gltf(path, verts, tris, color):
    pos = b"".join(struct.pack("<3f", *v) for v in verts)
    idx = b"".join(struct.pack("<3H", *t) for t in tris)
    blob = pos + idx
    lo = [min(v[c] for v in verts) for c in range(3)]
    hi = [max(v[c] for v in verts) for c in range(3)]
    doc = {
        "asset": {"version": "2.0", "generator": "apparent data/scenes/make_clocks.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": color + [1.0], "metallicFactor": 0.0}}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos), "target": 34962},
                        {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx), "target": 34963}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(verts), "type": "VEC3", "min": lo, "max": hi},
                      {"bufferView": 1, "componentType": 5123, "count": 3 * len(tris), "type": "SCALAR"}],
    }
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def prism(outline, z0, z1):
    """A closed prism over a convex outline (counter-clockwise seen from +z) between z0 and z1."""
    n = len(outline)
    verts = [(x, y, z0) for x, y in outline] + [(x, y, z1) for x, y in outline]
    tris = []
    for i in range(1, n - 1):
        tris.append((0, i + 1, i))              # back, facing -z
        tris.append((n, n + i, n + i + 1))      # front, facing +z
    for i in range(n):
        j = (i + 1) % n
        tris += [(i, j, n + j), (i, n + j, n + i)]  # sides, facing out
    return verts, tris


disc = [(math.cos(2 * math.pi * k / 32), math.sin(2 * math.pi * k / 32)) for k in range(32)]
write_gltf("../meshes/clock_face.gltf", *prism(disc, -0.025, 0.025), [0.8, 0.8, 0.75])
write_gltf("../meshes/clock_hand.gltf", *prism([(-0.05, 0), (0.05, 0), (0.05, 0.8), (-0.05, 0.8)], 0.03, 0.07),
           [0.6, 0.05, 0.05])

objects = []
for name, y, velocity in (("moving", 0.0, [0.8, 0, 0]), ("resting", 2.6, [0, 0, 0])):
    position = [0, y, -4]
    objects.append({"name": f"{name}_face", "mesh": "../meshes/clock_face.gltf", "position": position,
                    "velocity": velocity})
    for j in range(-6, 6):
        objects.append({"name": f"{name}_hand_{j:+d}", "mesh": "../meshes/clock_hand.gltf", "position": position,
                        "velocity": velocity, "rotation_deg": [0, 0, -30 * (j % 12)], "exists": [j, j + 1]})
scene = {
    "_about": "Clocks (docs/PICTURES.md 'Gallery', written by make_clocks.py): two clock faces 4 ls in front of the camera, each "
              "with a hand that jumps one hour per second of the clock's own time (12 hand objects with `exists` on "
              "the clock's proper time: hand j is there while the clock reads [j, j+1) s, 12 o'clock at 0). The lower "
              "clock passes at 0.8c (gamma 5/3) and is at x = 0 at lab time 0, so it is seen face-on at t = 4 s; the "
              "upper one rests. The camera sees each clock's reading at the emission event: both read 12 when seen at "
              "t = 4 s; the resting one advances one hour per second, the moving one by D hours per camera second, "
              "D = 3 while it approaches and 1/3 once it recedes (the light delay shrinks, then grows), 1/gamma of the "
              "resting one's rate in the lab.",
    "camera": {"position": [0, 0, 0], "look_at": [0, 1.3, -4], "up": [0, 1, 0], "fov_deg": 64},
    "frames": {"start": -2, "end": 10, "fps": 10},
    "model": "relativistic",
    "objects": objects,
}
with open("clocks.json", "w") as f:
    json.dump(scene, f, indent=1)
    f.write("\n")
