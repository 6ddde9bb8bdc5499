// apparent web viewer: plays exported .glb files (one node per frame, STEP scale animation "frames")
// from the scene camera, several models side by side in one WebGL canvas.
//
// URL parameters: ?dir=/out  ?models=instant,finite,relativistic  ?t=SECONDS  ?paused=1  ?shade=plain|doppler
// ?t is camera time, as the labels show it (the scene extras' frame_times); a t outside the files' camera times
// but inside the animation is read as animation time (from the first frame written), as links before issue 38 meant.
// Colours: files rendered with `--shade doppler` carry COLOR_0 (the Doppler-shifted colour) with a white
// material whose extras.base_color is the plain colour; the "Doppler" toggle switches between the two.
// An object that keeps its input's materials (textures, factors) has COLOR_0 = W(D) times the input's colour
// instead (docs/DOPPLER.md); with _DOPPLER in the file (--attributes doppler) the viewer shows the exact shift
// toneMap(A(D) colour) per fragment (doppler.mjs), the toggle off shows the input's own look.
// Test hook: window.apparentViewer (see the end of this file and README.md).

import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { DOPPLER_GLSL, dopplerModulation, dopplerUniformValues } from './doppler.mjs';

const VIEW_BG = '#1b1f27';   // viewport background (keep in sync with --view-bg in index.html)
const PAGE_BG = '#0e1014';   // gaps between viewports
const FRAME_NODE = /^frame_(\d+)$/;
const DEFAULT_FOV = 60;      // degrees, vertical, for files without a camera node

// ---------------------------------------------------------------- parameters
const params = new URLSearchParams(location.search);
const dir = (params.get('dir') || '/out').replace(/\/+$/, '');
const modelNames = (params.get('models') || 'instant,finite,relativistic')
  .split(',').map((s) => s.trim()).filter(Boolean);
const initialTime = Number(params.get('t')) || 0;
const startPaused = ['1', 'true', 'yes'].includes((params.get('paused') || '').toLowerCase());
let shade = (params.get('shade') || 'doppler').toLowerCase() === 'plain' ? 'plain' : 'doppler';
// ?aspect=16:9 or 1.6: aspect ratio of every viewport (default: the viewports fill the window, each showing at
// least the file camera's view, of its aspectRatio, else 16:9)
function parseAspect(v) {
  if (!v) return null;
  const m = /^\s*([\d.]+)\s*[:/x]\s*([\d.]+)\s*$/.exec(v);
  const a = m ? Number(m[1]) / Number(m[2]) : Number(v);
  return Number.isFinite(a) && a > 0.05 && a < 20 ? a : null;
}
const aspectParam = parseAspect(params.get('aspect'));
const DEFAULT_ASPECT = 16 / 9;

// ---------------------------------------------------------------- DOM
const canvas = document.getElementById('c');
const stage = document.getElementById('stage');
const viewsEl = document.getElementById('views');
const playBtn = document.getElementById('play');
const slider = document.getElementById('slider');
const timeEl = document.getElementById('time');
const speedSel = document.getElementById('speed');
const loopBox = document.getElementById('loop');
const statusEl = document.getElementById('status');
const dopplerBox = document.getElementById('doppler');

function setStatus(msg, isError = false) {
  statusEl.textContent = msg;
  statusEl.classList.toggle('error', isError);
}

// ---------------------------------------------------------------- renderer
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setScissorTest(false);
renderer.outputColorSpace = THREE.SRGBColorSpace;

const dracoLoader = new DRACOLoader();   // finds libs/draco/gltf/ next to itself in the browser
if (!dracoLoader.decoderPaths && !dracoLoader.decoderPath) {
  dracoLoader.setDecoderPath('/node_modules/three/examples/jsm/libs/draco/gltf/');
}
const loader = new GLTFLoader();
loader.setDRACOLoader(dracoLoader);
loader.setMeshoptDecoder(MeshoptDecoder);  // --compress meshopt (EXT_meshopt_compression)

