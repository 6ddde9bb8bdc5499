#!/usr/bin/env python3
"""An interrupted render never leaves a truncated output file (docs/HOSTILE_INPUT.md).

1. A complete run writes out/relativistic.glb and 200 per-frame PLY files (tolerance 0.01).
2. A second run (tolerance 0.003, other bytes) into the same folder is killed with SIGKILL after
   some but not all frame files were replaced. Every file under a final name must be complete:
   each PLY walks from its header to exactly its last byte, the .glb's header length equals its
   size and its chunks parse, and the .glb is still the first run's (it is written last).
   Leftovers may only be temporary files named ".frame_NNNNN.tmp-PID-RANDOM.ply" or
   ".MODEL.tmp-PID-RANDOM.glb" (the .glb writer's spill file of frame data has no name: never left).
3. The same run stopped by SIGTERM, SIGINT and SIGHUP: exit 143, 130 and 129 with a one-line
   message, no temporary file left, every file complete.
4. The same run under a file size limit (RLIMIT_FSIZE, as a full disk): exit 3 with a one-line
   error, no temporary file left, every file complete.
Usage: kill_test.py APPARENT SOURCE_DIR
"""
import hashlib
import json
import os
import re
import resource
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time

APPARENT, SRC = sys.argv[1], sys.argv[2]
SCENE = os.path.join(SRC, "data", "scenes", "flanges.json")
FINAL = re.compile(r"^(frame_\d{5}\.ply|[a-z]+\.glb)$")
# AtomicOutput's temporary names: ".STEM.tmp-PID-RANDOM.EXT" (frames, the .glb).
TEMP = re.compile(r"^\.(frame_\d{5}|[a-z]+)\.tmp-\d+-[a-z0-9]{12}\.(ply|glb)$")
PLY_TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
             "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
             "float": "f", "float32": "f", "double": "d", "float64": "d"}
failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL:", msg)


def ply_complete(path):
    """Walks a binary little-endian PLY from its header to its end; True when it ends exactly there."""
    data = open(path, "rb").read()
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        return False
    elements = []
    for line in data[:end].decode("ascii", "replace").splitlines():
        w = line.split()
        if w[:1] == ["format"] and w[1] != "binary_little_endian":
            return False
        if w[:1] == ["element"]:
            elements.append((int(w[2]), []))
        elif w[:1] == ["property"]:
            elements[-1][1].append(w[1:])
    pos = end + len("end_header\n")
    for count, props in elements:
        for _ in range(count):
            for p in props:
                if p[0] == "list":
                    n_fmt, i_fmt = PLY_TYPES[p[1]], PLY_TYPES[p[2]]
                    if pos + struct.calcsize(n_fmt) > len(data):
                        return False
                    (n,) = struct.unpack_from("<" + n_fmt, data, pos)
                    pos += struct.calcsize(n_fmt) + n * struct.calcsize(i_fmt)
                else:
                    pos += struct.calcsize(PLY_TYPES[p[0]])
                if pos > len(data):
                    return False
    return pos == len(data)


def glb_complete(path):
    data = open(path, "rb").read()
    if len(data) < 20:
        return False
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF" or version != 2 or length != len(data):
        return False
    pos, chunks = 12, []
    while pos < len(data):
        if pos + 8 > len(data):
            return False
        clen, ctype = struct.unpack_from("<I4s", data, pos)
        chunks.append((ctype, data[pos + 8:pos + 8 + clen]))
        pos += 8 + clen
    if pos != len(data) or not chunks or chunks[0][0] != b"JSON":
        return False
    doc = json.loads(chunks[0][1].decode("utf-8"))
    bin_len = len(chunks[1][1]) if len(chunks) > 1 else 0
    return all(b.get("byteLength", 0) <= bin_len for b in doc.get("buffers", []))


def check_folder(out, label, allow_temp):
    """Every final file complete; temporary files only where allowed. Returns (finals, temps)."""
    finals, temps = [], []
    for folder, _, names in os.walk(out):
        for name in names:
            path = os.path.join(folder, name)
            if FINAL.match(name):
                finals.append(path)
                ok = ply_complete(path) if name.endswith(".ply") else glb_complete(path)
                check(ok, "%s: %s is not complete" % (label, path))
            elif TEMP.match(name):
                temps.append(path)
            else:
                check(False, "%s: unexpected file %s" % (label, path))
    check(allow_temp or not temps, "%s: temporary files left: %s" % (label, temps))
    return finals, temps


