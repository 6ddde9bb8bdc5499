#!/usr/bin/env node
// Headless-browser test of the web viewer (exporters/web/).
//
//   node tests/web/viewer_test.js OUTDIR [--screenshot PATH] [--models a,b,c] [--frames 0,50,100,199]
//                                        [--shot-time SECONDS] [--chromium PATH] [--keep-profile] [--plain DIR]
//                                        [--open-time T --expect-camera-time C] [--expect-time-unit ns]
//
// OUTDIR holds <model>.glb for every model (plain or KHR_draco_mesh_compression). The test serves the repository
// root and OUTDIR (as /out/) on 127.0.0.1, opens the viewer in Debian Chromium (headless, SwiftShader WebGL) via
// playwright-core, and checks for each model:
//   - the viewer loaded every frame node of the file, with the fps from the scene extras;
//   - at t = k/fps + eps (several k, plus t = 0 and t = duration) exactly the expected frame node is visible, the
//     expectation being computed here in Node from the file's own animation data, and it is frame k;
//   - each visible node's vertex count in three.js equals the POSITION accessor counts in the file, and so does
//     that of its reflection child nodes ("frame_NNNNN mirror M") shown with it (a child that three.js
//     did not attach to its frame, or shows at another time, changes the count);
//   - a screenshot at t = --shot-time (default 10 s) has a meaningful number of non-background pixels in every
//     model's viewport, and the viewports fill the window (their widths and gaps its width, their heights its
//     height less the labels);
//   - with --open-time T: the viewer opened with ?t=T shows camera time C (--expect-camera-time: T for a camera
//     time of the files, the first frame's time plus T for an older link's animation time);
//   - for files with COLOR_0 (render --shade doppler): the viewer found the Doppler colours (on objects keeping
//     their input's materials, with _DOPPLER: the exact shift), and switching to plain colours changes the
//     picture where objects move (relativistic) but not where D = 1 (instant);
//   - with --plain DIR (the plain export of the same render; OUTDIR a --compress meshopt one, whose frames may be
//     morph targets of an earlier frame's mesh, exporters/gltf.h): at each checked time the world-space bounds of
//     the shown frame as three.js draws it (Mesh.getVertexPosition: morph targets applied) equal those of the plain
//     file's frame (its POSITION bounds plus the node translation) within half a quantization step per coordinate
//     (the shown scale) plus float32 rounding.
// Exit 0 when everything passed, 1 on a failed check, 2 on a usage or setup problem (nothing is skipped).
'use strict';

const fs = require('node:fs');
const os = require('node:os');
const path = require('node:path');
const { launchHeadless } = require('./chromium.js');

const REPO = path.resolve(__dirname, '..', '..');
const t0 = Date.now();
const elapsed = () => `${((Date.now() - t0) / 1000).toFixed(1)} s`;

function usage(msg) {
  if (msg) console.error(`viewer_test: ${msg}`);
  console.error('usage: node tests/web/viewer_test.js OUTDIR [--screenshot PATH] [--models a,b,c] ' +
    '[--frames 0,50,100,199] [--shot-time SECONDS] [--chromium PATH] [--keep-profile] [--plain DIR]');
  process.exit(2);
}

function setupFail(msg) {
  console.error(`viewer_test: SETUP ERROR: ${msg}`);
  process.exit(2);
}

