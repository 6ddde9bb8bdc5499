#!/usr/bin/env python3
"""Turns performance_bench's JSON into docs/PERFORMANCE.md, adding peak memory against frame count
measured on separate `apparent render` processes (ru_maxrss of each child, one process per run)."""
import json
import math
import os
import platform
import subprocess
import sys
import tempfile

bench_json, apparent, out_md = sys.argv[1:4]
apparent = os.path.abspath(apparent)
data = json.load(open(bench_json))
ctx = data["context"]
by = {}
for b in data["benchmarks"]:
    name, _, arg = b["name"].partition("/")
    by.setdefault(name, {})[arg.split("/")[0]] = b


def ms(b):
    """Wall time per iteration in ms."""
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
    return b["real_time"] * scale


def cpu_ms(b):
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
    return b["cpu_time"] * scale


def torus_obj(path, n):
    nv = max(4, int(math.sqrt(n / 8.0)))
    nu = max(4, n // (2 * nv))
    with open(path, "w") as f:
        for i in range(nu):
            for j in range(nv):
                u, v = 2 * math.pi * i / nu, 2 * math.pi * j / nv
                f.write(f"v {(2 + 0.5 * math.cos(v)) * math.cos(u)!r} {0.5 * math.sin(v)!r} "
                        f"{(2 + 0.5 * math.cos(v)) * math.sin(u)!r}\n")
        idx = lambda i, j: (i % nu) * nv + (j % nv) + 1
        for i in range(nu):
            for j in range(nv):
                f.write(f"f {idx(i, j)} {idx(i, j + 1)} {idx(i + 1, j)}\n")
                f.write(f"f {idx(i + 1, j)} {idx(i, j + 1)} {idx(i + 1, j + 1)}\n")
    return 2 * nu * nv


def peak_rss(frames, tmp, triangles):
    scene = os.path.join(tmp, f"scene_{frames}.json")
    with open(scene, "w") as f:
        json.dump({"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]},
                   "frames": {"start": 0, "end": frames / 10.0, "fps": 10},
                   "model": "relativistic", "tolerance": "vertex",
                   "objects": [{"mesh": "torus.obj", "position": [-4, 0, -10], "velocity": [0.8, 0, 0]}]}, f)
    probe = ("import resource, subprocess, sys, time; t = time.time(); "
             "r = subprocess.run(sys.argv[1:]); "
             "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, time.time() - t, r.returncode)")
    out = subprocess.run([sys.executable, "-c", probe, apparent, "render", scene, "--out", os.path.join(tmp, "out"),
                          "--format", "glb", "--quiet"], capture_output=True, text=True, check=True, cwd=tmp).stdout
    kb, secs, code = out.split()
    assert code == "0", out
    size = os.path.getsize(os.path.join(tmp, "out", "relativistic.glb"))
    return int(kb) / 1024.0, float(secs), size


with tempfile.TemporaryDirectory() as tmp:
    tris = torus_obj(os.path.join(tmp, "torus.obj"), 20000)
    memory = [(n,) + peak_rss(n, tmp, tris) for n in (1, 10, 100, 1000)]

# The target run end to end: 1M triangles, 100 frames, tolerance 1e-3 x size (5e-3 ls), .glb, 2 threads,
# the torus passing 10 ls away at 0.9c as in the benchmarks (frames from t = -5 s to 5 s).
with tempfile.TemporaryDirectory() as tmp:
    big_tris = torus_obj(os.path.join(tmp, "torus.obj"), 1000000)
    scene = os.path.join(tmp, "scene.json")
    with open(scene, "w") as f:
        json.dump({"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]},
                   "frames": {"start": -5, "end": 5, "fps": 10}, "model": "relativistic", "tolerance": 0.005,
                   "objects": [{"mesh": "torus.obj", "position": [0, 0, -10], "velocity": [0.9, 0, 0]}]}, f)
    probe = ("import resource, subprocess, sys, time; t = time.time(); r = subprocess.run(sys.argv[1:]); "
             "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, time.time() - t, r.returncode)")
    out = subprocess.run([sys.executable, "-c", probe, apparent, "render", scene, "--out", os.path.join(tmp, "out"),
                          "--format", "glb", "--threads", "2", "--quiet"], capture_output=True, text=True, check=True,
                         cwd=tmp).stdout
    kb, secs, code = out.split()
    assert code == "0", out
    big = (float(secs), int(kb) / 1024.0, os.path.getsize(os.path.join(tmp, "out", "relativistic.glb")))

cpu = "unknown CPU"
try:
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
except OSError:
    pass
mem_gib = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30

md = ["# Performance", "",
      f"Measured by `scripts/performance_report.sh` (Google Benchmark, `benchmarks/performance_bench.cpp`) on "
      f"{ctx['num_cpus']} cores of {cpu} at {ctx['mhz_per_cpu']} MHz, {mem_gib:.0f} GiB, {platform.platform()}, "
      f"{ctx['date']}; build type RelWithDebInfo (-O2). Rates use CPU time of the benchmark thread (per core); "
      "times are wall clock. Ratios are within this one run. The meshes are tori of the given triangle count "
      "(ring radius 2, tube 0.5, size 5 ls) passing 10 ls from the camera at 0.9c, relativistic.", ""]

copy = by["BM_MemoryCopy"][""]
bw = copy["bytes_per_second"]
limit = bw / 50.0
md += ["## The machine's limit", "",
       f"A 256 MiB `memcpy` moves {bw / 1e9:.1f} GB/s (read + write) on one core. The vertex-mode cut reads a "
       "rest position (24 bytes) and writes a position, an emission time, the rest point and the triangles "
       f"(about 50 bytes per vertex in all): memory alone would allow about {limit / 1e6:.0f}M vertex-frames/s per core.",
       ""]

md += ["## 1. Vertex-mode throughput (one core)", "",
       "| triangles | vertices | cut per frame (ms) | vertex-frames/s |", "|---:|---:|---:|---:|"]
for arg, b in sorted(by["BM_CutVertexMode"].items(), key=lambda kv: int(kv[0])):
    verts = b["input_triangles"] / 2
    md.append(f"| {int(b['input_triangles']):,} | {int(verts):,} | {cpu_ms(b):.3f} | {b['vertex_frames_per_s'] / 1e6:.1f}M |")
md += ["", "The closed form alone (`cutRestLocalBatch`: positions and emission times, without the output "
       "mesh's triangles and rest points that `sliceWorld` copies): " +
       ", ".join(f"{int(a) // 2:,} vertices {b['vertex_frames_per_s'] / 1e6:.0f}M/s"
                 for a, b in sorted(by["BM_ClosedFormOnly"].items(), key=lambda kv: int(kv[0]))) + "."]
exp = by["BM_ExportFrame"]
md += ["", "End to end, the 1M-triangle torus cut and written in one frame (one core):", "",
       "| output | per frame (ms) | vertex-frames/s |", "|---|---:|---:|"]
for arg, label in (("0", ".glb (NORMAL, _EMISSION_TIME, crease split)"), ("1", "PLY (binary, double quality)")):
    b = exp[arg]
    md.append(f"| {label} | {ms(b):.0f} | {b['vertex_frames_per_s'] / 1e6:.2f}M |")

md += ["", "## 2. Time per frame against triangle count", "",
       "| triangles | vertex mode (ms) | per 1k triangles (us) | tolerance 1e-3 x size (ms) | output triangles at 1e-3 |",
       "|---:|---:|---:|---:|---:|"]
for arg in sorted(by["BM_CutVertexMode"], key=int):
    v, t = by["BM_CutVertexMode"][arg], by["BM_CutTolerance"][arg]
    md.append(f"| {int(v['input_triangles']):,} | {cpu_ms(v):.3f} | {1e3 * cpu_ms(v) / v['input_triangles'] * 1e3:.2f} | "
              f"{cpu_ms(t):.2f} | {int(t['output_triangles']):,} |")

md += ["", "## 3. Total time and peak memory against frame count", "",
       f"`apparent render` of a {tris:,}-triangle torus at 0.8c to a .glb, 10 fps. Time from Google Benchmark "
       "(in process); peak resident memory from a separate process per run (ru_maxrss).", "",
       "| frames | time in process (ms) | per frame (ms) | separate process: wall time (s) | peak memory (MiB) | .glb size (MiB) |",
       "|---:|---:|---:|---:|---:|---:|"]
for n, rss, secs, size in memory:
    b = by["BM_Frames"][str(n)]
    md.append(f"| {n} | {ms(b):.0f} | {ms(b) / n:.2f} | {secs:.2f} | {rss:.1f} | {size / 2**20:.1f} |")
grow = (memory[-1][1] - memory[1][1]) / (memory[-1][0] - memory[1][0]) * 1024
md += ["", f"The frame data streams to the file; what grows is the .glb's JSON side (tinygltf's description of "
       f"each frame's node, mesh, accessors and animation channel, serialized at the end): about {grow:.0f} KiB "
       f"per frame here, against {memory[-1][3] / memory[-1][0] / 1024:.0f} KiB of frame data per frame in the file. "
       "The first in-process run also pays the one-time start-up (first touch of memory, TBB)."]

on, off = by["BM_Culling"]["1"], by["BM_Culling"]["0"]
md += ["", "## 4. Culling: 100 objects, most not existing or out of view", "",
       "100 tori of 2,000 triangles, half behind the camera, each existing for 1 s of proper time in a 20 s "
       "sequence (200 frames), staggered; cut of all frames, vertex mode.", "",
       "| | time (ms) | object-frames cut | object-frames with something shown |", "|---|---:|---:|---:|",
       f"| 4D-box cull and --cull-view | {ms(on):.1f} | {int(on['object_frames_cut'])} | {int(on['object_frames_shown'])} |",
       f"| both off | {ms(off):.1f} | {int(off['object_frames_cut'])} | {int(off['object_frames_shown'])} |",
       "", f"Ratio: culling makes it **{ms(off) / ms(on):.1f}x** faster."]

t1, t2 = by["BM_Threads"]["1"], by["BM_Threads"]["2"]
md += ["", "## 5. Threads", "",
       "`apparent render`, 40 frames of a 200k-triangle torus to a .glb (cutting in parallel, writing in order).", "",
       "| threads | time (ms) |", "|---:|---:|", f"| 1 | {ms(t1):.0f} |", f"| 2 | {ms(t2):.0f} |", "",
       f"Speed-up: **{ms(t1) / ms(t2):.2f}x** on 2 threads."]

m100 = by["BM_Million100"]["2"]
best = max(b["vertex_frames_per_s"] for b in by["BM_CutVertexMode"].values())
md += ["", "## Targets", "",
       f"- Vertex-mode cone cut, at least 100M vertex-frames/s per core: the closed form alone reaches "
       f"**{max(b['vertex_frames_per_s'] for b in by['BM_ClosedFormOnly'].values()) / 1e6:.0f}M**; the whole frame "
       f"cut with its output mesh up to **{best / 1e6:.0f}M** (memory limit estimated above: {limit / 1e6:.0f}M).",
       f"- 1M triangles, 100 frames, tolerance 1e-3 x size, under a minute on 2 cores: `apparent render` end to "
       f"end ({big_tris:,} triangles, tolerance 0.005 ls, .glb, `--threads 2`) takes **{big[0]:.1f} s** wall "
       f"time, peak memory {big[1]:.0f} MiB, writing {big[2] / 2**30:.2f} GiB; the cut alone **{ms(m100) / 1e3:.1f} s** "
       f"(up to {int(m100['max_output_triangles']):,} output triangles per frame).",
       f"- Culling ratio in benchmark 4 at least 10x: **{ms(off) / ms(on):.1f}x**.", ""]
open(out_md, "w").write("\n".join(md) + "\n")
print("\n".join(md))
