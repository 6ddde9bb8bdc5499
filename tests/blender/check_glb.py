# Blender check of apparent's animated .glb files (one node per frame, STEP scale toggles visibility).
#
#   blender -b --factory-startup --python tests/blender/check_glb.py -- FILE.glb [FILE.glb ...]
#           [--scene-fps N] [--frames 0,50,100,199] [--draco-library PATH]
#
# For each file, in a fresh empty Blender scene:
#   - bpy.ops.import_scene.gltf succeeds (a KHR_draco_mesh_compression file needs Blender's Draco library,
#     libextern_draco.so: the build's, build/blender/, or --draco-library PATH, given to the importer as
#     scripts/blender_import.py does; when it is missing the file FAILS with the importer's own error message);
#   - one object per frame node, named like the node (frame_NNNNN; a Blender rename "frame_00007.001" is
#     accepted and reported), MESH for a node with a mesh and EMPTY for an empty frame; the camera node too;
#   - mesh vertex counts match the file (plain files: the referenced vertices of every primitive, which is what
#     the importer keeps);
#   - reflection nodes (children "frame_NNNNN mirror M" of frame nodes) are child objects of their frame objects,
#     with the file's vertex counts, and shown exactly when their frame is;
#   - the animation imported: every frame object has an action with scale fcurves (x, y, z), all keyframes
#     CONSTANT (glTF STEP), at Blender frames = glTF seconds * scene.render.fps (what the importer uses);
#   - at t = (k + 0.5) / fps for several k, and at t = duration, exactly frame object k has a non-zero world
#     scale and every other frame object a zero one, after scene.frame_set(frame, subframe=...). The expected
#     answer is also computed from the file's own animation data (read here, without Blender), so a mismatch
#     says whether the file or the import is wrong;
#   - every whole Blender frame from 0 to the end shows exactly one frame object, the file's (what the timeline
#     plays), and the mesh bounding boxes match the POSITION min/max; the importer logs no ERROR.
# Blender's default scene fps is 24; --scene-fps N sets scene.render.fps before the import (e.g. the file's own
# fps, so that every glTF frame starts on a whole Blender frame).
# Prints one line per check failure and a summary; exit status 0 when everything passed, 1 on any failure,
# 2 on a usage problem.
import json
import math
import os
import re
import struct
import sys
import time
import traceback

import bpy

FRAME_NODE = re.compile(r'^frame_(\d+)$')
T0 = time.time()


def usage(msg):
    print(f'check_glb: {msg}', file=sys.stderr)
    print('usage: blender -b --factory-startup --python tests/blender/check_glb.py -- FILE.glb [...] '
          '[--scene-fps N] [--frames 0,50,100,199] [--draco-library PATH]', file=sys.stderr)
    sys.stdout.flush()
    os._exit(2)


# ---------------------------------------------------------------- arguments (everything after "--")
argv = sys.argv[sys.argv.index('--') + 1:] if '--' in sys.argv else []
files, scene_fps, frames_opt = [], None, None
# The build's Draco library for Blender (CMakeLists.txt target blender_draco), as scripts/blender_import.py finds it.
draco_path = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), 'build',
                          'blender', 'libextern_draco.so')
i = 0
while i < len(argv):
    a = argv[i]
    if a == '--draco-library':
        if i + 1 >= len(argv):
            usage(f'{a} needs a value')
        draco_path = os.path.abspath(argv[i + 1])
        i += 2
        continue
    if a in ('--scene-fps', '--frames'):
        if i + 1 >= len(argv):
            usage(f'{a} needs a value')
        v = argv[i + 1]
        i += 2
        try:
            if a == '--scene-fps':
                scene_fps = int(v)
                if scene_fps <= 0:
                    raise ValueError
            else:
                frames_opt = [int(x) for x in v.split(',') if x.strip()]
                if any(k < 0 for k in frames_opt):
                    raise ValueError
        except ValueError:
            usage(f'bad value for {a}: {v}')
        continue
    if a.startswith('--'):
        usage(f'unknown option {a}')
    files.append(os.path.abspath(a))
    i += 1
