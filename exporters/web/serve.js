#!/usr/bin/env node
// Minimal static file server for the apparent web viewer. No dependencies (node:http only).
//
//   node exporters/web/serve.js [--root DIR] [--port N] [--mount /out=DIR ...]
//
// - Binds 127.0.0.1 only. Default port 8080 (--port 0 picks a free port). Default root: the repository root.
// - --mount PREFIX=DIR serves DIR under the URL prefix PREFIX (e.g. --mount /out=/tmp/webtest); repeatable.
// - Refuses any path that escapes its root (also through symlinks), serves GET/HEAD only, sends no-store.
// Also usable as a module: const { startServer } = require('./serve.js').
'use strict';

const http = require('node:http');
const fs = require('node:fs');
const path = require('node:path');

const MIME = {
  '.html': 'text/html; charset=utf-8',
  '.htm': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json; charset=utf-8',
  '.map': 'application/json; charset=utf-8',
  '.md': 'text/plain; charset=utf-8',
  '.txt': 'text/plain; charset=utf-8',
  '.glb': 'model/gltf-binary',
  '.gltf': 'model/gltf+json',
  '.bin': 'application/octet-stream',
  '.wasm': 'application/wasm',
  '.png': 'image/png',
  '.jpg': 'image/jpeg',
  '.jpeg': 'image/jpeg',
  '.svg': 'image/svg+xml',
  '.ico': 'image/x-icon',
};

function mimeType(file) {
  return MIME[path.extname(file).toLowerCase()] || 'application/octet-stream';
}

// Normalise a URL prefix to "/name" form without a trailing slash ("" for the root).
function normPrefix(p) {
  let s = '/' + String(p).replace(/^\/+|\/+$/g, '');
  return s === '/' ? '' : s;
}

function isInside(dir, p) {
  return p === dir || p.startsWith(dir.endsWith(path.sep) ? dir : dir + path.sep);
}

// mounts: [{prefix: '/out', dir: '/tmp/x'}]; root is mounted at ''. Longest prefix wins.
function makeHandler({ root, mounts = [], log = null }) {
  const table = [{ prefix: '', dir: root }, ...mounts]
    .map((m) => ({ prefix: normPrefix(m.prefix), dir: fs.realpathSync(path.resolve(m.dir)) }))
    .sort((a, b) => b.prefix.length - a.prefix.length);

  function send(res, code, msg, headers = {}) {
    res.writeHead(code, { 'Content-Type': 'text/plain; charset=utf-8', 'Cache-Control': 'no-store', ...headers });
    res.end(msg + '\n');
  }

  return function handler(req, res) {
    const done = (code) => { if (log) log(`${code} ${req.method} ${req.url}`); };
    if (req.method !== 'GET' && req.method !== 'HEAD') {
      done(405); return send(res, 405, 'method not allowed', { Allow: 'GET, HEAD' });
    }
    let pathname;
    try {
      pathname = decodeURIComponent(new URL(req.url, 'http://127.0.0.1').pathname);
    } catch {
      done(400); return send(res, 400, 'bad request');
    }
    if (pathname.includes('\0') || pathname.includes('\\')) { done(400); return send(res, 400, 'bad request'); }

    const m = table.find((t) => t.prefix === '' || pathname === t.prefix || pathname.startsWith(t.prefix + '/'));
    const rel = pathname.slice(m.prefix.length);
    // Reject any ".." segment outright, then double-check the resolved (and symlink-resolved) path.
    if (rel.split('/').some((seg) => seg === '..')) { done(403); return send(res, 403, 'forbidden'); }
    let file = path.resolve(m.dir, '.' + (rel || '/'));
    if (!isInside(m.dir, file)) { done(403); return send(res, 403, 'forbidden'); }

    fs.realpath(file, (err, real) => {
      if (err) { done(404); return send(res, 404, 'not found'); }
      if (!isInside(m.dir, real)) { done(403); return send(res, 403, 'forbidden'); }
      fs.stat(real, (err2, st) => {
        if (err2) { done(404); return send(res, 404, 'not found'); }
        if (st.isDirectory()) {
          if (!pathname.endsWith('/')) {
            done(301);
            const u = new URL(req.url, 'http://127.0.0.1');
            return send(res, 301, 'moved', { Location: u.pathname + '/' + u.search });
          }
          real = path.join(real, 'index.html');
          try { st = fs.statSync(real); } catch { done(404); return send(res, 404, 'not found'); }
          if (!st.isFile()) { done(404); return send(res, 404, 'not found'); }
        } else if (!st.isFile()) {
          done(404); return send(res, 404, 'not found');
        }
        res.writeHead(200, {
          'Content-Type': mimeType(real),
          'Content-Length': st.size,
          'Cache-Control': 'no-store',
          'X-Content-Type-Options': 'nosniff',
        });
        done(200);
        if (req.method === 'HEAD') return res.end();
        const stream = fs.createReadStream(real);
        stream.on('error', () => res.destroy());
        stream.pipe(res);
      });
    });
  };
}

// Starts the server; resolves to { server, port, url }. port 0 = any free port.
function startServer({ root = path.resolve(__dirname, '..', '..'), port = 8080, mounts = [], log = null } = {}) {
  const server = http.createServer(makeHandler({ root, mounts, log }));
  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(port, '127.0.0.1', () => {
      const p = server.address().port;
      resolve({ server, port: p, url: `http://127.0.0.1:${p}` });
    });
  });
}

function parseArgs(argv) {
  const opts = { root: path.resolve(__dirname, '..', '..'), port: 8080, mounts: [], quiet: false };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    const val = () => {
      if (i + 1 >= argv.length) throw new Error(`${a} needs a value`);
      return argv[++i];
    };
    if (a === '--root') opts.root = path.resolve(val());
    else if (a === '--port') {
      const v = val();
      if (!/^\d+$/.test(v) || Number(v) > 65535) throw new Error(`bad port: ${v}`);
      opts.port = Number(v);
    } else if (a === '--mount') {
      const v = val();
      const eq = v.indexOf('=');
      if (eq <= 0) throw new Error(`--mount wants PREFIX=DIR, got ${v}`);
      opts.mounts.push({ prefix: v.slice(0, eq), dir: path.resolve(v.slice(eq + 1)) });
    } else if (a === '--quiet' || a === '-q') opts.quiet = true;
    else if (a === '--help' || a === '-h') {
      console.log('usage: node exporters/web/serve.js [--root DIR] [--port N] [--mount /PREFIX=DIR]... [--quiet]');
      process.exit(0);
    } else throw new Error(`unknown argument: ${a}`);
  }
  return opts;
}

if (require.main === module) {
  let opts;
  try {
    opts = parseArgs(process.argv.slice(2));
    for (const d of [opts.root, ...opts.mounts.map((m) => m.dir)]) {
      if (!fs.statSync(d).isDirectory()) throw new Error(`not a directory: ${d}`);
    }
  } catch (e) {
    console.error(`serve.js: ${e.message}`);
    process.exit(2);
  }
  startServer({ ...opts, log: opts.quiet ? null : (s) => console.log(s) }).then(({ url }) => {
    console.log(`serving ${opts.root} at ${url}/`);
    for (const m of opts.mounts) console.log(`  ${normPrefix(m.prefix)}/ -> ${m.dir}`);
    console.log(`viewer: ${url}/exporters/web/?dir=/out`);
  }, (e) => {
    console.error(`serve.js: ${e.message}`);
    process.exit(1);
  });
}

module.exports = { startServer, makeHandler, mimeType, parseArgs };
