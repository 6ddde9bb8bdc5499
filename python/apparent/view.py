"""An interactive three.js view of a Frame for notebooks (Frame._repr_html_), self-contained: the
three.js module text (three.core.js, three.module.js and OrbitControls.js of the repository's
node_modules/three, copied next to this file by the build as three/) and the frame's arrays are
inlined in the HTML, so it needs no server and no network (about 2.2 MB per view)."""
import base64
import html
import json
import os
import uuid

import numpy as np

_HERE = os.path.dirname(os.path.abspath(__file__))
_FILES = ("three.core.js", "three.module.js", "OrbitControls.js")
_PALETTE = [(0.80, 0.36, 0.26), (0.27, 0.52, 0.80), (0.62, 0.62, 0.62), (0.45, 0.70, 0.35), (0.85, 0.70, 0.25),
            (0.60, 0.40, 0.75)]


def three_folder():
    """The folder holding the three.js files, or None: the package's three/ (the build copies it),
    else the repository's node_modules/three (when run from the source tree)."""
    candidates = [os.path.join(_HERE, "three"),
                  os.path.join(_HERE, "..", "..", "node_modules", "three")]
    for folder in candidates:
        paths = [os.path.join(folder, f) for f in _FILES]
        flat = all(os.path.exists(p) for p in paths)
        if flat:
            return folder
        tree = [os.path.join(folder, "build", "three.core.js"), os.path.join(folder, "build", "three.module.js"),
                os.path.join(folder, "examples", "jsm", "controls", "OrbitControls.js")]
        if all(os.path.exists(p) for p in tree):
            return folder
    return None


def _three_texts(folder):
    flat = os.path.join(folder, "three.core.js")
    if os.path.exists(flat):
        paths = [os.path.join(folder, f) for f in _FILES]
    else:
        paths = [os.path.join(folder, "build", "three.core.js"), os.path.join(folder, "build", "three.module.js"),
                 os.path.join(folder, "examples", "jsm", "controls", "OrbitControls.js")]
    texts = []
    for p in paths:
        with open(p, encoding="utf-8") as f:
            texts.append(f.read())
    return texts


def _b64(array, dtype):
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode("ascii")


def _script_string(text):
    """A JavaScript string literal that may sit inside <script>."""
    return json.dumps(text).replace("</", "<\\/")


def frame_html(frame, height=420):
    """The HTML of an interactive view of `frame` (drag to orbit, wheel to zoom), or a note that
    three.js is missing. Positions are shown relative to their centre in float32."""
    folder = three_folder()
    if folder is None:
        return ("<p>%s (no three.js view: node_modules/three is missing; run <code>npm ci</code> in the "
                "repository and rebuild)</p>" % html.escape(repr(frame)))
    core, module, controls = _three_texts(folder)
    positions = np.asarray(frame.positions, dtype=np.float64)
    centre = positions.mean(axis=0) if len(positions) else np.zeros(3)
    radius = float(np.max(np.linalg.norm(positions - centre, axis=1))) if len(positions) else 1.0
    colours = np.array([_PALETTE[i % len(_PALETTE)] for i in frame.object], dtype=np.float32).reshape(-1, 3)
    element = "apparent-" + uuid.uuid4().hex
    data = {
        "positions": _b64(positions - centre, np.float32),
        "colours": _b64(colours, np.float32),
        "indices": _b64(frame.triangles, np.uint32),
        "radius": radius if radius > 0 else 1.0,
        "caption": repr(frame),
    }
    return """<div id="%(id)s" style="width:100%%;height:%(h)dpx;position:relative"><div style="position:absolute;left:6px;top:4px;font:12px sans-serif;color:#ddd">%(caption)s</div></div>
<script type="module">
const core = %(core)s, main = %(main)s, orbit = %(orbit)s, data = %(data)s;
const url = (text) => URL.createObjectURL(new Blob([text], {type: 'text/javascript'}));
const coreUrl = url(core);
const mainUrl = url(main.split("'./three.core.js'").join("'" + coreUrl + "'"));
const THREE = await import(mainUrl);
const { OrbitControls } = await import(url(orbit.split("'three'").join("'" + mainUrl + "'")));
const floats = (b64) => new Float32Array(Uint8Array.from(atob(b64), c => c.charCodeAt(0)).buffer);
const uints = (b64) => new Uint32Array(Uint8Array.from(atob(b64), c => c.charCodeAt(0)).buffer);
const host = document.getElementById('%(id)s');
const renderer = new THREE.WebGLRenderer({antialias: true});
renderer.setSize(host.clientWidth, host.clientHeight);
host.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x202428);
const geometry = new THREE.BufferGeometry();
geometry.setAttribute('position', new THREE.BufferAttribute(floats(data.positions), 3));
geometry.setAttribute('color', new THREE.BufferAttribute(floats(data.colours), 3));
geometry.setIndex(new THREE.BufferAttribute(uints(data.indices), 1));
geometry.computeVertexNormals();
scene.add(new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({vertexColors: true, side: THREE.DoubleSide, flatShading: true})));
scene.add(new THREE.AmbientLight(0xffffff, 0.6));
const light = new THREE.DirectionalLight(0xffffff, 1.5);
light.position.set(1, 2, 3);
scene.add(light);
const camera = new THREE.PerspectiveCamera(50, host.clientWidth / host.clientHeight, data.radius * 1e-3, data.radius * 100);
camera.position.set(0, 0, data.radius * 2.5);
const controls = new OrbitControls(camera, renderer.domElement);
renderer.setAnimationLoop(() => { controls.update(); renderer.render(scene, camera); });
</script>""" % {"id": element, "h": height, "caption": html.escape(data["caption"]), "core": _script_string(core),
                "main": _script_string(module), "orbit": _script_string(controls), "data": json.dumps(data)}
