#!/usr/bin/env python3
"""Compares the .glb files two renders wrote (the scene's and its web file's, tests/web_file/run.sh).

usage: compare_glb.py A_DIR B_DIR

Every <model>.glb of A_DIR must have B_DIR's twin with the same BIN chunk byte for byte and the same
JSON document but scenes[0].extras.scene_file (it names the file rendered): the same frames, camera,
light, materials, images and extras.
"""
import glob
import json
import os
import struct
import sys


def read(path):
    data = open(path, "rb").read()
    length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + length])
    doc["scenes"][0].get("extras", {}).pop("scene_file", None)
    return doc, data[20 + length:]


files = sorted(glob.glob(os.path.join(sys.argv[1], "*.glb")))
if not files:
    sys.exit("no .glb in " + sys.argv[1])
for fa in files:
    fb = os.path.join(sys.argv[2], os.path.basename(fa))
    ja, ba = read(fa)
    jb, bb = read(fb)
    if ba != bb:
        sys.exit(f"{os.path.basename(fa)}: the BIN chunks differ")
    if ja != jb:
        for key in sorted(set(ja) | set(jb)):
            if ja.get(key) != jb.get(key):
                sys.exit(f"{os.path.basename(fa)}: the JSON differs in {key}: {json.dumps(ja.get(key))[:300]} != {json.dumps(jb.get(key))[:300]}")
print(f"{len(files)} .glb identical (but scene_file)")
