#!/usr/bin/env node
// The web viewer's Doppler model (exporters/web/doppler.mjs) against the colours the C++ wrote
// (mesh4d/doppler_colour.h): in .glb files rendered with --shade doppler --attributes doppler, every
// vertex's COLOR_0 must equal, to float32 rounding, the JS colour at the vertex's _DOPPLER:
//   - on a material with extras.base_color (an object without its input's look): dopplerColour(base, D);
//   - on any other material (an object keeping its input's look; inputs without COLOR_0 only):
//     dopplerModulation(D), the shaded colour of white.
// Exit 1 on a mismatch, 2 on usage.
//   usage: node tests/web/doppler_agree.js FILE.glb...
'use strict';

const path = require('node:path');
const { readGlb, readFloatAccessor } = require('./glb.js');

const kTolerance = 2e-6;  // float32 COLOR_0 and _DOPPLER (the colour's slope in D times D's rounding)

(async () => {
  const files = process.argv.slice(2);
  if (!files.length) {
    console.error('usage: node tests/web/doppler_agree.js FILE.glb...');
    process.exit(2);
  }
  const model = await import(path.resolve(__dirname, '..', '..', 'exporters', 'web', 'doppler.mjs'));
  let failed = 0;
  for (const file of files) {
    const glb = readGlb(file);
    let based = 0, looks = 0, worst = 0, lo = Infinity, hi = -Infinity;
    for (const mesh of glb.json.meshes || []) {
      for (const p of mesh.primitives) {
        if (p.attributes.COLOR_0 === undefined || p.attributes._DOPPLER === undefined) continue;
        const base = (glb.json.materials || [])[p.material]?.extras?.base_color;
        const colours = readFloatAccessor(glb, p.attributes.COLOR_0);
        const dopplers = readFloatAccessor(glb, p.attributes._DOPPLER);
        for (let k = 0; k < colours.length; ++k) {
          const d = dopplers[k][0];
          lo = Math.min(lo, d);
          hi = Math.max(hi, d);
          const want = base ? model.dopplerColour(base, d) : model.dopplerModulation(d);
          for (let c = 0; c < 3; ++c) worst = Math.max(worst, Math.abs(colours[k][c] - want[c]));
          if (base) ++based; else ++looks;
        }
      }
    }
    console.log(`doppler_agree: ${file}: ${based} vertices of base colours, ${looks} of input materials, ` +
      `D from ${lo.toFixed(4)} to ${hi.toFixed(4)}: COLOR_0 within ${worst.toExponential(2)} of doppler.mjs`);
    if (based + looks === 0 || !(worst <= kTolerance)) {
      console.log(`FAIL ${file}: ${based + looks === 0 ? 'no COLOR_0 with _DOPPLER' : `beyond ${kTolerance}`}`);
      ++failed;
    }
  }
  process.exit(failed ? 1 : 0);
})();