// ------------------------------------------------------------------ arguments
const opts = { outdir: null, screenshot: null, models: ['instant', 'finite', 'relativistic'], frames: null,
  shotTime: 10, chromium: process.env.CHROMIUM || '/usr/bin/chromium', keepProfile: false, plain: null,
  openTime: 0, expectCameraTime: null, expectTimeUnit: null };
{
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    const val = () => (i + 1 < argv.length ? argv[++i] : usage(`${a} needs a value`));
    if (a === '--screenshot') opts.screenshot = path.resolve(val());
    else if (a === '--models') opts.models = val().split(',').map((s) => s.trim()).filter(Boolean);
    else if (a === '--frames') opts.frames = val().split(',').map((s) => Number(s.trim()));
    else if (a === '--shot-time') opts.shotTime = Number(val());
    else if (a === '--open-time') opts.openTime = Number(val());
    else if (a === '--expect-camera-time') opts.expectCameraTime = Number(val());
    else if (a === '--expect-time-unit') opts.expectTimeUnit = val();
    else if (a === '--chromium') opts.chromium = val();
    else if (a === '--keep-profile') opts.keepProfile = true;
    else if (a === '--plain') opts.plain = path.resolve(val());
    else if (a === '-h' || a === '--help') usage();
    else if (a.startsWith('-')) usage(`unknown option ${a}`);
    else if (!opts.outdir) opts.outdir = path.resolve(a);
    else usage(`unexpected argument ${a}`);
  }
  if (!opts.outdir) usage('OUTDIR is required');
  if (!opts.models.length) usage('--models is empty');
  if (opts.frames && opts.frames.some((k) => !Number.isInteger(k) || k < 0)) usage('--frames wants integers >= 0');
  if (!Number.isFinite(opts.shotTime) || opts.shotTime < 0) usage('--shot-time wants a number >= 0');
  if (!opts.screenshot) opts.screenshot = path.join(opts.outdir, 'viewer.png');
}

// ------------------------------------------------------------------ prerequisites (fail loudly, never skip)
if (!fs.existsSync(opts.outdir) || !fs.statSync(opts.outdir).isDirectory()) setupFail(`OUTDIR ${opts.outdir} is not a directory`);
for (const m of opts.models) {
  if (!fs.existsSync(path.join(opts.outdir, `${m}.glb`))) {
    setupFail(`${path.join(opts.outdir, m + '.glb')} is missing (generate it with: build/apparent render ` +
      `data/scenes/flanges.json --out ${opts.outdir} --model ${opts.models.join(',')})`);
  }
}
for (const [mod, file] of [['three', 'build/three.module.js'], ['three', 'examples/jsm/loaders/GLTFLoader.js'],
  ['three', 'examples/jsm/libs/draco/gltf/draco_decoder.wasm'], ['playwright-core', 'package.json']]) {
  if (!fs.existsSync(path.join(REPO, 'node_modules', mod, file))) {
    setupFail(`node_modules/${mod}/${file} not found: run "npm ci" (or "npm install") in ${REPO}`);
  }
}
if (!fs.existsSync(opts.chromium)) {
  setupFail(`${opts.chromium} not found: install Debian's Chromium with "apt-get install -y chromium" ` +
    '(or pass --chromium PATH / set CHROMIUM)');
}
for (const f of ['exporters/web/index.html', 'exporters/web/viewer.js', 'exporters/web/serve.js']) {
  if (!fs.existsSync(path.join(REPO, f))) setupFail(`${f} is missing`);
}

const { chromium } = require(path.join(REPO, 'node_modules', 'playwright-core'));
const { startServer } = require(path.join(REPO, 'exporters', 'web', 'serve.js'));
const { describe, expectedVisible } = require('./glb.js');
const { decodePNG } = require('./png.js');

// ------------------------------------------------------------------ checks bookkeeping
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
const fmtVis = (v) => (v.length ? v.map((x) => `${x.name}(${x.vertices}v${x.reflected ? ` +${x.reflected}v mirrored` : ''})`).join(' ') : '(none)');
const sameVis = (a, b) => a.length === b.length &&
  a.every((x, i) => x.name === b[i].name && x.vertices === b[i].vertices && (x.reflected || 0) === (b[i].reflected || 0));
const byName = (v) => [...v].sort((x, y) => (x.name < y.name ? -1 : x.name > y.name ? 1 : 0));

