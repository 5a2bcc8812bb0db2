// Validates glTF / GLB files with the Khronos glTF validator (the pinned npm package beside this
// file) and prints one JSON summary line per file: file, errors, warnings, infos, hints and the
// messages of every issue. Exits 1 if any file has an error or a warning, 2 on bad usage.
// Usage: node tools/gltf-validator/validate.js FILE...
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function main(files) {
  if (files.length === 0) {
    console.error('usage: node validate.js FILE.glb...');
    return 2;
  }
  let bad = false;
  for (const file of files) {
    const bytes = new Uint8Array(fs.readFileSync(file));
    const report = await validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues: 100,
      externalResourceFunction: (uri) => Promise.reject(`external resource ${uri}: not allowed`),
    });
    const i = report.issues;
    const messages = i.messages.map((m) => `${m.code} (severity ${m.severity}) at ${m.pointer || '-'}: ${m.message}`);
    console.log(JSON.stringify({
      file,
      validator: report.validatorVersion,
      errors: i.numErrors,
      warnings: i.numWarnings,
      infos: i.numInfos,
      hints: i.numHints,
      messages,
      extensionsUsed: (report.info && report.info.extensionsUsed) || [],
    }));
    if (i.numErrors > 0 || i.numWarnings > 0) bad = true;
  }
  return bad ? 1 : 0;
}

main(process.argv.slice(2)).then((code) => process.exit(code), (e) => {
  console.error(`gltf-validator failed: ${e}`);
  process.exit(2);
});
