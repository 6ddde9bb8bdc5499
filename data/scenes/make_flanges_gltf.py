#!/usr/bin/env python3
"""Writes flanges.gltf: the default scene of flanges.json authored as a glTF scene, as a Blender
user would export it with custom properties (docs/SCENES.md "Scenes in glTF"). Run from this folder; the
output is committed. Meshes come from ../meshes/flange.obj and ../meshes/stage.obj, embedded as
base64 data URIs so the file is self-contained."""
import base64
import json
import struct


from obj_mesh import read_obj


scene_json = json.load(open("flanges.json"))
meshes, accessors, views = [], [], []
blob = b""
mesh_index = {}
for name in ("flange", "stage", "backdrop"):
    verts, faces = read_obj(f"../meshes/{name}.obj")
    pos = b"".join(struct.pack("<3f", *v) for v in verts)
    idx = b"".join(struct.pack("<3H", *f) for f in faces)
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(pos), "target": 34962})
    blob += pos
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(idx), "target": 34963})
    blob += idx
    blob += b"\0" * (-len(blob) % 4)
    lo = [min(v[c] for v in verts) for c in range(3)]
    hi = [max(v[c] for v in verts) for c in range(3)]
    accessors.append({"bufferView": len(views) - 2, "componentType": 5126, "count": len(verts), "type": "VEC3",
                      "min": lo, "max": hi})
    accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": 3 * len(faces), "type": "SCALAR"})
    mesh_index[name] = len(meshes)
    meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                                 "indices": len(accessors) - 1}]})

# At the origin looking down -Z, like flanges.json; the instant model's look-back rides on the camera node.
nodes = [{"name": "camera", "camera": 0,
          "extras": {k: scene_json["camera"][k] for k in ("instant_delay",) if k in scene_json["camera"]}}]
for obj in scene_json["objects"]:
    extras = {k: obj[k] for k in ("t0", "velocity", "exists", "mirror") if k in obj}
    extras.setdefault("velocity", [0, 0, 0])
    nodes.append({"name": obj["name"], "mesh": mesh_index[obj["mesh"].split("/")[-1][:-4]],
                  "translation": obj["position"], "extras": extras})

gltf = {
    "asset": {"version": "2.0", "generator": "apparent data/scenes/make_flanges_gltf.py"},
    "scene": 0,
    "scenes": [{"name": "flanges", "nodes": list(range(len(nodes))),
                "extras": {k: scene_json[k] for k in ("frames", "model", "tolerance", "light") if k in scene_json}}],
    "nodes": nodes,
    "cameras": [{"type": "perspective",
                 "perspective": {"yfov": scene_json["camera"]["fov_deg"] * 3.141592653589793 / 180,
                                 "znear": 0.01, "zfar": 1000}}],
    "meshes": meshes,
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
}
with open("flanges.gltf", "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
