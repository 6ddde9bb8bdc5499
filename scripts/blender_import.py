# Opens one of apparent's animated .glb files in Blender, ready to play (docs/VIEWERS.md "Blender").
#
#   blender --python scripts/blender_import.py -- OUT.glb                  # opens it: press Space to play
#   blender --background --python scripts/blender_import.py -- OUT.glb --save OUT.blend
#
# In the current scene, emptied first:
#   - restores numpy's np.bool alias when it is missing: Debian 12's Blender 3.4 glTF importer uses it and
#     numpy 1.24 removed it (the import fails with "module 'numpy' has no attribute 'bool'");
#   - for a Draco file (KHR_draco_mesh_compression) points the importer at the Draco library the build
#     makes (build/blender/libextern_draco.so beside this script's folder, or --draco-library PATH; Debian's
#     Blender ships none); a meshopt file (EXT_meshopt_compression) is refused with one line, as Blender
#     3.4's importer does not read it;
#   - sets the scene's frame rate to the file's (scene extras "fps") before the import, so that every frame
#     of the file starts on a whole Blender frame (the importer places keys at seconds x the scene's fps);
#   - imports the file (bpy.ops.import_scene.gltf);
#   - sets the timeline to the file's frames: 0 .. N-1 for its N frames (scene extras "frame_times");
#   - makes the file's camera the scene camera;
#   - lights the scene as the file's scene is lit (scene extras "light"): a sun per distant light or a
#     point light, and the world colour the ambient share (docs/VIEWERS.md "Blender" derives the strengths),
#     with the "Standard" view transform (sRGB, as apparent's raytracer writes its pictures).
# --save PATH writes the result as a .blend file. --draco-library PATH: the Draco library (default: the
# build's; BLENDER_EXTERN_DRACO_LIBRARY_PATH, when set and no option is given). Exit status (with
# --background): 0 done, 1 the import failed, 2 a usage problem.
import json
import math
import os
import struct
import sys

import bpy
import mathutils


def fail(code, message):
    print(f'blender_import: {message}', file=sys.stderr)
    sys.stderr.flush()
    if bpy.app.background:
        os._exit(code)
    raise SystemExit(code)


USAGE = ('usage: blender [--background] --python scripts/blender_import.py -- OUT.glb [--save OUT.blend] '
         '[--draco-library PATH]')
# The Draco library the build makes (CMakeLists.txt target blender_draco), for a build in build/.
DEFAULT_DRACO = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'build', 'blender',
                             'libextern_draco.so')

argv = sys.argv[sys.argv.index('--') + 1:] if '--' in sys.argv else []
path, save, draco_library = None, None, None
i = 0
while i < len(argv):
    if argv[i] == '--save' and i + 1 < len(argv):
        save = os.path.abspath(argv[i + 1])
        i += 2
    elif argv[i] == '--draco-library' and i + 1 < len(argv):
        draco_library = os.path.abspath(argv[i + 1])
        i += 2
    elif argv[i].startswith('--') or path is not None:
        fail(2, f'unexpected argument {argv[i]}; {USAGE}')
    else:
        path = os.path.abspath(argv[i])
        i += 1
if path is None or not os.path.isfile(path):
    fail(2, f'{path or "no file given"}: not found; {USAGE}')

# Debian's numpy 1.24 dropped np.bool, an alias of the builtin bool that Blender 3.4's importer still uses.
try:
    import numpy
    if 'bool' not in numpy.__dict__:
        numpy.bool = bool
except ImportError:
    fail(1, "Blender's Python has no numpy, which the glTF importer needs (Debian: apt-get install python3-numpy)")


def read_document(glb_path):
    """The JSON chunk of a .glb, read without Blender."""
    with open(glb_path, 'rb') as f:
        head = f.read(20)
        if len(head) < 20 or head[:4] != b'glTF':
            fail(1, f'{glb_path}: not a binary glTF (.glb) file')
        length, kind = struct.unpack('<II', head[12:20])
        if kind != 0x4E4F534A:
            fail(1, f'{glb_path}: the first chunk is not JSON')
        try:
            doc = json.loads(f.read(length))
        except (ValueError, RecursionError) as e:
            fail(1, f'{glb_path}: the JSON chunk is not valid JSON ({str(e)[:80]})')
    if not isinstance(doc, dict):
        fail(1, f'{glb_path}: the JSON chunk is not an object')
    return doc


def scene_extras(glb_path, doc):
    """The glTF scene's extras."""
    scenes = doc.get('scenes')
    index = doc.get('scene', 0)
    if scenes is None:
        return {}
    if not isinstance(scenes, list) or isinstance(index, bool) or not isinstance(index, int) \
            or not 0 <= index < len(scenes) or not isinstance(scenes[index], dict):
        fail(1, f'{glb_path}: "scenes" / "scene" do not name a scene object')
    extras = scenes[index].get('extras')
    if extras is None:
        return {}
    if not isinstance(extras, dict):
        fail(1, f'{glb_path}: the scene\'s "extras" is not an object')
    return extras


