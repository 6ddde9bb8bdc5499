// One frame of a scene cut by the WebAssembly module (build/web/apparent_web.js, made by
// scripts/build_web.sh) under node, written as the native program's PLY (docs/WEB.md):
//   node exporters/web/cut.mjs SCENE (--time T | --frame K) [--model M] [--tolerance X] --out frame.ply
// SCENE is a glTF scene, or a JSON scene whose meshes are glTF (the module reads no OBJ or PLY),
// given relative to the working folder (the module reads below it) or as an absolute path to a
// self-contained file (a .glb, or a .gltf whose buffers are data: URIs). --frame K takes the scene's
// frame K's camera time. Bad input: the native program's one line on stderr and exit code 2.
import { readFileSync, writeFileSync, renameSync } from 'node:fs';
import { createRequire } from 'node:module';
import { dirname, isAbsolute, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const usage = 'usage: node cut.mjs SCENE (--time T | --frame K) [--model M] [--tolerance X] --out frame.ply [--module FILE]';
const fail = (message, code = 2) => {
  process.stderr.write(`error: ${message}\n`);
  process.exit(code);
};

// Step: the command line.
const args = { model: '', tolerance: '' };
const rest = process.argv.slice(2);
for (let i = 0; i < rest.length; ++i) {
  const a = rest[i];
  const value = () => (i + 1 < rest.length ? rest[++i] : fail(`${a}: needs a value (${usage})`));
  if (a === '--time') args.time = value();
  else if (a === '--frame') args.frame = value();
  else if (a === '--model') args.model = value();
  else if (a === '--tolerance') args.tolerance = value();
  else if (a === '--out') args.out = value();
  else if (a === '--module') args.module = value();
  else if (a.startsWith('--')) fail(`${a}: unknown option (${usage})`);
  else if (args.scene === undefined) args.scene = a;
  else fail(`${a}: one scene only (${usage})`);
}
if (args.scene === undefined || args.out === undefined) fail(usage);
if ((args.time === undefined) === (args.frame === undefined)) fail(`give one of --time and --frame (${usage})`);
const number = (text, name) => {
  const v = Number(text);
  if (text.trim() === '' || !Number.isFinite(v)) fail(`${name}: '${text}' is not a finite number`);
  return v;
};

// Step: the module, the working folder mounted in its file system (so that a relative scene path
// and the mesh paths in it read as the native program reads them; the PLY names the scene's path),
// or an absolute scene path's file copied in.
const here = dirname(fileURLToPath(import.meta.url));
const modulePath = resolve(args.module ?? resolve(here, '../../build/web/apparent_web.js'));
let createApparent;
try {
  createApparent = createRequire(import.meta.url)(modulePath);
} catch (e) {
  fail(`${modulePath}: cannot load the WebAssembly module (build it with scripts/build_web.sh): ${e.message}`, 3);
}
const apparent = await createApparent();
if (isAbsolute(args.scene)) {
  let bytes;
  try {
    bytes = readFileSync(args.scene);
  } catch (e) {
    fail(`${args.scene}: cannot be read (${e.code ?? e.message})`);
  }
  apparent.FS.mkdirTree(dirname(args.scene));
  apparent.FS.writeFile(args.scene, bytes);
} else {
  apparent.FS.mkdir('/work');
  apparent.FS.mount(apparent.NODEFS, { root: process.cwd() }, '/work');
  apparent.FS.chdir('/work');
}

// Step: the scene, the frame's time, the cut and the PLY (through a temporary name).
const scene = new apparent.Scene(args.scene);
if (scene.error()) fail(scene.error());
let t;
if (args.frame !== undefined) {
  const k = number(args.frame, '--frame');
  if (!Number.isInteger(k) || k < 0 || k >= scene.frameCount())
    fail(`--frame: ${args.frame} is not a frame of the scene (0 to ${scene.frameCount() - 1})`);
  t = scene.frameTime(k);
} else {
  t = number(args.time, '--time');
}
const frame = scene.cut(t, args.model, args.tolerance);
if (frame.error()) fail(frame.error());
const temporary = `${args.out}.partial-${process.pid}`;
try {
  writeFileSync(temporary, frame.ply());
  renameSync(temporary, args.out);
} catch (e) {
  fail(`${args.out}: cannot be written (${e.code ?? e.message})`, 3);
}
frame.delete();
scene.delete();
