#!/usr/bin/env python3
"""Packs a .gltf whose buffers are data URIs into a .glb holding the same JSON and buffer bytes.

The buffers are joined into the BIN chunk (each 4-byte aligned), their views moved by their
buffer's place; nothing else changes. usage: pack_glb.py IN.gltf OUT.glb
"""
import base64
import json
import struct
import sys

doc = json.load(open(sys.argv[1]))
bin_chunk = b""
offsets = []
for b in doc.get("buffers", []):
    uri = b["uri"]
    if not uri.startswith("data:"):
        sys.exit(f"{sys.argv[1]}: buffer {uri} is not a data URI")
    data = base64.b64decode(uri.split(",", 1)[1])
    offsets.append(len(bin_chunk))
    bin_chunk += data + b"\0" * (-len(data) % 4)
for v in doc.get("bufferViews", []):
    v["byteOffset"] = v.get("byteOffset", 0) + offsets[v["buffer"]]
    v["buffer"] = 0
doc["buffers"] = [{"byteLength": len(bin_chunk)}]
text = json.dumps(doc, separators=(",", ":")).encode()
text += b" " * (-len(text) % 4)
out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(bin_chunk))
out += struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(bin_chunk), 0x004E4942) + bin_chunk
open(sys.argv[2], "wb").write(out)
