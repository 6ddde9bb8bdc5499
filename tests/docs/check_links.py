#!/usr/bin/env python3
"""Every relative link and #anchor in README.md, CONTRIBUTING.md and docs/*.md resolves, and the README
stays a page for users (at most 350 lines).

A link is [text](target) or ![alt](target) outside fenced code blocks and inline code. A target with a
scheme (https:, mailto:) is skipped: the check reads no network. Any other target must name an existing
file or folder inside the repository; its #anchor, or a bare #anchor, must be the slug of a heading of
that Markdown file, made as GitHub makes it (lower case; everything but letters, digits, spaces, '-' and
'_' dropped; spaces become '-'; a repeated slug gets -1, -2, ...).

Usage: check_links.py REPOSITORY_ROOT     (exit 1 with one line per broken link)
       check_links.py --self-test         (the checker finds the broken links of a small tree it writes)"""
import os
import re
import sys
import tempfile

README_MAX_LINES = 350
FENCE = re.compile(r"^\s*(```|~~~)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
INLINE_CODE = re.compile(r"`+[^`]*`+")
LINK = re.compile(r"!?\[((?:[^\[\]]|\[[^\]]*\])*)\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")


def prose_lines(text):
    """(line number, line) for every line outside fenced code blocks."""
    inside = False
    for number, line in enumerate(text.split("\n"), 1):
        if FENCE.match(line):
            inside = not inside
            continue
        if not inside:
            yield number, line


def slug(heading):
    """GitHub's anchor for a heading's text."""
    text = re.sub(r"!?\[((?:[^\[\]]|\[[^\]]*\])*)\]\([^)]*\)", r"\1", heading)  # a link keeps its text
    text = text.strip().lower()
    text = "".join(c for c in text if c.isalnum() or c in " -_")
    return text.replace(" ", "-")


def anchors(path, cache):
    if path not in cache:
        seen, found = {}, set()
        with open(path, encoding="utf-8") as f:
            text = f.read()
        for _, line in prose_lines(text):
            m = HEADING.match(line)
            if not m:
                continue
            base = slug(m.group(2))
            n = seen.get(base, 0)
            seen[base] = n + 1
            found.add(base if n == 0 else f"{base}-{n}")
        cache[path] = found
    return cache[path]


def pages(root):
    names = ["README.md", "CONTRIBUTING.md"]
    docs = os.path.join(root, "docs")
    if os.path.isdir(docs):
        names += sorted("docs/" + n for n in os.listdir(docs) if n.endswith(".md"))
    return [n for n in names if os.path.isfile(os.path.join(root, n))]


def check(root):
    """The list of problems, one line each."""
    root = os.path.realpath(root)
    problems, cache = [], {}
    check.links = 0
    for name in pages(root):
        page = os.path.join(root, name)
        with open(page, encoding="utf-8") as f:
            text = f.read()
        for number, line in prose_lines(text):
            for m in LINK.finditer(INLINE_CODE.sub("", line)):
                target = m.group(2)
                check.links += 1
                if SCHEME.match(target):
                    continue
                where = f"{name}:{number}: ({target})"
                path_part, _, anchor = target.partition("#")
                dest = page if path_part == "" else os.path.realpath(
                    os.path.join(os.path.dirname(page), path_part))
                if dest != root and not dest.startswith(root + os.sep):
                    problems.append(f"{where}: leaves the repository")
                    continue
                if not os.path.exists(dest):
                    problems.append(f"{where}: no such file {os.path.relpath(dest, root)}")
                    continue
                if anchor:
                    if not dest.endswith(".md") or not os.path.isfile(dest):
                        problems.append(f"{where}: an #anchor into a file that is not Markdown")
                    elif anchor not in anchors(dest, cache):
                        problems.append(f"{where}: no heading #{anchor} in {os.path.relpath(dest, root)}")
    readme = os.path.join(root, "README.md")
    if os.path.isfile(readme):
        with open(readme, encoding="utf-8") as f:
            count = len(f.read().rstrip("\n").split("\n"))
        if count > README_MAX_LINES:
            problems.append(f"README.md: {count} lines, more than {README_MAX_LINES} "
                            "(move the detail to a docs/ page and link it)")
    return problems


def self_test():
    """A small tree with every kind of good and broken link: the checker reports exactly the broken."""
    with tempfile.TemporaryDirectory() as root:
        os.makedirs(os.path.join(root, "docs", "gallery"))
        open(os.path.join(root, "docs", "gallery", "a.png"), "wb").close()
        with open(os.path.join(root, "docs", "TOPIC.md"), "w") as f:
            f.write("# Topic\n\n## The `render` command: options\n\n## Twice\n\n## Twice\n\n"
                    "```\n## Not a heading\n[in a fence](missing.md)\n```\n"
                    "[back](../README.md#usage) [self](#twice-1) [bad self](#twice-2)\n")
        with open(os.path.join(root, "README.md"), "w") as f:
            f.write("# Demo\n\n## Usage\n\n"
                    "![pic](docs/gallery/a.png) [topic](docs/TOPIC.md#the-render-command-options)\n"
                    "[web](https://example.org/x) `[code](nowhere.md)` [folder](docs/gallery)\n"
                    "[gone](docs/GONE.md) [no heading](docs/TOPIC.md#not-a-heading) [out](../x.md)\n"
                    "[anchor into a picture](docs/gallery/a.png#x)\n")
        found = check(root)
        expected = ["README.md:7: (docs/GONE.md): no such file",
                    "README.md:7: (docs/TOPIC.md#not-a-heading): no heading #not-a-heading",
                    "README.md:7: (../x.md): leaves the repository",
                    "README.md:8: (docs/gallery/a.png#x): an #anchor into a file that is not Markdown",
                    "docs/TOPIC.md:13: (#twice-2): no heading #twice-2"]
        ok = len(found) == len(expected) and all(
            any(line.startswith(e) for line in found) for e in expected)
        with open(os.path.join(root, "README.md"), "a") as f:
            f.write("line\n" * README_MAX_LINES)
        long_found = [p for p in check(root) if p.startswith("README.md: ")]
        ok = ok and len(long_found) == 1
        if not ok:
            print("self-test FAILED; expected:\n  " + "\n  ".join(expected) + "\nfound:\n  " +
                  "\n  ".join(found) + "\nREADME length: " + repr(long_found), file=sys.stderr)
            return 1
        print("self-test passed: 5 broken links and an over-long README found, good links accepted")
        return 0


def main(argv):
    if len(argv) != 2:
        print(__doc__.split("\n\n")[-1], file=sys.stderr)
        return 2
    if argv[1] == "--self-test":
        return self_test()
    problems = check(argv[1])
    for p in problems:
        print("error: " + p, file=sys.stderr)
    if problems:
        return 1
    print(f"ok: all {check.links} links (relative ones checked, with their anchors) in "
          f"{len(pages(argv[1]))} pages resolve")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
