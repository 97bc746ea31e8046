// Re-measures preview's mip and specular-antialiasing figures in a renderer nobody here wrote:
// three.js (its GLTFLoader, KTX2Loader, MeshStandardMaterial and filtering) in headless Chromium.
//
//   node tools/threejs/measure.mjs --truth PNG.glb [--size 128] [--ssaa 16] \
//       --distance 4 --distance 8 NAME=FILE.glb ...
//
// The truth is the PNG file drawn from its level-0 texels only, supersampled ssaa x ssaa per pixel.
// Every NAME=FILE is drawn at one sample per pixel with three.js's defaults (trilinear; its own
// box mips for PNG, the file's levels for KTX2) and compared with the truth over the pixels the
// object covers: mean luminance ratio and PSNR (radiance clamped to [0, 1], peak 1).
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import puppeteer from 'puppeteer-core';

const here = path.dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const opt = { size: 128, ssaa: 16, distances: [], files: [], fov: 30, pitch: 35, truth: null, light: [0.3, 1, 0.6], intensity: 3, ambient: 0.05, anisotropy: 1 };
for (let i = 0; i < args.length; i++) {
  const a = args[i];
  const next = () => args[++i];
  if (a === '--truth') opt.truth = path.resolve(next());
  else if (a === '--size') opt.size = +next();
  else if (a === '--ssaa') opt.ssaa = +next();
  else if (a === '--distance') opt.distances.push(+next());
  else if (a === '--fov') opt.fov = +next();
  else if (a === '--pitch') opt.pitch = +next();
  else if (a === '--light') opt.light = next().split(',').map(Number);
  else if (a === '--intensity') opt.intensity = +next();
  else if (a === '--json') opt.json = next();
  else if (a === '--anisotropy') opt.anisotropy = +next();
  else if (a.includes('=')) {
    const [name, file] = a.split('=');
    opt.files.push({ name, file: path.resolve(file) });
  } else {
    console.error(`measure.mjs: unknown argument ${a}`);
    process.exit(2);
  }
}
if (!opt.truth || opt.distances.length === 0 || opt.files.length === 0) {
  console.error('measure.mjs: give --truth FILE, at least one --distance and NAME=FILE');
  process.exit(2);
}

// Files are served by number so that any path on disk can be loaded, with the glTF's own
// relative URIs resolved beside it.
const served = [opt.truth, ...opt.files.map((f) => f.file)];
const types = { '.js': 'text/javascript', '.mjs': 'text/javascript', '.wasm': 'application/wasm', '.html': 'text/html' };
const server = http.createServer((req, res) => {
  const url = decodeURIComponent(req.url.split('?')[0]);
  let file = null;
  if (url === '/') file = path.join(here, 'page.html');
  else if (url === '/page.js') file = path.join(here, 'page.js');
  else if (url.startsWith('/three/')) file = path.join(here, 'node_modules', url);
  else {
    const m = url.match(/^\/f(\d+)\/(.*)$/);
    if (m && served[+m[1]]) file = path.join(path.dirname(served[+m[1]]), m[2]);
  }
  if (!file || !fs.existsSync(file)) {
    res.writeHead(404).end();
    return;
  }
  res.writeHead(200, { 'content-type': types[path.extname(file)] || 'application/octet-stream' });
  fs.createReadStream(file).pipe(res);
});
await new Promise((r) => server.listen(0, '127.0.0.1', r));
const base = `http://127.0.0.1:${server.address().port}`;

const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--disable-gpu-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic'],
});
const page = await browser.newPage();
page.on('console', (m) => { if (m.type() === 'error') console.error('page:', m.text()); });
page.on('pageerror', (e) => console.error('page error:', e.message));
await page.goto(base + '/');
await page.waitForFunction('window.ready === true', { timeout: 60000 });

const url = (k) => `${base}/f${k}/${path.basename(served[k])}`;
const render = (k, distance, truth) => {
  const p = (opt.pitch * Math.PI) / 180;
  const eye = [0, distance * Math.sin(p), distance * Math.cos(p)];
  return page.evaluate((cfg) => window.renderView(cfg), {
    url: url(k), truth, size: opt.size, ssaa: truth ? opt.ssaa : 1, fov: opt.fov, distance, eye, target: [0, 0, 0],
    light: { dir: opt.light, intensity: opt.intensity }, ambient: opt.ambient, anisotropy: opt.anisotropy,
  });
};

function compare(img, ref) {
  let sumA = 0, sumB = 0, se = 0, n = 0;
  for (let i = 0; i < ref.length; i += 2) {
    if (ref[i + 1] < 0.999 || img[i + 1] < 0.999) continue;
    const a = img[i], b = ref[i];
    sumA += a; sumB += b;
    const d = Math.min(Math.max(a, 0), 1) - Math.min(Math.max(b, 0), 1);
    se += d * d; n++;
  }
  const mse = se / Math.max(n, 1);
  return { pixels: n, brightness: sumA / sumB, psnr_db: mse > 0 ? 10 * Math.log10(1 / mse) : Infinity };
}

const rows = [];
for (const d of opt.distances) {
  const truth = await render(0, d, true);
  for (let k = 0; k < opt.files.length; k++) {
    const r = await render(k + 1, d, false);
    const c = compare(r.pixels, truth.pixels);
    rows.push({ distance: d, name: opt.files[k].name, ...c, textures: r.textures });
    console.log(`${String(d).padStart(6)}  ${opt.files[k].name.padEnd(14)} brightness ${(100 * (c.brightness - 1)).toFixed(1).padStart(6)} %  PSNR ${c.psnr_db.toFixed(2)} dB  (${c.pixels} px; ${r.textures.map((t) => `${t.key} ${t.compressed ? 'KTX2' : 'PNG'} ${t.levels} levels`).join(', ')})`);
  }
}
if (opt.json) fs.writeFileSync(opt.json, JSON.stringify({ options: { ...opt, files: opt.files.map((f) => f.name) }, rows }, null, 2) + '\n');
await browser.close();
server.close();
