"""Frame.texcoords, texcoords1 and colors (issue 35): the input's TEXCOORD_0, TEXCOORD_1 and COLOR_0 at
every point of a cut, against the closed form at the point's rest point (tests/looks/make_textured_box.py:
on face a of the unit box, u = q_b + 0.5, v = q_c + 0.5, TEXCOORD_1 = (v, 1 - u), COLOR_0 = (u, v, 0.25, 1)), the rest point found from the
point and its emission time by the inverse boost of the uniform motion, independently of the cut."""
import math
import os
import subprocess
import sys

import numpy as np

import apparent

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_texcoords_and_colors_follow_the_rest_points(tmp_path):
    box = tmp_path / "box.glb"
    subprocess.run([sys.executable, os.path.join(ROOT, "tests", "looks", "make_textured_box.py"), str(box),
                    str(tmp_path / "texture.png")], check=True)
    p, v = np.array([-2.0, 0.3, -4.0]), np.array([0.9, 0.0, 0.0])
    scene = apparent.load({"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]},
                           "frames": {"start": 16, "end": 18, "fps": 2},
                           "objects": [{"name": "box", "mesh": str(box), "position": p.tolist(),
                                        "velocity": v.tolist()},
                                       {"name": "plain", "mesh": os.path.join(ROOT, "data", "meshes", "box.obj"),
                                        "position": [2, 0, -6]}]}, base_dir=str(tmp_path))
    frame = scene.cut(16.5, tolerance="1e-3x")
    mine = frame.object == 0
    assert mine.any() and (~mine).any()
    # The other object's file has no look: NaN.
    assert np.isnan(frame.texcoords[~mine]).all() and np.isnan(frame.colors[~mine]).all()
    assert np.isnan(frame.texcoords1[~mine]).all()
    for values in (frame.texcoords, frame.texcoords1, frame.colors):  # NaN would pass the max() below
        assert not np.isnan(values[mine]).any()
    g = 1 / math.sqrt(1 - v @ v)
    x = frame.positions[mine] - p
    t = frame.emission_time[mine]
    q = x.copy()
    q[:, 0] = g * (x[:, 0] - v[0] * t)  # the inverse boost along x (t0 = 0)
    worst = 0.0
    for k in range(len(q)):
        on = [a for a in range(3) if abs(abs(q[k, a]) - 0.5) < 1e-9]
        assert on, q[k]
        # A point on an edge lies on two faces; its values are those of the face its triangle holds,
        # so they match one of them.
        best = min(max(abs(frame.texcoords[mine][k, 0] - (q[k, b] + 0.5)), abs(frame.texcoords[mine][k, 1] - (q[k, c] + 0.5)),
                       abs(frame.colors[mine][k, 0] - (q[k, b] + 0.5)), abs(frame.colors[mine][k, 1] - (q[k, c] + 0.5)),
                       abs(frame.colors[mine][k, 2] - 0.25), abs(frame.colors[mine][k, 3] - 1.0),
                       abs(frame.texcoords1[mine][k, 0] - (q[k, c] + 0.5)),
                       abs(frame.texcoords1[mine][k, 1] - (0.5 - q[k, b])))
                   for a in on for b, c in [[i for i in range(3) if i != a]])
        worst = max(worst, best)
    print("texcoords and colours within %.1e of the closed form at %d points" % (worst, len(q)))
    assert worst < 1e-9, worst
