#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz harnesses (tests/fuzz) into OUT/<target>/:
scene  the shipped scenes and scene fixtures (data/scenes, data/fixtures);
obj    data/meshes, data/fixtures and Debian's assimp-testmodels OBJ and .mtl files (the harness reads
       each input as both);
ply    data/fixtures/ply and assimp-testmodels PLY files;
gltf   data/fixtures/gltf, data/scenes/flanges.gltf, tests/data/gltf-samples and
       assimp-testmodels .gltf files, each with its external buffers inlined as data: URIs
       (the harness reads one file; a relative URI would only find nothing);
glb    the .glb files of the same sources, and every one-buffer glTF seed packed as a .glb.
Files larger than MAX_BYTES are skipped (libFuzzer would truncate them to -max_len).
Usage: make_corpus.py OUT [MAX_BYTES]"""
import base64
import glob
import hashlib
import json
import os
import struct
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SAMPLES = os.path.join(ROOT, "tests", "data", "gltf-samples")
ASSIMP = "/usr/share/assimp/models"


def files(patterns):
    out = []
    for p in patterns:
        out += glob.glob(p, recursive=True)
    return sorted(set(out))


def inline_buffers(path):
    """The glTF JSON with relative buffer URIs replaced by base64 data URIs, or None."""
    try:
        with open(path, "rb") as f:
            doc = json.loads(f.read().decode("utf-8"))
        for b in doc.get("buffers", []):
            uri = b.get("uri", "")
            if uri and not uri.startswith("data:"):
                bin_path = os.path.join(os.path.dirname(path), uri)
                if os.path.isfile(bin_path):
                    with open(bin_path, "rb") as f:
                        b["uri"] = "data:application/octet-stream;base64," + base64.b64encode(f.read()).decode()
        return json.dumps(doc, separators=(",", ":")).encode()
    except (ValueError, UnicodeDecodeError, AttributeError, TypeError):
        with open(path, "rb") as f:  # broken on purpose: keep the bytes as they are
            return f.read()


def to_glb(gltf_bytes):
    """A .glb of an inlined glTF with one buffer (JSON chunk + BIN chunk), or None."""
    try:
        doc = json.loads(gltf_bytes.decode("utf-8"))
        buffers = doc.get("buffers", [])
        if not isinstance(buffers, list) or len(buffers) != 1 or not str(buffers[0].get("uri", "")).startswith("data:"):
            return None
        binary = base64.b64decode(buffers[0].pop("uri").split(",", 1)[1])
    except (ValueError, UnicodeDecodeError, AttributeError, TypeError, IndexError, KeyError):
        return None
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(text) + 8 + len(binary)
    return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(text), b"JSON") + text +
            struct.pack("<I4s", len(binary), b"BIN\0") + binary)


def main():
    out = sys.argv[1]
    max_bytes = int(sys.argv[2]) if len(sys.argv) > 2 else 65536
    d = lambda *p: os.path.join(ROOT, "data", *p)
    sources = {
        "scene": files([d("scenes", "*.json"), d("fixtures", "*.json")]),
        "obj": files([d("meshes", "*.obj"), d("fixtures", "*.obj"), ASSIMP + "/**/*.obj", ASSIMP + "/**/*.mtl"]),
        "ply": files([d("fixtures", "ply", "*.ply"), ASSIMP + "/**/*.ply"]),
        "gltf": files([d("fixtures", "gltf", "*.gltf"), d("scenes", "*.gltf"), SAMPLES + "/**/*.gltf", ASSIMP + "/**/*.gltf"]),
        "glb": files([d("scenes", "*.glb"), SAMPLES + "/**/*.glb", ASSIMP + "/**/*.glb"]),
    }
    for target, paths in sources.items():
        folder = os.path.join(out, target)
        os.makedirs(folder, exist_ok=True)
        kept = 0
        for p in paths:
            if target == "gltf":
                data = inline_buffers(p)
            else:
                with open(p, "rb") as f:
                    data = f.read()
            if len(data) > max_bytes:
                continue
            with open(os.path.join(folder, hashlib.sha1(data).hexdigest()), "wb") as f:
                f.write(data)
            kept += 1
            glb = to_glb(data) if target == "gltf" else None
            if glb and len(glb) <= max_bytes:  # the same model as a .glb seed
                os.makedirs(os.path.join(out, "glb"), exist_ok=True)
                with open(os.path.join(out, "glb", hashlib.sha1(glb).hexdigest()), "wb") as f:
                    f.write(glb)
        print("%s: %d of %d files (<= %d bytes), %d seeds in all" % (target, kept, len(paths), max_bytes, len(os.listdir(folder))))
    # Generated nesting seeds: just under and over the depth limit (128), and deep.
    for depth in (127, 129, 5000):
        nested = "[" * depth + "]" * depth
        scene = ('{"frames": {"start": 0, "end": 1, "fps": 2}, "objects": [{"mesh": "m.obj", "position": %s}]}' % nested)
        gltf = ('{"asset": {"version": "2.0"}, "scenes": [{"nodes": [0], "extras": {"a": %s}}], "nodes": [{"extras": %s}]}'
                % (nested, nested))
        for target, text in (("scene", scene), ("gltf", gltf)):
            data = text.encode()
            with open(os.path.join(out, target, hashlib.sha1(data).hexdigest()), "wb") as f:
                f.write(data)


if __name__ == "__main__":
    main()
