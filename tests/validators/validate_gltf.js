// Runs the Khronos glTF-Validator (npm gltf-validator) on each file given and prints its verdict.
// Exit status: 0 when every file has 0 errors and 0 warnings, 1 otherwise, 2 on usage errors.
// Infos and hints are printed but do not fail (Draco payloads, for instance, are reported as INFO).
'use strict';
const fs = require('fs');
const path = require('path');
let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.error('gltf-validator is not installed: run scripts/setup.sh test (npm install)');
  process.exit(2);
}

async function main(files) {
  if (files.length === 0) {
    console.error('usage: node validate_gltf.js FILE.glb...');
    return 2;
  }
  let failed = 0;
  for (const f of files) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(f)), {
      uri: path.basename(f),
      maxIssues: 0,  // unlimited: a truncated list could hide errors behind Draco's infos
      externalResourceFunction: (uri) =>
        fs.promises.readFile(path.resolve(path.dirname(f), decodeURIComponent(uri))),
    });
    const i = report.issues;
    console.log(`${f}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ` +
                `${i.numHints} hints (glTF-Validator ${validator.version()}; ` +
                (report.info ? `${report.info.animationCount} animations, ${report.info.totalVertexCount} vertices)` : 'no info)'));
    for (const m of i.messages) {
      if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'ERROR' : 'WARNING'} ${m.code} ${m.pointer || ''}: ${m.message}`);
    }
    if (i.numErrors > 0 || i.numWarnings > 0) failed++;
  }
  return failed ? 1 : 0;
}

main(process.argv.slice(2)).then((code) => process.exit(code), (e) => {
  console.error(e);
  process.exit(1);
});