// ---------------------------------------------------------------- models
/** @type {Array<object>} */
const models = modelNames.map((name) => {
  const view = document.createElement('div');
  view.className = 'view';
  const label = document.createElement('div');
  label.className = 'label';
  label.innerHTML = '<span class="name"></span><span class="sub">loading…</span>';
  label.querySelector('.name').textContent = name;
  const slot = document.createElement('div');
  slot.className = 'slot';
  slot.dataset.model = name;
  view.append(label, slot);
  viewsEl.append(view);
  return {
    name, url: new URL(`${dir}/${encodeURIComponent(name)}.glb`, location.href).href,
    view, label, sub: label.querySelector('.sub'), slot,
    gltf: null, scene: null, mixer: null, action: null, duration: 0, fps: 0, frameTimes: [],
    frames: [], camera: null, cameraObject: null, cameraSource: 'none', loaded: false,
  };
});

let time = 0;            // animation time: 0 at the first frame written
let cameraStart = 0;     // the camera time of animation time 0 (frame_times[0]; 0 without frame_times)
// Times shown in ns, us or ms when all the files' frame times are below 1 us, 1 ms or 1 s (a scene in metres
// lasts nanoseconds), as apparent figure labels them (pipeline/input/units.h).
let timeUnit = { name: 's', seconds: 1 };
function timeText(t, digits = 3) { return `${(t / timeUnit.seconds).toFixed(digits)} ${timeUnit.name}`; }
let zoom = 1;            // view zoom: fov' = 2 atan(tan(fov / 2) / zoom); the camera itself never moves
let aspect = aspectParam || DEFAULT_ASPECT;
let playing = !startPaused;
let maxDuration = 0;
let minFrameStep = 0.1;

// Sum of POSITION counts of the primitives of `node`'s own mesh (not of child nodes).
function nodeVertexCount(node, parser) {
  let n = 0;
  const visit = (o) => {
    if (o !== node && parser.associations.get(o)?.nodes !== undefined) return; // another glTF node
    if (o.isMesh && o.geometry?.attributes?.position) n += o.geometry.attributes.position.count;
    for (const c of o.children) visit(c);
  };
  visit(node);
  return n;
}

// The node is shown iff it and its ancestors are visible and no world-matrix column is (near) zero.
// (getWorldScale() is unreliable for zero scales, so read the columns directly.)
function isShown(obj) {
  for (let o = obj; o; o = o.parent) if (!o.visible) return false;
  const e = obj.matrixWorld.elements;
  const c0 = Math.hypot(e[0], e[1], e[2]), c1 = Math.hypot(e[4], e[5], e[6]), c2 = Math.hypot(e[8], e[9], e[10]);
  return Math.min(c0, c1, c2) > 1e-9;
}

function findFileCamera(m) {
  const json = m.gltf.parser.json;
  const nodes = json.nodes || [];
  let idx = nodes.findIndex((n) => n.name === 'camera' && n.camera !== undefined);
  if (idx < 0) idx = nodes.findIndex((n) => n.camera !== undefined);
  if (idx < 0) return null;
  let found = null;
  m.gltf.scene.traverse((o) => {
    if (!found && m.gltf.parser.associations.get(o)?.nodes === idx) found = o;
  });
  if (!found) return null;     // camera node not part of the scene
  if (found.isCamera) return found;
  let cam = null;
  found.traverse((o) => { if (!cam && o.isPerspectiveCamera) cam = o; });
  return cam;
}

async function fetchBuffer(url) {
  // fetch the whole file ourselves (three's FileLoader streams the body, which makes Chromium report the
  // request as aborted although all bytes arrived); this also gives clearer HTTP errors
  const res = await fetch(url, { cache: 'no-store' });
  if (!res.ok) throw new Error(`HTTP ${res.status} ${res.statusText} for ${url}`);
  return res.arrayBuffer();
}