// ------------------------------------------------------------------ --plain: the shown frame's bounds against the plain file
const plainFiles = {};
function checkBounds(m, frame, got, label) {
  if (!plainFiles[m]) plainFiles[m] = describe(path.join(opts.plain, `${m}.glb`));
  const pj = plainFiles[m].json, d = filesForBounds[m];
  const pn = pj.nodes.find((n) => n.name === frame.name), mn = d.json.nodes[frame.index];
  if (!check(pn && pn.mesh !== undefined, `${label}: the plain file has ${frame.name} with a mesh`)) return;
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  const tr = pn.translation || [0, 0, 0];
  for (const p of pj.meshes[pn.mesh].primitives) {
    const a = pj.accessors[p.attributes.POSITION];
    for (let c = 0; c < 3; ++c) { lo[c] = Math.min(lo[c], a.min[c] + tr[c]); hi[c] = Math.max(hi[c], a.max[c] + tr[c]); }
  }
  const channel = d.channels.find((ch) => ch.node === frame.index);
  const step = channel ? Math.max(...channel.values.map((v) => v[0])) : 1;
  const morph = (d.json.meshes[mn.mesh].primitives[0].targets || []).length > 0 && (mn.weights || []).some((w) => w);
  if (!check(got, `${label}: three.js shows ${frame.name} with vertices`)) return;
  let worst = 0, allowed = 0;
  for (let c = 0; c < 3; ++c) {
    const slack = step / 2 + (Math.abs(lo[c]) + Math.abs(hi[c]) + 1) * 2 ** -22;
    allowed = Math.max(allowed, slack);
    worst = Math.max(worst, Math.abs(got.min[c] - lo[c]) - slack, Math.abs(got.max[c] - hi[c]) - slack);
  }
  if (check(worst <= 0, `${label}: three.js bounds of ${frame.name}${morph ? ' (morph targets)' : ''} match the plain file's`,
    `three.js ${JSON.stringify(got)}, plain min ${lo} max ${hi}, allowed ${allowed}`)) {
    console.log(`  ok   ${label}: bounds of ${frame.name}${morph ? ' (morph targets applied)' : ''} within ${allowed.toExponential(2)} of the plain file's`);
  }
}
const filesForBounds = {};

