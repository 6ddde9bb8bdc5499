#!/usr/bin/env bash
# A textured, three-material box with vertex colours (make_textured_box.py) rendered at 0.9c: at the
# default tolerance, in vertex mode, and at rest in the instant model; each .glb passes the Khronos
# glTF-Validator and check_textured.py (every vertex's TEXCOORD_0, TEXCOORD_1 and COLOR_0 equal the closed form
# at its rest point, the materials and the image are the input's, the image once; with --shade
# doppler COLOR_0 is the modulation at the vertex's Doppler factor times that closed form). With --compress
# draco and meshopt the same, decoded (decode_glb.js), within the codecs' stated bounds; shards and
# MPI ranks give the one process's bytes; three.js in headless Chromium shows the texture, also of the
# compressed files, and with --shade doppler its exact shift (tests/web/doppler_*.js).
# Usage: run.sh APPARENT_BINARY SOURCE_DIR
set -euo pipefail
# OpenMPI's own allocations are not ours: no leak report for them under the sanitizers (as mpi_test.sh).
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
apparent=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
python3 "$src/tests/looks/make_textured_box.py" "$out/box.glb" "$out/texture.png"
scene() {  # velocity x, model, frames start[, file name]
  cat > "$out/${4:-scene_$2}.json" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_deg": 60},
 "frames": {"start": $3, "end": $(($3 + 2)), "fps": 2}, "model": "$2",
 "objects": [{"name": "box", "mesh": "box.glb", "position": [-2, 0.3, -4], "velocity": [$1, 0, 0],
              "rotation_deg": [20, 30, 0]}]}
JSON
}
scene 0.9 relativistic 16
scene 0 instant 0
"$apparent" render "$out/scene_relativistic.json" --out "$out/refined" --quiet
"$apparent" render "$out/scene_relativistic.json" --out "$out/vertex" --tolerance vertex --quiet
"$apparent" render "$out/scene_instant.json" --out "$out/rest" --tolerance vertex --quiet
python3 "$src/tests/looks/check_textured.py" "$out/refined/relativistic.glb" "$out/box.glb" -2 0.3 -4 0.9 0 0 20 30 0
python3 "$src/tests/looks/check_textured.py" "$out/vertex/relativistic.glb" "$out/box.glb" -2 0.3 -4 0.9 0 0 20 30 0
python3 "$src/tests/looks/check_textured.py" "$out/rest/instant.glb" "$out/box.glb" -2 0.3 -4 0 0 0 20 30 0
# --shade doppler keeps the input's materials and writes COLOR_0 = W(D) times the input's colour
# (docs/DOPPLER.md), W at each vertex's _DOPPLER.
# Camera times 3 to 5 s: D from about 0.6 to 1.9, where the shift changes colours without blacking them out.
scene 0.9 relativistic 3 scene_shaded
"$apparent" render "$out/scene_shaded.json" --out "$out/shaded" --shade doppler --attributes doppler --quiet
"$apparent" render "$out/scene_shaded.json" --out "$out/shaded_vertex" --tolerance vertex --shade doppler \
  --attributes doppler --quiet
python3 "$src/tests/looks/check_textured.py" "$out/shaded/relativistic.glb" "$out/box.glb" -2 0.3 -4 0.9 0 0 20 30 0 \
  --shade-doppler
python3 "$src/tests/looks/check_textured.py" "$out/shaded_vertex/relativistic.glb" "$out/box.glb" -2 0.3 -4 0.9 0 0 \
  20 30 0 --shade-doppler
(cd "$src" && node tests/validators/validate_gltf.js "$out/refined/relativistic.glb" "$out/vertex/relativistic.glb" \
  "$out/rest/instant.glb" "$out/shaded/relativistic.glb")
# three.js in headless Chromium shows the texture: texels of the texture's own colours in the picture
# (the box without COLOR_0, near the camera), and the viewer takes an input's COLOR_0 for no Doppler shading.
python3 "$src/tests/looks/make_textured_box.py" "$out/plain_box.glb" "$out/texture2.png" --no-colors
cat > "$out/near.json" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_deg": 40},
 "frames": {"start": 9.5, "end": 10.5, "fps": 4},
 "objects": [{"name": "box", "mesh": "plain_box.glb", "position": [-5.2, 0, -2.5], "velocity": [0.9, 0, 0],
              "rotation_deg": [20, 30, 0]}]}
JSON
"$apparent" render "$out/near.json" --out "$out/near" --quiet
(cd "$src" && node tests/web/viewer_test.js "$out/near" --models relativistic --frames 0,3 --shot-time 0.3 \
  --screenshot "$out/near.png" && node tests/looks/texels.js "$out/near.png" &&
  node tests/web/viewer_test.js "$out/refined" --models relativistic --frames 0,3 --shot-time 0.3)
