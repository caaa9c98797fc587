// Validates .glb files with the Khronos glTF-Validator; prints errors, warnings and the first
// messages per file; exit 1 when any file has an error.
// Usage: (cd bench/peers/gltf && npm install) && node bench/peers/gltf/validate.js FILE.glb...
'use strict';
const fs = require('fs');
const validator = require('gltf-validator');

(async () => {
  let failed = false;
  for (const file of process.argv.slice(2)) {
    const r = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    const i = r.issues;
    console.log(`${file}: ${i.numErrors} error(s), ${i.numWarnings} warning(s), ${i.numInfos} info(s), ` +
      `${r.info.animationCount} animation(s), ${r.info.totalTriangleCount} triangles`);
    for (const m of i.messages.slice(0, 10)) console.log(`  ${m.code} ${m.pointer || ''}: ${m.message}`);
    failed = failed || i.numErrors > 0;
  }
  process.exit(failed ? 1 : 0);
})();