async function loadModel(m) {
  const buffer = await fetchBuffer(m.url);
  const gltf = await loader.parseAsync(buffer, THREE.LoaderUtils.extractUrlBase(m.url));
  m.gltf = gltf;
  const json = gltf.parser.json;
  const sceneDef = json.scenes?.[json.scene ?? 0] || {};
  const extras = sceneDef.extras || gltf.scene.userData || {};
  m.extras = extras;
  m.fps = Number(extras.fps) || 0;
  m.frameTimes = Array.isArray(extras.frame_times) ? extras.frame_times : [];
  m.firstFrame = Number.isFinite(extras.first_frame) ? extras.first_frame : 0;

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(VIEW_BG);
  scene.add(gltf.scene);
  m.scene = scene;
  m.parser = gltf.parser;

  // frame nodes, in frame order
  gltf.scene.traverse((o) => {
    const ni = gltf.parser.associations.get(o)?.nodes;
    if (ni === undefined) return;
    const name = json.nodes[ni].name || '';
    const mm = FRAME_NODE.exec(name);
    if (!mm) return;
    // reflections in mirrors: child glTF nodes of the frame node ("frame_NNNNN mirror M")
    const children = [];
    o.traverse((c) => {
      if (c !== o && gltf.parser.associations.get(c)?.nodes !== undefined) {
        children.push({ object: c, vertices: nodeVertexCount(c, gltf.parser) });
      }
    });
    m.frames.push({ index: ni, name, number: Number(mm[1]), object: o,
      vertices: nodeVertexCount(o, gltf.parser), children });
  });
  m.frames.sort((a, b) => a.number - b.number);

  // animation
  const clip = gltf.animations.find((a) => a.name === 'frames') || gltf.animations[0];
  if (clip) {
    m.mixer = new THREE.AnimationMixer(gltf.scene);
    m.action = m.mixer.clipAction(clip);
    m.action.setLoop(THREE.LoopOnce, 1);
    m.action.clampWhenFinished = true;
    m.duration = clip.duration;
  }
  if (!m.fps && m.duration > 0 && m.frames.length) m.fps = m.frames.length / m.duration;

  // camera
  m.camera = new THREE.PerspectiveCamera(DEFAULT_FOV, 1, 0.01, 1000);
  m.cameraObject = findFileCamera(m);
  m.cameraSource = m.cameraObject ? 'file' : 'default';
  if (m.cameraObject?.isOrthographicCamera) {
    // An orthographic file camera (scene camera.projection): xmag is half the view's width; the
    // height follows each viewport's aspect.
    const ci = m.gltf.parser.associations.get(m.cameraObject)?.cameras;
    const cdef = ci !== undefined ? json.cameras[ci] : (json.cameras || []).find((c) => c.type === 'orthographic');
    m.orthoHalfWidth = Number(cdef?.orthographic?.xmag) || m.cameraObject.right;
    m.camera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0, 1000);
    m.cameraNote = `file camera "${json.nodes.find((n) => n.camera !== undefined)?.name || ''}", ` +
      `orthographic, width ${(2 * m.orthoHalfWidth).toPrecision(4)}`;
  } else if (m.cameraObject) {
    const ci = m.gltf.parser.associations.get(m.cameraObject)?.cameras;
    const cdef = ci !== undefined ? json.cameras[ci] : (json.cameras || []).find((c) => c.type === 'perspective');
    m.fileAspect = Number(cdef?.perspective?.aspectRatio) || null;
    m.baseFov = m.cameraObject.fov;
    m.cameraNote = `file camera "${json.nodes.find((n) => n.camera !== undefined)?.name || ''}", ` +
      `yfov ${m.cameraObject.fov.toFixed(1)}°${m.fileAspect ? `, aspect ${m.fileAspect.toFixed(3)}` : ''}`;
  }
  scene.add(m.camera);
  // headlight: follows the camera
  const light = new THREE.DirectionalLight(0xffffff, 2.2);
  light.position.set(0.4, 0.8, 0);
  light.target.position.set(0, 0, -1);
  m.camera.add(light, light.target);
  scene.add(new THREE.HemisphereLight(0xdde6ff, 0x303028, 1.1));

  // Doppler colours (--shade doppler): the meshes with COLOR_0 and their materials' plain colours
  m.shaded = [];
  gltf.scene.traverse((o) => {
    const base = o.material?.userData?.base_color;
    if (o.isMesh && o.geometry?.attributes?.color && Array.isArray(base)) m.shaded.push({ mesh: o, base });
  });
  // The input's own materials with COLOR_0 = W(D) c and _DOPPLER: the exact shift per fragment
  m.exact = [];
  const recovered = new Map();
  gltf.scene.traverse((o) => {
    const g = o.geometry;
    if (!o.isMesh || Array.isArray(o.material) || !g?.attributes?.color || !g.attributes._doppler) return;
    if (Array.isArray(o.material.userData?.base_color)) return;
    if (!recovered.has(g.attributes.color)) recovered.set(g.attributes.color, inputColours(g.attributes.color, g.attributes._doppler));
    g.setAttribute('color', recovered.get(g.attributes.color));
    exactShift(o.material);
    m.exact.push(o);
  });
  m.loaded = true;
  return m;
}

