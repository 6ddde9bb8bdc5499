#!/usr/bin/env node
// Google's <model-viewer> (npm @google/model-viewer) check of apparent's animated .glb files, in headless Chromium.
//
//   node tests/model_viewer/check.js OUTDIR|FILE.glb [OUTDIR|FILE.glb ...] [--models a,b,c] [--frames 0,50,100,199]
//        [--shot-time SECONDS] [--screenshot-dir DIR] [--chromium PATH] [--keep-profile] [--debug-requests]
//
// Every .glb in each OUTDIR (or only <model>.glb for --models), plain, KHR_draco_mesh_compression or
// EXT_meshopt_compression; give the plain, --draco and --compress meshopt output directories together to check all. The script serves the repository root and each
// directory on 127.0.0.1, opens tests/model_viewer/index.html (the model-viewer dist build from node_modules, Draco
// decoder from node_modules/three, no network) in Debian Chromium through playwright-core, and checks per file:
//   - model-viewer fires 'load' (no 'error'), availableAnimations includes "frames", duration = frames / fps;
//   - with "frames" selected and paused, at currentTime = (k + 0.5) / fps for several k (0, 1, 3n/4, n-1, the
//     shot frame and a quarter of it; or --frames): the element screenshot shows geometry, and the pixels that show
//     geometry all belong to frame node k (its own mesh or its reflection child nodes). model-viewer's public
//     surfaceFromPoint(x, y) names the glTF mesh under a pixel, and the file maps meshes to frame nodes (a mesh
//     whose morph targets make a run of frames, --compress meshopt, stands for each of them: that three.js, which
//     model-viewer loads with, draws each frame's own shape is checked by tests/web/viewer_test.js --plain); the
//     expectation is also evaluated from the file's own animation data (tests/web/glb.js);
//   - the screenshot at t = --shot-time (default 10 s, taken mid-frame) shows geometry (non-background pixels), and
//     differs from the one at a quarter of that time;
//   - pressing play advances currentTime;
//   - no browser errors and no request leaving 127.0.0.1 (a "net::ERR_ABORTED" that Chromium reports for a request
//     after its complete 200 response, while the data was used, is only counted).
// Screenshots: DIR/[inI-]<model>-mv-<k>.png for the two screenshot frames (DIR: --screenshot-dir, else the first
// input's directory). model-viewer ignores the file's camera node and frames the model from its bounding box at load.
// --debug-requests logs every request and response.
// Exit 0 when everything passed, 1 on a failed check, 2 on a usage or setup problem.
'use strict';

const fs = require('node:fs');
const os = require('node:os');
const path = require('node:path');
const { launchHeadless } = require('../web/chromium.js');

const REPO = path.resolve(__dirname, '..', '..');
const t0 = Date.now();
const elapsed = () => `${((Date.now() - t0) / 1000).toFixed(1)} s`;

function usage(msg) {
  if (msg) console.error(`model_viewer check: ${msg}`);
  console.error('usage: node tests/model_viewer/check.js OUTDIR|FILE.glb [...] [--models a,b,c] [--frames 0,50,100,199] ' +
    '[--shot-time SECONDS] [--screenshot-dir DIR] [--chromium PATH] [--keep-profile] [--debug-requests]');
  process.exit(2);
}
function setupFail(msg) {
  console.error(`model_viewer check: SETUP ERROR: ${msg}`);
  process.exit(2);
}

// ------------------------------------------------------------------ arguments
const opts = { inputs: [], models: null, frames: null, shotTime: 10, shotDir: null,
  chromium: process.env.CHROMIUM || '/usr/bin/chromium', keepProfile: false, debugRequests: false };
{
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    const val = () => (i + 1 < argv.length ? argv[++i] : usage(`${a} needs a value`));
    if (a === '--models') opts.models = val().split(',').map((s) => s.trim()).filter(Boolean);
    else if (a === '--frames') opts.frames = val().split(',').map((s) => Number(s.trim()));
    else if (a === '--shot-time') opts.shotTime = Number(val());
    else if (a === '--screenshot-dir') opts.shotDir = path.resolve(val());
    else if (a === '--chromium') opts.chromium = val();
    else if (a === '--keep-profile') opts.keepProfile = true;
    else if (a === '--debug-requests') opts.debugRequests = true;
    else if (a === '-h' || a === '--help') usage();
    else if (a.startsWith('-')) usage(`unknown option ${a}`);
    else opts.inputs.push(path.resolve(a));
  }
  if (!opts.inputs.length) usage('give at least one OUTDIR or .glb file');
  if (opts.frames && opts.frames.some((k) => !Number.isInteger(k) || k < 0)) usage('--frames wants integers >= 0');
  if (!Number.isFinite(opts.shotTime) || opts.shotTime <= 0) usage('--shot-time wants a number > 0');
}

