// The WebAssembly module's cut of frames, timed in the page's way (benchmarks/wasm_cut.sh):
//   node benchmarks/wasm_cut.mjs MODULE SCENE TOLERANCE N
// prints "wasm MEDIAN_MS MIN_MS TRIANGLES": N cuts at the scene's frame times (spread over its range,
// after one cut to build the histories), each timed alone with performance.now().
import { createRequire } from 'node:module';
import { resolve } from 'node:path';

const [modulePath, scenePath, tolerance, count] = process.argv.slice(2);
const apparent = await createRequire(import.meta.url)(resolve(modulePath))();
apparent.FS.mkdir('/work');
apparent.FS.mount(apparent.NODEFS, { root: process.cwd() }, '/work');
apparent.FS.chdir('/work');
const scene = new apparent.Scene(scenePath);
if (scene.error()) { console.error(scene.error()); process.exit(2); }
const n = Number(count), frames = scene.frameCount();
const times = [];
let triangles = 0;
for (let i = -1; i < n; ++i) {
  const k = i < 0 ? 0 : Math.floor((i * frames) / n);
  const start = performance.now();
  const frame = scene.cut(scene.frameTime(k), '', tolerance);
  const ms = performance.now() - start;
  if (frame.error()) { console.error(frame.error()); process.exit(2); }
  if (i >= 0) times.push(ms);
  triangles = 0;
  for (let o = 0; o < frame.objectCount(); ++o) triangles += frame.indices(o).length / 3;
  frame.delete();
}
times.sort((a, b) => a - b);
console.log(`wasm ${times[Math.floor(times.length / 2)].toFixed(3)} ${times[0].toFixed(3)} ${triangles}`);