# The same box with --shade doppler --attributes doppler, approaching (camera times 6.5 to 7.5 s, D from
# about 0.6 to 1.8), beside a JSON scene's coloured box: COLOR_0 is W(D) on the box's own materials and
# the shaded colour on the other, as the viewer's model (exporters/web/doppler.mjs) computes them; the
# viewer's shader computes that model's colours; the viewer shows the exact shift of the texture, and
# its Doppler toggle changes the picture (docs/gallery/textured_box_doppler.png is this file at 0.3 s), also
# where the input has its own COLOR_0 (the shaded box above, its colour recovered as COLOR_0 / W(D)).
cp "$src/data/meshes/box.obj" "$out/box.obj"
cat > "$out/approach.json" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_deg": 40},
 "frames": {"start": 6.5, "end": 7.5, "fps": 4},
 "objects": [{"name": "box", "mesh": "plain_box.glb", "position": [-5.2, 0, -2.5], "velocity": [0.9, 0, 0],
              "rotation_deg": [20, 30, 0]}]}
JSON
python3 - "$out/approach.json" "$out/agree.json" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
scene["objects"].append({"name": "marker", "mesh": "box.obj", "position": [-6, 1, -6], "velocity": [0.8, 0, 0],
                         "color": [0.2, 0.7, 0.4]})
json.dump(scene, open(sys.argv[2], "w"))
PY
"$apparent" render "$out/agree.json" --out "$out/agree" --shade doppler --attributes doppler --quiet
"$apparent" render "$out/approach.json" --out "$out/approach" --shade doppler --attributes doppler --quiet
(cd "$src" && node tests/web/doppler_agree.js "$out/agree/relativistic.glb" "$out/approach/relativistic.glb" &&
  node tests/web/doppler_shader.js &&
  node tests/web/viewer_test.js "$out/approach" --models relativistic --frames 0,3 --shot-time 0.3 &&
  node tests/web/viewer_test.js "$out/shaded" --models relativistic --frames 0,3 --shot-time 0.3)
# Shards merged give the one process's shaded file.
for i in 0 1; do
  "$apparent" render "$out/scene_shaded.json" --out "$out/shaded_shards" --shard $i/2 --shade doppler --attributes doppler \
    --quiet
done
"$apparent" merge "$out/shaded_shards" --quiet
cmp "$out/shaded/relativistic.glb" "$out/shaded_shards/relativistic.glb" || { echo "FAIL: shaded shards differ"; exit 1; }
# The same through three.js's DRACOLoader and MeshoptDecoder (the viewer's): the compressed files show the texture.
for c in draco meshopt; do
  "$apparent" render "$out/near.json" --out "$out/near-$c" --compress $c --quiet
  (cd "$src" && node tests/web/viewer_test.js "$out/near-$c" --models relativistic --frames 0,3 --shot-time 0.3 \
    --screenshot "$out/near-$c.png" && node tests/looks/texels.js "$out/near-$c.png")
done
# Compressed files keep the look: --compress draco (one Draco mesh per material, TEXCOORD_0 quantized to
# --draco-texcoord-bits) and --compress meshopt (float32 TEXCOORD_0, normalized uint16 COLOR_0), refined and in
# vertex mode, decoded by the decoders three.js uses (decode_glb.js) and checked against the closed form
# and, vertex by vertex, against the plain file within the stated bounds; no warning; valid files.
for mode in refined vertex; do
  args=()
  [ "$mode" = vertex ] && args=(--tolerance vertex)
  "$apparent" render "$out/scene_relativistic.json" --out "$out/draco-$mode" --compress draco "${args[@]}" \
    2> "$out/draco-$mode.err"
  "$apparent" render "$out/scene_relativistic.json" --out "$out/draco10-$mode" --compress draco \
    --draco-texcoord-bits 10 "${args[@]}" --quiet
  "$apparent" render "$out/scene_relativistic.json" --out "$out/meshopt-$mode" --compress meshopt "${args[@]}" \
    2> "$out/meshopt-$mode.err"
  if grep -q "not carried" "$out/draco-$mode.err" "$out/meshopt-$mode.err"; then echo "FAIL: a look dropped"; exit 1; fi
  for c in draco draco10 meshopt; do
    (cd "$src" && node tests/looks/decode_glb.js "$out/$c-$mode/relativistic.glb" "$out/$c-$mode/decoded.glb")
  done
  plain="$out/$mode/relativistic.glb"
  python3 "$src/tests/looks/check_textured.py" "$out/draco-$mode/decoded.glb" "$out/box.glb" -2 0.3 -4 0.9 0 0 20 30 0 \
    draco 14 12 "$plain"
  python3 "$src/tests/looks/check_textured.py" "$out/draco10-$mode/decoded.glb" "$out/box.glb" -2 0.3 -4 0.9 0 0 20 30 0 \
    draco 14 10 "$plain"
  python3 "$src/tests/looks/check_textured.py" "$out/meshopt-$mode/decoded.glb" "$out/box.glb" -2 0.3 -4 0.9 0 0 20 30 0 \
    meshopt "$plain"
  (cd "$src" && node tests/validators/validate_gltf.js "$out/draco-$mode/relativistic.glb" \
    "$out/meshopt-$mode/relativistic.glb")
