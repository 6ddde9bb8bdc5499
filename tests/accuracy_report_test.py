#!/usr/bin/env python3
"""scripts/accuracy_report.py on a copy of docs/ACCURACY.md and docs/trade/ in a temporary directory:
every line outside the generated blocks is kept byte for byte (a hand-written sentinel paragraph among
them), a generated table follows its data file (instructions.csv changed, the expected row computed
here from the CSV's counts), a second run changes nothing, and a missing marker exits 2 with one line
naming it while neither ACCURACY.md nor accuracy.gp is written.
Usage: accuracy_report_test.py REPOSITORY_ROOT"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

root = sys.argv[1]
script = os.path.join(root, "scripts", "accuracy_report.py")
MARKER = re.compile(r"^<!-- (end )?generated: (\S+) -->$")
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL: " + what, file=sys.stderr)


def outside_blocks(text):
    """The lines outside every generated block, markers included."""
    kept, inside = [], False
    for line in text.split("\n"):
        m = MARKER.match(line)
        if m:
            inside = m.group(1) is None
            kept.append(line)
        elif not inside:
            kept.append(line)
    return kept


def block(text, name):
    return text.split(f"<!-- generated: {name} -->\n", 1)[1].split(f"<!-- end generated: {name} -->", 1)[0]


def run(trade, docs):
    return subprocess.run([sys.executable, script, trade, docs], capture_output=True, text=True)


with tempfile.TemporaryDirectory() as tmp:
    docs, trade = os.path.join(tmp, "docs"), os.path.join(tmp, "docs", "trade")
    os.makedirs(docs)
    shutil.copytree(os.path.join(root, "docs", "trade"), trade)
    md = os.path.join(docs, "ACCURACY.md")
    original = open(os.path.join(root, "docs", "ACCURACY.md")).read()
    sentinel = "Sentinel paragraph, hand-written between two sections: it must survive the report."
    original = original.replace("\n## Where nothing needs refining\n", f"\n{sentinel}\n\n## Where nothing needs refining\n", 1)
    check(sentinel in original, "the sentinel was placed in the copy")
    open(md, "w").write(original)

    # The instructions of the box at k = 3 doubled: its row must read 2 x 901770 / 640 = 2818 per triangle
    # (the vertex side 53148 / 768 = 69.2, the ratio 40.7), whatever the committed table says.
    csv_path = os.path.join(trade, "instructions.csv")
    rows = open(csv_path).read().split("\n")
    head = rows[0].split(",")
    for i, r in enumerate(rows[1:], start=1):
        f = r.split(",")
        if len(f) == len(head) and f[0] == "0" and f[1] == "3":
            f[head.index("tolerance_instructions")] = str(2 * int(f[head.index("tolerance_instructions")]))
            tol = int(f[head.index("tolerance_instructions")]) / int(f[head.index("tolerance_triangles")])
            ver = int(f[head.index("vertex_instructions")]) / int(f[head.index("vertex_triangles")])
            expected_row = f"| box | 3 | {f[2]} | {tol:.0f} | {f[4]} | {ver:.1f} | {tol / ver:.1f} |"
            rows[i] = ",".join(f)
    open(csv_path, "w").write("\n".join(rows))

    r = run(trade, docs)
    check(r.returncode == 0, f"the report exits 0 (got {r.returncode}: {r.stderr.strip()})")
    after = open(md).read()
    check(outside_blocks(after) == outside_blocks(original), "every line outside the generated blocks is kept")
    check(sentinel in after, "the sentinel paragraph survives")
    check(expected_row in block(after, "instructions"),
          f"the instruction table follows instructions.csv ({expected_row} in the block)")
    check(block(after, "trade-plate") == "\n```\n" + open(os.path.join(trade, "plate", "table.txt")).read().rstrip()
          + "\n```\n\n", "the plate's block is its table.txt")

    r = run(trade, docs)
    check(r.returncode == 0 and open(md).read() == after, "a second run changes nothing")

    # A missing begin marker: exit 2, one line naming it, nothing written.
    broken = after.replace("<!-- generated: cheap-path -->\n", "", 1)
    open(md, "w").write(broken)
    gp = os.path.join(docs, "accuracy.gp")
    open(gp, "w").write("untouched\n")
    r = run(trade, docs)
    check(r.returncode == 2, f"a missing marker exits 2 (got {r.returncode})")
    check(len(r.stderr.strip().split("\n")) == 1 and "generated: cheap-path" in r.stderr,
          f"one line naming the marker (got {r.stderr.strip()!r})")
    check(open(md).read() == broken and open(gp).read() == "untouched\n", "nothing is written after a missing marker")

    # A block removed whole (both markers): the same.
    open(md, "w").write(after.replace("<!-- generated: trade-flanges -->", "", 1)
                        .replace("<!-- end generated: trade-flanges -->", "", 1))
    r = run(trade, docs)
    check(r.returncode == 2 and "'<!-- generated: trade-flanges -->' missing" in r.stderr,
          f"a block without markers exits 2 naming it (got {r.returncode}: {r.stderr.strip()!r})")

print(f"accuracy_report_test: {'FAILED ' + str(len(failures)) if failures else 'passed'}")
sys.exit(1 if failures else 0)
