#!/usr/bin/env node
// Decode time of apparent's .glb files in three.js (GLTFLoader with DRACOLoader and MeshoptDecoder) in Debian's
// headless Chromium: each file's bytes are fetched once, then parsed RUNS times (the first run, which also
// compiles the decoders, is reported apart); prints a Markdown table with the median of the other runs.
//   node scripts/measure_decode_times.js [--runs N] FILE.glb...
'use strict';
const fs = require('node:fs');
const os = require('node:os');
const path = require('node:path');
const REPO = path.resolve(__dirname, '..');
const { launchHeadless } = require(path.join(REPO, 'tests', 'web', 'chromium.js'));
const { startServer } = require(path.join(REPO, 'exporters', 'web', 'serve.js'));
const { chromium } = require(path.join(REPO, 'node_modules', 'playwright-core'));

async function main() {
  const argv = process.argv.slice(2);
  let runs = 7;
  const files = [];
  for (let i = 0; i < argv.length; ++i) {
    if (argv[i] === '--runs') runs = Number(argv[++i]);
    else files.push(path.resolve(argv[i]));
  }
  if (!files.length || !(runs >= 2)) {
    console.error('usage: node scripts/measure_decode_times.js [--runs N >= 2] FILE.glb...');
    return 2;
  }
  const dirs = [...new Set(files.map((f) => path.dirname(f)))];
  const mounts = dirs.map((d, i) => ({ prefix: `/in${i}`, dir: d }));
  const { server, url } = await startServer({ root: REPO, port: 0, mounts });
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'apparent-decode-'));
  const ctx = await launchHeadless(chromium, profile, process.env.CHROMIUM || '/usr/bin/chromium', { width: 320, height: 240 });
  try {
    const page = ctx.pages()[0] || await ctx.newPage();
    await page.goto(`${url}/scripts/decode_time/index.html`, { waitUntil: 'load' });
    await page.waitForFunction(() => window.decodeReady === true, null, { timeout: 20000 });
    console.log('| file | bytes | vertices in three.js | first parse (ms) | median of the next ' + (runs - 1) + ' (ms) |');
    console.log('|---|---|---|---|---|');
    for (const f of files) {
      const u = `/in${dirs.indexOf(path.dirname(f))}/${encodeURIComponent(path.basename(f))}`;
      const r = await page.evaluate(([x, n]) => window.decodeTime(x, n), [u, runs]);
      const rest = r.times.slice(1).sort((a, b) => a - b);
      const median = rest[Math.floor(rest.length / 2)];
      console.log(`| ${path.basename(f)} | ${r.bytes} | ${r.vertices} | ${r.times[0].toFixed(1)} | ${median.toFixed(1)} |`);
    }
  } finally {
    await ctx.close();
    server.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
  return 0;
}
main().then((c) => process.exit(c), (e) => { console.error(e); process.exit(1); });