// The input's COLOR_0 c from the file's W(D) c (doppler.mjs), per vertex. A channel whose W is below
// kLostChannel (shifted out of the samples; W's rounding is about 1e-16) has lost c and is taken as 1.
const kLostChannel = 1e-6;
function inputColours(color, doppler) {
  const out = new Float32Array(color.count * 3);
  for (let k = 0; k < color.count; ++k) {
    const w = dopplerModulation(doppler.getX(k));
    const c = [color.getX(k), color.getY(k), color.getZ(k)];
    for (let i = 0; i < 3; ++i) out[3 * k + i] = w[i] > kLostChannel ? Math.min(1, Math.max(0, c[i] / w[i])) : 1;
  }
  return new THREE.BufferAttribute(out, 3);
}

// One set of uniforms for every material the exact shift patches; `dopplerOn` follows the toggle.
const exactUniforms = (() => {
  const v = dopplerUniformValues();
  return {
    dopplerUnmix: { value: new THREE.Matrix3().fromArray(v.dopplerUnmix) },
    dopplerCentres: { value: new THREE.Vector3(...v.dopplerCentres) },
    dopplerWidth: { value: v.dopplerWidth },
    dopplerOn: { value: 1 },
  };
})();
const patched = new WeakSet();

// The material's linear colour after texture and vertex colour (three's color_fragment) shifted by
// toneMap(A(D) colour), D interpolated from the vertices' _DOPPLER.
function exactShift(material) {
  if (patched.has(material)) return;
  patched.add(material);
  material.onBeforeCompile = (shader) => {
    Object.assign(shader.uniforms, exactUniforms);
    shader.vertexShader = shader.vertexShader
      .replace('#include <common>', '#include <common>\nattribute float _doppler;\nvarying float vDoppler;')
      .replace('#include <begin_vertex>', '#include <begin_vertex>\nvDoppler = _doppler;');
    shader.fragmentShader = shader.fragmentShader
      .replace('#include <common>', `#include <common>\nvarying float vDoppler;\nuniform float dopplerOn;\n${DOPPLER_GLSL}`)
      .replace('#include <color_fragment>',
        '#include <color_fragment>\nif (dopplerOn > 0.5) diffuseColor.rgb = dopplerShift(diffuseColor.rgb, vDoppler);');
  };
  material.customProgramCacheKey = () => 'apparent-doppler-exact';
  material.needsUpdate = true;
}

// 'doppler': COLOR_0 times a white material; 'plain': the material's extras.base_color without COLOR_0.
function applyShade() {
  exactUniforms.dopplerOn.value = shade === 'doppler' ? 1 : 0;
  for (const m of models) {
    if (!m.loaded) continue;
    for (const { mesh, base } of m.shaded) {
      const doppler = shade === 'doppler';
      mesh.material.vertexColors = doppler;
      if (doppler) mesh.material.color.setRGB(1, 1, 1, THREE.LinearSRGBColorSpace);
      else mesh.material.color.setRGB(base[0], base[1], base[2], THREE.LinearSRGBColorSpace);
      mesh.material.needsUpdate = true;
    }
  }
}

function setShade(s) {
  if (s !== 'plain' && s !== 'doppler') throw new Error(`setShade: 'plain' or 'doppler', not ${s}`);
  shade = s;
  dopplerBox.checked = shade === 'doppler';
  applyShade();
  render();
  return shade;
}

