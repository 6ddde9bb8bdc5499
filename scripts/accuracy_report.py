#!/usr/bin/env python3
"""Fills the generated blocks of docs/ACCURACY.md from the measurements of scripts/accuracy_report.sh,
and writes docs/accuracy_<scene>.dat and docs/accuracy.gp for docs/accuracy.png.

Usage: accuracy_report.py TRADE_DIR DOCS_DIR      (the .sh runs it as: docs/trade docs)

Only the lines between a block's markers are replaced, every other byte of ACCURACY.md is kept:

    <!-- generated: NAME -->
    ... replaced ...
    <!-- end generated: NAME -->

The blocks (NAME: what fills it, from TRADE_DIR):
    method           the method paragraph (with measured.txt's date and build, if present)
    at-equal-error   the adaptive / uniform ratios at equal error (<scene>/trade.csv) and the plot's link
    end-to-end       end_to_end.md as scripts/trade_end_to_end.py wrote it
    cheap-path       cheap_path.json (performance_bench: BM_CutVertexMode, BM_CutTolerance)
    per-triangle     per_triangle.json (refine_bench: BM_PerTriangle)
    instructions     instructions.csv (callgrind counts of refine_bench --count)
    trade-<scene>    <scene>/table.txt, one per scene of SCENES
    motions-method   the other motions' method paragraph (with motions/measured.txt's date and build)
    motions-at-equal-error  each tolerance row of motions/<scene>/trade.csv against uniform subdivision
                     at the row's own error, parametric and geometric
    trade-<scene>    motions/<scene>/table.txt, one per scene of MOTION_SCENES
The hand-written analysis lives outside the markers. A block whose data file is absent is left as it
is (said on stderr). A marker missing, doubled, out of order or unknown, or a data file without a field
it needs: one line on stderr naming the file and the problem, exit 2, and nothing is written.

At each uniform subdivision level whose error lies in 1e-4 .. 1e-2 x size, the adaptive rows are
interpolated (log-log, between the two tolerances whose errors bracket it) to the same error: the
ratios of triangles and of time end to end are the comparison."""
import csv
import json
import math
import os
import re
import sys

SCENES = ["flanges", "box_near", "sphere320", "plate", "sphere20480"]
# The other motions (keyframed, accelerated, spinning, rolling), measured into TRADE_DIR/motions/.
MOTION_SCENES = ["keyed", "keyed_cubic", "rocket", "spinning_wheel", "rolling_wheel"]
BLOCKS = ["method", "at-equal-error", "end-to-end", "cheap-path", "per-triangle", "instructions"] + \
         [f"trade-{name}" for name in SCENES] + ["motions-method", "motions-at-equal-error"] + \
         [f"trade-{name}" for name in MOTION_SCENES]
BEGIN = re.compile(r"^<!-- generated: (\S+) -->$")
END = re.compile(r"^<!-- end generated: (\S+) -->$")


class BadInput(Exception):
    """One line naming the file, the field and the problem."""


def number(path, row_no, row, key):
    try:
        return float(row[key])
    except KeyError:
        raise BadInput(f"{path}: no column '{key}'")
    except (TypeError, ValueError):
        raise BadInput(f"{path}: row {row_no}, '{key}': not a number ({row[key]!r})")


def field(path, record, key):
    try:
        return record[key]
    except KeyError:
        raise BadInput(f"{path}: no field '{key}' in {record.get('name', 'the record')}")


def load_trade(path):
    """The rows of one scene's trade.csv that were measured (skipped ones left out)."""
    rows = []
    with open(path) as f:
        for i, r in enumerate(csv.DictReader(f), start=2):
            if field(path, r, "skipped") == "1":
                continue
            for k in ("parameter", "error_ls", "error_rel", "triangles_per_frame", "cut_seconds_per_frame",
                      "export_seconds_per_frame", "glb_bytes_per_frame"):
                r[k] = number(path, i, r, k)
            field(path, r, "family")
            # The geometric distance (added after the first reports: absent from older files).
            if r.get("geometric_error_ls") not in (None, ""):
                for k in ("geometric_error_ls", "geometric_error_rel"):
                    r[k] = number(path, i, r, k)
            r["total"] = r["cut_seconds_per_frame"] + r["export_seconds_per_frame"]
            rows.append(r)
    return rows


