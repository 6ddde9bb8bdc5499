#!/usr/bin/env python3
"""Turns load_bench's JSON into the section "Loading and per-frame export against gltfpack" of
docs/PERFORMANCE.md, replacing that section when it is there, appending it otherwise.
Usage: load_report.py LOAD_BENCH_JSON PERFORMANCE_MD"""
import json
import sys

bench_json, out_md = sys.argv[1:3]
data = json.load(open(bench_json))
ctx = data["context"]
by = {}
for b in data["benchmarks"]:
    by[b["name"].split("/iterations")[0]] = b


def ms(b):
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
    return b["real_time"] * scale


sizes = [1000, 10000, 100000, 1000000]
formats = [("OBJ", 0, "the same OBJ"), ("PLY (binary)", 1, "the OBJ of the same torus"), (".glb", 2, "the same .glb")]
title = "## Loading and per-frame export against gltfpack"
md = [title, "",
      "What loading and writing a frame cost against the cut, and against gltfpack on the same files (issue 16).", "",
      f"Measured by `scripts/load_report.sh` (`benchmarks/load_bench.cpp`, Google Benchmark) on {ctx['num_cpus']} cores, "
      f"{ctx['date']}, load average {', '.join(f'{x:.1f}' for x in ctx.get('load_avg', []))} at the start "
      "(the machine was shared: ratios within this run only). Tori of the given triangle count (ring radius 2, tube 0.5), "
      "0.9c, vertex mode.", "",
      "**Loading**: a child process does what `apparent render` does before its first frame (scene, mesh file with "
      "every check, transform, the 4D history of one model); another runs `gltfpack -i FILE -o out.glb` (read, "
      "optimize, write) on the same file. Both are measured alike: wall time (mean of 3 runs) and peak resident "
      "memory (`ru_maxrss` from `wait4`). gltfpack reads no PLY: the PLY rows compare with gltfpack on the OBJ of the "
      "same torus. The OBJ is written with 17 digits (53 MB at 1M triangles); the .glb is gltfpack's own conversion "
      "of it (`-noq`, float positions).", "",
      "| triangles | file | load (s) | gltfpack (s) | time ratio | load peak (MiB) | gltfpack peak (MiB) | peak ratio |",
      "|---:|---|---:|---:|---:|---:|---:|---:|"]
for n in sizes:
    for name, f, _ in formats:
        b = by.get(f"BM_LoadVsGltfpack/{f}/{n}")
        if not b or "load_s" not in b:
            continue
        md.append(f"| {int(b['triangles']):,} | {name} | {b['load_s']:.3f} | {b['gltfpack_s']:.3f} | "
                  f"**{b['time_ratio']:.2f}** | {b['load_peak_MiB']:.1f} | {b['gltfpack_peak_MiB']:.1f} | "
                  f"**{b['peak_ratio']:.2f}** |")
md += ["",
       "**Per frame**: the vertex-mode cut of one frame (one core) and that frame written by the PLY sink (binary, "
       "double `x y z quality`) and the OBJ sink (17 digits), each through its temporary file with `fsync` and rename; "
       "the writers serialize in parallel blocks on the run's 2 threads.", "",
       "| triangles | cut (ms) | PLY bytes in memory (ms) | PLY write (ms) | PLY / cut | PLY bytes | OBJ write (ms) | OBJ / cut |",
       "|---:|---:|---:|---:|---:|---:|---:|---:|"]
for n in sizes:
    c, p, o, m = by.get(f"BM_Cut/{n}"), by.get(f"BM_WritePly/{n}"), by.get(f"BM_WriteObj/{n}"), by.get(f"BM_SerializePly/{n}")
    if not (c and p and o and m):
        continue
    md.append(f"| {int(c['triangles']):,} | {ms(c):.3f} | {ms(m):.3f} | {ms(p):.2f} | **{ms(p) / ms(c):.1f}** | "
              f"{int(p['bytes']):,} | {ms(o):.2f} | {ms(o) / ms(c):.1f} |")
small, big = by.get("BM_WritePly/1000"), by.get("BM_WritePly/1000000")
mem = by.get("BM_SerializePly/1000000")
if small and big and mem:
    md += ["",
           f"The 990-triangle PLY file takes {ms(small):.1f} ms to write against {ms(by['BM_SerializePly/1000']):.3f} ms "
           "for its bytes: below 100k triangles the time is the file's creation, write, `fsync` and rename "
           "(exporters/atomic_file.h), not its bytes. At 1M triangles the bytes take "
           f"{ms(mem):.1f} ms in memory of the {ms(big):.0f} ms the file takes."]
section = "\n".join(md) + "\n"

text = open(out_md).read()
start = text.find(title)
if start < 0:
    text = text.rstrip("\n") + "\n\n" + section
else:
    end = text.find("\n## ", start + len(title))
    text = text[:start] + section + (text[end + 1:] if end >= 0 else "")
open(out_md, "w").write(text)
