// Runs the Khronos glTF-Validator over every .gltf/.glb under the given folders. Usage:
//   node validate-gltf.js DIR...
// An output must be no less valid than its input. A test that wrote OUT from an input that
// itself has Khronos warnings records the input beside it, in OUT.input.json:
//   { "input": "/path/to/input.gltf", "explained": { "CODE": "why the output could not avoid it" } }
// (`explained` is optional: what bumpbake's report said about a new code). Such an output fails
// on any error or warning code that neither its input has nor the record explains; every other
// output fails on any error or warning.
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

async function validate(f) {
  const dir = path.dirname(f);
  return validator.validateBytes(new Uint8Array(fs.readFileSync(f)), {
    uri: path.basename(f),
    maxIssues: 50,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(dir, decodeURIComponent(uri)), (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
      }),
  });
}

// Error and warning messages (severity 0 and 1).
const serious = (report) => report.issues.messages.filter((m) => m.severity <= 1);

async function main() {
  const files = process.argv.slice(2).flatMap((d) => (fs.existsSync(d) ? walk(d, []) : []));
  if (files.length === 0) {
    console.error('validate-gltf: no glTF files found under', process.argv.slice(2).join(' '));
    process.exit(1);
  }
  let bad = 0;
  let compared = 0;
  for (const f of files.sort()) {
    const record = `${f}.input.json`;
    let allowed = new Set();
    let from = '';
    if (fs.existsSync(record)) {
      const { input, explained = {} } = JSON.parse(fs.readFileSync(record, 'utf8'));
      const inputIssues = serious(await validate(input));
      allowed = new Set([...inputIssues.map((m) => m.code), ...Object.keys(explained)]);
      from = ` (input ${input}: ${[...allowed].sort().join(', ') || 'no issues'})`;
      compared++;
    }
    const report = await validate(f);
    const newIssues = serious(report).filter((m) => !allowed.has(m.code));
    if (newIssues.length > 0) {
      bad++;
      console.log(`FAIL ${f}: ${newIssues.length} error(s) or warning(s) its input does not have${from}`);
      for (const m of newIssues) {
        console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer || ''}: ${m.message}`);
      }
    } else {
      const kept = serious(report).length;
      console.log(`ok   ${f}${kept ? `: ${kept} issue(s), all the input's${from}` : ''}`);
    }
  }
  console.log(`${compared} output(s) compared with their inputs`);
  console.log(`glTF-Validator: ${files.length - bad} passed, ${bad} failed`);
  process.exit(bad > 0 ? 1 : 0);
}

main().catch((e) => {
  console.error('validate-gltf:', e);
  process.exit(1);
});