done
# The stated error where the position error is (--verbose).
"$apparent" render "$out/scene_relativistic.json" --out "$out/draco-verbose" --compress draco --verbose 2>&1 |
  grep -q "Draco texture-coordinate error <= 0.000122" || { echo "FAIL: no Draco texture-coordinate error"; exit 1; }
"$apparent" render "$out/scene_relativistic.json" --out "$out/meshopt-verbose" --compress meshopt --verbose 2>&1 |
  grep -q "meshopt texture coordinates float32 (error 0)" || { echo "FAIL: no meshopt texture-coordinate error"; exit 1; }
# A Khronos sample with COLOR_0 (tests/data/gltf-samples/BoxVertexColors.gltf) at 0.5c: its colours
# carried (COLOR_0 in every primitive, the input's material), valid for the Khronos validator.
cp "$src/tests/data/gltf-samples/BoxVertexColors.gltf" "$out/"
cat > "$out/vertex_colors.json" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]}, "frames": {"start": 6, "end": 7, "fps": 2},
 "objects": [{"name": "vc", "mesh": "BoxVertexColors.gltf", "position": [-1, 0, -5], "velocity": [0.5, 0, 0]}]}
JSON
"$apparent" render "$out/vertex_colors.json" --out "$out/vertex_colors" --quiet
python3 - "$out/vertex_colors/relativistic.glb" "$out/BoxVertexColors.gltf" <<'PY'
import json, struct, sys
b = open(sys.argv[1], "rb").read()
doc = json.loads(b[20:20 + struct.unpack_from("<I", b, 12)[0]])
src = json.load(open(sys.argv[2]))
prims = [p for m in doc["meshes"] for p in m["primitives"]]
assert prims and all("COLOR_0" in p["attributes"] for p in prims), "COLOR_0 missing"
assert [m.get("pbrMetallicRoughness") for m in doc["materials"]] == [m.get("pbrMetallicRoughness") for m in src["materials"]]
print("BoxVertexColors: COLOR_0 in all %d primitives, the input's %d material(s)" % (len(prims), len(doc["materials"])))
PY
(cd "$src" && node tests/validators/validate_gltf.js "$out/vertex_colors/relativistic.glb")
# A JSON scene's own material on an OBJ mesh: its factors in the .glb, and in the shard header.
cp "$src/data/meshes/box.obj" "$out/box.obj"
cat > "$out/material.json" <<JSON
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1]}, "frames": {"start": 0, "end": 1, "fps": 2},
 "objects": [{"name": "marker", "mesh": "box.obj", "position": [0, 0, -4],
              "material": {"base_color": [0.9, 0.1, 0.05], "metallic": 0.5, "roughness": 0.25, "emissive": [0, 0, 0.5]}}]}
JSON
"$apparent" render "$out/material.json" --out "$out/material" --quiet
for i in 0 1; do "$apparent" render "$out/material.json" --out "$out/material_shards" --shard $i/2 --quiet; done
"$apparent" merge "$out/material_shards" --quiet
cmp "$out/material/relativistic.glb" "$out/material_shards/relativistic.glb" || { echo "FAIL: material: shards differ"; exit 1; }
python3 - "$out/material/relativistic.glb" <<'PY'
import json, struct, sys
b = open(sys.argv[1], "rb").read()
m = json.loads(b[20:20 + struct.unpack_from("<I", b, 12)[0]])["materials"][0]
want = {"baseColorFactor": [0.9, 0.1, 0.05, 1.0], "metallicFactor": 0.5, "roughnessFactor": 0.25}
assert m["pbrMetallicRoughness"] == want and m["emissiveFactor"] == [0, 0, 0.5], m
print("material.json: the scene's material in the .glb:", m)
PY
(cd "$src" && node tests/validators/validate_gltf.js "$out/material/relativistic.glb")
# Frames made by other processes carry the look too: two shards merged, and three MPI ranks, give the
# one process's bytes.
for i in 0 1; do
  "$apparent" render "$out/scene_relativistic.json" --out "$out/shard" --shard $i/2 --quiet
