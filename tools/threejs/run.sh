#!/usr/bin/env bash
# Reproduces docs/threejs-specular-aa.json: the asset (make_asset.py), baked by bumpbake with a
# PNG normal map (three.js makes its own box mips), with bumpbake's KTX2 chain alone, and with the
# chain plus specular antialiasing, at roughness 0.15 and 0.5, measured by three.js in headless
# Chromium against the supersampled level-0 truth under three lights (highlight in view, half in
# view, out of view).
#   bash tools/threejs/run.sh [BUMPBAKE] [WORKDIR] [ASSET]
# ASSET: empty (twelve waves, bake --strength 3) or noise (random bumps, --strength 4.6: the same
# mean normal length at level 3, 0.986; writes threejs-specular-aa-noise.json).
# PITCH (environment, default 35): the camera's angle above the plane; the first two lights put
# the highlight in view and half in view from there. Another pitch adds -pitchP to the name.
# Needs: python3, node, /usr/bin/chromium (Debian's chromium), `npm ci` in tools/threejs.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
bb=${1:-bumpbake}
work=${2:-$(mktemp -d)}
asset=${3:-}
strength=3 out=threejs-specular-aa.json
if [ "$asset" = noise ]; then strength=4.6 out=threejs-specular-aa-noise.json; fi
pitch=${PITCH:-35}
if [ "$pitch" != 35 ]; then out=${out%.json}-pitch$pitch.json; fi
# The mirror direction of the view: (0, sin p, -cos p).
mirror=$(python3 -c "import math,sys; p=math.radians(float(sys.argv[1])); print('%.3f,%.3f' % (math.sin(p), -math.cos(p)))" "$pitch")
cd "$work"
python3 "$here/make_asset.py" $asset
"$bb" bake plane.obj --height height.png --strength $strength -o plane.gltf --quiet
rows=()
for r in 0.15 0.5; do
  python3 - "$r" <<'PY'
import json, sys
g = json.load(open('plane.gltf'))
g['materials'][0]['pbrMetallicRoughness']['roughnessFactor'] = float(sys.argv[1])
json.dump(g, open(f'png_{sys.argv[1]}.gltf', 'w'))
PY
  "$bb" textures "png_$r.gltf" --no-specular-aa -o "mips_$r.glb" --quiet
  "$bb" textures "png_$r.gltf" -o "specaa_$r.glb" --quiet
done
for light in 0,$mirror 0.3,$mirror 0.5,0.7,-0.5; do
  for r in 0.15 0.5; do
    echo "== roughness $r, light from $light"
    node "$here/measure.mjs" --truth "png_$r.gltf" --size 160 --ssaa 12 --intensity 1 --light "$light" --pitch "$pitch" \
      --distance 2.5 --distance 6 --json "m_${r}_${light}.json" \
      box="png_$r.gltf" mips="mips_$r.glb" specaa="specaa_$r.glb"
  done
done
node -e '
const fs = require("fs");
const runs = fs.readdirSync(".").filter((f) => f.startsWith("m_") && f.endsWith(".json")).sort()
  .map((f) => { const j = JSON.parse(fs.readFileSync(f)); const [, r, light] = f.slice(0, -5).split("_");
    return { roughness: +r, light, rows: j.rows.map(({ textures, ...x }) => x) }; });
fs.writeFileSync(process.argv[1], JSON.stringify({ three: "0.187.0", size: 160, ssaa: 12, pitch: +process.argv[2], runs }, null, 1) + "\n");' "$out" "$pitch"
echo "written: $work/$out"
