import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def apparent_exe():
    """The command-line program: $APPARENT_EXE (set by ctest), else build/apparent."""
    return os.environ.get("APPARENT_EXE", str(ROOT / "build" / "apparent"))


def run_cli(*args):
    """Runs the command; (exit code, stdout, the error line without 'error: ')."""
    p = subprocess.run([apparent_exe(), *map(str, args)], capture_output=True, text=True)
    lines = [l[len("error: "):] for l in p.stderr.splitlines() if l.startswith("error: ")]
    return p.returncode, p.stdout, lines[-1] if lines else p.stderr.strip()


@pytest.fixture(autouse=True)
def in_the_repository(monkeypatch):
    """The working folder is the repository, as for the command line's examples (the shipped
    scenes' meshes are in data/meshes, outside data/scenes: docs/HOSTILE_INPUT.md)."""
    monkeypatch.chdir(ROOT)
