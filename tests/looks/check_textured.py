#!/usr/bin/env python3
"""Checks a .glb that `apparent render` made of tests/looks/make_textured_box.py's box (standard library only).

usage: check_textured.py OUT.glb INPUT PX PY PZ VX VY VZ RX RY RZ [--shade-doppler | draco POSITION_BITS TEXCOORD_BITS | meshopt] [PLAIN.glb]
  INPUT: make_textured_box.py's .glb, or make_textured_obj.py's EXPECTED.json (the OBJ box: its
  materials must equal the JSON's whole, the image the PNG file's bytes; it has no COLOR_0).
  P the box's position at t = 0, V its velocity (relativistic model, t0 = 0), R its rotation_deg (X then
  Y then Z). For every vertex of every frame: its rest point follows from its position and emission time
  in closed form (the inverse Lorentz boost of the uniform motion, then the inverse rotation), lies on a
  face of the unit box, and its TEXCOORD_0, TEXCOORD_1 (where the input has it) and COLOR_0 must be
  the face's closed form at that point (make_textured_box.py), within 1e-4; the primitive's material
  must be the face's. The materials, their count, factors and occlusion textures equal the input's,
  the texture's image is the input's bytes, once.
  --shade-doppler (a render with --shade doppler --attributes doppler): COLOR_0 must be the modulation
  W(D) of docs/DOPPLER.md at the vertex's _DOPPLER (the band model computed here) times that closed form.
  A compressed file, decoded to a plain one by decode_glb.js, is checked within the codec's stated bounds
  on top (exporters/gltf.h), found here from the bit counts and the decoded file:
  - draco: each coordinate of a position within e_p = E / (2 (2^POSITION_BITS - 1)) (E the primitive's
    largest extent), each texture coordinate within e_t = R / (2 (2^TEXCOORD_BITS - 1)) with R <= 1 (the
    closed form's coordinates lie in [0, 1]); emission times and colours lossless;
  - meshopt: each coordinate of a position within e_p = step / 2 (the frame node's step, in the node's
    extras `decoded_step`), the emission time within step / 2, COLOR_0 (normalized uint16) within
    e_c = 0.5 / 65535, TEXCOORD_0 float32 as in the plain file (e_t = 0).
  A position moved by dx moves the rest point by at most g |dx| (the inverse boost stretches by g along
  the motion, the rotation by nothing), and an emission time moved by dt by g b dt: with |dx| <= sqrt(3)
  e_p, the rest points within 1e-4 + g (sqrt(3) e_p + b dt), and the texture coordinates (the rest point's
  face coordinates + 0.5) within that plus e_t, the colours plus e_c.
  With PLAIN.glb (the same render without compression) the attributes' own quantization is checked
  apart from the positions': each decoded vertex's plain twin is the nearest vertex of the same frame
  and material in the plain file (within sqrt(3) e_p + 1e-6), and its TEXCOORD_0 must lie within
  e_t + 1e-6 of the twin's, its COLOR_0 within e_c + 1e-6 (TEXCOORD_1 is checked against the
  closed form only).
"""
import json
import math
import os
import struct
import sys


def read_glb(path):
    data = open(path, "rb").read()
    assert data[:4] == b"glTF", path
    jlen = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + jlen])
    off = 20 + jlen
    blen = struct.unpack_from("<I", data, off)[0]
    return doc, data[off + 8:off + 8 + blen]


def accessor(doc, binary, i):
    a = doc["accessors"][i]
    v = doc["bufferViews"][a["bufferView"]]
    n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[a["type"]]
    fmt = {5126: "f", 5125: "I", 5123: "H"}[a["componentType"]]
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    vals = struct.unpack_from("<%d%s" % (a["count"] * n, fmt), binary, start)
    return [vals[k * n:(k + 1) * n] for k in range(a["count"])]


BANDS_NM = (610.0, 550.0, 465.0)  # R, G, B centres and the width, as docs/DOPPLER.md states them
WIDTH_NM = 40.0


