#!/usr/bin/env node
// The web viewer's per-fragment Doppler shift (DOPPLER_GLSL of exporters/web/doppler.mjs, what the viewer
// patches into three.js's shader) against the same module's JS toneMap(A(D) a), which
// tests/web/doppler_agree.js ties to the C++: in headless Chromium (WebGL2, SwiftShader) one pixel per
// case is drawn with the shader's colour and read back; each channel must be the JS colour within 1.5/255
// (8-bit rounding). Cases: D from 0.4 to 2.5 and the texture's colours, white, a grey and two mixtures.
//   usage: node tests/web/doppler_shader.js [--chromium PATH]
// Exit 0 when every case agrees, 1 otherwise, 2 on a setup problem.
'use strict';

const fs = require('node:fs');
const os = require('node:os');
const path = require('node:path');
const { launchHeadless } = require('./chromium.js');

const REPO = path.resolve(__dirname, '..', '..');

(async () => {
  const argv = process.argv.slice(2);
  const chromiumPath = argv[0] === '--chromium' ? argv[1] : process.env.CHROMIUM || '/usr/bin/chromium';
  let chromium, startServer;
  try {
    ({ chromium } = require(path.join(REPO, 'node_modules', 'playwright-core')));
    ({ startServer } = require(path.join(REPO, 'exporters', 'web', 'serve.js')));
  } catch (e) {
    console.error(`doppler_shader: SETUP ERROR: ${e.message}`);
    process.exit(2);
  }
  const { server, url } = await startServer({ root: REPO, port: 0 });
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'apparent-doppler-shader-'));
  let ctx = null, failed = 0;
  try {
    ctx = await launchHeadless(chromium, profile, chromiumPath, { width: 64, height: 64 });
    const page = ctx.pages()[0] || await ctx.newPage();
    await page.goto(`${url}/README.md`);
    const result = await page.evaluate(async () => {
      const model = await import('/exporters/web/doppler.mjs');
      const colours = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1], [0.5, 0.5, 0.5], [1, 0.4, 0.05], [0.2, 0.7, 0.4]];
      const dopplers = [0.4, 0.6, 0.8, 0.9, 1.0, 1.1, 1.25, 1.5, 2.0, 2.5];
      const cases = [];
      for (const d of dopplers) for (const a of colours) cases.push({ a, d });
      const canvas = document.createElement('canvas');
      canvas.width = cases.length;
      canvas.height = 1;
      const gl = canvas.getContext('webgl2');
      if (!gl) return { error: 'no WebGL2' };
      const compile = (type, src) => {
        const s = gl.createShader(type);
        gl.shaderSource(s, src);
        gl.compileShader(s);
        if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
        return s;
      };
      const program = gl.createProgram();
      gl.attachShader(program, compile(gl.VERTEX_SHADER, `#version 300 es
        void main() { vec2 p[3] = vec2[3](vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
                      gl_Position = vec4(p[gl_VertexID], 0.0, 1.0); }`));
      gl.attachShader(program, compile(gl.FRAGMENT_SHADER, `#version 300 es
        precision highp float;
        ${model.DOPPLER_GLSL}
        uniform vec3 colour;
        uniform float doppler;
        out vec4 result;
        void main() { result = vec4(dopplerShift(colour, doppler), 1.0); }`));
      gl.linkProgram(program);
      if (!gl.getProgramParameter(program, gl.LINK_STATUS)) return { error: gl.getProgramInfoLog(program) };
      gl.useProgram(program);
      const v = model.dopplerUniformValues();
      gl.uniformMatrix3fv(gl.getUniformLocation(program, 'dopplerUnmix'), false, v.dopplerUnmix);
      gl.uniform3fv(gl.getUniformLocation(program, 'dopplerCentres'), v.dopplerCentres);
      gl.uniform1f(gl.getUniformLocation(program, 'dopplerWidth'), v.dopplerWidth);
      gl.enable(gl.SCISSOR_TEST);
      gl.viewport(0, 0, cases.length, 1);
      cases.forEach((c, i) => {
        gl.scissor(i, 0, 1, 1);
        gl.uniform3fv(gl.getUniformLocation(program, 'colour'), c.a);
        gl.uniform1f(gl.getUniformLocation(program, 'doppler'), c.d);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
      });
      const pixels = new Uint8Array(4 * cases.length);
      gl.readPixels(0, 0, cases.length, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
      return { cases: cases.map((c, i) => ({ ...c, want: model.dopplerColour(c.a, c.d),
        got: [pixels[4 * i], pixels[4 * i + 1], pixels[4 * i + 2]].map((x) => x / 255) })) };
    });
    if (result.error) throw new Error(result.error);
    let worst = 0, coloured = 0;
    for (const c of result.cases) {
      const err = Math.max(...c.want.map((w, i) => Math.abs(w - c.got[i])));
      worst = Math.max(worst, err);
      if (Math.max(...c.want) > 0.1) ++coloured;
      if (err > 1.5 / 255) {
        console.log(`FAIL D ${c.d} colour ${c.a}: shader ${c.got.map((x) => x.toFixed(4))}, ` +
          `doppler.mjs ${c.want.map((x) => x.toFixed(4))}`);
        ++failed;
      }
    }
    console.log(`doppler_shader: ${result.cases.length} cases (${coloured} not black), the shader within ` +
      `${(255 * worst).toFixed(2)}/255 of doppler.mjs`);
    if (coloured === 0) ++failed;
  } catch (e) {
    console.error(`doppler_shader: SETUP ERROR: ${e.message}`);
    process.exitCode = 2;
  } finally {
    if (ctx) await ctx.close();
    server.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
  if (!process.exitCode) process.exitCode = failed ? 1 : 0;
})();
