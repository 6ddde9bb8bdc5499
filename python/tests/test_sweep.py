"""The speed sweep of issue 34 against closed forms (docs/DESIGN.md, "Closed forms"):
- a rod on the line of sight, rest length L, speed b, appears L/(1-b) approaching and L/(1+b)
  receding with finite light speed alone (finite model), L sqrt((1+b)/(1-b)) and
  L sqrt((1-b)/(1+b)) with the Lorentz contraction too (relativistic model; Lampa 1924);
- a far cube moving across the view appears rotated by asin(b) (Terrell 1959, Penrose 1959).
The rod's ends are exact vertices in vertex mode, so the lengths hold to rounding."""
import math

import numpy as np
import pytest

import apparent

SPEEDS = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.99]
L = 2.0


def rod_scene(b):
    # A thin tetrahedron whose first two vertices are the rod's ends, on the camera's axis (-z).
    w = 1e-3
    vertices = np.array([[0, 0, 0], [0, 0, -L], [w, 0, -L / 2], [0, w, -L / 2]], dtype=float)
    triangles = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return {
        "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0]},
        "frames": {"start": 0, "end": 1, "fps": 1},
        "tolerance": "vertex",
        "objects": [{"name": "rod", "mesh": {"vertices": vertices, "triangles": triangles},
                     "position": [0, 0, -50], "t0": 0, "velocity": [0, 0, b]}],
    }


def apparent_rod_length(b, model):
    scene = apparent.load(rod_scene(b))
    vertices, _ = scene.cut(0.0, model, tolerance=0).object_mesh("rod")
    return abs(vertices[0, 2] - vertices[1, 2])


@pytest.mark.parametrize("b", SPEEDS)
def test_rod_on_the_line_of_sight(b):
    checks = {
        ("finite", b): L / (1 - b),
        ("finite", -b): L / (1 + b),
        ("relativistic", b): L * math.sqrt((1 + b) / (1 - b)),
        ("relativistic", -b): L * math.sqrt((1 - b) / (1 + b)),
    }
    for (model, v), expected in checks.items():
        measured = apparent_rod_length(v, model)
        assert abs(measured - expected) <= 1e-9 * expected, (model, v, measured, expected)


def cube_rotation_deg(b, distance=1000.0):
    """The apparent rotation of a unit cube moving along x at speed b, seen from `distance` along
    its line of sight when its image is centred: from the image x (x / depth, orthographic in the
    limit) of the right edge's near and far corners, sin(angle) = (near - far) / size, as a cube
    rotated by the angle about y shows (both vertical edges averaged: perspective cancels to first
    order)."""
    h = 0.5
    corners = np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)])
    faces = []
    # The cube's 12 triangles from its corners (index = 4 ix + 2 iy + iz), outward.
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    for a, b_, c, d in quads:
        faces += [[a, b_, c], [a, c, d]]
    scene = apparent.load({
        "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "up": [0, 1, 0]},
        "frames": {"start": 0, "end": 1, "fps": 1},
        "tolerance": "vertex",
        # At lab time -distance the cube is centred on the axis: its light then reaches the camera at 0.
        "objects": [{"name": "cube", "mesh": {"vertices": corners, "triangles": np.array(faces)},
                     "position": [0, 0, -distance], "t0": -distance, "velocity": [b, 0, 0]}],
    })
    vertices, _ = scene.cut(0.0, "relativistic", tolerance=0).object_mesh("cube")
    image_x = distance * vertices[:, 0] / -vertices[:, 2]
    sines = []
    for x in (-h, h):
        near = image_x[[i for i, c in enumerate(corners) if c[0] == x and c[2] == h]].mean()
        far = image_x[[i for i, c in enumerate(corners) if c[0] == x and c[2] == -h]].mean()
        sines.append((near - far) / (2 * h))
    return math.degrees(math.asin(np.mean(sines)))


@pytest.mark.parametrize("b", SPEEDS)
def test_far_cube_appears_rotated_by_asin_b(b):
    measured = cube_rotation_deg(b)
    assert abs(measured - math.degrees(math.asin(b))) <= 0.02, (b, measured)
