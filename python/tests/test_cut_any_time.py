"""Scene.cut at camera times outside the scene's frames (issue 34: "for any camera time t"): the
cut equals frame 0 of `apparent render` on a copy of the scene whose frames are one frame at that
time, value for value (double); a time that is not finite is refused."""
import json
import math
import pathlib

import numpy as np
import pytest

import apparent
from conftest import ROOT, run_cli
from test_against_cli import read_ply


def moved_copy(scene_path, t, folder, fps=None):
    """The scene with its frames moved to one frame at camera time t (start t, the same fps unless
    given), its meshes named by absolute path; returns the copy's path."""
    scene = json.loads(pathlib.Path(scene_path).read_text())
    fps = fps or scene["frames"]["fps"]
    scene["frames"] = {"start": t, "end": t + 0.5 / fps, "fps": fps}
    for obj in scene["objects"]:
        obj["mesh"] = str((pathlib.Path(scene_path).parent / obj["mesh"]).resolve())
    path = pathlib.Path(folder) / "moved.json"
    path.write_text(json.dumps(scene))
    return path


@pytest.mark.parametrize("scene_path", ["data/scenes/flanges.json", "data/scenes/spinning_wheel.json"])
@pytest.mark.parametrize("side", ["before", "after"])
def test_cut_outside_the_frames_equals_the_moved_commands_ply(scene_path, side, tmp_path):
    scene = apparent.load(ROOT / scene_path)
    times = scene.frame_times
    # Off the frame grid, beyond either end of the frames.
    t = times[0] - 2.37 if side == "before" else times[-1] + 3.21
    frame = scene.cut(t, scene.model)
    assert frame.camera_time == t
    copy = moved_copy(ROOT / scene_path, t, tmp_path)
    out = tmp_path / "out"
    code, _, error = run_cli("render", copy, "--format", "ply", "--out", out, "--quiet", "--allow-outside")
    assert code == 0, error
    files = sorted((out / scene.model).glob("frame_*.ply"))
    assert len(files) == 1
    columns, faces = read_ply(files[0])
    assert len(faces) > 0  # something is seen at that time
    np.testing.assert_array_equal(frame.positions[:, 0], columns["x"])
    np.testing.assert_array_equal(frame.positions[:, 1], columns["y"])
    np.testing.assert_array_equal(frame.positions[:, 2], columns["z"])
    np.testing.assert_array_equal(frame.emission_time, columns["quality"])
    if "doppler" in columns:
        np.testing.assert_array_equal(frame.doppler, columns["doppler"])
        np.testing.assert_array_equal(frame.proper_time, columns["proper_time"])
    np.testing.assert_array_equal(frame.triangles, faces)
    # Cut again (its histories kept): the same frame.
    again = scene.cut(t, scene.model)
    np.testing.assert_array_equal(again.positions, frame.positions)
    np.testing.assert_array_equal(again.triangles, frame.triangles)


def test_cut_at_a_frame_time_is_unchanged_after_cuts_outside():
    scene = apparent.load(ROOT / "data/scenes/spinning_wheel.json")
    before = scene.cut(scene.frame_times[5], scene.model)
    scene.cut(scene.frame_times[0] - 1.5, scene.model)
    after = scene.cut(scene.frame_times[5], scene.model)
    np.testing.assert_array_equal(before.positions, after.positions)
    np.testing.assert_array_equal(before.triangles, after.triangles)


@pytest.mark.parametrize("t", [math.nan, math.inf, -math.inf])
def test_a_time_that_is_not_finite_is_refused(t):
    scene = apparent.load(ROOT / "data/scenes/flanges.json")
    with pytest.raises(apparent.Error, match="is not finite"):
        scene.cut(t, scene.model)


def test_a_time_beyond_the_coordinate_limit_is_refused_as_the_command_refuses_its_frame(tmp_path):
    scene_path = ROOT / "data/scenes/spinning_wheel.json"
    scene = apparent.load(scene_path)
    t = 2e12
    # (An fps the scene reader resolves at 2e12 s: one frame's histories do not depend on it.)
    code, _, line = run_cli("render", moved_copy(scene_path, t, tmp_path, fps=1e-6), "--format", "ply", "--out",
                            tmp_path / "out", "--quiet", "--allow-outside")
    assert code == 2
    assert "viewed time of frame 0" in line
    with pytest.raises(apparent.Error) as refused:
        scene.cut(t, scene.model)
    # The same line but the file's name.
    assert str(refused.value).replace(str(scene_path), "SCENE") == line.replace(str(tmp_path / "moved.json"), "SCENE")