done
"$apparent" merge "$out/shard" --quiet
cmp "$out/refined/relativistic.glb" "$out/shard/relativistic.glb" || { echo "FAIL: shards differ from one process"; exit 1; }
# A shard is input too: a look whose material is not a JSON object, or whose texture reference
# leaves the look or reads a texture coordinate set the look does not have, is refused by merge
# with the field named.
for tamper in 'b"{\"name\":\"textured\"", b"[\"name\":\"textured\""' 'b"{\"index\":0}", b"{\"index\":7}"' \
  'b"\"texCoord\":1", b"\"texCoord\":2"'; do
  rm -rf "$out/bad" && mkdir -p "$out/bad/shards"
  cp "$out/shard/shards/"* "$out/bad/shards/" 2>/dev/null || { "$apparent" render "$out/scene_relativistic.json" --out "$out/bad" --shard 0/2 --quiet; }
  for f in "$out/bad/shards/"*; do
    python3 -c "import sys; p=sys.argv[1]; b=open(p,'rb').read(); a,c=$tamper; assert a in b, p; open(p,'wb').write(b.replace(a,c,1))" "$f"
  done
  if "$apparent" merge "$out/bad" 2> "$out/bad.err"; then echo "FAIL: merge took a tampered look"; exit 1; fi
  grep -q "looks\[0\]\.materials\[[0-2]\]" "$out/bad.err" || { echo "FAIL: merge's message:"; cat "$out/bad.err"; exit 1; }
done
timeout 300 mpirun --oversubscribe -n 3 "$apparent" render "$out/scene_relativistic.json" --out "$out/mpi" --quiet
cmp "$out/refined/relativistic.glb" "$out/mpi/relativistic.glb" || { echo "FAIL: MPI ranks differ from one process"; exit 1; }
# And compressed: the material parts' Draco meshes and meshopt records made by other processes.
for c in draco meshopt; do
  for i in 0 1; do
    "$apparent" render "$out/scene_relativistic.json" --out "$out/shard-$c" --compress $c --shard $i/2 --quiet
  done
  "$apparent" merge "$out/shard-$c" --quiet
  cmp "$out/$c-refined/relativistic.glb" "$out/shard-$c/relativistic.glb" || { echo "FAIL: $c shards differ"; exit 1; }
  timeout 300 mpirun --oversubscribe -n 3 "$apparent" render "$out/scene_relativistic.json" --out "$out/mpi-$c" \
    --compress $c --quiet
  cmp "$out/$c-refined/relativistic.glb" "$out/mpi-$c/relativistic.glb" || { echo "FAIL: $c MPI ranks differ"; exit 1; }
done
# Texture coordinate sets beyond the two carried: the box with a TEXCOORD_2 and its occlusion map read
# through it, and the box without TEXCOORD_1 whose occlusion map reads TEXCOORD_1: one warning each
# naming the attribute and the material's texture, which is dropped; the output stays valid.
python3 - "$out/box.glb" "$out/set2.glb" "$out/noset1.glb" <<'PY'
import json, struct, sys
b = open(sys.argv[1], "rb").read()
n = struct.unpack_from("<I", b, 12)[0]
doc, rest = json.loads(b[20:20 + n]), b[20 + n:]
def write(path, d):
    js = json.dumps(d, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    open(path, "wb").write(struct.pack("<III", 0x46546C67, 2, 20 + len(js) + len(rest)) +
                           struct.pack("<II", len(js), 0x4E4F534A) + js + rest)
set2 = json.loads(json.dumps(doc))
for p in set2["meshes"][0]["primitives"]:
    p["attributes"]["TEXCOORD_2"] = p["attributes"]["TEXCOORD_1"]
set2["materials"][2]["occlusionTexture"]["texCoord"] = 2
write(sys.argv[2], set2)
for p in doc["meshes"][0]["primitives"]:
    del p["attributes"]["TEXCOORD_1"]
write(sys.argv[3], doc)
PY
for variant in set2 noset1; do
  sed "s/box.glb/$variant.glb/" "$out/scene_relativistic.json" > "$out/$variant.json"
  "$apparent" render "$out/$variant.json" --out "$out/$variant" 2> "$out/$variant.err" > /dev/null
  (cd "$src" && node tests/validators/validate_gltf.js "$out/$variant/relativistic.glb")
done
grep -q "attribute TEXCOORD_2: not carried to the outputs (TEXCOORD_0, TEXCOORD_1 and COLOR_0 are)" "$out/set2.err" &&
  grep -q "materials\[2\].occlusionTexture: uses texture coordinate set 2; TEXCOORD_0 and TEXCOORD_1 are carried (dropped)" \
    "$out/set2.err" &&
  grep -q "materials\[2\].occlusionTexture: uses texture coordinate set 1, which its meshes do not have (dropped)" \
    "$out/noset1.err" || { echo "FAIL: texture coordinate set warnings:"; cat "$out/set2.err" "$out/noset1.err"; exit 1; }
echo "looks: ok"
