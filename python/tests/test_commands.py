"""Scene.render and apparent.trade run the commands in-process (issue 34): the same files, the same
table, the same messages."""
import csv

import numpy as np
import pytest

import apparent
from conftest import ROOT, run_cli


def test_render_writes_what_the_command_writes(tmp_path):
    scene = apparent.load(ROOT / "data/scenes/spinning_wheel.json")
    scene.render(tmp_path / "py", models=["relativistic", "finite"], formats=["ply", "glb"], frames="0:3", quiet=True)
    code, _, error = run_cli("render", ROOT / "data/scenes/spinning_wheel.json", "--out", tmp_path / "cli", "--model",
                             "relativistic,finite", "--format", "ply,glb", "--frames", "0:3", "--quiet")
    assert code == 0, error
    written = sorted(p.relative_to(tmp_path / "cli") for p in (tmp_path / "cli").rglob("*") if p.is_file())
    assert len(written) == 2 * 3 + 2
    for name in written:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name


def test_render_refuses_as_the_command(tmp_path):
    scene = apparent.load(ROOT / "data/scenes/spinning_wheel.json")
    code, _, line = run_cli("render", scene.path, "--out", tmp_path / "cli", "--format", "xyz")
    assert code == 2
    with pytest.raises(apparent.Error) as caught:
        scene.render(tmp_path / "py", formats="xyz")
    assert str(caught.value) == line
    assert not (tmp_path / "py").exists()


def test_trade_returns_the_commands_table(tmp_path):
    path = ROOT / "data/scenes/trade/box_near.json"
    rows = apparent.trade(path, frames="0:2", levels=2, tolerances="0.1,0.03")
    table = apparent.trade(apparent.load(path), frames=(0, 2), levels=2, tolerances="0.1,0.03", structured=True)
    code, _, error = run_cli("trade", path, "--out", tmp_path, "--frames", "0:2", "--levels", "2", "--tolerances",
                             "0.1,0.03", "--quiet")
    assert code == 0, error
    with open(tmp_path / "trade.csv") as f:
        expected = list(csv.DictReader(f))
    assert [r["family"] for r in rows] == [r["family"] for r in expected] == ["vertex", "uniform", "uniform",
                                                                             "tolerance", "tolerance"]
    # Everything but the timings, which differ run to run.
    for column in ("parameter", "error_ls", "error_rel", "triangles_per_frame", "glb_bytes_per_frame"):
        assert [r[column] for r in rows] == [float(r[column]) for r in expected], column
        np.testing.assert_array_equal(table[column], [float(r[column]) for r in expected])
    assert list(table["family"]) == [r["family"] for r in expected]
