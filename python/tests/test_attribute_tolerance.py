"""Scene.cut's attribute_tolerance (issue 31): the distance alone leaves the faces that contain the
velocity coarse inside; bounding each point's own image refines them too, as --attribute-tolerance
does on the command line."""
import os

import numpy as np
import pytest

import apparent

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BOX = os.path.join(ROOT, "data", "scenes", "trade", "box_near.json")


def test_attribute_tolerance_refines_the_sliding_faces():
    scene = apparent.load(BOX)
    t = scene.frame_times[0]  # the box nearest the camera
    distance = scene.cut(t, tolerance="1e-3x")
    both = scene.cut(t, tolerance="1e-3x", attribute_tolerance="1e-3x")
    assert 0 < len(distance.triangles) < 0.5 * len(both.triangles)
    assert np.isfinite(distance.positions).all()


def test_attribute_tolerance_refused_like_the_command_line():
    scene = apparent.load(BOX)
    for bad in (0, "vertex", -1.0, "abc"):
        with pytest.raises(apparent.Error, match="--attribute-tolerance"):
            scene.cut(scene.frame_times[0], attribute_tolerance=bad)