def interpolate(adaptive, error, key, by="error_ls"):
    """The adaptive rows' `key` at `error` (of column `by`), log-log between the bracketing rows (None outside)."""
    pts = sorted((r[by], r[key]) for r in adaptive if r[by] > 0)
    for (e0, v0), (e1, v1) in zip(pts, pts[1:]):
        if e0 <= error <= e1 and e0 < e1:
            t = (math.log(error) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(v0) + t * (math.log(v1) - math.log(v0)))
        if error == e0:
            return v0
    return None


def method_block(trade_dir):
    stamp = os.path.join(trade_dir, "measured.txt")
    when = ""
    if os.path.exists(stamp):
        text = open(stamp).read().strip()
        if text:
            when = f" ({text})"
    return ["Measured by `scripts/accuracy_report.sh`" + when + ": `apparent trade` on each scene (5 frames spread "
            "over the sequence, one thread, times in CPU time of the thread), tables in `docs/trade/<scene>/table.txt` "
            "and `trade.csv`. Each row: the measured two-sided error (`mesh4d/refine/measure.h`: 12 samples of every output "
            "triangle against the exact surface, and 45 exact-surface points of every input triangle against the "
            "output; the largest over objects and frames; parametric: each output point against the exact image of its own "
            "rest point, and, where trade.csv has it, geometric: against the nearest point of the other surface, "
            "geometricTwoSided), triangles per frame (mean), the cut (refinement included) "
            "and the .glb conversion per frame (normals, float32: the writer's per-frame work), and .glb bytes per "
            "frame. *Uniform k* splits every input triangle 4-to-1 k times, then vertex mode: what per-vertex engines "
            "do. *T* is `--tolerance T`, the adaptive refinement (`mesh4d/slice.h`, bound in `mesh4d/refine/chord_error.h`). "
            "Size = the largest moving object's bounding-box diagonal."]


def equal_error_rows(name, rows):
    adaptive = [r for r in rows if r["family"] == "tolerance"]
    out = []
    for u in (r for r in rows if r["family"] == "uniform"):
        rel = u["error_rel"]
        if not (1e-4 <= rel <= 1e-2):
            continue
        n = interpolate(adaptive, u["error_ls"], "triangles_per_frame")
        t = interpolate(adaptive, u["error_ls"], "total")
        if n is None:
            continue
        out.append(f"| {name} | {int(u['parameter'])}: {rel:.3g} | {u['triangles_per_frame']:.0f} | {n:.0f} | "
                   f"{n / u['triangles_per_frame']:.2f} | {t / u['total']:.2f} |")
    return out


def equal_geometric_error_rows(name, rows):
    """As equal_error_rows with the geometric distance (rows without it: none), the tolerance rows
    against uniform subdivision: uniform's triangles and time interpolated to each tolerance row's
    geometric error."""
    if not rows or "geometric_error_ls" not in rows[0]:
        return []
    uniform = [r for r in rows if r["family"] in ("vertex", "uniform")]  # vertex mode: uniform level 0
    size = next((r["error_ls"] / r["error_rel"] for r in rows if r["error_rel"] > 0), None)
    if size is None:
        return []
    out = []
    for a in (r for r in rows if r["family"] == "tolerance"):
        n = interpolate(uniform, a["geometric_error_ls"], "triangles_per_frame", "geometric_error_ls")
        t = interpolate(uniform, a["geometric_error_ls"], "total", "geometric_error_ls")
        if n is None:
            continue
        out.append(f"| {name} | {a['parameter'] / size:.2g} | "
                   f"{a['geometric_error_ls'] / a['parameter']:.2f} | {a['error_ls'] / a['parameter']:.2f} | "
                   f"{a['triangles_per_frame']:.0f} | {n:.0f} | {a['triangles_per_frame'] / n:.2f} | "
                   f"{a['total'] / t:.2f} |")
    return out


