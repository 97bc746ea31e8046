#!/bin/sh
# The specular-antialiasing figures and table (README, docs/preview.md "Mip levels and specular
# antialiasing"). From the repository root, after `cargo build --release`.
set -e
D=${D:-target/saa}; B=${B:-target/release/bumpbake}
cargo run -q --release --example specular_aa_scene -- height $D
$B normalmap $D/height.png -o $D/normal.png --strength 1.5 -q
$B normalmap $D/height.png -o $D/normal.ktx2 --strength 1.5 -q
cargo run -q --release --example specular_aa_scene -- scene $D > $D/roughness-levels.txt
# Seen from 50° above the plane, the light placed for the highlight, no ambient.
V="--size 256x256 --pitch 50 --shading pbr --ambient 0 --light dir:0,0.766,-0.643@2"
T="--reference-mips off --reference-ssaa 16"
for r in 0.15 0.5; do
  for d in 1.5 4.5; do
    $B preview $D/png-$r.gltf -o $D/truth-$r-$d.png $V --distance $d --mips off --ssaa 16 -q
    $B preview $D/png-$r.gltf -o $D/box-$r-$d.png $V --distance $d --mips box -q
    $B preview $D/ktx2-$r.gltf -o $D/ktx2-$r-$d.png $V --distance $d -q
    $B preview $D/saa-$r.gltf -o $D/saa-$r-$d.png $V --distance $d -q
    $B preview --reference $D/png-$r.gltf $T --compare $D/png-$r.gltf --mips box $V --distance $d -o $D/diff-box-$r-$d.png --json > $D/box-$r-$d.json
    $B preview --reference $D/png-$r.gltf $T --compare $D/ktx2-$r.gltf $V --distance $d -o $D/diff-ktx2-$r-$d.png --json > $D/ktx2-$r-$d.json
    $B preview --reference $D/png-$r.gltf $T --compare $D/saa-$r.gltf $V --distance $d -o $D/diff-saa-$r-$d.png --json > $D/saa-$r-$d.json
  done
  python3 -c '
import sys; from PIL import Image
d, r = sys.argv[1], sys.argv[2]
rows = [[Image.open(f"{d}/{k}-{r}-{dist}.png") for k in ("truth", "box", "ktx2", "saa")] for dist in ("1.5", "4.5")]
w, h = rows[0][0].size
out = Image.new("RGB", (4 * w, 2 * h))
for j, row in enumerate(rows):
    for i, im in enumerate(row):
        out.paste(im, (i * w, j * h))
out.save(f"docs/images/specular-aa-{r}.png", optimize=True)' $D $r
done
for f in $D/*-*-*.json; do
  printf '%s ' "$(basename $f .json)"
  python3 -c 'import json,sys; c=json.load(open(sys.argv[1]))["comparison"]; print("ratio %.3f psnr %.2f dB" % (c["brightness_ratio"], c["psnr_db"]))' $f
done