def extensions(doc, key):
    """The names in extensionsUsed or extensionsRequired (strings only)."""
    names = doc.get(key)
    return {n for n in names if isinstance(n, str)} if isinstance(names, list) else set()


def shown(value):
    """A JSON value for a one-line message, cut short."""
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + '...'


# The extras this script uses, checked: "fps" a finite number > 0 (24 when absent), "frame_times" a list.
document = read_document(path)
extras = scene_extras(path, document)
fps = extras.get('fps', 24)
if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not math.isfinite(fps) or fps <= 0:
    fail(1, f'{path}: scene extras "fps": {shown(fps)} is not a finite number > 0')
fps = float(fps)
frame_times = extras.get('frame_times', [])
if not isinstance(frame_times, list):
    fail(1, f'{path}: scene extras "frame_times": {shown(frame_times)} is not a list')
frames = len(frame_times) or 1


def vector3(value):
    """A list of 3 finite numbers, or None."""
    if not isinstance(value, list) or len(value) != 3:
        return None
    if any(isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) for v in value):
        return None
    return [float(v) for v in value]


def fraction(value):
    """A number in [0, 1], or None."""
    ok = not isinstance(value, bool) and isinstance(value, (int, float)) and 0 <= value <= 1
    return float(value) if ok else None


def read_light(light):
    """The scene extras "light" (apparent's glb writer, exporters/glb/document.cpp) as a list of
    ('SUN' or 'POINT', glTF vector, weight) and the ambient share; one line and exit 1 if malformed."""
    def bad(field, what):
        fail(1, f'{path}: scene extras "light": "{field}" {what}')
    if not isinstance(light, dict):
        fail(1, f'{path}: scene extras "light": {shown(light)} is not an object')
    ambient = fraction(light.get('ambient', 0.2))
    if ambient is None:
        bad('ambient', f'{shown(light.get("ambient"))} is not a number in [0, 1]')
    key_weight = fraction(light.get('key_weight', 0))
    if key_weight is None:
        bad('key_weight', f'{shown(light.get("key_weight"))} is not a number in [0, 1]')
    if ('position' in light) == ('direction' in light):
        fail(1, f'{path}: scene extras "light": needs exactly one of "position" and "direction"')
    kind = 'POINT' if 'position' in light else 'SUN'
    field = 'position' if kind == 'POINT' else 'direction'
    main = vector3(light[field])
    if main is None or (kind == 'SUN' and not any(main)):
        bad(field, f'{shown(light[field])} is not a list of 3 finite numbers' + (', not all 0' if kind == 'SUN' else ''))
    lights = [(kind, main, 1 - key_weight)]
    if key_weight > 0:
        key = vector3(light.get('key_direction'))
        if key is None or not any(key):
            bad('key_direction', f'{shown(light.get("key_direction"))} is not a list of 3 finite numbers, not all 0')
        lights.append(('SUN', key, key_weight))
    return lights, ambient


def blender_axes(v):
    """glTF's Y-up (x, y, z) in Blender's Z-up axes, as the importer turns them: (x, -z, y)."""
    return mathutils.Vector((v[0], -v[2], v[1]))


# The file's light: a file without the "light" extras (one written before apparent recorded it, or by
# another program) is lit by one sun overhead (glTF's +Y) with the ambient 0.2 of the scene default.
if 'light' in extras:
    lights, ambient = read_light(extras['light'])
    light_source = 'the file\'s scene light (scene extras "light")'
else:
    lights, ambient = [('SUN', [0.0, 1.0, 0.0], 1.0)], 0.2
    light_source = 'a sun overhead: the file records no light (scene extras "light")'

# Step: the codecs. The importer reads Draco through a library it loads by path
# (io_scene_gltf2/io/com/gltf2_io_draco_compression_extension.py dll_path(): the environment variable
# BLENDER_EXTERN_DRACO_LIBRARY_PATH, read at each import, else beside Blender's own Python, where
# Debian's package has none); it refuses EXT_meshopt_compression, which it does not know.
if 'EXT_meshopt_compression' in extensions(document, 'extensionsRequired'):
    fail(1, f'{path}: uses EXT_meshopt_compression, which Blender {bpy.app.version_string}\'s glTF importer does '
            'not read; render it with --compress draco (or none) for Blender')
if 'KHR_draco_mesh_compression' in extensions(document, 'extensionsUsed'):
    if draco_library is None:
        draco_library = os.environ.get('BLENDER_EXTERN_DRACO_LIBRARY_PATH') or DEFAULT_DRACO
    if not os.path.isfile(draco_library):
        fail(1, f'{path}: uses Draco (KHR_draco_mesh_compression) and the Draco library for Blender is not at '
                f'{draco_library}: build it (scripts/setup.sh build, or cmake --build build --target blender_draco) '
                'or give --draco-library PATH')
    os.environ['BLENDER_EXTERN_DRACO_LIBRARY_PATH'] = draco_library
    print(f'blender_import: Draco: {draco_library}')

