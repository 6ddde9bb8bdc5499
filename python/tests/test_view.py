"""Frame._repr_html_: a self-contained three.js view (python/apparent/view.py)."""
import base64
import json
import re

import numpy as np
import pytest

import apparent
from apparent import view
from conftest import ROOT


def test_the_view_inlines_three_and_the_frames_arrays():
    if view.three_folder() is None:
        pytest.skip("node_modules/three is missing (npm ci)")
    scene = apparent.load(ROOT / "data/scenes/spinning_wheel.json")
    frame = scene.cut(scene.frame_times[3], scene.model)
    page = frame._repr_html_()
    assert "http://" not in page.split("<script", 1)[0] and "src=" not in page  # nothing fetched
    assert page.count("<script") == 1 and page.count("</script>") == 1  # the inlined text is escaped
    data = json.loads(re.search(r", data = (\{.*?\});\n", page).group(1))
    positions = np.frombuffer(base64.b64decode(data["positions"]), dtype=np.float32).reshape(-1, 3)
    indices = np.frombuffer(base64.b64decode(data["indices"]), dtype=np.uint32).reshape(-1, 3)
    centre = frame.positions.mean(axis=0)
    np.testing.assert_array_equal(positions, (frame.positions - centre).astype(np.float32))
    np.testing.assert_array_equal(indices, frame.triangles)
    assert "class WebGLRenderer" in page and "class OrbitControls" in page
