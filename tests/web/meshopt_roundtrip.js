#!/usr/bin/env node
// Round trip of apparent's --compress meshopt .glb through the decoder three.js uses (the npm
// `meshoptimizer` package's MeshoptDecoder), against the plain export of the same render:
//
//   node tests/web/meshopt_roundtrip.js PLAIN.glb MESHOPT.glb
//
// For every frame node and reflection node, primitive by primitive:
//   - the file requires EXT_meshopt_compression and KHR_mesh_quantization, and every compressed view decodes;
//   - vertex and index counts equal the plain file's, and the node translations (the frame origins) agree;
//   - the quantization step (the frame node's shown scale, read from the animation) is at most tolerance / sqrt(3)
//     when the scene extras give a tolerance (gltf.h: quantization error <= tolerance / 2);
//   - _EMISSION_TIME is the plain file's rounded (half away from zero) to a multiple of q, the largest power of two
//     not above the step (gltf.h), bit for bit: so each decoded vertex has plain vertices with that rounded time;
//   - every decoded position (step * q) lies within the stated bound sqrt(3) / 2 * step (plus float32 rounding of
//     the plain file) of a plain vertex with the same rounded emission time, and its normal within the octahedral
//     bound of that vertex's normal (the closest of them: crease-split copies share position and time). The normals'
//     view uses the OCTAHEDRAL filter at 8 bits: the two octahedral coordinates are rounded to multiples of 1/127
//     (error <= 0.5/127 each); the unnormalized vector (u, v, 1 - |u| - |v|) then moves by at most sqrt(6) * 0.5/127
//     and has length >= 1/sqrt(3), so the direction moves by at most sqrt(18) * 0.5/127 = 2.13/127, and the decoder's
//     int8 output adds 0.5/127 per component: each component within 2.63/127 of the plain normal;
//   - with --attributes / --shade doppler: _DOPPLER and _PROPER_TIME equal the plain file's float32 bit for bit, and
//     COLOR_0 (normalized uint16) is within 0.5/65535 (plus float32 rounding) of the plain file's float colour;
//   - the triangles, each written as its three corners' rounded emission times, are the same multiset as the plain
//     file's;
//   - frame coherence (gltf.h): where a frame node's mesh has morph targets, its vertices are the base's plus the
//     targets times the node's weights (0 or 1), the targets' POSITION int16 (not normalized, with bounds), NORMAL
//     normalized int8, _EMISSION_TIME float32; the sums go through every check above (the emission time rounded to
//     float32 once, at the end).
// Prints the largest position error against the bound. Exit 0 when all passed, 1 on a failed check, 2 on usage.
'use strict';

const path = require('node:path');
const { readGlb, describe, FRAME_NODE } = require('./glb.js');

const REPO = path.resolve(__dirname, '..', '..');
let MeshoptDecoder;
try {
  ({ MeshoptDecoder } = require(path.join(REPO, 'node_modules', 'meshoptimizer')));
} catch (e) {
  console.error('meshopt_roundtrip: node_modules/meshoptimizer missing: run "npm ci" (scripts/setup.sh test)');
  process.exit(2);
}

const [plainFile, meshoptFile] = process.argv.slice(2);
if (!plainFile || !meshoptFile) {
  console.error('usage: node tests/web/meshopt_roundtrip.js PLAIN.glb MESHOPT.glb');
  process.exit(2);
}

let failures = 0, passed = 0;
function check(cond, what) {
  if (cond) { ++passed; return true; }
  ++failures;
  if (failures <= 20) console.log(`  FAIL ${what}`);
  return false;
}

const SIZE = { 5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4 };
const COMPONENTS = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };

// The bytes of every buffer view: BIN chunk views as they are, meshopt views decoded.
function viewBytes(glb) {
  const { json, bin } = glb;
  return (json.bufferViews || []).map((bv, i) => {
    const ext = bv.extensions && bv.extensions.EXT_meshopt_compression;
    if (!ext) {
      if (bv.buffer !== 0) throw new Error(`bufferViews[${i}]: not in the BIN chunk and not compressed`);
      return bin.subarray(bv.byteOffset || 0, (bv.byteOffset || 0) + bv.byteLength);
    }
    const target = new Uint8Array(ext.count * ext.byteStride);
    const source = bin.subarray(ext.byteOffset || 0, (ext.byteOffset || 0) + ext.byteLength);
    MeshoptDecoder.decodeGltfBuffer(target, ext.count, ext.byteStride, source, ext.mode, ext.filter || 'NONE');
    if (target.length !== bv.byteLength) throw new Error(`bufferViews[${i}]: decoded ${target.length} bytes, view says ${bv.byteLength}`);
    return target;
  });
}