def modulation(d):
    """W(D) = toneMap(A(D) (1, 1, 1)): the band samples D^3 sum_c g(l_k D - l_c), unmixed by M (Cramer)."""
    g = lambda x: math.exp(-x * x / (2 * WIDTH_NM ** 2))
    m = [[g(lk - lc) for lc in BANDS_NM] for lk in BANDS_NM]
    s = [d ** 3 * sum(g(lk * d - lc) for lc in BANDS_NM) for lk in BANDS_NM]
    det = lambda a: (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                     a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
    w = [det([[s[k] if c == i else m[k][c] for c in range(3)] for k in range(3)]) / det(m) for i in range(3)]
    w = [max(0.0, x) for x in w]
    top = max(w)
    return [x / top for x in w] if top > 1 else w


def rot_xyz(deg):
    ax, ay, az = (math.radians(d) for d in deg)
    rx = [[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]]
    ry = [[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]]
    rz = [[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]]
    mul = lambda a, b: [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    return mul(rz, mul(ry, rx))  # X first, then Y, then Z


def prim_arrays(doc, binary, prim):
    """A primitive's used vertices: (position, texcoord, colour) each."""
    pos = accessor(doc, binary, prim["attributes"]["POSITION"])
    uv = accessor(doc, binary, prim["attributes"]["TEXCOORD_0"])
    col = accessor(doc, binary, prim["attributes"]["COLOR_0"]) if "COLOR_0" in prim["attributes"] else None
    used = sorted({i for (i,) in accessor(doc, binary, prim["indices"])})
    return [(pos[k], uv[k], col[k] if col else [0.0, 0.0, 0.0]) for k in used]


def against_plain(doc, binary, plain, e_p, e_t, e_c):
    """The decoded vertices' attributes against their plain twins' (the docstring); failures as text."""
    pdoc, pbin = read_glb(plain)
    twins = {}
    for node in pdoc["nodes"]:
        if "mesh" in node:
            for prim in pdoc["meshes"][node["mesh"]]["primitives"]:
                twins[(node["name"], prim["material"])] = (node.get("translation", [0, 0, 0]),
                                                           prim_arrays(pdoc, pbin, prim))
    fails, worst, checked = [], [0.0, 0.0, 0.0], 0
    for node in doc["nodes"]:
        if "mesh" not in node:
            continue
        t0 = node.get("translation", [0, 0, 0])
        for prim in doc["meshes"][node["mesh"]]["primitives"]:
            e = e_p(node, prim)
            pt0, plain_vertices = twins[(node["name"], prim["material"])]
            for x, uv, col in prim_arrays(doc, binary, prim):
                at = [t0[c] + x[c] - pt0[c] for c in range(3)]
                d, puv, pcol = min((math.dist(at, px), puv, pcol) for px, puv, pcol in plain_vertices)
                du = max(abs(uv[c] - puv[c]) for c in range(2))
                dc = max(abs(col[c] - pcol[c]) for c in range(3))
                worst = [max(worst[0], d), max(worst[1], du), max(worst[2], dc)]
                checked += 1
                if d > math.sqrt(3) * e + 1e-6 or du > e_t + 1e-6 or dc > e_c + 1e-6:
                    fails.append("%s material %d: a vertex %.3g from its plain twin (bound %.3g), texture coordinates "
                                 "%.3g from its (bound %.3g), colour %.3g (bound %.3g)" %
                                 (node["name"], prim["material"], d, math.sqrt(3) * e + 1e-6, du, e_t + 1e-6, dc,
                                  e_c + 1e-6))
    print("against %s: %d vertices, each within %.2e of its plain twin, texture coordinates within %.2e (bound %.2e), "
          "colours within %.2e (bound %.2e)" % (plain, checked, worst[0], worst[1], e_t + 1e-6, worst[2], e_c + 1e-6))
    return fails + (["no vertex compared with the plain file"] if checked == 0 else [])


def main(out, inp, p, v, r, codec):
    shade = codec[:1] == ["--shade-doppler"]
    if shade:
        codec = codec[1:]
    doc, binary = read_glb(out)
    fails = []
    colors = True
    texcoord1 = False
    if inp.endswith(".json"):
        # make_textured_obj.py's EXPECTED.json: the whole materials, the image file, no COLOR_0.
        expected = json.load(open(inp))
        if doc["materials"] != expected["materials"]:
            fails.append("materials differ: %s" % doc["materials"])
        want_image = open(os.path.join(os.path.dirname(inp), expected["image"]), "rb").read()
        colors = expected.get("colors", True)
    else:
        idoc, ibin = read_glb(inp)
        # Materials: the input's, in first-use order (here the input's order), factors equal.
        for key in ("pbrMetallicRoughness", "occlusionTexture"):
            if [m.get(key) for m in doc["materials"]] != [m.get(key) for m in idoc["materials"]]:
                fails.append("materials differ (%s): %s" % (key, doc["materials"]))
        texcoord1 = any("TEXCOORD_1" in p["attributes"] for m in idoc["meshes"] for p in m["primitives"])
        ivi = idoc["bufferViews"][idoc["images"][0]["bufferView"]]
        want_image = ibin[ivi.get("byteOffset", 0):ivi.get("byteOffset", 0) + ivi["byteLength"]]
    if len(doc.get("images", [])) != 1:
        fails.append("images: %d, expected 1" % len(doc.get("images", [])))
    else:
        iv = doc["bufferViews"][doc["images"][0]["bufferView"]]
        image = binary[iv.get("byteOffset", 0):iv.get("byteOffset", 0) + iv["byteLength"]]
        if image != want_image:
            fails.append("the image's bytes differ from the input's")
    R = rot_xyz(r)
    b2 = sum(x * x for x in v)
    g = 1 / math.sqrt(1 - b2)
    n = [x / math.sqrt(b2) for x in v] if b2 > 0 else [1.0, 0.0, 0.0]
    worst_uv = worst_rest = 0.0
    bound_uv = bound_rest = 0.0
    doppler_range = [math.inf, -math.inf]
    shifted = 0  # vertices whose colour the shift changed by more than 0.05 (the check is not idle)
    checked = checked1 = 0
    for node in doc["nodes"]:
        if "mesh" not in node:
            continue
        t0 = node.get("translation", [0, 0, 0])
        for prim in doc["meshes"][node["mesh"]]["primitives"]:
            pos = accessor(doc, binary, prim["attributes"]["POSITION"])
            # The codec's bounds for this primitive (the docstring).
            e_p = e_t = e_c = dt = 0.0
            if codec and codec[0] == "draco":
                a = doc["accessors"][prim["attributes"]["POSITION"]]
                extent = max(a["max"][c] - a["min"][c] for c in range(3))
                e_p = extent / (2 * (2 ** int(codec[1]) - 1))
                e_t = 1.0 / (2 * (2 ** int(codec[2]) - 1))
            elif codec and codec[0] == "meshopt":
                e_p = dt = node["extras"]["decoded_step"] / 2
                e_c = 0.5 / 65535
            moved = g * (math.sqrt(3) * e_p + math.sqrt(b2) * dt)
            bound_rest = max(bound_rest, 1e-4 + moved)
            bound_uv = max(bound_uv, 1e-4 + moved + max(e_t, e_c))
            tim = accessor(doc, binary, prim["attributes"]["_EMISSION_TIME"])
            uv = accessor(doc, binary, prim["attributes"]["TEXCOORD_0"])
            if texcoord1 and "TEXCOORD_1" not in prim["attributes"]:
                fails.append("TEXCOORD_1 missing in a primitive of %s" % node["name"])
            uv1 = accessor(doc, binary, prim["attributes"]["TEXCOORD_1"]) if "TEXCOORD_1" in prim["attributes"] else None
            col = accessor(doc, binary, prim["attributes"]["COLOR_0"]) if colors else None
            if not colors and "COLOR_0" in prim["attributes"]:
                fails.append("COLOR_0 where the input has none")
            dop = accessor(doc, binary, prim["attributes"]["_DOPPLER"]) if shade else None
            used = sorted({i for (i,) in accessor(doc, binary, prim["indices"])})
            for k in used:
                x = [t0[c] + pos[k][c] - p[c] for c in range(3)]
                t = tim[k][0]
                # Inverse boost of the uniform motion: the rest-frame point (relativistic model, t0 = 0).
                xn = sum(x[c] * n[c] for c in range(3))
                tn = math.sqrt(b2) * t
                q_lab = [x[c] + (g - 1) * xn * n[c] - g * tn * n[c] for c in range(3)]
                q = [sum(R[i][c] * q_lab[i] for i in range(3)) for c in range(3)]  # R^T q_lab
                # Material m holds the faces of axis m (on an edge the point lies on both faces).
                axis = prim["material"]
                rest = max(abs(abs(q[axis]) - 0.5), max(abs(x) for x in q) - 0.5)
                b, c = [a for a in range(3) if a != axis]
                want = (q[b] + 0.5, q[c] + 0.5)
                du = max(abs(uv[k][0] - want[0]), abs(uv[k][1] - want[1]))
                if uv1:
                    checked1 += 1
                    du = max(du, abs(uv1[k][0] - want[1]), abs(uv1[k][1] - (1 - want[0])))
                colour = [min(1, max(0, want[0])), min(1, max(0, want[1])), 0.25]
                if shade:
                    d = dop[k][0]
                    doppler_range = [min(doppler_range[0], d), max(doppler_range[1], d)]
                    unshifted = colour
                    colour = [w * x for w, x in zip(modulation(d), colour)]
                    shifted += max(abs(a - b) for a, b in zip(colour, unshifted)) > 0.05
                dc = max((abs(col[k][i] - colour[i]) for i in range(3 if colors else 0)), default=0.0)
                worst_rest = max(worst_rest, rest)
                worst_uv = max(worst_uv, du, dc)
                if rest > 1e-4 + moved or du > 1e-4 + moved + e_t or dc > 1e-4 + moved + e_c:
                    fails.append("vertex %d of %s: rest point off by %.3g, texture coordinates by %.3g, colour by %.3g "
                                 "(bounds %.3g, %.3g, %.3g)" % (k, node["name"], rest, du, dc, 1e-4 + moved,
                                                                1e-4 + moved + e_t, 1e-4 + moved + e_c))
                checked += 1
    print("%s: %d vertices checked, rest points within %.2e of the box (bound %.2e), texture coordinates and colours "
          "within %.2e of the closed form (bound %.2e); %d materials, %d images" %
          (out, checked, worst_rest, bound_rest, worst_uv, bound_uv, len(doc["materials"]), len(doc.get("images", []))))
    if texcoord1:
        print("  TEXCOORD_1 checked at %d vertices" % checked1)
    if shade:
        print("  COLOR_0 the modulation W(D) times the input's colour, D from %.4f to %.4f; %d vertices shifted by "
              "more than 0.05" % (*doppler_range, shifted))
        if shifted == 0:
            fails.append("no colour shifted")
    if checked == 0:
        fails.append("no vertex checked")
    plain = codec[-1] if codec and codec[-1].endswith(".glb") else None
    if plain and codec[0] == "draco":
        def e_p(node, prim):
            a = doc["accessors"][prim["attributes"]["POSITION"]]
            return max(a["max"][c] - a["min"][c] for c in range(3)) / (2 * (2 ** int(codec[1]) - 1))
        fails += against_plain(doc, binary, plain, e_p, 1.0 / (2 * (2 ** int(codec[2]) - 1)), 0.0)
    elif plain:
        fails += against_plain(doc, binary, plain, lambda node, prim: node["extras"]["decoded_step"] / 2,
                               0.0, 0.5 / 65535)
    for f in fails[:5]:
        print("FAIL", f)
    return 1 if fails else 0


if __name__ == "__main__":
    a = sys.argv[1:]
    codec = a[11:-1] if a[-1].endswith(".glb") and len(a) > 12 else a[11:]
    if not (codec in ([], ["meshopt"], ["--shade-doppler"]) or (len(codec) == 3 and codec[0] == "draco")):
        sys.exit(__doc__)
    sys.exit(main(a[0], a[1], [float(x) for x in a[2:5]], [float(x) for x in a[5:8]], [float(x) for x in a[8:11]],
                  a[11:]))
