#!/usr/bin/env python3
"""End to end at equal error (docs/ACCURACY.md, docs/trade/end_to_end.md): `apparent render` of a whole
trade scene (every frame, one thread, .glb) with the input subdivided uniformly k times (--tolerance vertex,
what per-vertex engines do) against the original input at --tolerance = the error uniform level k measured
(docs/trade/<scene>/trade.csv, written by scripts/accuracy_report.sh). The subdivided meshes go to a temporary
folder (4-to-1 splits at edge midpoints, as mesh4d/refine/subdivide.h).

Timing on a shared machine: the CPU time (user + system) of the child process, so time spent waiting for a
core is left out; every run of a row is alternated with the others of the row (uniform, tolerance, and each
again with --fps-factor times the frame rate), the order turned round on every repetition, and the least of
--runs repetitions is reported with the spread (median over least). The whole run is what a user waits for:
process start, loading and the .glb's assembly weigh as much as the frames in these short runs (9 - 230 ms),
so the CPU per frame is reported too: the same scene at --fps-factor times the frame rate (the same span of
time, so its frames sample the same motion) minus the scene itself, over the frames it adds.

Usage: scripts/trade_end_to_end.py BUILD_DIR [--runs N] [--fps-factor F] [--peer APPARENT] [--count]
  > docs/trade/end_to_end.md
--peer: a second binary (e.g. the main branch's, copied aside) whose tolerance runs are alternated with the
same row's, for a before/after in one session: adds its time and its ratio against this build's uniform run.
--count: a second table, where the instructions go (valgrind --tool=callgrind, which counts the same on a
loaded machine): each run of the first table split into the cut (mesh4d::sliceWorld: in tolerance mode the
refinement), the light factors, the .glb (the sinks' prepare, add and finish), loading with the 4D worlds,
and the rest (process start, scene parsing)."""
import argparse
import csv
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
SCENES = [("box_near", "box"), ("sphere320", "icosphere320"), ("plate", "plate")]
COMMON = ["--threads", "1", "--quiet", "--allow-outside", "--format", "glb"]


def load_obj(path):
    V, F = [], []
    for line in open(path):
        if line.startswith("v "):
            V.append(tuple(map(float, line.split()[1:4])))
        elif line.startswith("f "):
            F.append(tuple(int(x.split("/")[0]) - 1 for x in line.split()[1:4]))
    return V, F


def subdivide(V, F):
    V, mid, G = list(V), {}, []

    def m(a, b):
        key = (min(a, b), max(a, b))
        if key not in mid:
            V.append(tuple((V[a][i] + V[b][i]) / 2 for i in range(3)))
            mid[key] = len(V) - 1
        return mid[key]

    for a, b, c in F:
        ab, bc, ca = m(a, b), m(b, c), m(c, a)
        G += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return V, G


def cpu_seconds(args):
    """CPU time (user + system) of one run of the child process."""
    p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(p.pid, 0)
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        raise subprocess.CalledProcessError(code, args)
    return usage.ru_utime + usage.ru_stime


def frame_count(args):
    """Frames the run renders, from its summary line ("<model>: N frames, up to ...")."""
    done = subprocess.run([a for a in args if a != "--quiet"], capture_output=True, text=True, check=True)
    text = done.stdout + done.stderr
    m = re.search(r": (\d+) frames, up to", text)
    if not m:
        sys.exit("trade_end_to_end.py: no frame count in the summary of " + " ".join(args))
    return int(m.group(1))


def alternate(runs, commands):
    """The CPU seconds of `runs` repetitions of every command, alternated; the order is reversed on
    every other repetition, so neither command always follows the other."""
    times = {name: [] for name in commands}
    names = list(commands)
    for r in range(runs):
        for name in (names if r % 2 == 0 else names[::-1]):
            times[name].append(cpu_seconds(commands[name]))
    return times


