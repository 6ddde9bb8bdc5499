#!/usr/bin/env python3
"""Writes make_textured_box.py's box as an OBJ with a .mtl library and a PNG (standard library only).

The unit box has its 8 corners once ('v'); each face's corners carry their own 'vt', so every corner
position is used with three different texture coordinates (the reader must split it). Faces +-x use
material "textured" (map_Kd texture.png), faces +-y "orange", faces +-z "grey" (their 'usemtl' in that
order: first use gives output materials 0, 1, 2). On face a, with b < c the two other axes, a point q has
u = q_b + 0.5 and OBJ's v = 0.5 - q_c, so glTF's TEXCOORD_0 = (u, 1 - v) = (q_b + 0.5, q_c + 0.5), the
closed form check_textured.py checks.

Also writes EXPECTED.json: the glTF materials the .mtl must become, worked out here from docs/INPUT.md's
mapping (not from the reader): {"materials": [...], "image": "texture.png", "colors": false}.

usage: make_textured_obj.py OUT_FOLDER
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_textured_box import png_2x2  # noqa: E402

MTL = """# apparent tests/looks/make_textured_obj.py
newmtl textured
Ka 1 1 1
Kd 1 1 1
illum 2
map_Kd texture.png

newmtl orange
Kd 1.0 0.4 0.05
Pr 0.7
Pm 0

newmtl grey
Kd 0.5
Ns 225
Pm 0.5
Ke 0 0 0.25
d 0.8
"""


def main(folder):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "texture.png"), "wb") as f:
        f.write(png_2x2())
    with open(os.path.join(folder, "box.mtl"), "w") as f:
        f.write(MTL)
    corners = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
    lines = ["# apparent tests/looks/make_textured_obj.py", "mtllib box.mtl"]
    lines += ["v %g %g %g" % c for c in corners]
    vts, faces = [], []
    for material, axis in zip(("textured", "orange", "grey"), (0, 1, 2)):
        faces.append("usemtl " + material)
        b, c = [a for a in range(3) if a != axis]
        for sign in (1, -1):
            quad = []
            for qb, qc in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]:
                q = [0.0, 0.0, 0.0]
                q[axis], q[b], q[c] = 0.5 * sign, qb, qc
                vts.append((qb + 0.5, 0.5 - qc))
                quad.append((corners.index(tuple(q)) + 1, len(vts)))
            outward = (1 if axis != 1 else -1) * sign > 0
            order = [0, 1, 2, 3] if outward else [0, 3, 2, 1]
            faces.append("f " + " ".join("%d/%d" % quad[k] for k in order))
    lines += ["vt %g %g" % t for t in vts] + faces
    with open(os.path.join(folder, "box.obj"), "w") as f:
        f.write("\n".join(lines) + "\n")
    # The glTF materials the mapping gives (docs/INPUT.md): Ns 225 -> roughness 1 - sqrt(225) / 30.
    expected = {"image": "texture.png", "colors": False, "materials": [
        {"name": "textured", "doubleSided": True,
         "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 1,
                                  "baseColorTexture": {"index": 0}}},
        {"name": "orange", "doubleSided": True,
         "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.4, 0.05, 1], "metallicFactor": 0, "roughnessFactor": 0.7}},
        {"name": "grey", "doubleSided": True, "alphaMode": "BLEND", "emissiveFactor": [0, 0, 0.25],
         "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 0.8], "metallicFactor": 0.5,
                                  "roughnessFactor": 1 - math.sqrt(225) / 30}},
    ]}
    with open(os.path.join(folder, "EXPECTED.json"), "w") as f:
        json.dump(expected, f)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
