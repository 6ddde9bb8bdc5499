#!/usr/bin/env node
// Decodes a --compress draco or --compress meshopt .glb with the decoders three.js uses (its
// DRACOLoader's Draco decoder, node_modules/three/examples/jsm/libs/draco/draco_decoder.js, called
// as DRACOLoader calls it; the npm meshoptimizer package's MeshoptDecoder, as GLTFLoader calls it)
// and writes the same model as a plain .glb for check_textured.py: every primitive's attributes as
// float32 (normalized integers divided out, KHR_mesh_quantization's integer POSITION times the
// frame node's shown scale, as a viewer draws it) and its indices as uint32, the images kept.
// usage: node tests/looks/decode_glb.js IN.glb OUT.glb
'use strict';

const fs = require('node:fs');
const path = require('node:path');
const { readGlb } = require('../web/glb.js');

const REPO = path.resolve(__dirname, '..', '..');
const COMPONENTS = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };
const SIZE = { 5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4 };
// Normalized integers as KHR_mesh_quantization (glTF 3.11) maps them to floats.
const NORMALIZE = { 5120: (v) => Math.max(v / 127, -1), 5121: (v) => v / 255, 5122: (v) => Math.max(v / 32767, -1),
  5123: (v) => v / 65535 };

function readComponent(buf, at, type) {
  switch (type) {
    case 5120: return buf.readInt8(at);
    case 5121: return buf.readUInt8(at);
    case 5122: return buf.readInt16LE(at);
    case 5123: return buf.readUInt16LE(at);
    case 5125: return buf.readUInt32LE(at);
    case 5126: return buf.readFloatLE(at);
    default: throw new Error(`component type ${type}`);
  }
}

