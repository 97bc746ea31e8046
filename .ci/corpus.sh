#!/usr/bin/env bash
# The real-world corpus: what glTF-Transform and gltfpack (pinned in .ci/package-lock.json) write
# from the fixtures, the way users run them. tests/corpus.rs runs every command on every file.
# Usage: bash .ci/corpus.sh OUT_DIR   (needs `npm ci` in .ci first)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: corpus.sh OUT_DIR}
bin=.ci/node_modules/.bin
rm -rf "$out"
mkdir -p "$out"
for src in fixtures/khronos/NormalTangentMirrorTest.glb fixtures/real/mirror_small.glb; do
  name=$(basename "$src" .glb)
  for cmd in quantize meshopt draco; do
    "$bin/gltf-transform" "$cmd" "$src" "$out/$name.$cmd.glb" >/dev/null
  done
  "$bin/gltf-transform" jpeg "$src" "$out/$name.jpeg.glb" --formats '*' >/dev/null
  "$bin/gltf-transform" webp "$src" "$out/$name.webp.glb" --formats '*' >/dev/null
  "$bin/gltfpack" -i "$src" -o "$out/$name.gltfpack.glb" >/dev/null
  "$bin/gltfpack" -i "$src" -o "$out/$name.gltfpack-c.glb" -c >/dev/null
done
ls "$out"
