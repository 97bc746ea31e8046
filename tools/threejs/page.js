// Runs in the browser: renders one glTF with three.js's own loaders, filters and shading, and
// hands the linear radiance back to measure.mjs.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { KTX2Loader } from 'three/addons/loaders/KTX2Loader.js';

const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
renderer.toneMapping = THREE.NoToneMapping;
const ktx2 = new KTX2Loader().setTranscoderPath('/three/examples/jsm/libs/basis/').detectSupport(renderer);
const gltfLoader = new GLTFLoader().setKTX2Loader(ktx2);

// `truth`: every texture sampled from its full-resolution level only (no mips); the caller
// supersamples. Otherwise three.js's defaults: trilinear, its own box mips for PNG, the file's
// levels for KTX2.
function levelZeroOnly(root) {
  root.traverse((o) => {
    if (!o.isMesh) return;
    for (const key of ['map', 'normalMap', 'roughnessMap', 'metalnessMap', 'aoMap']) {
      const t = o.material[key];
      if (!t) continue;
      t.minFilter = THREE.LinearFilter;
      t.generateMipmaps = false;
      t.needsUpdate = true;
    }
  });
}

window.renderView = async (cfg) => {
  const gltf = await gltfLoader.loadAsync(cfg.url);
  if (cfg.truth) levelZeroOnly(gltf.scene);
  // `--anisotropy N` (default 1, three.js's): every texture filtered anisotropically, up to what
  // the context allows.
  else if (cfg.anisotropy > 1) {
    const n = Math.min(cfg.anisotropy, renderer.capabilities.getMaxAnisotropy());
    gltf.scene.traverse((o) => {
      if (!o.isMesh) return;
      for (const key of ['normalMap', 'roughnessMap', 'metalnessMap']) if (o.material[key]) o.material[key].anisotropy = n;
    });
  }
  const scene = new THREE.Scene();
  scene.add(gltf.scene);
  const light = new THREE.DirectionalLight(0xffffff, cfg.light.intensity);
  light.position.set(...cfg.light.dir);
  scene.add(light);
  scene.add(new THREE.AmbientLight(0xffffff, cfg.ambient));
  const n = cfg.size * cfg.ssaa;
  const camera = new THREE.PerspectiveCamera(cfg.fov, 1, cfg.distance / 100, cfg.distance * 100);
  camera.position.set(...cfg.eye);
  camera.lookAt(...cfg.target);
  const rt = new THREE.WebGLRenderTarget(n, n, { type: THREE.FloatType, depthBuffer: true });
  renderer.setRenderTarget(rt);
  renderer.setClearColor(0x000000, 0);
  renderer.render(scene, camera);
  const px = new Float32Array(n * n * 4);
  renderer.readRenderTargetPixels(rt, 0, 0, n, n, px);
  renderer.setRenderTarget(null);
  rt.dispose();
  // Box-filter the supersamples down to size x size: linear radiance and coverage.
  const out = new Float32Array(cfg.size * cfg.size * 2);
  const s = cfg.ssaa;
  for (let y = 0; y < cfg.size; y++) {
    for (let x = 0; x < cfg.size; x++) {
      let lum = 0, cover = 0;
      for (let j = 0; j < s; j++) {
        for (let i = 0; i < s; i++) {
          const k = ((y * s + j) * n + (x * s + i)) * 4;
          lum += 0.2126 * px[k] + 0.7152 * px[k + 1] + 0.0722 * px[k + 2];
          cover += px[k + 3];
        }
      }
      out[(y * cfg.size + x) * 2] = lum / (s * s);
      out[(y * cfg.size + x) * 2 + 1] = cover / (s * s);
    }
  }
  const textures = [];
  gltf.scene.traverse((o) => {
    if (!o.isMesh) return;
    for (const key of ['normalMap', 'roughnessMap']) {
      const t = o.material[key];
      if (t) textures.push({ key, compressed: !!t.isCompressedTexture, levels: t.mipmaps ? t.mipmaps.length : 0, minFilter: t.minFilter });
    }
  });
  return { pixels: Array.from(out), textures };
};
window.ready = true;
