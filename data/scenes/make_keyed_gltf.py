#!/usr/bin/env python3
"""Writes keyed.gltf (and keyed_cubic.gltf, its corner as a CUBICSPLINE, at the end): a box that
follows a keyframed path (docs/MOTION.md "Keyframed paths"), as a Blender user exports an animated object:
LINEAR translation and rotation channels on the object's node,
key times in seconds (lab time), positions in light-seconds. Run from this folder; the output is
committed. The box (../meshes/box.obj) follows the path:

  t = 0 .. 5 s   from (-4, -1, -6) to (0, -1, -6): 0.8c along +x, turning a quarter turn about y
  t = 5 .. 10 s  from (0, -1, -6) to (0, 2, -6):  0.6c along +y (a corner at t = 5 s), still turning
  before t = 0 and after t = 10 s it rests at its end pose (glTF players hold the end values).

The fastest vertex: 0.8c plus the turn's rim speed (pi/20 rad/s x 0.71 ls = 0.11c) stays below 1.
The node's extras hold t0 = 0 (an object field, which makes the node an object) and the scene's
extras set the vertex tolerance (the fastest; `--tolerance` overrides it)."""
import base64
import json
import math
import struct


from obj_mesh import read_obj


def quat_y(angle):
    """glTF (x, y, z, w) of a turn by `angle` about +y."""
    return [0.0, math.sin(angle / 2), 0.0, math.cos(angle / 2)]


verts, faces = read_obj("../meshes/box.obj")


def write(name, times, positions, rotations, tangents=None):
    """Writes `name`: the box on the keyed path. With `tangents` (ls/s, one per key) the translation
    channel is CUBICSPLINE (glTF 2.0 appendix C: in-tangent, value, out-tangent per key)."""
    chunks = []
    views, accessors = [], []

    def add(data, target=None):
        offset = sum(len(c) for c in chunks)
        view = {"buffer": 0, "byteOffset": offset, "byteLength": len(data)}
        if target:
            view["target"] = target
        views.append(view)
        chunks.append(data + b"\0" * (-len(data) % 4))
        return len(views) - 1

    pos_view = add(b"".join(struct.pack("<3f", *v) for v in verts), 34962)
    idx_view = add(b"".join(struct.pack("<3H", *f) for f in faces), 34963)
    accessors.append({"bufferView": pos_view, "componentType": 5126, "count": len(verts), "type": "VEC3",
                      "min": [min(v[c] for v in verts) for c in range(3)],
                      "max": [max(v[c] for v in verts) for c in range(3)]})
    accessors.append({"bufferView": idx_view, "componentType": 5123, "count": 3 * len(faces), "type": "SCALAR"})
    time_view = add(b"".join(struct.pack("<f", t) for t in times))
    if tangents:
        tr_view = add(b"".join(struct.pack("<3f", *t) + struct.pack("<3f", *p) + struct.pack("<3f", *t)
                               for p, t in zip(positions, tangents)))
    else:
        tr_view = add(b"".join(struct.pack("<3f", *p) for p in positions))
    rot_view = add(b"".join(struct.pack("<4f", *q) for q in rotations))
    accessors.append({"bufferView": time_view, "componentType": 5126, "count": len(times), "type": "SCALAR",
                      "min": [times[0]], "max": [times[-1]]})
    accessors.append({"bufferView": tr_view, "componentType": 5126, "count": (3 if tangents else 1) * len(times),
                      "type": "VEC3"})
    accessors.append({"bufferView": rot_view, "componentType": 5126, "count": len(times), "type": "VEC4"})
    blob = b"".join(chunks)
    gltf = {
        "asset": {"version": "2.0", "generator": "apparent data/scenes/make_keyed_gltf.py"},
        "scene": 0,
        "scenes": [{"name": "keyed", "nodes": [0, 1],
                    "extras": {"frames": {"start": 0, "end": 16, "fps": 10}, "model": "relativistic",
                               "tolerance": "vertex"}}],
        "nodes": [{"name": "camera", "camera": 0},
                  {"name": "box", "mesh": 0, "translation": positions[0], "rotation": rotations[0],
                   "extras": {"t0": 0}}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0471975511965976, "znear": 0.01, "zfar": 1000}}],
        "meshes": [{"name": "box", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "animations": [{"name": "path",
                        "channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}},
                                     {"sampler": 1, "target": {"node": 1, "path": "rotation"}}],
                        "samplers": [{"input": 2, "output": 3, "interpolation": "CUBICSPLINE" if tangents else "LINEAR"},
                                     {"input": 2, "output": 4, "interpolation": "LINEAR"}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    }
    with open(name, "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


rotations = [quat_y(0.0), quat_y(math.pi / 4), quat_y(math.pi / 2)]
write("keyed.gltf", [0.0, 5.0, 10.0], [[-4.0, -1.0, -6.0], [0.0, -1.0, -6.0], [0.0, 2.0, -6.0]], rotations)
# The same corner as a CUBICSPLINE, slower (keys at 0, 8, 16 s) so that the spline's overshoot and the
# turn stay below c: the reader samples it into many LINEAR keys (docs/MOTION.md "Keyframed paths").
write("keyed_cubic.gltf", [0.0, 8.0, 16.0], [[-4.0, -1.0, -6.0], [0.0, -1.0, -6.0], [0.0, 2.0, -6.0]], rotations,
      [[0.5, 0.0, 0.0], [0.25, 0.19, 0.0], [0.0, 0.375, 0.0]])