# Inclusive instruction counts of the phases of a run (callgrind_annotate's function names).
PHASES = [("cut", ["mesh4d::sliceWorld("]), ("light", ["mesh4d::addLightFactors("]),
          ("glb", ["apparent::GlbSink::prepare(", "apparent::GlbSink::add(", "apparent::GlbSink::finish("]),
          ("load", ["apparent::loadStage(", "apparent::takeWorlds("])]


def count_phases(args, tmp):
    """Instructions of one run: total and per phase (PHASES), from callgrind's inclusive costs."""
    out = os.path.join(tmp, "callgrind.out")
    subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + out] + args,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", out],
                          capture_output=True, text=True, check=True).stdout
    os.remove(out)

    def cost(name):
        for line in text.split("\n"):
            if name in line and re.match(r"^\s*[\d,]+ ", line):
                return int(line.split()[0].replace(",", ""))
        return 0

    total = int(re.search(r"^\s*([\d,]+) .*PROGRAM TOTALS", text, re.M).group(1).replace(",", ""))
    counts = {phase: sum(cost(n) for n in names) for phase, names in PHASES}
    counts["rest"] = total - sum(counts.values())
    counts["total"] = total
    return counts


def write_scene(spec, mesh, fps_factor, path):
    s = json.loads(json.dumps(spec))
    s["objects"][0]["mesh"] = mesh
    s["frames"]["fps"] = s["frames"]["fps"] * fps_factor
    json.dump(s, open(path, "w"))
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build", nargs="?", default=os.path.join(ROOT, "build"))
    ap.add_argument("--runs", type=int, default=11, help="repetitions of every run (the least is reported)")
    ap.add_argument("--fps-factor", type=int, default=10, help="frame rate factor of the runs that give the CPU per frame")
    ap.add_argument("--peer", help="a second apparent binary whose tolerance runs are alternated with this build's")
    ap.add_argument("--max-level", type=int, default=4, help="the finest uniform level compared (1 - 4)")
    ap.add_argument("--count", action="store_true", help="also count instructions per phase (callgrind)")
    args = ap.parse_args()
    apparent = os.path.join(os.path.abspath(args.build), "apparent")
    peer = os.path.abspath(args.peer) if args.peer else None
    k = args.fps_factor

    def spread(ts):
        return 100 * (statistics.median(ts) / min(ts) - 1)

    head = ("| scene | uniform level k | its error (ls) | frames | uniform: s (spread), .glb MB | "
            "--tolerance (that error): s (spread), .glb MB | time ratio | CPU per frame, ms: uniform, tolerance | "
            "per-frame ratio | size ratio |")
    if peer:
        head += " peer's tolerance: s | peer's ratio | peer's per-frame ratio |"
    print(head)
    print("|---" * (head.count("|") - 1) + "|")
    counted = []
    with tempfile.TemporaryDirectory() as tmp:
        for scene, mesh in SCENES:
            rows = list(csv.DictReader(open(os.path.join(ROOT, "docs", "trade", scene, "trade.csv"))))
            spec = json.load(open(os.path.join(ROOT, "data", "scenes", "trade", scene + ".json")))
            mesh_path = os.path.join(ROOT, "data", "meshes", mesh + ".obj")
            V, F = load_obj(mesh_path)
            base = write_scene(spec, mesh_path, 1, os.path.join(tmp, scene + ".json"))
            base_k = write_scene(spec, mesh_path, k, os.path.join(tmp, f"{scene}_x{k}.json"))
            for level in range(1, args.max_level + 1):
                V, F = subdivide(V, F)
                row = next((r for r in rows if r["family"] == "uniform" and int(float(r["parameter"])) == level), None)
                if row is None or row["skipped"] == "1":
                    break
                obj = os.path.join(tmp, f"{mesh}_u{level}.obj")
                with open(obj, "w") as f:
                    f.writelines("v %.17g %.17g %.17g\n" % v for v in V)
                    f.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in F)
                sub = write_scene(spec, obj, 1, os.path.join(tmp, f"{scene}_u{level}.json"))
                sub_k = write_scene(spec, obj, k, os.path.join(tmp, f"{scene}_u{level}_x{k}.json"))
                error = repr(float(row["error_ls"]))
                out = {n: os.path.join(tmp, n) for n in ("u", "a", "p")}
                uniform = ["--tolerance", "vertex"] + COMMON
                tol = ["--tolerance", error] + COMMON
                commands = {
                    "u": [apparent, "render", sub, "--out", out["u"]] + uniform,
                    "a": [apparent, "render", base, "--out", out["a"]] + tol,
                    "uk": [apparent, "render", sub_k, "--out", out["u"] + "k"] + uniform,
                    "ak": [apparent, "render", base_k, "--out", out["a"] + "k"] + tol,
                }
                if peer:
                    commands["p"] = [peer, "render", base, "--out", out["p"]] + tol
                    commands["pk"] = [peer, "render", base_k, "--out", out["p"] + "k"] + tol
                n1, nk = frame_count(commands["u"]), frame_count(commands["uk"])
                if frame_count(commands["a"]) != n1 or frame_count(commands["ak"]) != nk:
                    sys.exit(f"trade_end_to_end.py: {scene}: the two runs render different frame counts")
                t = alternate(args.runs, commands)
                best = {name: min(ts) for name, ts in t.items()}
                per_frame = {name: (best[name + "k"] - best[name]) / (nk - n1) for name in ("u", "a", "p") if name in best}
                model = spec.get("model", "relativistic")
                mb = {name: os.path.getsize(os.path.join(out[name], model + ".glb")) / 1e6 for name in ("u", "a")}
                line = (f"| {scene} | {level} | {float(error):.3g} | {n1} | {best['u']:.4f} ({spread(t['u']):.0f}%), {mb['u']:.2f} | "
                        f"{best['a']:.4f} ({spread(t['a']):.0f}%), {mb['a']:.2f} | {best['a'] / best['u']:.2f} | "
                        f"{1e3 * per_frame['u']:.3f}, {1e3 * per_frame['a']:.3f} | {per_frame['a'] / per_frame['u']:.2f} | "
                        f"{mb['a'] / mb['u']:.2f} |")
                if peer:
                    line += (f" {best['p']:.4f} ({spread(t['p']):.0f}%) | {best['p'] / best['u']:.2f} | "
                             f"{per_frame['p'] / per_frame['u']:.2f} |")
                print(line, flush=True)
                if args.count:
                    cu, ca = count_phases(commands["u"], tmp), count_phases(commands["a"], tmp)
                    counted.append(f"| {scene} | {level} | " + " | ".join(
                        f"{cu[p] / 1e6:.1f}, {ca[p] / 1e6:.1f}" for p in ("total", "cut", "light", "glb", "load", "rest")) +
                        f" | {ca['total'] / cu['total']:.2f} | {(ca['cut'] - (ca['total'] - cu['total'])) / ca['cut']:.2f} |")
    print()
    print(f"Least CPU time (user + system) of {args.runs} alternated runs each; spread: the median over the least. "
          f"CPU per frame: (least of the run at {k}x the frame rate - least of the run) / the frames it adds.")
    if counted:
        print()
        print("| scene | k | instructions, M: uniform, tolerance | cut | light factors | .glb | load and 4D worlds | "
              "rest | instruction ratio | cut at parity / cut |")
        print("|---" * 10 + "|")
        print("\n".join(counted))
        print()
        print("Instructions of the first table's runs (callgrind, inclusive): the cut is mesh4d::sliceWorld (in "
              "tolerance mode the refinement), .glb the sinks' prepare, add and finish, rest the process start and "
              "the scene. Cut at parity: the share of the tolerance run's cut it may keep for the whole run to count "
              "no more instructions than the uniform one (above 1: already fewer).")


if __name__ == "__main__":
    main()
