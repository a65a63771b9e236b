#!/usr/bin/env node
// Validates a .glb or .gltf file with the Khronos glTF validator and prints one JSON line:
// {"file": ..., "errors": N, "warnings": N, "infos": N, "messages": [...]}.
// Exit status: 0 when there are no errors, 1 when there are, 2 when the file cannot be read.
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const file = process.argv[2];
if (!file) {
  console.error('usage: validate.js FILE.glb');
  process.exit(2);
}
let bytes;
try {
  bytes = new Uint8Array(fs.readFileSync(file));
} catch (e) {
  console.error(`${file}: ${e.message}`);
  process.exit(2);
}
validator
  .validateBytes(bytes, {
    uri: path.basename(file),
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  })
  .then((report) => {
    const issues = report.issues;
    const messages = issues.messages
      .filter((m) => m.severity <= 1)
      .slice(0, 20)
      .map((m) => `${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer || ''}: ${m.message}`);
    console.log(JSON.stringify({file, errors: issues.numErrors, warnings: issues.numWarnings, infos: issues.numInfos, messages}));
    process.exit(issues.numErrors > 0 ? 1 : 0);
  })
  .catch((e) => {
    console.error(`${file}: the validator failed: ${e}`);
    process.exit(2);
  });
