# Checks a .blend saved by scripts/blender_import.py from a --compress draco .glb of tests/looks/make_textured_box.py's
# box (Draco keeps the look): Blender's importer decoded every frame mesh's TEXCOORD_0 and COLOR_0 and
# kept the three materials, the textured one with the input's image.
#
#   blender -b OUT.blend --python-exit-code 1 --python tests/blender/check_look.py
#
# Per mesh: a UV layer whose coordinates lie in [0, 1] (the box's closed form, make_textured_box.py, within the
# 12-bit quantization and float rounding: 1e-3) and span more than half of it; a colour attribute (COLOR_0) whose
# blue channel is the box's 0.25 (linear) within 1e-3; materials among the input's names. Over all: the three
# materials used, "textured" with an image texture node holding the input's image "checker".
# Prints the numbers and one line per failed check; exit status 0 all passed, 1 a check failed.
import os
import sys

import bpy

fails = []
meshes = [o for o in bpy.data.objects if o.type == 'MESH']
used = set()
lo, hi = 1.0, 0.0
for o in meshes:
    m = o.data
    if not m.uv_layers:
        fails.append('%s: no UV layer' % o.name)
        continue
    uv = [c for d in m.uv_layers[0].data for c in d.uv]
    lo, hi = min(lo, min(uv)), max(hi, max(uv))
    if min(uv) < -1e-3 or max(uv) > 1 + 1e-3 or max(uv) - min(uv) < 0.5:
        fails.append('%s: UVs span [%g, %g]' % (o.name, min(uv), max(uv)))
    colors = getattr(m, 'color_attributes', None) or m.vertex_colors
    if not colors:
        fails.append('%s: no colour attribute' % o.name)
    else:
        blue = [d.color[2] for d in colors[0].data]
        if any(abs(b - 0.25) > 1e-3 for b in blue):
            fails.append('%s: COLOR_0 blue %g .. %g, expected 0.25' % (o.name, min(blue), max(blue)))
    used.update(s.name.split('.')[0] for s in m.materials if s)
if not meshes:
    fails.append('no mesh imported')
if not {'textured', 'orange', 'grey'} <= used:
    fails.append('materials used: %s' % sorted(used))
textured = bpy.data.materials.get('textured')
images = [n.image.name for n in (textured.node_tree.nodes if textured and textured.use_nodes else [])
          if n.type == 'TEX_IMAGE' and n.image]
if not any(i.startswith('checker') for i in images):
    fails.append('material "textured" has no image texture "checker": %s' % images)
print('check_look: %d meshes, UVs in [%g, %g], materials %s, textured images %s' % (len(meshes), lo, hi, sorted(used),
                                                                                  images))
for f in fails[:10]:
    print('check_look: FAIL %s' % f)
sys.stdout.flush()
os._exit(1 if fails else 0)
