# Opens one of apparent's animated .glb files in Blender, ready to play (docs/VIEWERS.md "Blender").
#
#   blender --python scripts/blender_import.py -- OUT.glb                  # opens it: press Space to play
#   blender --background --python scripts/blender_import.py -- OUT.glb --save OUT.blend
#
# In the current scene, emptied first:
#   - restores numpy's np.bool alias when it is missing: Debian 12's Blender 3.4 glTF importer uses it and
#     numpy 1.24 removed it (the import fails with "module 'numpy' has no attribute 'bool'");
#   - sets the scene's frame rate to the file's (scene extras "fps") before the import, so that every frame
#     of the file starts on a whole Blender frame (the importer places keys at seconds x the scene's fps);
#   - imports the file (bpy.ops.import_scene.gltf);
#   - sets the timeline to the file's frames: 0 .. N-1 for its N frames (scene extras "frame_times");
#   - makes the file's camera the scene camera.
# --save PATH writes the result as a .blend file. Exit status (with --background): 0 done, 1 the import
# failed, 2 a usage problem.
import json
import math
import os
import struct
import sys

import bpy


def fail(code, message):
    print(f'blender_import: {message}', file=sys.stderr)
    sys.stderr.flush()
    if bpy.app.background:
        os._exit(code)
    raise SystemExit(code)


argv = sys.argv[sys.argv.index('--') + 1:] if '--' in sys.argv else []
path, save = None, None
i = 0
while i < len(argv):
    if argv[i] == '--save' and i + 1 < len(argv):
        save = os.path.abspath(argv[i + 1])
        i += 2
    elif argv[i].startswith('--') or path is not None:
        fail(2, f'unexpected argument {argv[i]}; usage: blender [--background] --python '
                'scripts/blender_import.py -- OUT.glb [--save OUT.blend]')
    else:
        path = os.path.abspath(argv[i])
        i += 1
if path is None or not os.path.isfile(path):
    fail(2, f'{path or "no file given"}: not found; usage: blender [--background] --python '
            'scripts/blender_import.py -- OUT.glb [--save OUT.blend]')

# Debian's numpy 1.24 dropped np.bool, an alias of the builtin bool that Blender 3.4's importer still uses.
try:
    import numpy
    if 'bool' not in numpy.__dict__:
        numpy.bool = bool
except ImportError:
    fail(1, "Blender's Python has no numpy, which the glTF importer needs (Debian: apt-get install python3-numpy)")


def scene_extras(glb_path):
    """The glTF scene's extras of a .glb (its JSON chunk), read without Blender."""
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
    scenes = doc.get('scenes') if isinstance(doc, dict) else None
    index = doc.get('scene', 0) if isinstance(doc, dict) else 0
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


def shown(value):
    """A JSON value for a one-line message, cut short."""
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + '...'


# The extras this script uses, checked: "fps" a finite number > 0 (24 when absent), "frame_times" a list.
extras = scene_extras(path)
fps = extras.get('fps', 24)
if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not math.isfinite(fps) or fps <= 0:
    fail(1, f'{path}: scene extras "fps": {shown(fps)} is not a finite number > 0')
fps = float(fps)
frame_times = extras.get('frame_times', [])
if not isinstance(frame_times, list):
    fail(1, f'{path}: scene extras "frame_times": {shown(frame_times)} is not a list')
frames = len(frame_times) or 1

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
print(f'blender_import: {path}: {frames} frames at {fps:g} fps, timeline 0..{frames - 1}, camera '
      f'{cameras[0].name if cameras else "(none in the file)"}')
if save:
    bpy.ops.wm.save_as_mainfile(filepath=save)
    print(f'blender_import: saved {save}')
