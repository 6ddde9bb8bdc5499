"""apparent: what a camera sees of meshes moving near the speed of light, as numpy arrays.

The same stage, physics and frame loop as the ``apparent`` command (docs/PYTHON.md): a scene is
loaded and checked once, and cut with the camera's past lightcone at any camera time.

Units: lengths and positions in light-seconds, times in seconds, velocities as fractions of c
(c = 1). Positions are absolute lab coordinates (the camera's rest frame for a moving camera), as in
the PLY files the command writes.

Models (``model=``):
  instant       infinite light speed, Galilean motion: where the object is at the camera time
                (minus the scene's camera.instant_delay)
  finite        finite light speed, Galilean motion: light delay without Lorentz contraction
  relativistic  the past lightcone and Lorentz motion: what a real camera records
                (Terrell-Penrose rotation, aberration)
  contracted    Lorentz-contracted shape at one instant, no light delay

Errors: bad input raises :class:`apparent.Error` (a ``ValueError``) whose message is the command
line's one line (naming the file, the field and the problem).
"""

import concurrent.futures
import csv
import json
import os
import tempfile

import numpy as np

from . import _apparent
from ._apparent import Error

__version__ = _apparent.__version__

MODELS = ("instant", "finite", "relativistic", "contracted")

__all__ = ["Error", "Frame", "MODELS", "Scene", "load", "trade", "__version__"]


def _tolerance_text(tolerance):
    """None: the scene's; 0 or "vertex": vertex mode; a number: light-seconds; "1e-3x": relative."""
    if tolerance is None:
        return ""
    if isinstance(tolerance, str):
        return tolerance
    if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float, np.integer, np.floating)):
        raise Error("--tolerance: %r is neither a positive number of light-seconds, a fraction of each "
                    "object's size such as 1e-3x, nor 'vertex'" % (tolerance,))
    if tolerance == 0:
        return "vertex"
    # As typed on the command line: -1 stays "-1", 1e-3 "0.001"
    return str(int(tolerance)) if isinstance(tolerance, (int, np.integer)) else repr(float(tolerance))


class Frame:
    """One apparent frame: every object's surface as the camera sees it at ``camera_time``.

    Attributes (numpy arrays; N vertices, M triangles; objects in scene order, then mirror
    reflections):
      positions      N x 3 float64, absolute apparent positions, light-seconds
      triangles      M x 3 int64, vertex indices (triangles with a repeated corner left out, as in
                     the PLY)
      object         N int32, each vertex's object as an index into ``objects``
      emission_time  N float64, lab time (s) at which each point emitted the light seen
      doppler        N float64, Doppler factor of that light (received / emitted frequency)
      proper_time    N float64, the object's own clock at emission, seconds
      texcoords      N x 2 float64, the input's TEXCOORD_0 at each point (NaN where its file has none)
      texcoords1     N x 2 float64, the input's TEXCOORD_1 likewise
      colors         N x 4 float64, the input's COLOR_0, linear RGBA (NaN where its file has none)
      camera_time    the camera time (s); model: the model's name; objects: the object names
    """

    def __init__(self, data):
        self.camera_time = data.camera_time
        self.model = data.model
        self.objects = tuple(data.object_names)
        self.positions = data.positions
        self.triangles = data.triangles
        self.object = data.object
        self.emission_time = data.emission_time
        self.doppler = data.doppler
        self.proper_time = data.proper_time
        self.texcoords = data.texcoords
        self.texcoords1 = data.texcoords1
        self.colors = data.colors

    def object_mesh(self, name):
        """(vertices K x 3 float64, triangles L x 3 int64) of the object called ``name``, its
        triangles indexing its own vertices. Raises apparent.Error for an unknown name."""
        if name not in self.objects:
            raise Error("object_mesh: no object named %r (objects: %s)" % (name, ", ".join(self.objects)))
        index = self.objects.index(name)
        mine = np.flatnonzero(self.object == index)
        if mine.size == 0:
            return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
        keep = self.object[self.triangles[:, 0]] == index
        return self.positions[mine].copy(), self.triangles[keep] - mine[0]

    def __repr__(self):
        return "<apparent.Frame %s t=%g s: %d vertices, %d triangles, %d objects>" % (
            self.model, self.camera_time, len(self.positions), len(self.triangles), len(self.objects))

    def _repr_html_(self):
        from . import view
        return view.frame_html(self)


