// Runs the Khronos glTF-Validator over every .gltf/.glb under the given folders and fails
// when any file has an error or a warning. Usage: node validate-gltf.js DIR...
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

function walk(dir, out) {
  for (const e of fs.readdirSync(dir, { withFileTypes: true })) {
    const p = path.join(dir, e.name);
    if (e.isDirectory()) walk(p, out);
    else if (/\.(gltf|glb)$/i.test(e.name)) out.push(p);
  }
  return out;
}

async function main() {
  const files = process.argv.slice(2).flatMap((d) => (fs.existsSync(d) ? walk(d, []) : []));
  if (files.length === 0) {
    console.error('validate-gltf: no glTF files found under', process.argv.slice(2).join(' '));
    process.exit(1);
  }
  let bad = 0;
  for (const f of files.sort()) {
    const dir = path.dirname(f);
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(f)), {
      uri: path.basename(f),
      maxIssues: 50,
      externalResourceFunction: (uri) =>
        new Promise((resolve, reject) => {
          fs.readFile(path.join(dir, decodeURIComponent(uri)), (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
        }),
    });
    const { numErrors, numWarnings } = report.issues;
    if (numErrors > 0 || numWarnings > 0) {
      bad++;
      console.log(`FAIL ${f}: ${numErrors} errors, ${numWarnings} warnings`);
      for (const m of report.issues.messages.filter((m) => m.severity <= 1)) {
        console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer || ''}: ${m.message}`);
      }
    } else {
      console.log(`ok   ${f}`);
    }
  }
  console.log(`glTF-Validator: ${files.length - bad} passed, ${bad} failed`);
  process.exit(bad > 0 ? 1 : 0);
}

main().catch((e) => {
  console.error('validate-gltf:', e);
  process.exit(1);
});