// World-space box of all frames' content at rest scale (frames are hidden by a zero scale most of the time).
function contentBox(m) {
  const box = new THREE.Box3();
  const one = new THREE.Vector3(1, 1, 1);
  m.gltf.scene.updateMatrixWorld(true);
  for (const f of m.frames) {
    f.object.traverse((o) => {
      if (!o.isMesh) return;
      if (!o.geometry.boundingBox) o.geometry.computeBoundingBox();
      const local = new THREE.Matrix4().compose(f.object.position, f.object.quaternion, one);
      if (f.object.parent) local.premultiply(f.object.parent.matrixWorld);
      // o may be a child primitive of f.object
      const rel = new THREE.Matrix4();
      for (let p = o; p && p !== f.object; p = p.parent) rel.premultiply(p.matrix);
      const b = o.geometry.boundingBox.clone().applyMatrix4(local.multiply(rel));
      box.union(b);
    });
  }
  return box;
}

// Shared default camera for all models without a camera node: the observer at the origin looking down -Z
// with a 60 degree vertical fov (the apparent shape is only correct from there). If the content is outside
// that view cone, turn to face its centre. Near/far planes are fitted to the content.
function setupDefaultCameras() {
  const need = models.filter((m) => m.loaded && !m.cameraObject);
  if (!need.length) return;
  const box = new THREE.Box3();
  for (const m of need) box.union(contentBox(m));
  const dirv = new THREE.Vector3(0, 0, -1);
  let note = 'origin, -Z';
  if (!box.isEmpty()) {
    const c = box.getCenter(new THREE.Vector3());
    if (c.lengthSq() > 0 && c.clone().normalize().angleTo(dirv) > THREE.MathUtils.degToRad(DEFAULT_FOV / 2)) {
      dirv.copy(c).normalize();
      note = 'origin, facing content';
    }
  }
  let near = 0.01, far = 1000;
  if (!box.isEmpty()) {
    const corners = [];
    for (let i = 0; i < 8; ++i) {
      corners.push(new THREE.Vector3(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y,
        i & 4 ? box.max.z : box.min.z));
    }
    const maxDist = Math.max(...corners.map((p) => p.length()));
    const minDepth = Math.min(...corners.map((p) => p.dot(dirv)));
    far = Math.max(1, maxDist * 2);
    near = minDepth > 0 ? Math.max(minDepth * 0.5, far * 1e-5) : far * 1e-4;
  }
  for (const m of need) {
    m.camera.position.set(0, 0, 0);
    m.camera.up.set(0, 1, 0);
    m.camera.lookAt(dirv);
    m.camera.fov = DEFAULT_FOV;
    m.baseFov = DEFAULT_FOV;
    m.camera.near = near;
    m.camera.far = far;
    m.cameraNote = `default camera: ${note}, yfov ${DEFAULT_FOV}°`;
  }
}

// ---------------------------------------------------------------- time and rendering
function applyTime(t) {
  for (const m of models) {
    if (!m.loaded) continue;
    if (m.action) {
      m.action.reset();
      m.action.play();
      m.mixer.setTime(Math.max(0, t));
    }
    m.scene.updateMatrixWorld(true);
  }
}

function visibleOf(m) {
  if (!m.loaded) return [];
  return m.frames.filter((f) => isShown(f.object)).map((f) => ({ name: f.name, vertices: f.vertices,
    reflected: f.children.filter((c) => isShown(c.object)).reduce((n, c) => n + c.vertices, 0) }));
}

function shownBounds(m) {
  if (!m.loaded) return null;
  const box = new THREE.Box3(), v = new THREE.Vector3();
  let vertices = 0;
  for (const f of m.frames) {
    if (!isShown(f.object)) continue;
    f.object.updateWorldMatrix(true, true);
    const visit = (o) => {
      if (o !== f.object && m.parser.associations.get(o)?.nodes !== undefined) return; // a reflection node
      if (o.isMesh && o.geometry?.attributes?.position) {
        const n = o.geometry.attributes.position.count;
        for (let i = 0; i < n; ++i) box.expandByPoint(o.getVertexPosition(i, v).applyMatrix4(o.matrixWorld));
        vertices += n;
      }
      for (const c of o.children) visit(c);
    };
    visit(f.object);
  }
  return vertices ? { min: box.min.toArray(), max: box.max.toArray(), vertices } : null;
}

function frameIndexAt(m, t) {
  if (!m.frames.length || !m.fps) return -1;
  return Math.min(m.frames.length - 1, Math.max(0, Math.floor(t * m.fps + 1e-9)));
}