async function main() {
  const [inFile, outFile] = process.argv.slice(2);
  if (!inFile || !outFile) {
    console.error('usage: node tests/looks/decode_glb.js IN.glb OUT.glb');
    process.exit(2);
  }
  const { json, bin } = readGlb(inFile);
  // three's package is an ES module package: its classic-script decoder is loaded as a script.
  const dracoFile = path.join(REPO, 'node_modules/three/examples/jsm/libs/draco/draco_decoder.js');
  const DracoDecoderModule = new Function('__filename', '__dirname', 'require', `${fs.readFileSync(dracoFile, 'utf8')}\nreturn DracoDecoderModule;`)(dracoFile, path.dirname(dracoFile), require);
  const draco = await DracoDecoderModule();
  const { MeshoptDecoder } = require(path.join(REPO, 'node_modules', 'meshoptimizer'));
  await MeshoptDecoder.ready;

  // Step: every EXT_meshopt_compression view decoded (GLTFLoader's GLTFMeshoptCompression).
  const views = (json.bufferViews || []).map((v) => {
    const ext = (v.extensions || {}).EXT_meshopt_compression;
    if (!ext) return v.buffer === 0 ? bin.subarray(v.byteOffset || 0, (v.byteOffset || 0) + v.byteLength) : null;
    const source = bin.subarray(ext.byteOffset || 0, (ext.byteOffset || 0) + ext.byteLength);
    const target = new Uint8Array(ext.count * ext.byteStride);
    MeshoptDecoder.decodeGltfBuffer(target, ext.count, ext.byteStride, source, ext.mode, ext.filter);
    return Buffer.from(target.buffer);
  });
  // An accessor's values as numbers, n per element (normalized ones as floats).
  const values = (index) => {
    const a = json.accessors[index];
    const n = COMPONENTS[a.type];
    const view = views[a.bufferView];
    const stride = json.bufferViews[a.bufferView].byteStride || n * SIZE[a.componentType];
    const out = [];
    for (let i = 0; i < a.count; ++i)
      for (let c = 0; c < n; ++c) {
        const v = readComponent(view, (a.byteOffset || 0) + i * stride + c * SIZE[a.componentType], a.componentType);
        out.push(a.normalized ? NORMALIZE[a.componentType](v) : v);
      }
    return out;
  };
  // The frame nodes' shown scale (meshopt: the step; the largest value of its scale channel).
  const scaleOf = new Map();
  for (const anim of json.animations || [])
    for (const ch of anim.channels)
      if (ch.target.path === 'scale') {
        const s = values(anim.samplers[ch.sampler].output);
        scaleOf.set(ch.target.node, Math.max(...s));
      }
  const meshScale = new Map();
  (json.nodes || []).forEach((node, i) => {
    if (node.mesh === undefined) return;
    const s = json.extensionsUsed && json.extensionsUsed.includes('KHR_mesh_quantization') ? scaleOf.get(i) ?? 1 : 1;
    meshScale.set(node.mesh, s);
    if (s !== 1) node.extras = Object.assign(node.extras || {}, { decoded_step: s });
    delete node.scale;
  });

  // Step: each primitive's data as float32 / uint32 in new views after the input's BIN.
  const pieces = [bin];
  let size = bin.length;
  const accessors = json.accessors;
  const newAccessor = (type, count, array, componentType) => {
    const bytes = Buffer.from(array.buffer);
    json.bufferViews.push({ buffer: 0, byteOffset: size, byteLength: bytes.length });
    pieces.push(bytes);
    size += bytes.length;
    const a = { bufferView: json.bufferViews.length - 1, componentType, count, type };
    if (type === 'VEC3' && componentType === 5126) {  // POSITION needs min and max
      a.min = [0, 1, 2].map((c) => Math.min(...array.filter((_, k) => k % 3 === c)));
      a.max = [0, 1, 2].map((c) => Math.max(...array.filter((_, k) => k % 3 === c)));
    }
    accessors.push(a);
    return accessors.length - 1;
  };
  let decodedDraco = 0, decodedMeshopt = 0;
  (json.meshes || []).forEach((mesh, m) => {
    for (const prim of mesh.primitives) {
      const ext = (prim.extensions || {}).KHR_draco_mesh_compression;
      if (ext) {
        // DRACOLoader's decodeGeometry: the mesh, its indices, each attribute by its unique id.
        const view = views[ext.bufferView];
        const decoder = new draco.Decoder();
        const mesh3 = new draco.Mesh();
        const status = decoder.DecodeArrayToMesh(new Int8Array(view.buffer, view.byteOffset, view.length), view.length, mesh3);
        if (!status.ok() || mesh3.ptr === 0) throw new Error(`mesh ${m}: Draco: ${status.error_msg()}`);
        const faces = mesh3.num_faces(), points = mesh3.num_points();
        const ptr = draco._malloc(faces * 12);
        decoder.GetTrianglesUInt32Array(mesh3, faces * 12, ptr);
        const index = new Uint32Array(draco.HEAPF32.buffer, ptr, faces * 3).slice();
        draco._free(ptr);
        for (const [name, id] of Object.entries(ext.attributes)) {
          const attr = decoder.GetAttributeByUniqueId(mesh3, id);
          const n = attr.num_components();
          const p = draco._malloc(points * n * 4);
          decoder.GetAttributeDataArrayForAllPoints(mesh3, attr, draco.DT_FLOAT32, points * n * 4, p);
          const data = new Float32Array(draco.HEAPF32.buffer, p, points * n).slice();
          draco._free(p);
          if (accessors[prim.attributes[name]].count !== points) throw new Error(`mesh ${m}: ${name}: count differs`);
          prim.attributes[name] = newAccessor(Object.keys(COMPONENTS)[n - 1], points, data, 5126);
        }
        if (accessors[prim.indices].count !== 3 * faces) throw new Error(`mesh ${m}: index count differs`);
        prim.indices = newAccessor('SCALAR', 3 * faces, index, 5125);
        draco.destroy(mesh3);
        draco.destroy(decoder);
        delete prim.extensions;
        ++decodedDraco;
        continue;
      }
      if (!json.bufferViews.some((v) => (v.extensions || {}).EXT_meshopt_compression)) continue;
      const scale = meshScale.get(m) ?? 1;
      for (const [name, index] of Object.entries(prim.attributes)) {
        const a = accessors[index];
        const v = values(index);
        const k = name === 'POSITION' && !a.normalized ? scale : 1;
        prim.attributes[name] = newAccessor(a.type, a.count, Float32Array.from(v, (x) => x * k), 5126);
      }
      prim.indices = newAccessor('SCALAR', accessors[prim.indices].count, Uint32Array.from(values(prim.indices)), 5125);
      delete prim.targets;
      ++decodedMeshopt;
    }
  });

  // Step: the plain file: the compression extensions gone, one buffer.
  for (const key of ['extensionsUsed', 'extensionsRequired'])
    if (json[key]) {
      json[key] = json[key].filter((e) => !['KHR_draco_mesh_compression', 'EXT_meshopt_compression',
        'KHR_mesh_quantization'].includes(e));
      if (json[key].length === 0) delete json[key];
    }
  json.buffers = [{ byteLength: size }];
  const pad = (b, c) => Buffer.concat([b, Buffer.alloc((4 - (b.length % 4)) % 4, c)]);
  const jsonChunk = pad(Buffer.from(JSON.stringify(json)), 0x20);
  const binChunk = pad(Buffer.concat(pieces), 0);
  const head = Buffer.alloc(12);
  head.writeUInt32LE(0x46546c67, 0);
  head.writeUInt32LE(2, 4);
  head.writeUInt32LE(12 + 8 + jsonChunk.length + 8 + binChunk.length, 8);
  const chunk = (type, body) => {
    const h = Buffer.alloc(8);
    h.writeUInt32LE(body.length, 0);
    h.writeUInt32LE(type, 4);
    return Buffer.concat([h, body]);
  };
  fs.writeFileSync(outFile, Buffer.concat([head, chunk(0x4e4f534a, jsonChunk), chunk(0x004e4942, binChunk)]));
  console.log(`decode_glb.js: ${inFile}: ${decodedDraco} Draco and ${decodedMeshopt} meshopt primitives decoded`);
}

main().catch((e) => {
  console.error(`decode_glb.js: ${e.message}`);
  process.exit(1);
});