// ------------------------------------------------------------------ prerequisites (fail loudly, never skip)
const files = [];   // {file, dir, mount}
for (const p of opts.inputs) {
  if (!fs.existsSync(p)) setupFail(`${p} does not exist (make it with: build/apparent render data/scenes/flanges.json ` +
    '--out DIR --model instant,finite,relativistic [--draco])');
  if (fs.statSync(p).isDirectory()) {
    const names = opts.models ? opts.models.map((m) => `${m}.glb`)
      : fs.readdirSync(p).filter((f) => f.endsWith('.glb')).sort();
    if (!names.length) setupFail(`${p} has no .glb file`);
    for (const n of names) {
      if (!fs.existsSync(path.join(p, n))) setupFail(`${path.join(p, n)} is missing`);
      files.push({ file: path.join(p, n), dir: p });
    }
  } else {
    files.push({ file: p, dir: path.dirname(p) });
  }
}
const MV = 'node_modules/@google/model-viewer/dist/model-viewer.min.js';
for (const f of [MV, 'node_modules/@google/model-viewer/package.json', 'node_modules/playwright-core/package.json',
  'node_modules/three/examples/jsm/libs/draco/gltf/draco_decoder.wasm',
  'node_modules/three/examples/jsm/libs/draco/gltf/draco_wasm_wrapper.js', 'node_modules/meshoptimizer/meshopt_decoder.js']) {
  if (!fs.existsSync(path.join(REPO, f))) setupFail(`${f} not found: run "npm ci" (or "npm install") in ${REPO}`);
}
if (!fs.existsSync(opts.chromium)) {
  setupFail(`${opts.chromium} not found: install Debian's Chromium with "apt-get install -y chromium" ` +
    '(or pass --chromium PATH / set CHROMIUM)');
}
for (const f of ['tests/model_viewer/index.html', 'exporters/web/serve.js', 'tests/web/glb.js', 'tests/web/png.js']) {
  if (!fs.existsSync(path.join(REPO, f))) setupFail(`${f} is missing`);
}

const { chromium } = require(path.join(REPO, 'node_modules', 'playwright-core'));
const { startServer } = require(path.join(REPO, 'exporters', 'web', 'serve.js'));
const { describe, expectedVisible } = require(path.join(REPO, 'tests', 'web', 'glb.js'));
const { decodePNG } = require(path.join(REPO, 'tests', 'web', 'png.js'));
const mvVersion = require(path.join(REPO, 'node_modules', '@google', 'model-viewer', 'package.json')).version;

// ------------------------------------------------------------------ bookkeeping
const failures = [];
const warnings = [];
let passed = 0;
function check(cond, what, detail = '') {
  if (cond) { ++passed; return true; }
  failures.push(detail ? `${what}: ${detail}` : what);
  console.log(`  FAIL ${what}${detail ? ': ' + detail : ''}`);
  return false;
}
function warn(msg) { warnings.push(msg); console.log(`  WARN ${msg}`); }

const BG = [255, 255, 255];   // index.html: page and <model-viewer> background
function foreground(img) {
  const pts = [];
  for (let y = 1; y < img.height - 1; ++y) {
    for (let x = 1; x < img.width - 1; ++x) {
      const o = (y * img.width + x) * img.channels;
      const dmax = Math.max(Math.abs(img.data[o] - BG[0]), Math.abs(img.data[o + 1] - BG[1]),
        Math.abs(img.data[o + 2] - BG[2]));
      if (dmax > 6) pts.push([x, y]);   // the background is exactly BG; the grey stage is only ~25 darker
    }
  }
  return pts;
}
function imageDiff(a, b) {
  if (a.width !== b.width || a.height !== b.height) return 1;
  let n = 0;
  for (let i = 0; i < a.width * a.height; ++i) {
    const oa = i * a.channels, ob = i * b.channels;
    if (Math.max(Math.abs(a.data[oa] - b.data[ob]), Math.abs(a.data[oa + 1] - b.data[ob + 1]),
      Math.abs(a.data[oa + 2] - b.data[ob + 2])) > 24) ++n;
  }
  return n / (a.width * a.height);
}
// up to n points spread over the list (foreground pixels, row-major)
const spread = (pts, n) => (pts.length <= n ? pts : Array.from({ length: n }, (_, i) => pts[Math.floor((i + 0.5) * pts.length / n)]));