function updateLabels() {
  for (const m of models) {
    if (!m.loaded) continue;
    const vis = visibleOf(m);
    const k = frameIndexAt(m, time);
    const camT = k >= 0 && m.frameTimes[k] !== undefined ? ` · camera t ${timeText(Number(m.frameTimes[k]))}` : '';
    const shown = vis.length ? vis.map((v) => `${v.name} · ${v.vertices} vertices` +
      (v.reflected ? ` + ${v.reflected} in mirrors` : '')).join(', ') : 'empty frame';
    m.sub.textContent = `${shown}${camT}`;
    m.label.title = `${m.url}\n${m.cameraNote || ''}${zoom !== 1 ? `\nzoom ${zoom.toFixed(2)}×` : ''}`;
  }
  timeEl.textContent = `t = ${timeText(time + cameraStart)} · ${timeText(time)} / ${timeText(maxDuration)}` +
    (zoom !== 1 ? ` · zoom ${zoom.toFixed(2)}×` : '');
  slider.value = String(time);
}

// Lay the viewports out side by side, filling the stage (with ?aspect: all of that aspect ratio, as large as the
// stage allows).
function layout() {
  const n = models.length;
  if (!n) return;
  const cs = getComputedStyle(viewsEl);
  const padX = parseFloat(cs.paddingLeft) + parseFloat(cs.paddingRight);
  const padY = parseFloat(cs.paddingTop) + parseFloat(cs.paddingBottom);
  const gap = parseFloat(cs.columnGap) || 0;
  const labelH = models[0].label.offsetHeight;
  let w = Math.floor((viewsEl.clientWidth - padX - gap * (n - 1)) / n);
  const maxH = Math.max(1, Math.floor(viewsEl.clientHeight - padY - labelH));
  let h = aspectParam ? Math.floor(w / aspect) : maxH;
  if (h > maxH) { h = maxH; w = Math.max(1, Math.floor(h * aspect)); }
  for (const m of models) {
    m.view.style.width = `${w}px`;
    m.slot.style.height = `${h}px`;
  }
}

function resize() {
  layout();
  const w = stage.clientWidth, h = stage.clientHeight;
  const pr = renderer.getPixelRatio();
  if (canvas.width !== Math.floor(w * pr) || canvas.height !== Math.floor(h * pr)) renderer.setSize(w, h, false);
}

const _pos = new THREE.Vector3(), _quat = new THREE.Quaternion(), _scl = new THREE.Vector3();

function render() {
  resize();
  const canvasRect = canvas.getBoundingClientRect();
  renderer.setScissorTest(false);
  renderer.setClearColor(PAGE_BG, 1);
  renderer.clear();
  renderer.setScissorTest(true);
  for (const m of models) {
    const r = m.slot.getBoundingClientRect();
    const x = r.left - canvasRect.left, y = canvasRect.bottom - r.bottom;
    if (r.width < 1 || r.height < 1) continue;
    renderer.setViewport(x, y, r.width, r.height);
    renderer.setScissor(x, y, r.width, r.height);
    if (!m.loaded) {
      renderer.setClearColor(VIEW_BG, 1);
      renderer.clear();
      continue;
    }
    const cam = m.camera;
    if (m.cameraObject) {
      m.cameraObject.updateWorldMatrix(true, false);
      m.cameraObject.matrixWorld.decompose(_pos, _quat, _scl);
      cam.position.copy(_pos);
      cam.quaternion.copy(_quat);
      cam.near = m.cameraObject.near;
      cam.far = m.cameraObject.far;
    }
    if (cam.isOrthographicCamera) {
      const hw = m.orthoHalfWidth / zoom, hh = hw * r.height / r.width;
      cam.left = -hw; cam.right = hw; cam.top = hh; cam.bottom = -hh;
    } else {
      // A viewport narrower than the file camera's aspect widens the vertical field so that the file's whole
      // horizontal field stays in view.
      const base = THREE.MathUtils.degToRad(m.baseFov || DEFAULT_FOV);
      const widen = Math.max(1, aspect / (r.width / r.height));
      cam.fov = THREE.MathUtils.radToDeg(2 * Math.atan(Math.tan(base / 2) * widen / zoom));
      cam.aspect = r.width / r.height;
    }
    cam.updateProjectionMatrix();
    renderer.render(m.scene, cam);
  }
  renderer.setScissorTest(false);
}