// Accessor `index` as an array of element arrays (normalized integers mapped to [-1, 1] as glTF says).
function readAccessor(json, views, index) {
  const acc = json.accessors[index];
  const bv = json.bufferViews[acc.bufferView];
  const bytes = views[acc.bufferView];
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const size = SIZE[acc.componentType], n = COMPONENTS[acc.type];
  const stride = bv.byteStride || size * n;
  const read = {
    5120: (o) => (acc.normalized ? Math.max(dv.getInt8(o) / 127, -1) : dv.getInt8(o)),
    5121: (o) => dv.getUint8(o), 5122: (o) => dv.getInt16(o, true), 5123: (o) => dv.getUint16(o, true),
    5125: (o) => dv.getUint32(o, true), 5126: (o) => dv.getFloat32(o, true),
  }[acc.componentType];
  const out = [];
  for (let i = 0; i < acc.count; ++i) {
    const base = (acc.byteOffset || 0) + i * stride;
    const e = [];
    for (let c = 0; c < n; ++c) e.push(read(base + c * size));
    out.push(e);
  }
  return out;
}

const f32 = new Float32Array(1), u32 = new Uint32Array(f32.buffer);
// -0 and +0 as one key (a morph target's sum gives +0 where the rounding gave -0: the same time)
const bits = (x) => { f32[0] = x === 0 ? 0 : x; return u32[0]; };