scene = bpy.context.scene
for obj in list(scene.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
# Blender's frame rate is fps / fps_base with an integer fps.
try:
    scene.render.fps = max(1, round(fps))
    scene.render.fps_base = scene.render.fps / fps
except (ValueError, TypeError, OverflowError):
    fail(1, f'{path}: scene extras "fps": {fps:g} is beyond what Blender\'s frame rate holds')
try:
    result = bpy.ops.import_scene.gltf(filepath=path)
except RuntimeError as e:
    fail(1, f'{path}: the glTF importer failed: {e}')
if 'FINISHED' not in result:
    fail(1, f'{path}: the glTF importer did not finish ({result})')
scene.frame_start = 0
scene.frame_end = frames - 1
scene.frame_set(0)
cameras = [o for o in scene.objects if o.type == 'CAMERA']
if cameras:
    scene.camera = cameras[0]

# Step: the lights, in linear radiance as the raytracer shades (pipeline/trace/raytrace.cpp shadeWith: base x
# (ambient + (1 - ambient) x weighted Lambert)). A diffuse surface of albedo a under a sun of strength S
# at normal incidence leaves radiance a S / pi, and under a uniform world of colour W radiance a W: so
# each sun gets S = pi (1 - ambient) weight and the world the ambient share. The raytracer's point
# light does not fall off: in Cycles a Light Falloff node's "Constant" output of strength X on a point
# light of power P gives radiance a P X / (4 pi^2) at any distance, and without it (Eevee) a point light
# lights like a sun of strength P / (4 pi r^2) at distance r (both measured, docs/VIEWERS.md); so
# P = 4 pi r^2 S and X = 1 / r^2, with r from the light to the centre of the meshes shown at frame 0:
# Cycles then matches the raytracer everywhere, Eevee there.
# The meshes shown at frame 0 (the others have scale 0 there).
meshes = [o for o in scene.objects if o.type == 'MESH' and len(o.data.vertices) and o.matrix_world.determinant() != 0]
centre = mathutils.Vector((0.0, 0.0, 0.0))
if meshes:
    corners = [o.matrix_world @ mathutils.Vector(c) for o in meshes for c in o.bound_box]
    centre = (mathutils.Vector([min(c[k] for c in corners) for k in range(3)]) +
              mathutils.Vector([max(c[k] for c in corners) for k in range(3)])) / 2
for n, (kind, vector, weight) in enumerate(lights):
    strength = math.pi * (1 - ambient) * weight
    data = bpy.data.lights.new(f'apparent light {n}', kind)
    data.shadow_soft_size = 0
    obj = bpy.data.objects.new(f'apparent light {n}', data)
    if kind == 'SUN':
        data.energy = strength
        # A sun shines along its local -Z: +Z towards the light.
        obj.rotation_euler = blender_axes(vector).to_track_quat('Z', 'Y').to_euler()
    else:
        obj.location = blender_axes(vector)
        r2 = max((obj.location - centre).length_squared, 1e-12)
        data.energy = 4 * math.pi * r2 * strength
        data.use_nodes = True
        nodes = data.node_tree.nodes
        falloff = nodes.new('ShaderNodeLightFalloff')
        falloff.inputs['Strength'].default_value = 1 / r2
        data.node_tree.links.new(falloff.outputs['Constant'], nodes['Emission'].inputs['Strength'])
    scene.collection.objects.link(obj)
if scene.world is None:
    scene.world = bpy.data.worlds.new('apparent world')
scene.world.color = (ambient, ambient, ambient)
if scene.world.use_nodes and 'Background' in scene.world.node_tree.nodes:
    background = scene.world.node_tree.nodes['Background']
    background.inputs['Color'].default_value = (ambient, ambient, ambient, 1)
    background.inputs['Strength'].default_value = 1
# Linear radiance to the picture as the raytracer does (sRGB transfer curve, clipped at 1: Blender's
# "Standard" view; its default "Filmic" compresses and desaturates the highlights).
scene.view_settings.view_transform = 'Standard'
scene.view_settings.look = 'None'
print(f'blender_import: lit by {light_source}: ' +
      ', '.join(f'{kind.lower()} {weight:g}' for kind, _, weight in lights) + f', world {ambient:g}')
print(f'blender_import: {path}: {frames} frames at {fps:g} fps, timeline 0..{frames - 1}, camera '
      f'{cameras[0].name if cameras else "(none in the file)"}')
if save:
    bpy.ops.wm.save_as_mainfile(filepath=save)
    print(f'blender_import: saved {save}')