function setTime(t) {
  t = Number(t);
  if (!Number.isFinite(t)) throw new Error(`setTime: bad time ${t}`);
  time = Math.max(0, t);
  applyTime(time);
  updateLabels();
  render();
  return time;
}

// ---------------------------------------------------------------- controls
function setPlaying(p) {
  playing = p;
  playBtn.textContent = playing ? 'Pause' : 'Play';
  lastTick = null;
}

let lastTick = null;
function tick(now) {
  requestAnimationFrame(tick);
  if (!playing || !maxDuration) { lastTick = null; return; }
  if (lastTick === null) { lastTick = now; return; }
  const dt = (now - lastTick) / 1000 * Number(speedSel.value);
  lastTick = now;
  let t = time + dt;
  if (t > maxDuration) {
    if (loopBox.checked) t = t % maxDuration;
    else { t = maxDuration; setPlaying(false); }
  }
  setTime(t);
}

function step(dirn) {
  // move to the middle of the neighbouring frame of the model with the finest frame step
  const k = Math.floor(time / minFrameStep + 1e-6) + dirn;
  setTime(Math.min(maxDuration, Math.max(0, (k + 0.5) * minFrameStep)));
}

playBtn.addEventListener('click', () => setPlaying(!playing));
document.getElementById('prev').addEventListener('click', () => { setPlaying(false); step(-1); });
document.getElementById('next').addEventListener('click', () => { setPlaying(false); step(+1); });
slider.addEventListener('input', () => { setPlaying(false); setTime(Number(slider.value)); });
window.addEventListener('resize', () => render());
dopplerBox.addEventListener('change', () => setShade(dopplerBox.checked ? 'doppler' : 'plain'));
function setZoom(z) {
  zoom = Math.min(50, Math.max(0.2, z));
  updateLabels();
  render();
}
stage.addEventListener('wheel', (ev) => { ev.preventDefault(); setZoom(zoom * Math.exp(-ev.deltaY * 0.0015)); },
  { passive: false });
stage.addEventListener('dblclick', () => setZoom(1));
window.addEventListener('keydown', (ev) => {
  if (ev.target instanceof HTMLInputElement && ev.target.type !== 'range') return;
  if (ev.key === ' ') { ev.preventDefault(); setPlaying(!playing); }
  else if (ev.key === 'ArrowLeft') { ev.preventDefault(); setPlaying(false); step(-1); }
  else if (ev.key === 'ArrowRight') { ev.preventDefault(); setPlaying(false); step(+1); }
  else if ((ev.key === 'd' || ev.key === 'D') && !dopplerBox.disabled) setShade(shade === 'doppler' ? 'plain' : 'doppler');
  else if (ev.key === 'Home') { ev.preventDefault(); setTime(0); }
  else if (ev.key === 'End') { ev.preventDefault(); setTime(maxDuration); }
  else if (ev.key === '+' || ev.key === '=') setZoom(zoom * 1.25);
  else if (ev.key === '-') setZoom(zoom / 1.25);
  else if (ev.key === '0') setZoom(1);
});

// ---------------------------------------------------------------- start
function info() {
  return Object.fromEntries(models.map((m) => [m.name, {
    url: m.url, loaded: m.loaded, fps: m.fps, duration: m.duration, frames: m.frames.length,
    firstFrame: m.firstFrame, frameTimes: m.frameTimes.length, camera: m.cameraSource,
    fov: m.baseFov ?? null, aspect, zoom, cameraNote: m.cameraNote || null, cameraStart,
    dopplerColours: (m.shaded || []).length, dopplerExact: (m.exact || []).length, shade,
  }]));
}

function errText(e) {
  if (e instanceof Error) return e.message;
  if (e && typeof e === 'object') return String(e.error || e.message || JSON.stringify(e));
  return String(e);
}