if not files:
    usage('no .glb file given')
# The importer loads the Draco library from this variable, read at each import (scripts/blender_import.py).
os.environ['BLENDER_EXTERN_DRACO_LIBRARY_PATH'] = draco_path

# ---------------------------------------------------------------- Debian workaround
# Debian's blender 3.4.1 ships an importer that uses np.bool, which numpy >= 1.24 (Debian 12) removed
# ("AttributeError: module 'numpy' has no attribute 'bool'" in set_poly_smoothing). np.bool was an alias of the
# builtin bool, so restoring the alias changes nothing else.
try:
    import numpy
    if 'bool' not in numpy.__dict__:
        numpy.bool = bool
        print(f'check_glb: note: numpy {numpy.__version__} has no np.bool, which Blender {bpy.app.version_string}\'s '
              'glTF importer uses; restored the alias (np.bool = bool)')
except ImportError:
    print('check_glb: SETUP ERROR: Blender\'s Python has no numpy, which the glTF importer needs '
          '(Debian: apt-get install -y python3-numpy)')
    sys.stdout.flush()
    os._exit(2)


# ---------------------------------------------------------------- the file, read without Blender
def read_glb(path):
    with open(path, 'rb') as f:
        buf = f.read()
    if len(buf) < 20 or struct.unpack_from('<I', buf, 0)[0] != 0x46546C67:
        raise ValueError('not a GLB file')
    if struct.unpack_from('<I', buf, 8)[0] != len(buf):
        raise ValueError(f'GLB header says {struct.unpack_from("<I", buf, 8)[0]} bytes, file has {len(buf)}')
    off, js, binc = 12, None, None
    while off + 8 <= len(buf):
        n, typ = struct.unpack_from('<II', buf, off)
        body = buf[off + 8:off + 8 + n]
        if typ == 0x4E4F534A:
            js = json.loads(body.decode('utf-8'))
        elif typ == 0x004E4942:
            binc = body
        off += 8 + n
    if js is None:
        raise ValueError('no JSON chunk')
    return js, binc


COMP = {5120: ('b', 1), 5121: ('B', 1), 5122: ('h', 2), 5123: ('H', 2), 5125: ('I', 4), 5126: ('f', 4)}
NCOMP = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3, 'VEC4': 4}


def read_accessor(js, binc, idx):
    acc = js['accessors'][idx]
    fmt, size = COMP[acc['componentType']]
    n = NCOMP[acc['type']]
    if 'bufferView' not in acc:
        return None
    bv = js['bufferViews'][acc['bufferView']]
    stride = bv.get('byteStride') or size * n
    base = bv.get('byteOffset', 0) + acc.get('byteOffset', 0)
    return [list(struct.unpack_from('<' + fmt * n, binc, base + k * stride)) for k in range(acc['count'])]


def step_sample(times, values, t):
    if t <= times[0]:
        return values[0]
    if t >= times[-1]:
        return values[-1]
    k = 0
    while k + 1 < len(times) and times[k + 1] <= t:
        k += 1
    return values[k]


def mesh_summary(js, binc, mesh):
    """(vertices Blender keeps, Draco?, POSITION min, max) of glTF mesh `mesh` (None: no mesh)."""
    verts, draco, lo, hi = 0, False, [math.inf] * 3, [-math.inf] * 3
    if mesh is None:
        return verts, draco, lo, hi
    for p in js['meshes'][mesh]['primitives']:
        pa = js['accessors'][p['attributes']['POSITION']]
        if 'min' in pa and 'max' in pa:
            lo = [min(a, b) for a, b in zip(lo, pa['min'])]
            hi = [max(a, b) for a, b in zip(hi, pa['max'])]
        if (p.get('extensions') or {}).get('KHR_draco_mesh_compression'):
            draco = True
            verts += pa['count']
        elif 'indices' in p:
            verts += len({v[0] for v in read_accessor(js, binc, p['indices'])})
        else:
            verts += pa['count']
    return verts, draco, lo, hi


