# Authors a keyframed path the way a Blender user would, and exports it with Blender's glTF exporter
# with animations on (docs/MOTION.md "Keyframed paths"):
#
#   blender -b --factory-startup --python tests/blender/make_keyed_scene.py -- OUT.glb
#
# At 10 frames per second, a cube of edge 1 keyed at frame 0 at (-2, 0, 0) and at frame 100 at
# (2, 0, 0) with a quarter turn about Blender's Z, LINEAR interpolation: 0.4 light-seconds per second
# along +X for 10 s. The cube's custom property t0 = 0 makes it an object; the scene's tolerance =
# "vertex" (the fastest mode) and up = "z". A camera 10 units behind (-Y).
import math
import os
import sys

import bpy

out = sys.argv[sys.argv.index('--') + 1:][0]
try:
    import numpy
    if 'bool' not in numpy.__dict__:
        numpy.bool = bool  # Debian's Blender 3.4 with numpy 1.24 (scripts/blender_import.py)
except ImportError:
    pass
scene = bpy.context.scene
for obj in list(scene.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
scene.render.fps = 10
scene.frame_start = 0
scene.frame_end = 100
bpy.ops.mesh.primitive_cube_add(size=1, location=(-2, 0, 0))
cube = bpy.context.active_object
cube.name = 'Cube'
cube['t0'] = 0.0
cube.keyframe_insert(data_path='location', frame=0)
cube.keyframe_insert(data_path='rotation_euler', frame=0)
cube.location = (2, 0, 0)
cube.rotation_euler = (0, 0, math.pi / 2)
cube.keyframe_insert(data_path='location', frame=100)
cube.keyframe_insert(data_path='rotation_euler', frame=100)
for curve in cube.animation_data.action.fcurves:
    for key in curve.keyframe_points:
        key.interpolation = 'LINEAR'
bpy.ops.object.camera_add(location=(0, -10, 0), rotation=(math.pi / 2, 0, 0))
scene.camera = bpy.context.active_object
scene['tolerance'] = 'vertex'
scene['up'] = 'z'
result = bpy.ops.export_scene.gltf(filepath=os.path.abspath(out), export_format='GLB', export_extras=True,
                                   export_cameras=True, export_animations=True)
print(f'make_keyed_scene: {out}: {result}')
sys.stdout.flush()
os._exit(0 if 'FINISHED' in result else 1)