const ready = (async () => {
  if (!models.length) throw new Error('no models given (?models=a,b,c)');
  render();   // empty viewports while loading
  const results = await Promise.allSettled(models.map(loadModel));
  const failed = results.map((r, i) => [r, models[i]]).filter(([r]) => r.status === 'rejected');
  for (const [r, m] of failed) {
    m.sub.textContent = `failed: ${errText(r.reason)}`;
  }
  setupDefaultCameras();
  if (!aspectParam) aspect = models.find((m) => m.fileAspect)?.fileAspect || DEFAULT_ASPECT;
  const ok = models.filter((m) => m.loaded);
  maxDuration = Math.max(0, ...ok.map((m) => m.duration));
  const steps = ok.filter((m) => m.fps > 0).map((m) => 1 / m.fps);
  minFrameStep = steps.length ? Math.min(...steps) : 0.1;
  slider.max = String(maxDuration || 1);
  dopplerBox.disabled = !ok.some((m) => m.shaded.length || m.exact.length);
  dopplerBox.checked = shade === 'doppler';
  applyShade();
  // ?t: camera time; outside the files' camera times but inside the animation, the old animation time.
  const timed = ok.find((m) => m.frameTimes.length);
  if (timed) cameraStart = Number(timed.frameTimes[0]);
  const largest = ok.reduce((a, m) => m.frameTimes.reduce((b, x) => Math.max(b, Math.abs(Number(x))), a), 0);
  if (largest > 0 && largest < 1) {
    timeUnit = largest >= 1e-3 ? { name: 'ms', seconds: 1e-3 } : largest >= 1e-6 ? { name: 'us', seconds: 1e-6 }
      : { name: 'ns', seconds: 1e-9 };
  }
  const cameraEnd = cameraStart + maxDuration;
  const oldLink = timed && (initialTime < cameraStart || initialTime > cameraEnd) && initialTime >= 0 &&
    initialTime <= maxDuration;
  setTime(Math.min(Math.max(0, oldLink ? initialTime : initialTime - cameraStart), maxDuration));
  setPlaying(playing);
  requestAnimationFrame(tick);
  if (failed.length) {
    const msg = failed.map(([r, m]) => `${m.name}: ${errText(r.reason)} (${m.url})`).join('\n');
    setStatus(`could not load:\n${msg}`, true);
    throw new Error(`could not load ${msg}`);
  }
  const gl = renderer.getContext();
  const dbg = gl.getExtension('WEBGL_debug_renderer_info');
  const glName = dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
  setStatus(`${dir}: ${ok.map((m) => `${m.name} (${m.frames.length} frames @ ${+m.fps.toFixed(3)} fps)`).join(', ')}` +
    ` · duration ${timeText(maxDuration)} · ${models[0].cameraNote || ''}\n` +
    `Space play/pause · ←/→ step · wheel or +/- zoom, 0 or double-click reset · ${glName}`);
  return info();
})();
ready.catch((e) => { if (!statusEl.classList.contains('error')) setStatus(String(e?.message || e), true); });

window.apparentViewer = {
  ready,
  models: modelNames.slice(),
  background: VIEW_BG,
  setTime,
  setZoom,
  // 'plain' or 'doppler' (files with COLOR_0 from --shade doppler); returns the shade now in use
  setShade,
  getTime: () => time,
  // camera time of the current animation time (?t reads it)
  getCameraTime: () => time + cameraStart,
  play: () => setPlaying(true),
  pause: () => setPlaying(false),
  isPlaying: () => playing,
  get duration() { return maxDuration; },
  render,
  info,
  // { model: [{ name: 'frame_00100', vertices: 16, reflected: 40 }, ...] } for the frame nodes shown right now
  // (reflected: the vertices of its reflection child nodes shown with it)
  visibleFrames: () => Object.fromEntries(models.map((m) => [m.name, visibleOf(m)])),
  // { model: { min: [x, y, z], max: [x, y, z], vertices } } world-space bounds of the frame nodes shown right now (their
  // own meshes, morph targets applied as three.js draws them: Mesh.getVertexPosition), or null when none is shown
  frameBounds: () => Object.fromEntries(models.map((m) => [m.name, shownBounds(m)])),
  // { model: {x, y, width, height} } CSS pixels of each model's drawing area, relative to the page viewport
  viewports: () => Object.fromEntries(models.map((m) => {
    const r = m.slot.getBoundingClientRect();
    return [m.name, { x: r.left, y: r.top, width: r.width, height: r.height }];
  })),
};