def sha(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def render_args(out, tolerance):
    return [APPARENT, "render", SCENE, "--out", out, "--model", "relativistic", "--format", "glb,ply",
            "--threads", "1", "--quiet", "--tolerance", tolerance]


def interrupted_run(out, sig, label):
    """Starts the slow run, waits until 20 or more frame files were replaced, sends `sig`."""
    marker = time.time()
    time.sleep(0.05)
    proc = subprocess.Popen(render_args(out, "0.003"), stderr=subprocess.PIPE, text=True)
    frames = os.path.join(out, "relativistic")
    replaced, deadline = 0, time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        replaced = sum(1 for n in os.listdir(frames)
                       if FINAL.match(n) and os.stat(os.path.join(frames, n)).st_mtime > marker)
        if replaced >= 20:
            break
        time.sleep(0.01)
    check(proc.poll() is None, "%s: the render ended before the signal (make it slower)" % label)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    replaced = sum(1 for n in os.listdir(frames) if FINAL.match(n) and os.stat(os.path.join(frames, n)).st_mtime > marker)
    print("%s: %d of 200 frame files replaced before the signal, exit %d" % (label, replaced, proc.returncode))
    check(0 < replaced < 200, "%s: %d frame files replaced (want some, not all)" % (label, replaced))
    return proc.returncode, err


def main():
    out = tempfile.mkdtemp(prefix="apparent_kill_")
    try:
        # Step 1: a complete run.
        subprocess.run(render_args(out, "0.01"), check=True)
        finals, _ = check_folder(out, "complete run", allow_temp=False)
        check(len(finals) == 201, "complete run: %d files, want 201" % len(finals))
        glb_before = sha(os.path.join(out, "relativistic.glb"))

        # Step 2: SIGKILL midway.
        code, _ = interrupted_run(out, signal.SIGKILL, "SIGKILL")
        check(code == -signal.SIGKILL, "SIGKILL: exit %s" % code)
        finals, temps = check_folder(out, "SIGKILL", allow_temp=True)
        check(len(finals) == 201, "SIGKILL: %d final files, want 201" % len(finals))
        check(sha(os.path.join(out, "relativistic.glb")) == glb_before, "SIGKILL: the .glb changed")
        print("SIGKILL: %d temporary file(s) left: %s" % (len(temps), [os.path.basename(t) for t in temps]))
        for t in temps:
            os.remove(t)

        # Step 3: SIGTERM, SIGINT and SIGHUP clean up after themselves.
        for sig, want, word in ((signal.SIGTERM, 143, "terminated (SIGTERM)"), (signal.SIGINT, 130, "interrupted (SIGINT)"),
                                (signal.SIGHUP, 129, "hung up (SIGHUP)")):
            label = signal.Signals(sig).name
            code, err = interrupted_run(out, sig, label)
            check(code == want, "%s: exit %s, want %d" % (label, code, want))
            check(word in err and err.count("\n") == 1, "%s: stderr %r" % (label, err))
            finals, _ = check_folder(out, label, allow_temp=False)
            check(len(finals) == 201, "%s: %d final files" % (label, len(finals)))

        # Step 4: a file size limit stands in for a full disk.
        limit = 64 * 1024
        proc = subprocess.run(render_args(out, "0.001"), stderr=subprocess.PIPE, text=True,
                              preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit)))
        print("file size limit: exit %d: %s" % (proc.returncode, proc.stderr.strip()))
        check(proc.returncode == 3, "file size limit: exit %d, want 3" % proc.returncode)
        check("cannot write" in proc.stderr and proc.stderr.count("\n") == 1, "file size limit: stderr %r" % proc.stderr)
        finals, _ = check_folder(out, "file size limit", allow_temp=False)
        check(len(finals) == 201, "file size limit: %d final files" % len(finals))
    finally:
        shutil.rmtree(out, ignore_errors=True)
    print("kill test: %s" % ("FAILED (%d)" % len(failures) if failures else "passed"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