async function main() {
  await MeshoptDecoder.ready;
  const plain = describe(plainFile), mo = describe(meshoptFile);
  const pj = plain.json, mj = mo.json;
  const required = mj.extensionsRequired || [];
  check(required.includes('EXT_meshopt_compression') && required.includes('KHR_mesh_quantization'),
    `extensionsRequired lists EXT_meshopt_compression and KHR_mesh_quantization (${JSON.stringify(required)})`);
  const pviews = viewBytes(readGlb(plainFile)), mviews = viewBytes(readGlb(meshoptFile));
  const tolerance = Number(mo.extras.tolerance) || 0;
  check(plain.frames.length === mo.frames.length, `frame counts ${plain.frames.length} vs ${mo.frames.length}`);

  // the shown scale of each frame node: the largest scale its channel takes
  const shownScale = new Map();
  for (const ch of mo.channels) shownScale.set(ch.node, Math.max(...ch.values.map((v) => v[0])));

  let worst = 0, worstRatio = 0, vertices = 0, primitives = 0, worstNormal = 0, attributeVertices = 0, morphed = 0;
  const pairs = [];
  for (let k = 0; k < Math.min(plain.frames.length, mo.frames.length); ++k) {
    const pf = plain.frames[k], mf = mo.frames[k];
    check(pf.name === mf.name, `frame ${k}: node names ${pf.name} vs ${mf.name}`);
    const step = shownScale.get(mf.index);
    pairs.push([pj.nodes[pf.index], mj.nodes[mf.index], step, pf.name]);
    const pc = (pj.nodes[pf.index].children || []).map((c) => pj.nodes[c]);
    const mc = (mj.nodes[mf.index].children || []).map((c) => mj.nodes[c]);
    check(pc.length === mc.length, `${pf.name}: reflection node counts ${pc.length} vs ${mc.length}`);
    for (let i = 0; i < Math.min(pc.length, mc.length); ++i) pairs.push([pc[i], mc[i], step, pc[i].name, pj.nodes[pf.index], mj.nodes[mf.index]]);
  }
  for (const [pn, mn, step, name, pparent, mparent] of pairs) {
    check((pn.mesh === undefined) === (mn.mesh === undefined), `${name}: both have a mesh or neither`);
    if (pn.mesh === undefined || mn.mesh === undefined) continue;
    const pt = (pparent || pn).translation || [0, 0, 0], mt = (mparent || mn).translation || [0, 0, 0];
    check(pt.every((x, c) => x === mt[c]), `${name}: frame origins ${pt} vs ${mt}`);
    if (!check(step > 0, `${name}: a positive quantization step (shown scale)`)) continue;
    if (tolerance > 0) check(step <= tolerance / Math.sqrt(3) * (1 + 1e-6), `${name}: step ${step} <= tolerance / sqrt(3)`);
    const bound = Math.sqrt(3) / 2 * step;
    const q = 2 ** Math.floor(Math.log2(step));
    const rounded = (t) => { f32[0] = Math.sign(t) * Math.floor(Math.abs(t) / q + 0.5) * q; return f32[0]; };
    const pprims = pj.meshes[pn.mesh].primitives, mprims = mj.meshes[mn.mesh].primitives;
    check(pprims.length === mprims.length, `${name}: primitive counts ${pprims.length} vs ${mprims.length}`);
    for (let p = 0; p < Math.min(pprims.length, mprims.length); ++p) {
      const a = pprims[p], b = mprims[p];
      const where = `${name} primitive ${p}`;
      ++primitives;
      check(a.material === b.material, `${where}: materials ${a.material} vs ${b.material}`);
      const apos = readAccessor(pj, pviews, a.attributes.POSITION), bpos = readAccessor(mj, mviews, b.attributes.POSITION);
      const anrm = readAccessor(pj, pviews, a.attributes.NORMAL), bnrm = readAccessor(mj, mviews, b.attributes.NORMAL);
      const atim = readAccessor(pj, pviews, a.attributes._EMISSION_TIME), btim = readAccessor(mj, mviews, b.attributes._EMISSION_TIME);
      const aidx = readAccessor(pj, pviews, a.indices).map((e) => e[0]), bidx = readAccessor(mj, mviews, b.indices).map((e) => e[0]);
      // frame coherence: a frame node whose mesh has morph targets adds the targets with its weights
      const targets = b.targets || [];
      const weights = mn.weights || [];
      if (targets.length) {
        ++morphed;
        check(weights.length === 0 || weights.length === targets.length, `${where}: ${weights.length} weights for ${targets.length} targets`);
        check(weights.every((w) => w === 0 || w === 1), `${where}: weights are 0 or 1 (${weights})`);
      }
      targets.forEach((target, t) => {
        const tpAcc = mj.accessors[target.POSITION], tnAcc = mj.accessors[target.NORMAL], ttAcc = mj.accessors[target._EMISSION_TIME];
        check(tpAcc && tpAcc.componentType === 5122 && !tpAcc.normalized && tpAcc.min && tpAcc.max,
          `${where} target ${t}: POSITION is int16, not normalized, with bounds`);
        check(tnAcc && tnAcc.componentType === 5120 && tnAcc.normalized, `${where} target ${t}: NORMAL is normalized int8`);
        check(ttAcc && ttAcc.componentType === 5126, `${where} target ${t}: _EMISSION_TIME is float32`);
        if (!weights[t]) return;
        const tp = readAccessor(mj, mviews, target.POSITION), tn = readAccessor(mj, mviews, target.NORMAL);
        const tt = readAccessor(mj, mviews, target._EMISSION_TIME);
        if (!check(tp.length === bpos.length && tn.length === bpos.length && tt.length === bpos.length,
          `${where} target ${t}: ${tp.length} vertices, the base has ${bpos.length}`)) return;
        for (let i = 0; i < bpos.length; ++i) {
          for (let c = 0; c < 3; ++c) {
            bpos[i][c] += weights[t] * tp[i][c];
            bnrm[i][c] += weights[t] * tn[i][c];
          }
          btim[i][0] += weights[t] * tt[i][0];
        }
      });
      if (targets.length) for (const e of btim) e[0] = Math.fround(e[0]);
      // the optional attributes: present in both files or in neither
      const extra = {};
      for (const name of ['_DOPPLER', '_PROPER_TIME', 'COLOR_0']) {
        if (!check((a.attributes[name] === undefined) === (b.attributes[name] === undefined), `${where}: ${name} in both files or in neither`)) continue;
        if (a.attributes[name] !== undefined) extra[name] = [readAccessor(pj, pviews, a.attributes[name]), readAccessor(mj, mviews, b.attributes[name])];
      }
      if (extra.COLOR_0) {
        const acc = mj.accessors[b.attributes.COLOR_0];
        check(acc.componentType === 5123 && acc.normalized, `${where}: COLOR_0 is normalized uint16`);
        extra.COLOR_0[1] = extra.COLOR_0[1].map((e) => e.map((x) => x / 65535));
      }
      if (!check(apos.length === bpos.length, `${where}: vertex counts ${apos.length} vs ${bpos.length}`)) continue;
      check(aidx.length === bidx.length, `${where}: index counts ${aidx.length} vs ${bidx.length}`);
      check(bidx.every((i) => i < bpos.length), `${where}: indices within the vertex count`);
      const mpAcc = mj.accessors[b.attributes.POSITION];
      check(mpAcc.componentType === 5122 && !mpAcc.normalized, `${where}: POSITION is int16, not normalized`);
      // plain vertices by emission time
      const byTime = new Map();
      const atimQ = atim.map((e) => [rounded(e[0])]);
      apos.forEach((x, i) => {
        const key = bits(atimQ[i][0]);
        if (!byTime.has(key)) byTime.set(key, []);
        byTime.get(key).push(i);
      });
      let unmatched = 0;
      for (let i = 0; i < bpos.length; ++i) {
        const cands = byTime.get(bits(btim[i][0])) || [];
        if (!cands.length) { ++unmatched; continue; }
        // float32 rounding of the plain coordinates: half an ulp of each
        const slack = Math.sqrt(3) * Math.max(...bpos[i].map((q) => Math.abs(q * step))) * 2 ** -24;
        // crease-split copies share position and time: the normal is checked against the closest of them
        let best = Infinity, bestNormal = Infinity, bestExtra = Infinity;
        for (const j of cands) {
          const d = Math.hypot(...[0, 1, 2].map((c) => bpos[i][c] * step - apos[j][c]));
          best = Math.min(best, d);
          if (d > bound + slack) continue;
          bestNormal = Math.min(bestNormal, Math.max(...[0, 1, 2].map((c) => Math.abs(bnrm[i][c] - anrm[j][c]))));
          // the attributes of the closest matching plain vertex: exact floats, colour within its rounding
          let off = 0;
          for (const name of ['_DOPPLER', '_PROPER_TIME']) if (extra[name] && bits(extra[name][0][j][0]) !== bits(extra[name][1][i][0])) off = Infinity;
          if (extra.COLOR_0) off = Math.max(off, ...[0, 1, 2].map((c) => Math.abs(extra.COLOR_0[0][j][c] - extra.COLOR_0[1][i][c])));
          bestExtra = Math.min(bestExtra, off);
        }
        worst = Math.max(worst, best);
        worstRatio = Math.max(worstRatio, best / bound);
        check(best <= bound + slack, `${where} vertex ${i}: position error ${best} > bound ${bound}`);
        check(bestNormal <= 2.63 / 127, `${where} vertex ${i}: normal differs by ${bestNormal}`);
        worstNormal = Math.max(worstNormal, bestNormal);
        if (Object.keys(extra).length) {
          ++attributeVertices;
          check(bestExtra <= 0.5 / 65535 + 1e-7, `${where} vertex ${i}: _DOPPLER/_PROPER_TIME/COLOR_0 differ from the plain file's (${bestExtra})`);
        }
      }
      check(unmatched === 0, `${where}: ${unmatched} vertices whose emission time the plain file does not have`);
      const tri = (idx, tim) => {
        const out = [];
        for (let t = 0; t + 2 < idx.length; t += 3) out.push([0, 1, 2].map((c) => bits(tim[idx[t + c]][0])).sort((x, y) => x - y).join(','));
        return out.sort().join(';');
      };
      check(tri(aidx, atimQ) === tri(bidx, btim), `${where}: triangles (as emission-time triples) differ`);
      vertices += bpos.length;
    }
  }
  console.log(`meshopt_roundtrip: ${meshoptFile}: ${primitives} primitives (${morphed} with morph targets), ${vertices} vertices; largest position ` +
    `error ${worst.toExponential(3)} ls, ${(100 * worstRatio).toFixed(1)}% of the stated bound; largest normal component ` +
    `error ${(worstNormal * 127).toFixed(2)}/127; ${attributeVertices} vertices with attributes checked; ${passed} checks passed, ` +
    `${failures} failed`);
  return failures ? 1 : 0;
}

main().then((code) => process.exit(code), (e) => {
  console.error(`meshopt_roundtrip: ${e.stack || e}`);
  process.exit(1);
});
