# Renders a .blend saved by scripts/blender_import.py headless (Cycles on the CPU, small and quick) and
# checks that the picture is not dark (docs/VIEWERS.md "Blender"):
#
#   blender -b OUT.blend --python-exit-code 1 --python tests/blender/check_render.py -- PICTURE.png [FRAME]
#
# FRAME (default: the middle of the timeline) is the Blender frame rendered. Three renders of that frame:
#   1. as imported, written to PICTURE.png: the mean display value (sRGB, 0..1, over R, G, B and every
#      pixel) must be >= kMeanPicture;
#   2. the same with a transparent film (the world still lights the scene; only its background is left
#      out): the opaque objects cover >= kCover of the pixels (alpha > 0.99; a blended mirror is left out), and their mean display value is
#      >= kMeanObject;
#   3. the control: as 2 without the script's lights and with Blender's default world colour (0.0508,
#      what an import without blender_import.py's lighting gets): the objects' mean display value must
#      be < kMeanObject, so the threshold tells a lit scene from an unlit one.
# Prints the numbers and one line per failed check; exit status 0 all passed, 1 a check failed.
import os
import sys

import bpy
import numpy

kMeanPicture = 0.3
kCover = 0.01
kMeanObject = 0.4
kDefaultWorld = 0.0508  # Blender 3.4's factory world colour

argv = sys.argv[sys.argv.index('--') + 1:] if '--' in sys.argv else []
if not 1 <= len(argv) <= 2:
    print('check_render: usage: blender -b OUT.blend --python tests/blender/check_render.py -- PICTURE.png [FRAME]')
    sys.stdout.flush()
    os._exit(1)
picture = os.path.abspath(argv[0])
scene = bpy.context.scene
frame = int(argv[1]) if len(argv) == 2 else (scene.frame_start + scene.frame_end) // 2
scene.frame_set(frame)

# Step: a small quick Cycles render on the CPU (Eevee needs a GPU context, which a headless Blender lacks);
# Debian's Blender has no OpenImageDenoise, so denoising is off.
scene.render.engine = 'CYCLES'
scene.cycles.device = 'CPU'
scene.cycles.samples = 16
scene.cycles.use_denoising = False
scene.render.resolution_x = 320
scene.render.resolution_y = 180
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = 'PNG'
scene.render.image_settings.color_mode = 'RGBA'


def render(path, transparent):
    """The display values (rows x columns x RGBA, 0..1) of the frame rendered into path."""
    scene.render.film_transparent = transparent
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    pixels = numpy.array(image.pixels[:], dtype=float).reshape(image.size[1], image.size[0], 4)
    bpy.data.images.remove(image)
    return pixels


failed = 0


def check(ok, what):
    global failed
    print(f'check_render: {"ok" if ok else "FAIL"}: {what}')
    failed += 0 if ok else 1


def objects(pixels):
    """The objects' share of the pixels and their mean display value."""
    covered = pixels[:, :, 3] > 0.99
    share = float(covered.mean())
    mean = float(pixels[covered][:, :3].mean()) if covered.any() else 0.0
    return share, mean


# Step: 1, the picture as a user renders it.
shown = render(picture, False)
mean_picture = float(shown[:, :, :3].mean())
check(mean_picture >= kMeanPicture, f'frame {frame}: mean display value {mean_picture:.3f} >= {kMeanPicture} ({picture})')

# Step: 2, the objects alone.
stem = os.path.splitext(picture)[0]
cover, mean_object = objects(render(stem + '_objects.png', True))
check(cover >= kCover, f'the objects cover {100 * cover:.1f}% of the pixels, >= {100 * kCover:g}%')
check(mean_object >= kMeanObject, f'the objects\' mean display value {mean_object:.3f} >= {kMeanObject}')

# Step: 3, the control: no lights of the script, the default world.
for obj in [o for o in scene.objects if o.type == 'LIGHT']:
    bpy.data.objects.remove(obj, do_unlink=True)
scene.world.color = (kDefaultWorld,) * 3
if scene.world.use_nodes and 'Background' in scene.world.node_tree.nodes:
    scene.world.node_tree.nodes['Background'].inputs['Color'].default_value = (kDefaultWorld,) * 3 + (1,)
cover_dark, mean_dark = objects(render(stem + '_unlit.png', True))
check(mean_dark < kMeanObject, f'control, unlit: the objects\' mean display value {mean_dark:.3f} < {kMeanObject} '
                               f'(cover {100 * cover_dark:.1f}%)')

print(f'check_render: {3 + 1 - failed} passed, {failed} failed')
sys.stdout.flush()
os._exit(1 if failed else 0)
