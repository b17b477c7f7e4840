// Runs the Khronos glTF validator on each file named: node validate_gltf.js VALIDATOR_DIR FILE...
// Prints "FILE: errors E warnings W infos I" per file, then each error; exits 1 when any file
// has an error (or cannot be read), 0 otherwise. External resources resolve next to the file.
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require(process.argv[2]);

async function validate(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const dir = path.dirname(file);
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(dir, decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  });
  const i = report.issues;
  console.log(`${file}: errors ${i.numErrors} warnings ${i.numWarnings} infos ${i.numInfos} hints ${i.numHints}`);
  for (const m of i.messages)
    if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer || ''}: ${m.message}`);
  return i.numErrors;
}

(async () => {
  let errors = 0;
  for (const file of process.argv.slice(3)) {
    try {
      errors += await validate(file);
    } catch (e) {
      console.log(`${file}: cannot be validated: ${e}`);
      errors += 1;
    }
  }
  process.exit(errors > 0 ? 1 : 0);
})();
