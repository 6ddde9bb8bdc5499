"""Scene.cut against the PLY files `apparent render` writes (issue 34): value for value (double),
in vertex mode, at the scene's default tolerance and at 1e-2x (each motion's refinement), for the
default scene, a moving camera, a spinning body and a keyed path."""
import pathlib

import numpy as np
import pytest

import apparent
from conftest import ROOT, run_cli


PLY_TYPES = {"double": "<f8", "uchar": "u1", "ushort": "<u2", "int": "<i4"}


def read_ply(path):
    """A binary little-endian PLY as apparent writes it (exporters/ply.h): vertex doubles x y z
    quality [doppler proper_time], the integer `object` index, faces as `list uchar int`. Returns
    (dict of vertex columns, faces M x 3)."""
    data = pathlib.Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("utf-8").splitlines()
    assert header[0] == "ply" and header[1] == "format binary_little_endian 1.0"
    names, counts, element = [], {}, None
    for line in header[2:]:
        words = line.split()
        if words[0] == "element":
            element = words[1]
            counts[element] = int(words[2])
        elif words[0] == "property" and element == "vertex":
            assert words[1] in PLY_TYPES
            names.append((words[2], PLY_TYPES[words[1]]))
        elif words[0] == "property" and element == "face":
            assert words[1:4] == ["list", "uchar", "int"]
    n, m = counts["vertex"], counts["face"]
    vertex = np.frombuffer(data, dtype=names, count=n, offset=end)
    faces = np.frombuffer(data, dtype=[("n", "u1"), ("v", "<i4", 3)], count=m, offset=end + vertex.nbytes)
    assert np.all(faces["n"] == 3)
    assert end + vertex.nbytes + faces.nbytes == len(data)
    return {name: vertex[name] for name, _ in names}, faces["v"].astype(np.int64)


SCENES = [
    "data/scenes/flanges.json",        # the default scene (its mirror included)
    "data/scenes/flyby.json",          # a moving camera
    "data/scenes/spinning_wheel.json",  # a spinning body
    "data/scenes/keyed.gltf",          # a keyed path
]


@pytest.mark.parametrize("scene_path", SCENES)
@pytest.mark.parametrize("tolerance", ["vertex", None, "1e-2x"])
def test_cut_equals_the_commands_ply(scene_path, tolerance, tmp_path):
    scene = apparent.load(ROOT / scene_path)
    out = tmp_path / "out"
    args = ["render", ROOT / scene_path, "--format", "ply", "--out", out, "--quiet"]
    if tolerance:
        args += ["--tolerance", tolerance]
    code, _, error = run_cli(*args)
    assert code == 0, error
    files = sorted((out / scene.model).glob("frame_*.ply"))
    assert len(files) == len(scene.frame_times)
    frames = range(len(files)) if len(files) <= 40 else range(0, len(files), len(files) // 20)
    for k in frames:
        columns, faces = read_ply(files[k])
        frame = scene.cut(scene.frame_times[k], scene.model, tolerance=tolerance)
        assert frame.camera_time == scene.frame_times[k]
        assert frame.model == scene.model
        np.testing.assert_array_equal(frame.positions[:, 0], columns["x"])
        np.testing.assert_array_equal(frame.positions[:, 1], columns["y"])
        np.testing.assert_array_equal(frame.positions[:, 2], columns["z"])
        np.testing.assert_array_equal(frame.emission_time, columns["quality"])
        np.testing.assert_array_equal(frame.object, columns["object"])
        if "doppler" in columns:
            np.testing.assert_array_equal(frame.doppler, columns["doppler"])
            np.testing.assert_array_equal(frame.proper_time, columns["proper_time"])
        np.testing.assert_array_equal(frame.triangles, faces)


@pytest.mark.parametrize("scene_path", SCENES)
def test_frame_object_follows_the_scenes_objects(scene_path):
    scene = apparent.load(ROOT / scene_path)
    frame = scene.cut(scene.frame_times[len(scene.frame_times) // 2], scene.model)
    # Objects first, in scene order, then any mirror reflections.
    assert frame.objects[: len(scene.objects)] == scene.objects
    assert frame.object.shape == (len(frame.positions),)
    assert np.all(np.diff(frame.object) >= 0)  # each object's vertices together, in order
    for i, name in enumerate(frame.objects):
        vertices, triangles = frame.object_mesh(name)
        np.testing.assert_array_equal(vertices, frame.positions[frame.object == i])
        if len(triangles):
            assert triangles.min() >= 0 and triangles.max() < len(vertices)
    # Every triangle joins vertices of one object.
    owners = frame.object[frame.triangles]
    assert np.all(owners == owners[:, :1])
    # The mesh of one object by name: the same count of triangles in total.
    assert sum(len(frame.object_mesh(n)[1]) for n in frame.objects) == len(frame.triangles)


def test_frames_iterates_in_order_as_cut():
    scene = apparent.load(ROOT / "data/scenes/spinning_wheel.json")
    frames = list(scene.frames(model=scene.model, frames=(3, 9), threads=2))
    assert [f.camera_time for f in frames] == list(scene.frame_times[3:9])
    for f in frames:
        one = scene.cut(f.camera_time, scene.model)
        np.testing.assert_array_equal(f.positions, one.positions)
        np.testing.assert_array_equal(f.triangles, one.triangles)