class Scene:
    """A loaded scene (JSON or glTF): see :func:`load`.

    Attributes: ``objects`` (names, in scene order), ``frame_times`` (numpy, seconds: the camera
    times of the scene's frames), ``models`` (the models this scene can be cut in), ``model``
    and ``tolerance`` (the scene's own), ``path``.
    """

    def __init__(self, handle, keep=None):
        self._handle = handle
        self._keep = keep  # the temporary folder of a scene given as a dict
        self.path = handle.path
        self.objects = tuple(handle.objects)
        self.frame_times = handle.frame_times
        self.model = handle.default_model
        self.tolerance = handle.default_tolerance
        self._models = None

    @property
    def models(self):
        """The models the scene can be cut in (the command line accepts it for them)."""
        if self._models is None:
            self._models = tuple(self._handle.models())
        return self._models

    def cut(self, t, model="relativistic", tolerance=None, max_triangles=0, attribute_tolerance=None):
        """The frame the camera sees at camera time ``t`` (seconds), as a :class:`Frame`.

        t          any finite camera time, not only a frame time; outside
                   ``frame_times[0]`` .. ``frame_times[-1]`` the histories are built for ``t``
                   (as the command builds them for a scene whose frames are one frame at ``t``)
        model      "instant", "finite", "relativistic" (default) or "contracted" (see the module)
        tolerance  None: the scene's; 0 or "vertex": vertex mode (exact vertices, straight edges);
                   a positive number: light-seconds, the largest distance from the exact apparent
                   surface; "1e-3x": that fraction of each object's size
        max_triangles  per frame (0: the command's default, 4 x the scene's input triangles)
        attribute_tolerance  None: only the distance is bounded (faces that contain the velocity stay
                   coarse inside: their points slide within them); a positive number or "1e-3x": also
                   each point's distance from the exact image of its own rest point (as
                   --attribute-tolerance), where textures and emission times land

        The cut at ``frame_times[k]`` holds the values of frame k of ``apparent render``.
        The GIL is released while cutting: several threads may cut at once. Bad input raises
        apparent.Error with the command line's message."""
        t = float(t)
        if attribute_tolerance is not None and (isinstance(attribute_tolerance, bool) or attribute_tolerance == 0 or
                                                attribute_tolerance == "vertex"):
            raise Error("--attribute-tolerance: %r is neither a positive number of light-seconds nor a fraction of "
                        "each object's size such as 1e-3x" % (attribute_tolerance,))
        attribute = "" if attribute_tolerance is None else _tolerance_text(attribute_tolerance)
        return Frame(self._handle.cut(t, str(model), _tolerance_text(tolerance), int(max_triangles), attribute))

    def frames(self, model="relativistic", tolerance=None, frames=None, threads=None):
        """Iterates the frames in order as :class:`Frame`, cut in parallel behind the iterator.

        frames   None: every frame; (A, B) or "A:B": frames A .. B-1; or any iterable of frame
                 numbers. threads: cutting threads (None: the machine's cores)."""
        count = len(self.frame_times)
        if frames is None:
            numbers = range(count)
        elif isinstance(frames, str):
            a, _, b = frames.partition(":")
            numbers = range(int(a) if a else 0, int(b) if b else count)
        elif isinstance(frames, tuple) and len(frames) == 2:
            numbers = range(frames[0], frames[1])
        else:
            numbers = list(frames)
        for k in numbers:
            if not 0 <= k < count:
                raise Error("%s: frame %d is outside 0..%d" % (self.path, k, count - 1))
        workers = threads or os.cpu_count() or 1
        with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
            pending = []
            it = iter(numbers)
            for k in it:
                pending.append(pool.submit(self.cut, self.frame_times[k], model, tolerance))
                if len(pending) >= 2 * workers:
                    yield pending.pop(0).result()
            while pending:
                yield pending.pop(0).result()

    def render(self, out, models=None, formats=None, **options):
        """Writes what ``apparent render SCENE --out OUT`` writes; returns its standard output.

        models: a name, a list of names or "all"; formats: "glb", "ply", "obj" or a list of them;
        every other option as the command's, with underscores: tolerance="1e-3x", frames="0:10",
        threads=2, max_triangles=..., quiet=True (a flag). Raises apparent.Error on failure."""
        args = ["render", self.path, "--out", os.fspath(out)]
        if models is not None:
            args += ["--model", models if isinstance(models, str) else ",".join(models)]
        if formats is not None:
            args += ["--format", formats if isinstance(formats, str) else ",".join(formats)]
        args += _options(options)
        return _run(args)

    def __repr__(self):
        return "<apparent.Scene %s: %d objects, %d frames>" % (self.path, len(self.objects), len(self.frame_times))

    def _repr_html_(self):
        from . import view
        return view.frame_html(self.cut(self.frame_times[len(self.frame_times) // 2], self.model))


def _options(options):
    args = []
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is True:
            args.append(flag)
        elif value is None or value is False:
            continue
        elif isinstance(value, (list, tuple)):
            args += [flag, ",".join(str(v) for v in value)]
        else:
            args += [flag, str(value)]
    return args


def _run(args):
    code, out, error = _apparent.run_command([str(a) for a in args])
    if code != 0:
        raise Error(error.strip() or "apparent %s: exit code %d" % (args[0], code))
    return out


def _write_obj(path, vertices, triangles):
    vertices = np.asarray(vertices, dtype=np.float64)
    triangles = np.asarray(triangles)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or triangles.ndim != 2 or triangles.shape[1] != 3:
        raise Error("mesh: vertices must be N x 3 and triangles M x 3")
    with open(path, "w") as f:
        for x, y, z in vertices.tolist():
            f.write("v %r %r %r\n" % (x, y, z))
        for a, b, c in triangles.astype(np.int64).tolist():
            f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


def load(path_or_dict, base_dir=None, allow_outside=False):
    """Loads a scene and checks it as the command line does; returns a :class:`Scene`.

    path_or_dict  a scene file (JSON or glTF, docs/SCENES.md), or a dict in the JSON scene format
                  whose objects' "mesh" is a path (relative to ``base_dir``, default the current
                  folder) or a dict {"vertices": N x 3, "triangles": M x 3} of numpy arrays
                  (triangles index vertices from 0).
    Units: light-seconds and seconds, velocities as fractions of c. Raises apparent.Error with the
    command line's message for bad input (a missing mesh, a speed >= 1, a non-finite number).
    A scene file's meshes must lie in its folder or the working folder, as for the command line,
    unless ``allow_outside`` (its --allow-outside)."""
    if isinstance(path_or_dict, dict):
        base = os.path.abspath(base_dir if base_dir is not None else os.getcwd())
        keep = tempfile.TemporaryDirectory(prefix="apparent-scene-")
        scene = json.loads(json.dumps(path_or_dict, default=_jsonable))
        for i, obj in enumerate(scene.get("objects", []) if isinstance(scene.get("objects"), list) else []):
            mesh = path_or_dict["objects"][i].get("mesh") if isinstance(obj, dict) else None
            if isinstance(mesh, dict):
                name = os.path.join(keep.name, "mesh_%d.obj" % i)
                _write_obj(name, mesh.get("vertices"), mesh.get("triangles"))
                obj["mesh"] = name
            elif isinstance(mesh, (str, os.PathLike)):
                obj["mesh"] = os.path.join(base, os.fspath(mesh))
        path = os.path.join(keep.name, "scene.json")
        with open(path, "w") as f:
            json.dump(scene, f, allow_nan=True)
        return Scene(_apparent.SceneHandle(path, True), keep)
    path = os.fspath(path_or_dict)
    if base_dir is not None and not os.path.isabs(path):
        path = os.path.join(base_dir, path)
    return Scene(_apparent.SceneHandle(path, bool(allow_outside)))


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, dict):
        return value
    raise TypeError("not JSON: %r" % (value,))


_TRADE_FIELDS = (("family", "U16"), ("parameter", "f8"), ("error_ls", "f8"), ("error_rel", "f8"),
                 ("triangles_per_frame", "f8"), ("cut_seconds_per_frame", "f8"),
                 ("export_seconds_per_frame", "f8"), ("glb_bytes_per_frame", "f8"), ("skipped", "?"))


def trade(scene, model=None, frames=None, levels=None, tolerances=None, max_triangles=None, structured=False):
    """The speed-accuracy trade of ``apparent trade`` on ``scene`` (a Scene or a path): its table as
    a list of dicts (the columns of trade.csv: family, parameter, error_ls, error_rel,
    triangles_per_frame, cut_seconds_per_frame, export_seconds_per_frame, glb_bytes_per_frame,
    skipped), or as a numpy structured array with ``structured=True``. Errors in light-seconds,
    times in seconds of CPU per frame."""
    path = scene.path if isinstance(scene, Scene) else os.fspath(scene)
    with tempfile.TemporaryDirectory(prefix="apparent-trade-") as out:
        args = ["trade", path, "--out", out, "--quiet"]
        args += _options({"model": model, "frames": frames if not isinstance(frames, tuple) else "%d:%d" % frames,
                          "levels": levels, "tolerances": tolerances, "max_triangles": max_triangles})
        _run(args)
        with open(os.path.join(out, "trade.csv")) as f:
            rows = []
            for row in csv.DictReader(f):
                rows.append({name: (row[name] if kind == "U16" else bool(int(row[name])) if kind == "?"
                                    else float(row[name])) for name, kind in _TRADE_FIELDS})
    if structured:
        return np.array([tuple(r[name] for name, _ in _TRADE_FIELDS) for r in rows], dtype=list(_TRADE_FIELDS))
    return rows