def motions_method_block(trade_dir):
    stamp = os.path.join(trade_dir, "motions", "measured.txt")
    text = open(stamp).read().strip() if os.path.exists(stamp) else ""
    return ["Measured by `scripts/accuracy_report.sh`" + (f" ({text})" if text else "") +
            ": `apparent trade SCENE --levels 4 --tolerances 1e-2,1e-3,1e-4` on each scene (5 frames spread over "
            "the sequence; the rolling wheel `--frames 8:9 --tolerances 1e-2,3e-3,1e-3`), one thread, CPU time of "
            "the thread, tables in `docs/trade/motions/<scene>/`. Each tolerance row against uniform subdivision "
            "(vertex mode as level 0, levels 1 - 4), uniform's triangles and time (cut + .glb conversion) "
            "interpolated log-log to the row's own measured error: parametric in the first table, geometric in the "
            "second (the exact surface found by `mesh4d/refine/measure.h`'s root search on the true worldlines). "
            "\"finer than uniform\": the row's error is below every uniform level's, so no uniform row matches it."]


def motions_rows(name, rows, by):
    """One line per tolerance row of `rows`: against uniform subdivision (vertex mode its level 0)
    interpolated log-log to the row's own error in column `by` (error_ls or geometric_error_ls)."""
    if not rows or by not in rows[0]:
        return []
    uniform = [r for r in rows if r["family"] in ("vertex", "uniform")]
    size = next((r["error_ls"] / r["error_rel"] for r in rows if r["error_rel"] > 0), None)
    if size is None:
        return []
    out = []
    for a in (r for r in rows if r["family"] == "tolerance"):
        err = a[by]
        head = f"| {name} | {a['parameter'] / size:.2g} | {err / a['parameter']:.2f} | {a['triangles_per_frame']:.0f} | " \
               f"{a['total'] * 1e3:.3g} |"
        n = interpolate(uniform, err, "triangles_per_frame", by)
        t = interpolate(uniform, err, "total", by)
        if n is None or t is None:
            finest = min((u for u in uniform if u[by] > 0), key=lambda u: u[by], default=None)
            coarsest = max(uniform, key=lambda u: u[by], default=None)
            if finest is not None and err < finest[by]:
                what = f"finer than uniform level {finest['parameter']:.0f} (its error {finest[by] / a['parameter']:.2g} T)"
            elif coarsest is not None and err > coarsest[by]:
                what = "coarser than vertex mode"
            else:
                what = "no uniform row brackets it"
            out.append(head + f" {what} | | | |")
            continue
        out.append(head + f" {n:.0f} | {t * 1e3:.3g} | {a['triangles_per_frame'] / n:.2f} | {a['total'] / t:.3g} |")
    return out


def motions_block(trade_dir):
    scene_rows = {}
    for name in MOTION_SCENES:
        path = os.path.join(trade_dir, "motions", name, "trade.csv")
        if os.path.exists(path):
            scene_rows[name] = load_trade(path)
    if not scene_rows:
        return None
    head = ["| scene | T / size | err / T | adaptive triangles | adaptive ms | uniform triangles at that error | "
            "uniform ms | triangles, adaptive / uniform | time, adaptive / uniform |", "|---|---|---|---|---|---|---|---|---|"]
    out = ["Parametric error (each output point against the exact image of its own rest point):", ""] + head
    for name, rows in scene_rows.items():
        out += motions_rows(name, rows, "error_ls")
    geometric = []
    for name, rows in scene_rows.items():
        geometric += motions_rows(name, rows, "geometric_error_ls")
    if geometric:
        out += ["", "Geometric distance (against the nearest point of the other surface: what `--tolerance` promises):",
                ""] + head + geometric
    return out


def cheap_path_block(path):
    bench = {b["name"]: b for b in field(path, json.load(open(path)), "benchmarks")}
    out = ["| N | vertex mode | T = 1e-3 x size | output triangles at T | ratio |", "|---|---|---|---|---|"]
    for n in ("1000", "10000", "100000", "1000000"):
        v, c = bench.get(f"BM_CutVertexMode/{n}"), bench.get(f"BM_CutTolerance/{n}")
        if v and c:
            vt, ct = field(path, v, "output_triangles"), field(path, c, "output_triangles")
            note = "" if ct == vt else " (refined: not a no-refinement case)"
            out.append(f"| {n} | {field(path, v, 'cpu_time'):.3g} {field(path, v, 'time_unit')} | "
                       f"{field(path, c, 'cpu_time'):.3g} {field(path, c, 'time_unit')} | {ct:.0f} of {vt:.0f}{note} | "
                       f"{c['cpu_time'] / v['cpu_time']:.2f} |")
    return out


