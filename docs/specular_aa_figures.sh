#!/bin/sh
# The specular-antialiasing figures and tables (README, docs/preview.md "Mip levels and specular
# antialiasing: measured"). From the repository root, after `cargo build --release`; about ten
# minutes on two cores.
#
# Two assets on the same plane: `noise` (random bumps) and `sine` (a regular pattern), each made
# into a normal map by `bumpbake normalmap` at the strength that gives both the same lost length
# at level 3 (mean normal length 0.986). Per roughness, three glTF files: `png-R` (the PNG map: the
# renderer's own box mips), `ktx2-R` (`bumpbake textures --no-specular-aa`: bumpbake's KTX2 mips)
# and `saa-R` (`bumpbake textures`: the same plus the widened roughness levels).
set -e
B=${B:-target/release/bumpbake}
# Seen from 50° above the plane, the light placed for the highlight, no ambient.
V="--size 256x256 --pitch 50 --shading pbr --ambient 0 --light dir:0,0.766,-0.643@2"
for asset in noise sine; do
  D=target/saa-$asset
  case $asset in noise) S=4.6 ;; *) S=1.5 ;; esac
  cargo run -q --release --example specular_aa_scene -- height $D $asset
  $B normalmap $D/height.png -o $D/normal.png --strength $S -q
  cargo run -q --release --example specular_aa_scene -- scene $D
  for r in 0.15 0.5; do
    $B textures $D/png-$r.gltf -o $D/ktx2-$r.gltf --no-specular-aa -q
    $B textures $D/png-$r.gltf -o $D/saa-$r.gltf -q
    for d in 1.5 4.5; do
      $B preview $D/png-$r.gltf -o $D/truth-$r-$d.png $V --distance $d --mips off --ssaa 16 --resolve hdr -q
      $B preview $D/png-$r.gltf -o $D/box-$r-$d.png $V --distance $d --mips box -q
      $B preview $D/ktx2-$r.gltf -o $D/ktx2-$r-$d.png $V --distance $d -q
      $B preview $D/saa-$r.gltf -o $D/saa-$r-$d.png $V --distance $d -q
      for res in hdr clamped; do
        T="--reference-mips off --reference-ssaa 16 --resolve $res"
        $B preview --reference $D/png-$r.gltf $T --compare $D/png-$r.gltf --mips box $V --distance $d -o $D/diff.png --json > $D/$res-box-$r-$d.json
        $B preview --reference $D/png-$r.gltf $T --compare $D/ktx2-$r.gltf $V --distance $d -o $D/diff.png --json > $D/$res-ktx2-$r-$d.json
        $B preview --reference $D/png-$r.gltf $T --compare $D/saa-$r.gltf $V --distance $d -o $D/diff.png --json > $D/$res-saa-$r-$d.json
      done
    done
    python3 -c '
import sys; from PIL import Image
d, r, a = sys.argv[1], sys.argv[2], sys.argv[3]
rows = [[Image.open(f"{d}/{k}-{r}-{dist}.png") for k in ("truth", "box", "ktx2", "saa")] for dist in ("1.5", "4.5")]
w, h = rows[0][0].size
out = Image.new("RGB", (4 * w, 2 * h))
for j, row in enumerate(rows):
    for i, im in enumerate(row):
        out.paste(im, (i * w, j * h))
out.save(f"docs/images/specular-aa-{a}-{r}.png", optimize=True)' $D $r $asset
  done
done
# One row per asset, truth resolve, roughness and distance: display-value brightness ratio,
# luminance ratio and PSNR of box mips, bumpbake's mips and bumpbake's mips with specular AA.
python3 -c '
import json
for a in ("noise", "sine"):
  for res in ("hdr", "clamped"):
    for r in ("0.15", "0.5"):
      for d in ("1.5", "4.5"):
        cells = []
        for k in ("box", "ktx2", "saa"):
          c = json.load(open(f"target/saa-{a}/{res}-{k}-{r}-{d}.json"))["comparison"]
          cells.append("%.3f / %.3f, %.2f dB" % (c["brightness_ratio"], c["luminance_ratio"], c["psnr_db"]))
        print(f"| {a} | {res} | {r}, {d} | " + " | ".join(cells) + " |")'