def describe(path):
    js, binc = read_glb(path)
    scene = (js.get('scenes') or [{}])[js.get('scene', 0)]
    extras = scene.get('extras') or {}
    nodes = js.get('nodes') or []
    frames = []
    for idx, nd in enumerate(nodes):
        m = FRAME_NODE.match(nd.get('name', ''))
        if not m:
            continue
        verts, draco, lo, hi = mesh_summary(js, binc, nd.get('mesh'))
        children = []
        for ci in nd.get('children') or []:
            cn = nodes[ci]
            cv, cd, _, _ = mesh_summary(js, binc, cn.get('mesh'))
            children.append({'index': ci, 'name': cn.get('name', ''), 'verts': cv, 'draco': cd})
        frames.append({'index': idx, 'name': nd['name'], 'number': int(m.group(1)), 'mesh': 'mesh' in nd,
                       'verts': verts, 'draco': draco, 'bbox': (lo, hi) if lo[0] <= hi[0] else None,
                       'children': children})
    frames.sort(key=lambda f: f['number'])
    anims = js.get('animations') or []
    anim = next((a for a in anims if a.get('name') == 'frames'), anims[0] if anims else None)
    channels, duration, interps = {}, 0.0, set()
    if anim:
        for ch in anim['channels']:
            tgt = ch['target']
            if tgt.get('path') != 'scale' or 'node' not in tgt:
                continue
            s = anim['samplers'][ch['sampler']]
            times = [v[0] for v in read_accessor(js, binc, s['input'])]
            values = read_accessor(js, binc, s['output'])
            interps.add(s.get('interpolation', 'LINEAR'))
            channels[tgt['node']] = (times, values)
            duration = max(duration, times[-1])
    fps = extras.get('fps')
    if not (isinstance(fps, (int, float)) and fps > 0):
        fps = len(frames) / duration if duration > 0 else None
    cam = next((nd.get('name') for nd in nodes if 'camera' in nd), None)
    return {'json': js, 'extras': extras, 'frames': frames, 'anim': anim, 'channels': channels,
            'duration': duration, 'interps': interps, 'fps': fps, 'camera': cam,
            'draco': 'KHR_draco_mesh_compression' in (js.get('extensionsUsed') or [])}


def file_visible(d, t):
    """Frame node names whose scale is non-zero at time t, from the file's own animation data."""
    nodes = d['json']['nodes']
    out = []
    for f in d['frames']:
        if f['index'] in d['channels']:
            s = step_sample(*d['channels'][f['index']], t)
        else:
            s = nodes[f['index']].get('scale', [1, 1, 1])
        if min(abs(x) for x in s) > 1e-9:
            out.append(f['name'])
    return out


# ---------------------------------------------------------------- checks
class Result:
    def __init__(self, name):
        self.name, self.passed, self.failed, self.notes = name, 0, [], []

    def check(self, cond, what, detail=''):
        if cond:
            self.passed += 1
            return True
        msg = f'{what}: {detail}' if detail else what
        self.failed.append(msg)
        print(f'  FAIL {msg}')
        return False

    def note(self, msg):
        self.notes.append(msg)
        print(f'  note {msg}')


class Tee:
    """Copies what is written to stdout, to read the importer's log."""

    def __init__(self, out):
        self.out, self.text = out, []

    def write(self, s):
        self.text.append(s)
        return self.out.write(s)

    def flush(self):
        self.out.flush()


def world_scale_nonzero(obj):
    m = obj.matrix_world
    cols = [math.sqrt(m[0][c] ** 2 + m[1][c] ** 2 + m[2][c] ** 2) for c in range(3)]
    return min(cols) > 1e-9


def draco_library():
    try:
        from io_scene_gltf2.io.com import gltf2_io_draco_compression_extension as dce
        p = dce.dll_path()
        return str(p), p.is_file()
    except Exception as e:  # noqa: BLE001
        return f'(cannot locate: {e})', False