def refine_bench_scene(code):
    return {"0": "box", "1": "sphere320"}.get(code, "plate (relativistic)")


def per_triangle_block(path):
    bench = [b for b in field(path, json.load(open(path)), "benchmarks")
             if b.get("run_type", "iteration") == "iteration"]
    out = ["| scene | k | output triangles at T | uniform triangles | tolerance, ns / triangle | "
           "vertex mode, ns / triangle | ratio |", "|---|---|---|---|---|---|---|"]
    for b in bench:
        parts = dict(p.split(":") for p in b["name"].split("/")[1:] if ":" in p)
        out.append(f"| {refine_bench_scene(parts.get('scene'))} | {parts.get('k')} | {field(path, b, 'triangles'):.0f} | "
                   f"{field(path, b, 'uniform_triangles'):.0f} | {field(path, b, 'tol_ns_per_tri'):.0f} | "
                   f"{field(path, b, 'vertex_ns_per_tri'):.1f} | {field(path, b, 'ratio'):.1f} |")
    return out


def instructions_block(path):
    out = ["| scene | k | output triangles at T | instructions / triangle | uniform triangles | "
           "vertex mode, instructions / triangle | ratio |", "|---|---|---|---|---|---|---|"]
    with open(path) as f:
        for i, r in enumerate(csv.DictReader(f), start=2):
            tol = number(path, i, r, "tolerance_instructions") / number(path, i, r, "tolerance_triangles")
            ver = number(path, i, r, "vertex_instructions") / number(path, i, r, "vertex_triangles")
            out.append(f"| {refine_bench_scene(field(path, r, 'scene'))} | {field(path, r, 'k')} | "
                       f"{r['tolerance_triangles']} | {tol:.0f} | {r['vertex_triangles']} | {ver:.1f} | {tol / ver:.1f} |")
    return out


def split_blocks(md_path, lines):
    """{name: (begin index, end index)} of the markers' lines; BadInput unless every block of BLOCKS
    is there exactly once, each begun before it ends and none inside another."""
    spans, open_name, open_at = {}, None, None
    for i, line in enumerate(lines):
        b, e = BEGIN.match(line), END.match(line)
        if b:
            name = b.group(1)
            if name not in BLOCKS:
                raise BadInput(f"{md_path}: line {i + 1}: unknown generated block '{name}' (known: {', '.join(BLOCKS)})")
            if open_name is not None:
                raise BadInput(f"{md_path}: line {i + 1}: block '{name}' begins inside block '{open_name}'")
            if name in spans:
                raise BadInput(f"{md_path}: line {i + 1}: block '{name}' appears twice")
            open_name, open_at = name, i
        elif e:
            if e.group(1) != open_name:
                raise BadInput(f"{md_path}: line {i + 1}: '<!-- end generated: {e.group(1)} -->' without its "
                               f"'<!-- generated: {e.group(1)} -->' marker before it; nothing written")
            spans[open_name] = (open_at, i)
            open_name = None
    if open_name is not None:
        raise BadInput(f"{md_path}: block '{open_name}' (line {open_at + 1}) has no "
                       f"'<!-- end generated: {open_name} -->' marker")
    missing = [n for n in BLOCKS if n not in spans]
    if missing:
        raise BadInput(f"{md_path}: marker '<!-- generated: {missing[0]} -->' missing"
                       + (f" (and {len(missing) - 1} more: {', '.join(missing[1:])})" if len(missing) > 1 else "")
                       + "; nothing written")
    return spans


