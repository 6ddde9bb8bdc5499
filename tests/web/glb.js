// Independent reader of apparent's .glb files for the viewer test (no three.js): JSON chunk, float accessors,
// frame nodes with their POSITION counts, and evaluation of the "frames" animation at a time t.
'use strict';

const fs = require('node:fs');

const FRAME_NODE = /^frame_(\d+)$/;

function readGlb(file) {
  const buf = fs.readFileSync(file);
  if (buf.length < 20 || buf.readUInt32LE(0) !== 0x46546c67) throw new Error(`${file}: not a GLB file`);
  if (buf.readUInt32LE(4) !== 2) throw new Error(`${file}: GLB version ${buf.readUInt32LE(4)}, expected 2`);
  if (buf.readUInt32LE(8) !== buf.length) {
    throw new Error(`${file}: GLB header says ${buf.readUInt32LE(8)} bytes, file has ${buf.length} (truncated?)`);
  }
  let off = 12, json = null, bin = null;
  while (off + 8 <= buf.length) {
    const len = buf.readUInt32LE(off), type = buf.readUInt32LE(off + 4);
    if (off + 8 + len > buf.length) throw new Error(`${file}: chunk at byte ${off} runs past the end of the file`);
    const body = buf.subarray(off + 8, off + 8 + len);
    if (type === 0x4e4f534a) json = JSON.parse(body.toString('utf8'));
    else if (type === 0x004e4942) bin = body;
    off += 8 + len;
  }
  if (!json) throw new Error(`${file}: no JSON chunk`);
  return { json, bin };
}

// Float accessor as an array of arrays (one per element).
function readFloatAccessor(glb, index) {
  const { json, bin } = glb;
  const acc = json.accessors[index];
  if (!acc) throw new Error(`accessor ${index} missing`);
  if (acc.componentType !== 5126) throw new Error(`accessor ${index}: component type ${acc.componentType}, expected FLOAT`);
  if (acc.sparse) throw new Error(`accessor ${index}: sparse accessors not supported by this test`);
  const n = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[acc.type];
  if (!n) throw new Error(`accessor ${index}: type ${acc.type} not supported`);
  if (acc.bufferView === undefined) return Array.from({ length: acc.count }, () => new Array(n).fill(0));
  const bv = json.bufferViews[acc.bufferView];
  if (bv.buffer !== 0 || !bin) throw new Error(`accessor ${index}: data not in the GLB BIN chunk`);
  const stride = bv.byteStride || 4 * n;
  const base = (bv.byteOffset || 0) + (acc.byteOffset || 0);
  const out = [];
  for (let i = 0; i < acc.count; ++i) {
    const e = [];
    for (let c = 0; c < n; ++c) e.push(bin.readFloatLE(base + i * stride + 4 * c));
    out.push(e);
  }
  return out;
}

function sampleAt(times, values, interp, t) {
  const last = times.length - 1;
  if (t <= times[0]) return values[0];
  if (t >= times[last]) return values[last];
  let i = 0;
  while (i < last && times[i + 1] <= t) ++i;
  if (interp === 'STEP') return values[i];
  if (interp === 'LINEAR' || interp === undefined) {
    const u = (t - times[i]) / (times[i + 1] - times[i]);
    return values[i].map((v, c) => v + (values[i + 1][c] - v) * u);
  }
  throw new Error(`interpolation ${interp} not supported by this test`);
}

// Summary of one exported file: frame nodes (sorted by number) with POSITION counts, scene extras, animation.
function describe(file) {
  const glb = readGlb(file);
  const { json } = glb;
  const sceneIdx = json.scene ?? 0;
  const scene = (json.scenes || [])[sceneIdx] || { nodes: [] };
  const extras = scene.extras || {};
  const parent = new Map();
  (json.nodes || []).forEach((n, i) => (n.children || []).forEach((c) => parent.set(c, i)));
  // nodes reachable from the scene
  const inScene = new Set();
  const stack = [...(scene.nodes || [])];
  while (stack.length) {
    const i = stack.pop();
    if (inScene.has(i)) continue;
    inScene.add(i);
    stack.push(...((json.nodes[i] || {}).children || []));
  }
  const frames = [];
  (json.nodes || []).forEach((n, i) => {
    const m = FRAME_NODE.exec(n.name || '');
    if (!m || !inScene.has(i)) return;
    let vertices = 0;
    const draco = [];
    if (n.mesh !== undefined) {
      for (const p of json.meshes[n.mesh].primitives) {
        const acc = json.accessors[p.attributes.POSITION];
        vertices += acc ? acc.count : 0;
        if (p.extensions && p.extensions.KHR_draco_mesh_compression) draco.push(true);
      }
    }
    // reflection nodes: the frame node's descendants, each with its POSITION count
    const children = [];
    const below = [...(n.children || [])];
    while (below.length) {
      const c = below.pop();
      const cn = json.nodes[c] || {};
      let cv = 0;
      if (cn.mesh !== undefined) for (const p of json.meshes[cn.mesh].primitives) cv += (json.accessors[p.attributes.POSITION] || {}).count || 0;
      children.push({ index: c, name: cn.name, vertices: cv });
      below.push(...(cn.children || []));
    }
    frames.push({ index: i, name: n.name, number: Number(m[1]), vertices, hasMesh: n.mesh !== undefined,
      draco: draco.length > 0, digits: m[1].length, children });
  });
  frames.sort((a, b) => a.number - b.number);
  const anims = json.animations || [];
  const anim = anims.find((a) => a.name === 'frames') || anims[0] || null;
  const channels = [];
  let duration = 0;
  if (anim) {
    for (const ch of anim.channels) {
      if (ch.target.path !== 'scale' || ch.target.node === undefined) continue;
      const s = anim.samplers[ch.sampler];
      const times = readFloatAccessor(glb, s.input).map((e) => e[0]);
      const values = readFloatAccessor(glb, s.output);
      duration = Math.max(duration, times[times.length - 1]);
      channels.push({ node: ch.target.node, times, values, interp: s.interpolation });
    }
  }
  const cameraNode = (json.nodes || []).findIndex((n) => n.camera !== undefined);
  return { file, glb, json, extras, frames, anim, animName: anim ? anim.name : null, channels, duration,
    parent, hasCamera: cameraNode >= 0, cameraNodeName: cameraNode >= 0 ? json.nodes[cameraNode].name : null,
    extensionsUsed: json.extensionsUsed || [] };
}

function restScale(node) {
  if (node.matrix) {
    const e = node.matrix;
    return [Math.hypot(e[0], e[1], e[2]), Math.hypot(e[4], e[5], e[6]), Math.hypot(e[8], e[9], e[10])];
  }
  return node.scale || [1, 1, 1];
}

// Names of the frame nodes whose world scale is non-zero at animation time t (animation evaluated here, in Node).
function expectedVisible(desc, t) {
  const scale = new Map();
  for (const ch of desc.channels) scale.set(ch.node, sampleAt(ch.times, ch.values, ch.interp, t));
  const shown = (i) => {
    for (let j = i; j !== undefined; j = desc.parent.get(j)) {
      const s = scale.has(j) ? scale.get(j) : restScale(desc.json.nodes[j]);
      if (Math.min(...s.map(Math.abs)) <= 1e-9) return false;
    }
    return true;
  };
  return desc.frames.filter((f) => shown(f.index)).map((f) => ({ name: f.name, vertices: f.vertices,
    reflected: f.children.filter((c) => shown(c.index)).reduce((n, c) => n + c.vertices, 0) }));
}

module.exports = { readGlb, readFloatAccessor, describe, expectedVisible, FRAME_NODE };