// ------------------------------------------------------------------ main
async function main() {
  console.log(`model_viewer check: @google/model-viewer ${mvVersion} (${MV}), ${files.length} file(s)`);
  // mounts: one URL prefix per directory
  const dirs = [...new Set(files.map((f) => f.dir))];
  const mounts = dirs.map((d, i) => ({ prefix: `/in${i}`, dir: d }));
  for (const f of files) {
    f.url = `/in${dirs.indexOf(f.dir)}/${encodeURIComponent(path.basename(f.file))}`;
    f.label = path.relative(process.cwd(), f.file) || f.file;
    if (f.label.startsWith('..')) f.label = f.file;
    f.d = describe(f.file);
    const d = f.d;
    d.fps = Number(d.extras.fps) > 0 ? Number(d.extras.fps) : d.duration > 0 ? d.frames.length / d.duration : NaN;
    f.draco = d.frames.some((x) => x.draco);
    f.meshopt = (d.json.extensionsRequired || []).includes('EXT_meshopt_compression');
    // glTF mesh index -> frame nodes using it (what surfaceFromPoint reports is the mesh index): one frame, or with
    // --compress meshopt's frame coherence the frames of a run, morph targets of one mesh (exporters/gltf.h)
    // (a frame's reflection child nodes, "frame_NNNNN mirror M", belong to it too)
    f.meshToFrames = new Map();
    d.frames.forEach((fr, k) => {
      for (const ni of [fr.index, ...fr.children.map((c) => c.index)]) {
        const m = d.json.nodes[ni].mesh;
        if (m === undefined) continue;
        if (!f.meshToFrames.has(m)) f.meshToFrames.set(m, []);
        f.meshToFrames.get(m).push(k);
      }
    });
    f.morph = (d.json.meshes || []).some((me) => me.primitives.some((p) => (p.targets || []).length > 0));
  }
  if (!files.some((f) => f.draco)) warn('no KHR_draco_mesh_compression file among the inputs: Draco not checked');
  if (!files.some((f) => !f.draco && !f.meshopt)) warn('no plain (uncompressed) file among the inputs');
  const shotDir = opts.shotDir || path.dirname(files[0].file);
  fs.mkdirSync(shotDir, { recursive: true });

  const { server, url } = await startServer({ root: REPO, port: 0, mounts });
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'apparent-model-viewer-'));
  let ctx = null;
  try {
    ctx = await launchHeadless(chromium, profile, opts.chromium, { width: 660, height: 500 });
    const page = ctx.pages()[0] || await ctx.newPage();
    const consoleMsgs = [];
    const external = [];
    // Chromium sometimes reports a fetch whose 200 response model-viewer (three's FileLoader) read completely as
    // "requestfailed net::ERR_ABORTED" right after the response; those are counted apart, not as errors.
    const ok200 = new WeakSet();
    let abortedAfter200 = 0;
    const debug = (s) => { if (opts.debugRequests) console.log(`  [${elapsed()}] ${s}`); };
    page.on('console', (msg) => {
      if (msg.type() === 'error' || msg.type() === 'warning') consoleMsgs.push(`${msg.type()}: ${msg.text()}`);
    });
    page.on('pageerror', (err) => consoleMsgs.push(`pageerror: ${err.message}`));
    page.on('request', (req) => {
      const u = req.url();
      debug(`request ${req.method()} ${u}`);
      if (!u.startsWith(url + '/') && !/^(data|blob):/.test(u)) external.push(u);
    });
    page.on('response', (res) => {
      debug(`response ${res.status()} ${res.url()}`);
      if (res.status() === 200) ok200.add(res.request());
      if (res.status() >= 400) consoleMsgs.push(`http ${res.status()}: ${res.url()}`);
    });
    page.on('requestfailed', (req) => {
      const why = req.failure()?.errorText;
      debug(`failed ${req.url()} ${why}`);
      if (why === 'net::ERR_ABORTED' && ok200.has(req)) ++abortedAfter200;
      else consoleMsgs.push(`requestfailed: ${req.url()} ${why}`);
    });

    const pageUrl = `${url}/tests/model_viewer/index.html`;
    console.log(`  browser: chromium ${ctx.browser()?.version() ?? ''}; page ${pageUrl}`);
    await page.goto(pageUrl, { waitUntil: 'load', timeout: 20000 });
    await page.waitForFunction(() => !!window.mvTest && !!customElements.get('model-viewer'), null, { timeout: 20000 });

    for (const f of files) {
      const d = f.d, n = d.frames.length;
      console.log(`\n== ${f.label}: ${n} frame nodes, fps ${d.fps}, ${d.duration} s${f.draco ? ', Draco' : ''}` +
        `${f.meshopt ? ', meshopt' : ''}${f.morph ? ', morph targets' : ''}`);
      let info;
      try {
        info = await page.evaluate((src) => window.mvTest.load(src), f.url);
      } catch (e) {
        check(false, `${f.label}: model-viewer loads the file`, e.message.split('\n')[0]);
        continue;
      }
      check(info.loaded, `${f.label}: model-viewer fired 'load' and reports loaded`);
      console.log(`  loaded in ${info.loadMs} ms; availableAnimations ${JSON.stringify(info.availableAnimations)}, ` +
        `animationName ${info.animationName}, duration ${info.duration}` +
        (f.draco ? `, Draco decoder from ${info.dracoDecoderLocation}` : '') +
        (f.meshopt ? `, meshopt decoder from ${info.meshoptDecoderLocation}` : ''));
      if (f.meshopt) {
        check(String(info.meshoptDecoderLocation).includes('/node_modules/meshoptimizer/'),
          `${f.label}: meshopt decoder location is the local copy`, String(info.meshoptDecoderLocation));
      }
      if (f.draco) {
        check(String(info.dracoDecoderLocation).includes('/node_modules/three/examples/jsm/libs/draco/gltf/'),
          `${f.label}: Draco decoder location is the local copy`, String(info.dracoDecoderLocation));
      }
      check(info.availableAnimations.includes('frames'), `${f.label}: availableAnimations includes "frames"`,
        JSON.stringify(info.availableAnimations));
      check(Math.abs(info.duration - n / d.fps) < 1e-3, `${f.label}: duration = frames / fps`,
        `${info.duration} vs ${n / d.fps}`);

      // visibility at mid-frame times: every hit pixel belongs to frame node k
      // the screenshots (at the shot time, mid-frame, and at a quarter of it) are taken among these probes
      const kShot = Math.min(n - 1, Math.floor(opts.shotTime * d.fps));
      const kQuarter = Math.floor(kShot / 4);   // shot time beyond the file: its last frame, and a quarter of that
      const shots = {};
      let ks = opts.frames || [0, 1, Math.floor((3 * n) / 4), n - 1];
      ks = [...new Set([...ks, kShot, kQuarter].filter((k) => k < n))].sort((a, b) => a - b);
      for (const k of ks) {
        const t = (k + 0.5) / d.fps;
        const st = await page.evaluate((tt) => window.mvTest.setTime(tt), t);
        const want = d.frames[k];
        const fileSays = expectedVisible(d, t).map((x) => x.name);
        check(fileSays.length === 1 && fileSays[0] === want.name,
          `${f.label} frame #${k} (t=${t.toFixed(3)}): file animation shows exactly ${want.name}`, JSON.stringify(fileSays));
        check(Math.abs(st.currentTime - t) < 1e-6 && st.paused, `${f.label} t=${t.toFixed(3)}: currentTime set, paused`,
          JSON.stringify(st));
        let shotFile;
        if (k === kShot || k === kQuarter) {
          shotFile = path.join(shotDir, `${dirs.length > 1 ? `in${dirs.indexOf(f.dir)}-` : ''}` +
            `${path.basename(f.file, '.glb')}-mv-${k}.png`);
        }
        const png = await page.locator('model-viewer').screenshot({ type: 'png', path: shotFile });
        const img = decodePNG(png);
        if (shotFile) shots[k] = { img, file: shotFile, t };
        const fg = foreground(img);
        if (!want.hasMesh && !want.children.some((c) => c.vertices > 0)) {
          check(fg.length === 0, `${f.label} frame #${k}: empty frame shows nothing`, `${fg.length} pixels`);
          continue;
        }
        if (!check(fg.length >= 50, `${f.label} frame #${k} (t=${t.toFixed(3)}): geometry on screen`,
          `${fg.length} non-background pixels`)) continue;
        const hits = await page.evaluate((pts) => window.mvTest.probe(pts), spread(fg, 40));
        const hitFrames = hits.filter((h) => h.mesh !== null).map((h) => {
          const ks = f.meshToFrames.get(h.mesh);
          return ks === undefined ? undefined : ks.includes(k) ? k : ks[0];
        });
        const others = [...new Set(hitFrames.filter((x) => x !== k))];
        check(hitFrames.length >= 0.5 * hits.length,
          `${f.label} frame #${k}: model-viewer's surfaceFromPoint hits geometry at the drawn pixels`,
          `${hitFrames.length} of ${hits.length}`);
        const ok = check(others.length === 0 && hitFrames.length > 0,
          `${f.label} frame #${k} (t=${t.toFixed(3)}): only ${want.name} is under the drawn pixels`,
          `also ${others.map((x) => (x === undefined ? 'a non-frame mesh' : d.frames[x].name)).join(', ')}`);
        if (ok) {
          console.log(`  ok   frame #${k} (t=${t.toFixed(3)} s): ${fg.length} pixels drawn, ` +
            `${hitFrames.length}/${hits.length} probed pixels on ${want.name}`);
        }
      }

      // the screenshot at the shot time shows geometry and differs from the one at a quarter of it
      const main = shots[kShot];
      const fgN = foreground(main.img).length;
      const frac = fgN / (main.img.width * main.img.height);
      check(fgN >= 200, `${f.label}: screenshot at t=${main.t.toFixed(2)} s shows the objects`,
        `${fgN} non-background pixels`);
      check(frac < 0.95, `${f.label}: screenshot at t=${main.t.toFixed(2)} s shows background too`,
        `${(100 * frac).toFixed(1)} % non-background`);
      let diffMsg = '';
      if (kQuarter !== kShot) {
        const diff = imageDiff(main.img, shots[kQuarter].img);
        check(diff > 0.0005, `${f.label}: screenshots at t=${main.t.toFixed(2)} and ${shots[kQuarter].t.toFixed(2)} s differ`,
          `${(100 * diff).toFixed(3)} % of pixels differ`);
        diffMsg = `; ${(100 * diff).toFixed(2)} % of pixels differ from t=${shots[kQuarter].t.toFixed(2)} s`;
      } else {
        warn(`${f.label}: one frame only, no second screenshot to compare`);
      }
      console.log(`  screenshot ${main.file}: ${fgN} object pixels (${(100 * frac).toFixed(1)} %)${diffMsg}`);

      // playback advances
      const pl = await page.evaluate(() => window.mvTest.playFor(400, 1));
      check(pl.t1 > pl.t0 + 0.05 && pl.paused, `${f.label}: play() advances currentTime`, JSON.stringify(pl));
    }

    // console and network
    const ignorable = (s) => /GPU stall due to ReadPixels|favicon\.ico/.test(s);
    const relevant = consoleMsgs.filter((s) => !ignorable(s));
    for (const s of relevant) console.log(`  console ${s}`);
    check(!relevant.some((s) => /^(error|pageerror|requestfailed|http)/.test(s)), 'no browser errors',
      relevant.filter((s) => /^(error|pageerror|requestfailed|http)/.test(s)).join(' | '));
    for (const s of relevant.filter((x) => x.startsWith('warning'))) warn(`browser ${s}`);
    check(external.length === 0, 'no request left 127.0.0.1', [...new Set(external)].slice(0, 5).join(' '));
    if (abortedAfter200) {
      console.log(`  note ${abortedAfter200} request(s) reported as net::ERR_ABORTED after a complete 200 response ` +
        '(Chromium/playwright reporting; the data was used)');
    }
  } finally {
    if (ctx) await ctx.close().catch(() => {});
    server.close();
    if (!opts.keepProfile) fs.rmSync(profile, { recursive: true, force: true });
  }
}

const watchdog = setTimeout(() => {
  console.error(`model_viewer check: FAIL: timed out after ${elapsed()}`);
  process.exit(1);
}, 120000);
watchdog.unref();

main().then(() => {
  console.log(`\nmodel_viewer check: ${warnings.length} warnings, ${elapsed()}`);
  console.log(`model_viewer: ${passed} passed, ${failures.length} failed`);
  if (failures.length) {
    console.log('FAILED:');
    for (const f of failures) console.log(`  - ${f}`);
    process.exit(1);
  }
  console.log('PASS');
  process.exit(0);
}, (e) => {
  console.error(`model_viewer check: FAIL: ${e && e.stack ? e.stack : e}`);
  process.exit(1);
});