// ------------------------------------------------------------------ main
async function main() {
  // 1. what the files say (independent of three.js)
  const files = {};
  console.log(`viewer_test: OUTDIR ${opts.outdir}`);
  for (const m of opts.models) {
    let d;
    try {
      d = describe(path.join(opts.outdir, `${m}.glb`));
    } catch (e) {
      throw new Error(`cannot read ${path.join(opts.outdir, m + '.glb')}: ${e.message}`);
    }
    files[m] = d;
    filesForBounds[m] = d;
    // frames per second: scene extras, else (e.g. after draco_transcoder, which drops extras) frames / duration
    d.fps = Number(d.extras.fps) > 0 ? Number(d.extras.fps) : d.duration > 0 ? d.frames.length / d.duration : NaN;
    const draco = d.frames.some((f) => f.draco);
    console.log(`  ${m}.glb: ${d.frames.length} frame nodes, fps ${d.fps}, animation "${d.animName}" ` +
      `(${d.channels.length} scale channels, ${d.duration} s)${draco ? ', Draco' : ''}` +
      `${d.hasCamera ? `, camera node "${d.cameraNodeName}"` : ', no camera node'}` +
      `, ${d.frames.reduce((n, f) => n + f.children.length, 0)} reflection nodes`);
    check(d.frames.length > 0, `${m}: file has frame nodes`);
    check(d.fps > 0, `${m}: fps known (scene extras or frames / animation duration)`);
    if (!(Number(d.extras.fps) > 0)) {
      warn(`${m}: scene extras have no fps${d.extras.frame_times ? '' : ' and no frame_times'} ` +
        `(${draco ? 'draco_transcoder drops scene extras' : 'apparent should write them'}); using ${d.fps} fps`);
    }
    check(d.animName === 'frames', `${m}: animation is named "frames"`, `got ${JSON.stringify(d.animName)}`);
    if (Array.isArray(d.extras.frame_times)) {
      check(d.extras.frame_times.length === d.frames.length, `${m}: frame_times has one entry per frame`,
        `${d.extras.frame_times.length} vs ${d.frames.length}`);
    }
    if (d.frames.length && d.fps > 0) {
      check(Math.abs(d.duration - d.frames.length / d.fps) < 1e-3, `${m}: animation duration = frames / fps`,
        `${d.duration} vs ${d.frames.length / d.fps}`);
    }
    const first = Number.isInteger(d.extras.first_frame) ? d.extras.first_frame : d.frames.length ? d.frames[0].number : 0;
    const gaps = d.frames.filter((f, i) => f.number !== first + i);
    check(gaps.length === 0, `${m}: frame nodes are numbered consecutively from first_frame ${first}`,
      gaps.length ? `e.g. node #${d.frames.indexOf(gaps[0])} is ${gaps[0].name}` : '');
    const badDigits = d.frames.filter((f) => f.digits !== 5);
    if (badDigits.length) {
      warn(`${m}: ${badDigits.length} frame node names are not 5-digit (e.g. "${badDigits[0].name}", ` +
        'documented layout: frame_00000)');
    }
  }

  // 2. server + browser
  const { server, url } = await startServer({ root: REPO, port: 0, mounts: [{ prefix: '/out', dir: opts.outdir }] });
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'apparent-viewer-test-'));
  let ctx = null;
  try {
    ctx = await launchHeadless(chromium, profile, opts.chromium, { width: 1440, height: 560 });
    const page = ctx.pages()[0] || await ctx.newPage();
    const consoleMsgs = [];
    page.on('console', (msg) => {
      if (msg.type() === 'error' || msg.type() === 'warning') consoleMsgs.push(`${msg.type()}: ${msg.text()}`);
    });
    page.on('pageerror', (err) => consoleMsgs.push(`pageerror: ${err.message}`));
    // Chromium sometimes reports a fetch whose 200 response was read completely (the Draco decoder files under
    // load) as "requestfailed net::ERR_ABORTED" right after it: counted apart, as tests/model_viewer/check.js does.
    const ok200 = new WeakSet();
    const delivered = new Set();  // URLs answered with a success at least once (by any request)
    let abortedAfter200 = 0;
    page.on('requestfailed', (req) => {
      const why = req.failure()?.errorText;
      if (why === 'net::ERR_ABORTED' && ok200.has(req)) ++abortedAfter200;
      else consoleMsgs.push(`requestfailed: ${req.url()} ${why}`);
    });
    page.on('response', (res) => {
      if (res.status() === 200) ok200.add(res.request());
      if (res.status() >= 400) consoleMsgs.push(`http ${res.status()}: ${res.url()}`);
      else delivered.add(res.url());
    });

    const viewerUrl = `${url}/exporters/web/?dir=/out&models=${opts.models.join(',')}&paused=1&t=${opts.openTime}`;
    console.log(`  browser: ${await ctx.browser()?.version() ?? 'chromium'}; opening ${viewerUrl}`);
    await page.goto(viewerUrl, { waitUntil: 'load', timeout: 20000 });
    await page.waitForFunction(() => !!window.apparentViewer, null, { timeout: 20000 });
    const info = await page.evaluate(() => Promise.race([
      window.apparentViewer.ready,
      new Promise((_, rej) => setTimeout(() => rej(new Error('apparentViewer.ready timed out after 30 s')), 30000)),
    ]));
    console.log(`  viewer ready after ${elapsed()}`);
    const glRenderer = await page.evaluate(() => document.getElementById('status').textContent.split(' · ').pop());
    console.log(`  WebGL: ${glRenderer}`);

    // 3. per-model info
    for (const m of opts.models) {
      const d = files[m], vi = info[m];
      check(vi && vi.loaded, `${m}: loaded in the viewer`);
      if (!vi) continue;
      check(vi.frames === d.frames.length, `${m}: viewer found every frame node`, `${vi.frames} vs ${d.frames.length}`);
      check(Math.abs(vi.fps - d.fps) <= 1e-5 * d.fps, `${m}: viewer fps`, `${vi.fps} vs ${d.fps}`);
      check(Math.abs(vi.duration - d.duration) < 1e-4, `${m}: viewer animation duration`, `${vi.duration} vs ${d.duration}`);
      check(vi.camera === (d.hasCamera ? 'file' : 'default'), `${m}: camera source`,
        `viewer uses ${vi.camera}, file ${d.hasCamera ? 'has' : 'has no'} camera node`);
      console.log(`  ${m}: viewer sees ${vi.frames} frames @ ${vi.fps} fps, ${vi.duration} s, ${vi.camera} camera ` +
        `(fov ${vi.fov})`);
    }

    // 3b. ?t is camera time (an older link's animation time when outside the files' camera times)
    if (opts.expectCameraTime !== null) {
      const cameraTime = await page.evaluate(() => window.apparentViewer.getCameraTime());
      check(Math.abs(cameraTime - opts.expectCameraTime) < 1e-6, `?t=${opts.openTime} opens at camera time ` +
        `${opts.expectCameraTime}`, `camera time ${cameraTime}`);
    }

    // 3c. times shown in the unit that fits the files' frame times (a scene in metres: ns)
    if (opts.expectTimeUnit !== null) {
      const shown = await page.evaluate(() => document.getElementById('time').textContent);
      check(new RegExp(`^t = -?[0-9.]+ ${opts.expectTimeUnit} `).test(shown), `times read in ${opts.expectTimeUnit}`, shown);
    }

    // 4. visibility and vertex counts at several times
    const nAll = opts.models.map((m) => files[m].frames.length);
    const nMin = Math.min(...nAll);
    let ks = opts.frames || [0, 50, 100, nMin - 1];
    ks = [...new Set(ks.filter((k) => k < nMin))].sort((a, b) => a - b);
    const times = [];
    for (const k of ks) times.push({ label: `frame #${k}`, k });
    times.push({ label: 't = 0', t: 0, k: 0 });
    for (const m of opts.models) {
      // the last frame must stay visible at t = duration (LoopRepeat would wrap to frame 0 here)
      times.push({ label: `${m} t = duration`, t: files[m].duration, k: files[m].frames.length - 1, only: m });
    }
    let lastSeen = null;
    for (const tc of times) {
      const models = tc.only ? [tc.only] : opts.models;
      // each model at its own fps; when fps differ, set the time per model
      const groups = new Map();
      for (const m of models) {
        const fps = files[m].fps;
        const t = tc.t !== undefined ? tc.t : tc.k / fps + 0.1 / fps;   // epsilon: a tenth of a frame
        if (!groups.has(t)) groups.set(t, []);
        groups.get(t).push(m);
      }
      for (const [t, ms] of groups) {
        const { seen, bounds } = await page.evaluate((tt) => {
          window.apparentViewer.setTime(tt);
          return { seen: window.apparentViewer.visibleFrames(), bounds: window.apparentViewer.frameBounds() };
        }, t);
        lastSeen = seen;
        for (const m of ms) {
          const d = files[m];
          const expect = byName(expectedVisible(d, t));
          const got = byName(seen[m] || []);
          const want = d.frames[Math.min(tc.k, d.frames.length - 1)];
          const ok1 = check(expect.length === 1 && expect[0].name === want.name,
            `${m} @ ${tc.label} (t=${t.toFixed(4)}): file animation shows exactly frame node #${tc.k}`,
            `file shows ${fmtVis(expect)}, frame #${tc.k} is ${want.name}`);
          const ok2 = check(sameVis(got, expect), `${m} @ ${tc.label} (t=${t.toFixed(4)}): viewer shows the file's frame`,
            `viewer ${fmtVis(got)}, file ${fmtVis(expect)}`);
          if (ok1 && ok2) console.log(`  ok   ${m} @ ${tc.label} (t=${t.toFixed(4)}): ${fmtVis(got)}`);
          if (opts.plain && ok1) checkBounds(m, want, bounds[m], `${m} @ ${tc.label}`);
        }
      }
    }
    void lastSeen;

    // 5. screenshot at the shot time and pixel check per viewport
    const maxDur = Math.max(...opts.models.map((m) => files[m].duration));
    const shotT = Math.min(opts.shotTime, maxDur);
    const { seen, vps, bg } = await page.evaluate((tt) => {
      const v = window.apparentViewer;
      v.setTime(tt);
      return { seen: v.visibleFrames(), vps: v.viewports(), bg: v.background };
    }, shotT);
    // make sure the composited frame contains the last render
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    fs.mkdirSync(path.dirname(opts.screenshot), { recursive: true });
    const png = await page.screenshot({ path: opts.screenshot, type: 'png' });
    const img = decodePNG(png);
    const bgRGB = [1, 3, 5].map((i) => parseInt(bg.slice(i, i + 2), 16));
    const room = await page.evaluate(() => {
      const v = document.getElementById('views'), cs = getComputedStyle(v);
      return { w: v.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight),
        h: v.clientHeight - parseFloat(cs.paddingTop) - parseFloat(cs.paddingBottom),
        gap: parseFloat(cs.columnGap) || 0, label: document.querySelector('.label').offsetHeight };
    });
    const widths = opts.models.reduce((a, m) => a + (vps[m]?.width || 0), 0) + room.gap * (opts.models.length - 1);
    check(widths >= room.w - opts.models.length - 1, 'viewports fill the window\'s width', `${widths} of ${room.w} px`);
    for (const m of opts.models) {
      check((vps[m]?.height || 0) >= room.h - room.label - 1, `${m}: viewport fills the window's height`,
        `${vps[m]?.height} of ${room.h - room.label} px`);
    }
    console.log(`  screenshot at t = ${shotT} s: ${opts.screenshot} (${img.width}x${img.height})`);
    for (const m of opts.models) {
      const r = vps[m];
      if (!check(r && r.width > 10 && r.height > 10, `${m}: viewport has a size`, JSON.stringify(r))) continue;
      const x0 = Math.ceil(r.x) + 2, y0 = Math.ceil(r.y) + 2;
      const x1 = Math.min(img.width, Math.floor(r.x + r.width) - 2), y1 = Math.min(img.height, Math.floor(r.y + r.height) - 2);
      let differ = 0, bgLike = 0, total = 0;
      for (let y = y0; y < y1; ++y) {
        for (let x = x0; x < x1; ++x) {
          const o = (y * img.width + x) * img.channels;
          const dmax = Math.max(Math.abs(img.data[o] - bgRGB[0]), Math.abs(img.data[o + 1] - bgRGB[1]),
            Math.abs(img.data[o + 2] - bgRGB[2]));
          ++total;
          if (dmax > 24) ++differ;
          else if (dmax <= 2) ++bgLike;
        }
      }
      const frac = differ / Math.max(1, total);
      const minFrac = 0.005;   // at least 0.5 % of the viewport shows geometry
      console.log(`  ${m}: ${differ} of ${total} px differ from the background ${bg} (${(100 * frac).toFixed(2)} %), ` +
        `${(100 * bgLike / Math.max(1, total)).toFixed(1)} % are background; visible ${fmtVis(seen[m] || [])}`);
      check(frac >= minFrac, `${m}: screenshot shows geometry`, `${(100 * frac).toFixed(3)} % < ${100 * minFrac} % non-background`);
      check(bgLike / Math.max(1, total) > 0.05, `${m}: screenshot viewport shows background too`,
        `${(100 * bgLike / total).toFixed(2)} % background pixels: wrong background colour, or view filled?`);
    }

    // 5b. Doppler colours: the toggle against the plain colours, in the same viewports
    // (--shade doppler's COLOR_0: on materials with extras.base_color; an input's own COLOR_0 is not Doppler)
    const withColour = opts.models.filter((m) => (files[m].json.meshes || []).some((me) =>
      me.primitives.some((p) => p.attributes.COLOR_0 !== undefined &&
        (files[m].json.materials || [])[p.material]?.extras?.base_color !== undefined)));
    // (an object keeping its input's materials, with _DOPPLER: the viewer's exact shift, exporters/web/doppler.mjs)
    const withExact = opts.models.filter((m) => (files[m].json.meshes || []).some((me) =>
      me.primitives.some((p) => p.attributes.COLOR_0 !== undefined && p.attributes._DOPPLER !== undefined &&
        (files[m].json.materials || [])[p.material]?.extras?.base_color === undefined)));
    const toggled = [...new Set([...withColour, ...withExact])];
    if (toggled.length) {
      for (const m of withColour) {
        check(info[m].dopplerColours > 0, `${m}: viewer found the COLOR_0 meshes`, `${info[m].dopplerColours}`);
      }
      for (const m of withExact) {
        check(info[m].dopplerExact > 0, `${m}: viewer shifts the input's materials exactly`, `${info[m].dopplerExact}`);
      }
      await page.evaluate(() => window.apparentViewer.setShade('plain'));
      await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
      const plain = decodePNG(await page.screenshot({ type: 'png' }));
      await page.evaluate(() => window.apparentViewer.setShade('doppler'));
      for (const m of toggled) {
        const r = vps[m];
        let changed = 0, total = 0;
        for (let y = Math.ceil(r.y) + 2; y < Math.min(img.height, Math.floor(r.y + r.height) - 2); ++y) {
          for (let x = Math.ceil(r.x) + 2; x < Math.min(img.width, Math.floor(r.x + r.width) - 2); ++x) {
            const o = (y * img.width + x) * img.channels;
            const d = Math.max(Math.abs(img.data[o] - plain.data[o]), Math.abs(img.data[o + 1] - plain.data[o + 1]),
              Math.abs(img.data[o + 2] - plain.data[o + 2]));
            ++total;
            if (d > 24) ++changed;
          }
        }
        const frac = changed / Math.max(1, total);
        console.log(`  ${m}: Doppler vs plain colours differ in ${(100 * frac).toFixed(2)} % of the viewport`);
        if (m === 'instant') check(frac < 0.001, `${m}: Doppler colours equal the plain ones (D = 1)`, `${(100 * frac).toFixed(3)} %`);
        if (m === 'relativistic') check(frac > 0.001, `${m}: Doppler colours differ from the plain ones`, `${(100 * frac).toFixed(3)} %`);
      }
    }

    // 6. console
    // SwiftShader's performance notes about ReadPixels (screenshots) are harmless
    // A cancelled duplicate of a request whose URL another request delivered (three.js's DRACOLoader
    // may fetch its decoder once per loader) is not an error either; an aborted URL never delivered is.
    const abortedDuplicate = (s) => {
      const m = /^requestfailed: (\S+) net::ERR_ABORTED$/.exec(s);
      return !!m && delivered.has(m[1]);
    };
    const ignorable = (s) => /favicon\.ico|GPU stall due to ReadPixels/.test(s) || abortedDuplicate(s);
    if (abortedAfter200) console.log(`  note ${abortedAfter200} request(s) reported as net::ERR_ABORTED after a complete 200 response`);
    const relevant = consoleMsgs.filter((s) => !ignorable(s));
    for (const s of relevant) console.log(`  console ${s}`);
    check(!relevant.some((s) => /^(error|pageerror|requestfailed|http)/.test(s)), 'no browser errors',
      relevant.filter((s) => /^(error|pageerror|requestfailed|http)/.test(s)).join(' | '));
    for (const s of relevant.filter((x) => x.startsWith('warning'))) warn(`browser ${s}`);
  } finally {
    if (ctx) await ctx.close().catch(() => {});
    server.close();
    if (!opts.keepProfile) fs.rmSync(profile, { recursive: true, force: true });
  }
}

const watchdog = setTimeout(() => {
  console.error(`viewer_test: FAIL: timed out after ${elapsed()}`);
  process.exit(1);
}, 120000);
watchdog.unref();

main().then(() => {
  console.log(`\nviewer_test: ${passed} checks passed, ${failures.length} failed, ${warnings.length} warnings ` +
    `(${elapsed()})`);
  if (failures.length) {
    console.log('FAILED:');
    for (const f of failures) console.log(`  - ${f}`);
    process.exit(1);
  }
  console.log(`PASS  screenshot: ${opts.screenshot}`);
  process.exit(0);
}, (e) => {
  console.error(`viewer_test: FAIL: ${e && e.stack ? e.stack : e}`);
  process.exit(1);
});
