#!/usr/bin/env python3
"""Writes a textured, three-material unit box as a .glb (standard library only), for the look tests.

Faces +-x use material 0 (a 2x2 PNG texture, nearest sampling), faces +-y material 1 (an orange
factor), faces +-z material 2 (a grey factor, metallic 0.5, the texture as its occlusion map read
through TEXCOORD_1). Every vertex has TEXCOORD_0, TEXCOORD_1 and COLOR_0 that are linear on its face,
so the value at any point q of face a (the axis |q_a| = 0.5) is known in closed form: with b < c the
two other axes, u = q_b + 0.5, v = q_c + 0.5, TEXCOORD_0 = (u, v), TEXCOORD_1 = (v, 1 - u) and
COLOR_0 = (u, v, 0.25, 1).

usage: make_textured_box.py OUT.glb OUT_TEXTURE.png [--no-colors]
  --no-colors: without COLOR_0 (the texture's own colours show, for the screenshot test)
"""
import json
import struct
import sys
import zlib


def png_2x2():
    rows = [(255, 0, 0, 0, 255, 0), (0, 0, 255, 255, 255, 255)]  # red green / blue white
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def face(axis, sign):
    b, c = [a for a in range(3) if a != axis]
    corners = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
    verts = []
    for qb, qc in corners:
        q = [0.0, 0.0, 0.0]
        q[axis], q[b], q[c] = 0.5 * sign, qb, qc
        verts.append((q, (qb + 0.5, qc + 0.5)))
    # Outward winding: (b, c, axis) is right-handed for axis 0 and 2, left-handed for axis 1.
    outward = (1 if axis != 1 else -1) * sign > 0
    tris = [(0, 1, 2), (0, 2, 3)] if outward else [(0, 2, 1), (0, 3, 2)]
    return verts, tris


def main(out_glb, out_png, colors=True):
    image = png_2x2()
    with open(out_png, "wb") as f:
        f.write(image)
    bin_ = bytearray()
    views, accessors, primitives = [], [], []

    def view(data, target=None):
        while len(bin_) % 4:
            bin_.append(0)
        v = {"buffer": 0, "byteOffset": len(bin_), "byteLength": len(data)}
        if target:
            v["target"] = target
        bin_.extend(data)
        views.append(v)
        return len(views) - 1

    for material, axis in enumerate((0, 1, 2)):
        pos, uv, uv1, col, idx = [], [], [], [], []
        for sign in (1, -1):
            verts, tris = face(axis, sign)
            base = len(pos)
            for q, t in verts:
                pos.append(q)
                uv.append(t)
                uv1.append((t[1], 1 - t[0]))
                col.append((t[0], t[1], 0.25, 1.0))
            idx += [base + i for tri in tris for i in tri]
        flat = lambda rows: [x for r in rows for x in r]
        a_pos = len(accessors)
        accessors.append({"bufferView": view(struct.pack("<%df" % (3 * len(pos)), *flat(pos)), 34962), "componentType": 5126,
                          "count": len(pos), "type": "VEC3", "min": [min(p[i] for p in pos) for i in range(3)],
                          "max": [max(p[i] for p in pos) for i in range(3)]})
        accessors.append({"bufferView": view(struct.pack("<%df" % (2 * len(uv)), *flat(uv)), 34962), "componentType": 5126,
                          "count": len(uv), "type": "VEC2"})
        accessors.append({"bufferView": view(struct.pack("<%df" % (4 * len(col)), *flat(col)), 34962), "componentType": 5126,
                          "count": len(col), "type": "VEC4"})
        accessors.append({"bufferView": view(struct.pack("<%dH" % len(idx), *idx), 34963), "componentType": 5123,
                          "count": len(idx), "type": "SCALAR"})
        accessors.append({"bufferView": view(struct.pack("<%df" % (2 * len(uv1)), *flat(uv1)), 34962), "componentType": 5126,
                          "count": len(uv1), "type": "VEC2"})
        attributes = {"POSITION": a_pos, "TEXCOORD_0": a_pos + 1, "TEXCOORD_1": a_pos + 4}
        if colors:
            attributes["COLOR_0"] = a_pos + 2
        primitives.append({"attributes": attributes,
                           "indices": a_pos + 3, "material": material})
    image_view = view(image)
    doc = {
        "asset": {"version": "2.0", "generator": "apparent tests/looks/make_textured_box.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "box"}],
        "meshes": [{"primitives": primitives}],
        "materials": [
            {"name": "textured", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}},
            {"name": "orange", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.4, 0.05, 1.0], "metallicFactor": 0.0,
                                                        "roughnessFactor": 0.7}},
            {"name": "grey", "doubleSided": True, "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0],
                                                                           "metallicFactor": 0.5},
             "occlusionTexture": {"index": 0, "texCoord": 1}},
        ],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "minFilter": 9728}],
        "images": [{"bufferView": image_view, "mimeType": "image/png", "name": "checker"}],
        "accessors": accessors, "bufferViews": views, "buffers": [{"byteLength": len(bin_)}],
    }
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    while len(bin_) % 4:
        bin_.append(0)
    total = 12 + 8 + len(js) + 8 + len(bin_)
    with open(out_glb, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, total))
        f.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
        f.write(struct.pack("<II", len(bin_), 0x004E4942) + bytes(bin_))


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4) or (len(sys.argv) == 4 and sys.argv[3] != "--no-colors"):
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], len(sys.argv) == 3)
