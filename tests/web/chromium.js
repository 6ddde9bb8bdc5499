// Launching Debian's Chromium headless for the browser checks (tests/web, tests/model_viewer), with
// the flags this machine needs (docs/DEPENDENCIES.md section 6): no sandbox as root, no
// background networking (the network is closed), WebGL through SwiftShader.
'use strict';

const CHROMIUM_ARGS = ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync', '--use-gl=angle',
  '--use-angle=swiftshader', '--enable-unsafe-swiftshader'];

// A persistent context in the fresh profile folder `profile` (Playwright refuses --user-data-dir in args).
function launchHeadless(chromium, profile, executablePath, viewport) {
  return chromium.launchPersistentContext(profile, {
    executablePath, headless: true, viewport, deviceScaleFactor: 1, timeout: 30000, args: CHROMIUM_ARGS,
  });
}

module.exports = { CHROMIUM_ARGS, launchHeadless };
