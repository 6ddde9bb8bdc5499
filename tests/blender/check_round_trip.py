# Checks a .blend saved by scripts/blender_import.py against the .glb it imported:
#
#   blender -b SAVED.blend --python tests/blender/check_round_trip.py -- OUT.glb DX DY DZ K
#
# - the scene's frame rate (fps / fps_base) is the file's scene extras "fps";
# - the timeline runs 0 .. N-1 for the file's N frames (extras "frame_times");
# - the scene camera is a camera object of the file;
# - between frame objects frame_00000 and frame_K (instant model, an object in uniform motion) the mesh's
#   world bounding-box centre moved by (DX, DY, DZ) in Blender's axes: the motion the scene's author meant.
# Prints one line per failure and a summary; exit status 0 when all passed, 1 otherwise.
import json
import os
import struct
import sys

import bpy
from mathutils import Vector

argv = sys.argv[sys.argv.index('--') + 1:]
glb, expected, k = argv[0], Vector([float(v) for v in argv[1:4]]), int(argv[4])
with open(glb, 'rb') as f:
    head = f.read(20)
    doc = json.loads(f.read(struct.unpack('<I', head[12:16])[0]))
extras = doc['scenes'][doc.get('scene', 0)]['extras']
failures = []


def check(ok, message):
    if not ok:
        failures.append(message)
        print(f'check_round_trip: FAIL: {message}')


scene = bpy.context.scene
fps = scene.render.fps / scene.render.fps_base
check(abs(fps - extras['fps']) < 1e-9 * extras['fps'], f'scene fps {fps}, file fps {extras["fps"]}')
n = len(extras['frame_times'])
check((scene.frame_start, scene.frame_end) == (0, n - 1),
      f'timeline {scene.frame_start}..{scene.frame_end}, file frames 0..{n - 1}')
check(scene.camera is not None and scene.camera.type == 'CAMERA', f'scene camera {scene.camera}')


def centre(name):
    obj = bpy.data.objects.get(name)
    if obj is None or obj.type != 'MESH':
        check(False, f'no mesh object {name}')
        return Vector((0, 0, 0))
    points = [obj.matrix_world @ v.co for v in obj.data.vertices]
    lo = Vector([min(p[i] for p in points) for i in range(3)])
    hi = Vector([max(p[i] for p in points) for i in range(3)])
    return (lo + hi) / 2


moved = centre(f'frame_{k:05d}') - centre('frame_00000')
check((moved - expected).length < 1e-4, f'the object moved by {tuple(moved)}, expected {tuple(expected)}')
print(f'check_round_trip: moved {tuple(round(c, 6) for c in moved)}; {len(failures)} failed')
sys.stdout.flush()
os._exit(1 if failures else 0)
