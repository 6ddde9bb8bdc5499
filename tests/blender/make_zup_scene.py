# Authors a scene the way a Blender user would, and exports it with Blender's glTF exporter:
#
#   blender -b --factory-startup --python tests/blender/make_zup_scene.py -- OUT.glb VX VY VZ
#
# A cube of edge 1 at the origin with the custom property velocity = [VX, VY, VZ] in Blender's axes
# (Z up, Y into the screen), a camera 10 units behind it (at -Y) looking along +Y, and the scene custom
# properties model = "instant" and up = "z" (apparent reads vectors in the extras as Z-up then). The
# exporter copies custom properties into the glTF extras unchanged and turns the geometry to glTF's Y-up.
import math
import os
import sys

import bpy

argv = sys.argv[sys.argv.index('--') + 1:]
out, velocity = argv[0], [float(v) for v in argv[1:4]]
try:
    import numpy
    if 'bool' not in numpy.__dict__:
        numpy.bool = bool  # Debian's Blender 3.4 with numpy 1.24 (scripts/blender_import.py)
except ImportError:
    pass
scene = bpy.context.scene
for obj in list(scene.objects):
    bpy.data.objects.remove(obj, do_unlink=True)
bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 0, 0))
cube = bpy.context.active_object
cube.name = 'Cube'
cube['velocity'] = velocity
bpy.ops.object.camera_add(location=(0, -10, 0), rotation=(math.pi / 2, 0, 0))
scene.camera = bpy.context.active_object
scene['model'] = 'instant'
scene['up'] = 'z'
result = bpy.ops.export_scene.gltf(filepath=os.path.abspath(out), export_format='GLB', export_extras=True,
                                   export_cameras=True)
print(f'make_zup_scene: {out}: {result}')
sys.stdout.flush()
os._exit(0 if 'FINISHED' in result else 1)