def write_atomically(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def main(trade_dir, docs):
    md_path = os.path.join(docs, "ACCURACY.md")
    try:
        lines = open(md_path).read().split("\n")
    except OSError as err:
        raise BadInput(f"{md_path}: cannot be read ({err.strerror})")
    spans = split_blocks(md_path, lines)

    # Every block's new lines, or None where its data is absent (the block is then kept).
    new = {"method": method_block(trade_dir)}
    summary = ["| scene | uniform level: error / size | uniform triangles | adaptive triangles at that error | "
               "ratio | time (cut + .glb conversion), adaptive / uniform |", "|---|---|---|---|---|---|"]
    scene_rows = {}
    for name in SCENES:
        csv_path, table = os.path.join(trade_dir, name, "trade.csv"), os.path.join(trade_dir, name, "table.txt")
        if not (os.path.exists(csv_path) and os.path.exists(table)):
            new[f"trade-{name}"] = None
            continue
        scene_rows[name] = load_trade(csv_path)
        summary += equal_error_rows(name, scene_rows[name])
        new[f"trade-{name}"] = ["```"] + open(table).read().rstrip().split("\n") + ["```"]
    geometric = []
    for name, rows in scene_rows.items():
        geometric += equal_geometric_error_rows(name, rows)
    if geometric:
        summary += ["", "At equal geometric distance (what `--tolerance` promises; `mesh4d/refine/measure.h` geometricTwoSided): "
                    "each tolerance row against uniform subdivision interpolated log-log to the row's geometric error.", "",
                    "| scene | T / size | geometric / T | parametric / T | adaptive triangles | uniform triangles at that "
                    "geometric error | ratio | time, adaptive / uniform |", "|---|---|---|---|---|---|---|---|"] + geometric
    new["at-equal-error"] = summary + ["", "![error against triangles per frame](accuracy.png)"] if scene_rows else None
    e2e = os.path.join(trade_dir, "end_to_end.md")
    new["end-to-end"] = open(e2e).read().rstrip().split("\n") if os.path.exists(e2e) else None
    for name, file, make in (("cheap-path", "cheap_path.json", cheap_path_block),
                             ("per-triangle", "per_triangle.json", per_triangle_block),
                             ("instructions", "instructions.csv", instructions_block)):
        path = os.path.join(trade_dir, file)
        new[name] = make(path) if os.path.exists(path) else None
    new["motions-at-equal-error"] = motions_block(trade_dir)
    new["motions-method"] = motions_method_block(trade_dir) if new["motions-at-equal-error"] else None
    for name in MOTION_SCENES:
        table = os.path.join(trade_dir, "motions", name, "table.txt")
        new[f"trade-{name}"] = ["```"] + open(table).read().rstrip().split("\n") + ["```"] \
            if os.path.exists(table) else None

    # Replace the blocks from the last to the first, so that earlier spans keep their indices.
    for name, (b, e) in sorted(spans.items(), key=lambda s: -s[1][0]):
        if new[name] is None:
            print(f"accuracy_report.py: no data for block '{name}' in {trade_dir}: left as it was", file=sys.stderr)
            continue
        lines[b + 1:e] = [""] + new[name] + [""]
    write_atomically(md_path, "\n".join(lines))

    for name in SCENES:
        if name not in scene_rows:
            continue
        with open(os.path.join(docs, f"accuracy_{name}.dat"), "w") as d:
            for fam in ("vertex", "uniform", "tolerance"):
                d.write(f"# {fam}\n")
                for r in scene_rows[name]:
                    if r["family"] == fam:
                        d.write(f"{r['triangles_per_frame']} {r['error_rel']}\n")
                d.write("\n\n")
    with open(os.path.join(docs, "accuracy.gp"), "w") as g:
        g.write("set terminal pngcairo size 1000,620 font ',11' noenhanced\nset output 'accuracy.png'\nset logscale xy\n"
                "set xlabel 'output triangles per frame'\nset ylabel 'measured two-sided error / size'\nset grid\n"
                "set key outside right\nset title 'apparent: error against triangles (solid: --tolerance, dashed: uniform subdivision)'\n")
        plots = []
        for i, name in enumerate(SCENES):
            if name not in scene_rows:
                continue
            plots.append(f"'accuracy_{name}.dat' index 2 using 1:2 with linespoints lw 2 pt 7 lc {i + 1} title '{name}: tolerance'")
            plots.append(f"'accuracy_{name}.dat' index 1 using 1:2 with linespoints lw 1 dt 2 pt 6 lc {i + 1} title '{name}: uniform'")
        g.write("plot " + ", \\\n     ".join(plots) + "\n")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print("usage: accuracy_report.py TRADE_DIR DOCS_DIR", file=sys.stderr)
        sys.exit(2)
    try:
        main(sys.argv[1], sys.argv[2])
    except BadInput as err:
        print(f"accuracy_report.py: {err}", file=sys.stderr)
        sys.exit(2)