def check_file(path):
    r = Result(os.path.basename(path))
    t_start = time.time()
    print(f'\n== {path}')
    try:
        d = describe(path)
    except Exception as e:  # noqa: BLE001
        r.check(False, 'read the file', f'{type(e).__name__}: {e}')
        return r
    n = len(d['frames'])
    fps = d['fps']
    print(f'  file: {n} frame nodes, fps {fps}, animation {d["anim"]["name"] if d["anim"] else None!r} '
          f'({len(d["channels"])} scale channels, {d["duration"]} s, {"/".join(sorted(d["interps"]))})'
          f'{", Draco" if d["draco"] else ""}, camera node {d["camera"]!r}, first_frame {d["extras"].get("first_frame")}')
    if not r.check(n > 0, 'file has frame_NNNNN nodes') or not r.check(fps, 'fps known (scene extras fps)'):
        return r

    # fresh empty scene, then import
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    if scene_fps:
        scene.render.fps, scene.render.fps_base = scene_fps, 1.0
    bfps = scene.render.fps  # the importer converts seconds to frames with scene.render.fps
    if d['draco']:
        lib, ok = draco_library()
        print(f'  Blender Draco library: {lib} ({"present" if ok else "MISSING"})')
    before = set(bpy.data.objects.keys())
    t_imp = time.time()
    tee = Tee(sys.stdout)
    sys.stdout = tee
    try:
        res = bpy.ops.import_scene.gltf(filepath=path)
    except Exception as e:  # noqa: BLE001
        sys.stdout = tee.out
        text = str(e)
        key = [ln.strip() for ln in text.splitlines()
               if re.search(r'(Error|Exception):|cannot open', ln) and 'Traceback' not in ln]
        # the innermost error (e.g. "OSError: .../libextern_draco.so: cannot open shared object file")
        detail = key[-1] if key else text.strip().splitlines()[-1]
        if d['draco'] and 'extern_draco' in text:
            detail = (f'Blender\'s Draco library is not available in this build: {detail} '
                      '(Debian\'s blender package does not ship libextern_draco.so; the build makes it: '
                      'cmake --build build --target blender_draco, or give --draco-library PATH)')
        r.check(False, 'import_scene.gltf', detail)
        return r
    sys.stdout = tee.out
    r.check(res == {'FINISHED'}, 'import_scene.gltf finished', str(res))
    # the importer reports problems (e.g. "Draco Decoder: Unable to decode. Skipping primitive") on stdout only
    logged = ''.join(tee.text).splitlines()
    errs = [ln.strip() for ln in logged if re.search(r'\bERROR\b', ln)]
    warns = [ln.strip() for ln in logged if re.search(r'\bWARNING\b', ln)]
    r.check(not errs, 'importer logged no ERROR', f'{len(errs)} lines, e.g. {errs[:2]}')
    if warns:
        r.note(f'importer logged {len(warns)} WARNING lines, e.g. {warns[:2]}')
    print(f'  imported in {time.time() - t_imp:.2f} s; scene fps {scene.render.fps}/{scene.render.fps_base}, '
          f'frame range {scene.frame_start}..{scene.frame_end}')
    new = [o for o in bpy.data.objects if o.name not in before]

    # objects <-> frame nodes (by name; Blender appends .001 etc. on a clash)
    by_name = {}
    for o in new:
        base = re.sub(r'\.\d{3}$', '', o.name)
        if FRAME_NODE.match(base):
            by_name.setdefault(base, []).append(o)
    objs = []
    renamed = 0
    for f in d['frames']:
        cand = by_name.get(f['name'], [])
        if not r.check(len(cand) == 1, f'one Blender object for node {f["name"]}', f'found {len(cand)}'):
            objs.append(None)
            continue
        o = cand[0]
        renamed += o.name != f['name']
        objs.append(o)
        r.check(o.type == ('MESH' if f['mesh'] else 'EMPTY'), f'{f["name"]} object type',
                f'{o.type}, node {"has a mesh" if f["mesh"] else "has no mesh"}')
    extra = sorted(set(by_name) - {f['name'] for f in d['frames']})
    r.check(not extra, 'no frame objects beyond the file\'s frame nodes', ', '.join(extra[:5]))
    if renamed:
        r.note(f'Blender renamed {renamed} frame objects (name clash)')
    print(f'  objects: {sum(o is not None for o in objs)}/{n} frame objects '
          f'({sum(1 for o in objs if o and o.type == "MESH")} meshes, '
          f'{sum(1 for o in objs if o and o.type == "EMPTY")} empties); all new objects: {len(new)}')
    if d['camera']:
        cams = [o for o in new if o.type == 'CAMERA']
        r.check(len(cams) == 1 and re.sub(r'\.\d{3}$', '', cams[0].name) == d['camera'],
                f'camera node {d["camera"]!r} imported as a camera object',
                ', '.join(f'{o.name}:{o.type}' for o in cams) or 'no camera object')

    # geometry
    badv = []
    for f, o in zip(d['frames'], objs):
        if o is None or o.type != 'MESH':
            continue
        nv = len(o.data.vertices)
        ok = (0 < nv <= f['verts']) if f['draco'] else (nv == f['verts'])
        if not ok:
            badv.append(f'{f["name"]}: Blender {nv}, file {f["verts"]}')
    r.check(not badv, 'mesh vertex counts match the file' +
            (' (Draco: 0 < Blender <= POSITION count)' if d['draco'] else ' (referenced vertices)'),
            f'{len(badv)} differ, e.g. {"; ".join(badv[:3])}')
    # positions: the Blender mesh's bounding box, back in glTF axes (Blender x, y, z = glTF x, -z, y), against the
    # POSITION accessors' min/max (for Draco the min/max of the decoded positions)
    badb = []
    for f, o in zip(d['frames'], objs):
        if o is None or o.type != 'MESH' or not f['bbox'] or not len(o.data.vertices):
            continue
        co = [(v.co.x, v.co.z, -v.co.y) for v in o.data.vertices]
        lo = [min(c[a] for c in co) for a in range(3)]
        hi = [max(c[a] for c in co) for a in range(3)]
        wlo, whi = f['bbox']
        tol = 1e-4 * max(1.0, max(b - a for a, b in zip(wlo, whi)))
        if any(abs(x - y) > tol for x, y in zip(lo + hi, list(wlo) + list(whi))):
            badb.append(f'{f["name"]}: Blender {[round(x, 4) for x in lo + hi]}, '
                        f'file {[round(x, 4) for x in list(wlo) + list(whi)]}')
    r.check(not badb, 'mesh bounding boxes match the POSITION min/max of the file',
            f'{len(badb)} differ, e.g. {"; ".join(badb[:2])}')
    # reflections in mirrors: child nodes "frame_NNNNN mirror M" of the frame nodes, imported as child
    # objects of their frame objects with the file's vertex counts
    new_by_name = {}
    for o in new:
        new_by_name.setdefault(re.sub(r'\.\d{3}$', '', o.name), []).append(o)
    child_objs, bad_child = {}, []
    for f, o in zip(d['frames'], objs):
        for c in f['children']:
            cand = new_by_name.get(c['name'], [])
            if len(cand) != 1:
                bad_child.append(f'{c["name"]}: {len(cand)} objects')
                continue
            co = cand[0]
            child_objs[c['name']] = co
            if o is not None and co.parent != o:
                bad_child.append(f'{c["name"]}: parent {co.parent.name if co.parent else None}, not {o.name}')
            nv = len(co.data.vertices) if co.type == 'MESH' else 0
            if not ((0 < nv <= c['verts']) if c['draco'] else (nv == c['verts'])):
                bad_child.append(f'{c["name"]}: Blender {nv} vertices, file {c["verts"]}')
    n_children = sum(len(f['children']) for f in d['frames'])
    r.check(not bad_child, f'{n_children} reflection nodes imported as children of their frame objects with the '
            'file\'s vertex counts', f'{len(bad_child)} wrong, e.g. {"; ".join(bad_child[:3])}')
    tot_v = sum(len(o.data.vertices) for o in objs if o and o.type == 'MESH')
    tot_f = sum(len(o.data.polygons) for o in objs if o and o.type == 'MESH')
    print(f'  geometry: {tot_v} vertices, {tot_f} faces in Blender')

    # animation data
    no_action, bad_fc, bad_interp, bad_keys = [], [], [], []
    for f, o in zip(d['frames'], objs):
        if o is None:
            continue
        ad = o.animation_data
        act = ad.action if ad else None
        if act is None:
            no_action.append(f['name'])
            continue
        fcs = {fc.array_index: fc for fc in act.fcurves if fc.data_path == 'scale'}
        if sorted(fcs) != [0, 1, 2]:
            bad_fc.append(f'{f["name"]}: scale fcurves {sorted(fcs)}')
            continue
        for fc in fcs.values():
            interp = {kp.interpolation for kp in fc.keyframe_points}
            if interp != {'CONSTANT'}:
                bad_interp.append(f'{f["name"]}: {sorted(interp)}')
                break
        ch = d['channels'].get(f['index'])
        if ch:
            got = [kp.co[0] for kp in fcs[0].keyframe_points]
            want = [t * bfps for t in ch[0]]
            if len(got) != len(want) or any(abs(a - b) > 1e-3 * max(1.0, abs(b)) for a, b in zip(got, want)):
                bad_keys.append(f'{f["name"]}: keys at {[round(x, 3) for x in got][:4]}, '
                                f'expected {[round(x, 3) for x in want][:4]}')
    r.check(not no_action, 'every frame object has an action', f'{len(no_action)} without, e.g. {no_action[:3]}')
    r.check(not bad_fc, 'actions animate scale x, y, z', '; '.join(bad_fc[:3]))
    r.check(not bad_interp, 'all scale keyframes are CONSTANT (glTF STEP)', '; '.join(bad_interp[:3]))
    r.check(not bad_keys, f'keyframes at glTF time * scene fps ({bfps})', '; '.join(bad_keys[:3]))
    acts = {o.animation_data.action.name for o in objs if o and o.animation_data and o.animation_data.action}
    print(f'  animation: {len(acts)} actions (e.g. {sorted(acts)[:2]}), scale keys CONSTANT: {not bad_interp}')

    # visibility over time
    ks = frames_opt if frames_opt is not None else [0, 1, n // 4, n // 2, (3 * n) // 4, n - 2, n - 1]
    ks = sorted({k for k in ks if 0 <= k < n})
    probes = [(f'frame #{k}', (k + 0.5) / fps, k) for k in ks]
    probes.append(('t = duration', d['duration'], n - 1))
    for label, t, k in probes:
        bf = t * bfps
        fi = math.floor(bf)
        scene.frame_set(fi, subframe=bf - fi)
        shown = [f['name'] for f, o in zip(d['frames'], objs) if o is not None and world_scale_nonzero(o)]
        want = d['frames'][k]['name']
        file_says = file_visible(d, t)
        ok1 = r.check(file_says == [want], f'{label} (t={t:.3f} s): file animation shows exactly {want}',
                      f'file shows {file_says[:5]}')
        ok2 = r.check(shown == [want], f'{label} (t={t:.3f} s, Blender frame {bf:.3f}): Blender shows exactly {want}',
                      f'Blender shows {shown[:5]}{" ..." if len(shown) > 5 else ""} ({len(shown)} objects)')
        shown_children = sorted(name for name, co in child_objs.items() if world_scale_nonzero(co))
        want_children = sorted(c['name'] for c in d['frames'][k]['children'])
        ok3 = r.check(shown_children == want_children, f'{label}: Blender shows exactly the reflections of {want}',
                      f'Blender shows {shown_children[:3]}, file {want_children[:3]}')
        if ok1 and ok2 and ok3:
            print(f'  ok   {label}: t={t:.3f} s = Blender frame {bf:.3f} -> {shown[0]} only'
                  + (f' (+ {len(shown_children)} reflection nodes)' if shown_children else ''))

    # playback: every whole Blender frame from 0 to the end of the animation shows exactly one frame object, the
    # one the file's animation shows at that time (this is what the timeline plays)
    last = math.ceil(d['duration'] * bfps - 1e-6)
    sweep_bad, seen_names, boundary = [], set(), [0, 0]
    for bf in range(0, last + 1):
        scene.frame_set(bf)
        shown = [f['name'] for f, o in zip(d['frames'], objs) if o is not None and world_scale_nonzero(o)]
        # a whole Blender frame can fall exactly on a glTF frame boundary (10 fps scene, 10 fps file): the file's
        # float32 key times then decide by ~1e-7 s which side wins, so either neighbour is accepted there
        t = bf / bfps
        after, before = file_visible(d, t + 1e-4), file_visible(d, t - 1e-4)
        seen_names.update(shown)
        if len(shown) != 1 or (shown != after and shown != before):
            sweep_bad.append(f'frame {bf}: Blender {shown[:3]}, file {after[:3]}')
        elif after != before:
            boundary[shown == after] += 1
    r.check(not sweep_bad, f'whole Blender frames 0..{last}: exactly one frame object visible, as in the file',
            f'{len(sweep_bad)} frames wrong, e.g. {"; ".join(sweep_bad[:3])}')
    expect_seen = math.ceil(min(bfps / fps, 1.0) * n - 1e-9)  # at a scene fps below the file's, frames are skipped
    r.check(len(seen_names) >= expect_seen, 'the sweep showed every frame object (scene fps >= file fps)',
            f'{len(seen_names)} of {n} seen')
    if not sweep_bad:
        print(f'  ok   Blender frames 0..{last}: one frame object each, {len(seen_names)} distinct of {n}'
              + (f'; {sum(boundary)} fall on a glTF frame boundary, Blender shows the new frame at {boundary[1]}, '
                 f'the old one at {boundary[0]}' if sum(boundary) else ''))

    # scene extras arrive as custom properties of the scene (informational)
    keys = [k for k in ('fps', 'frame_times', 'model', 'first_frame', 'objects') if k in d['extras']]
    missing = [k for k in keys if k not in scene.keys()]
    if missing:
        r.note(f'scene extras {missing} did not arrive as scene custom properties')
    last_frame = d['duration'] * bfps
    if scene.frame_end < last_frame:
        r.note(f'the importer leaves the scene frame range at {scene.frame_start}..{scene.frame_end}, the animation '
               f'runs to Blender frame {last_frame:g} ({d["duration"]:g} s at {bfps} fps): set the frame range '
               'to see the whole animation in the timeline')
    print(f'  {r.passed} checks passed, {len(r.failed)} failed ({time.time() - t_start:.2f} s)')
    return r


def main():
    print(f'check_glb: Blender {bpy.app.version_string}, Python {sys.version.split()[0]}, {len(files)} file(s)'
          f'{f", scene fps {scene_fps}" if scene_fps else ""}')
    results = []
    for p in files:
        try:
            results.append(check_file(p))
        except Exception:  # noqa: BLE001
            r = Result(os.path.basename(p))
            r.check(False, 'unexpected error', traceback.format_exc().strip().splitlines()[-1])
            traceback.print_exc()
            results.append(r)
    print('\ncheck_glb summary:')
    for p, r in zip(files, results):
        print(f'  {"PASS" if not r.failed else "FAIL"}  {p}: {r.passed} passed, {len(r.failed)} failed'
              + (f' (first: {r.failed[0]})' if r.failed else ''))
    np_ = sum(r.passed for r in results)
    nf = sum(len(r.failed) for r in results)
    print(f'check_glb: {len(files)} file(s) in {time.time() - T0:.1f} s')
    print(f'check_glb: {np_} passed, {nf} failed')
    sys.stdout.flush()
    return 1 if nf else 0


# os._exit: a Python exception or sys.exit inside --python does not set Blender's exit status
code = 1
try:
    code = main()
finally:
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
