// The second reader of the KTX2 files the tests wrote: ktx-parse (pinned in package-lock.json),
// the container parser three.js's KTX2Loader and glTF-Transform use. It reads the files
// tests/ktx2_reference.rs left with manifest.json, and must find what bumpbake's reader found:
// the level count, level 0's size, the supercompression scheme, a Basis Universal payload
// (vkFormat 0) and, for UASTC, each level's inflated length (16 bytes per 4x4 block of the level's
// size as KTX2 sizes levels).
import { read } from 'ktx-parse';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';

const dir = process.argv[2];
const manifest = JSON.parse(readFileSync(join(dir, 'manifest.json'), 'utf8'));
let failed = 0;
let levels = 0;
for (const entry of manifest) {
  const problems = [];
  let c;
  try {
    c = read(new Uint8Array(readFileSync(join(dir, entry.file))));
  } catch (e) {
    problems.push(`ktx-parse cannot read it: ${e.message}`);
  }
  if (c) {
    const want = entry.levels;
    if (c.levels.length !== want.length) problems.push(`${c.levels.length} levels, bumpbake reads ${want.length}`);
    if (c.pixelWidth !== want[0][0] || c.pixelHeight !== want[0][1]) {
      problems.push(`level 0 is ${c.pixelWidth}x${c.pixelHeight}, bumpbake reads ${want[0][0]}x${want[0][1]}`);
    }
    if (c.vkFormat !== 0) problems.push(`vkFormat ${c.vkFormat}, not a Basis Universal payload`);
    if (c.supercompressionScheme !== entry.supercompression) {
      problems.push(`supercompression ${c.supercompressionScheme}, bumpbake reads ${entry.supercompression}`);
    }
    c.levels.forEach((level, k) => {
      if (level.levelData.byteLength === 0) problems.push(`level ${k} is empty`);
      if (entry.codec === 'ASTC_RGBA' && k < want.length) {
        const [w, h] = want[k];
        const blocks = Math.ceil(w / 4) * Math.ceil(h / 4) * 16;
        if (level.uncompressedByteLength !== blocks) {
          problems.push(`level ${k} inflates to ${level.uncompressedByteLength} bytes where ${w}x${h} UASTC needs ${blocks}`);
        }
      }
    });
    levels += c.levels.length;
  }
  if (problems.length) {
    failed += 1;
    console.error(`${entry.name}: ${problems.join('; ')}`);
  }
}
console.log(`ktx-parse read ${manifest.length - failed} of ${manifest.length} KTX2 files (${levels} levels) as bumpbake does`);
if (failed || manifest.length === 0) process.exit(1);
