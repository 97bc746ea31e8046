#!/usr/bin/env bash
# Prints one sha256 per output of every command over every fixture, so a refactor can show its
# outputs are byte-identical: run it before and after, diff the two listings.
#   bash .ci/output-hashes.sh [path/to/bumpbake] > hashes.txt
# Report lines that carry timings (tangents/bake reports on stderr) are not hashed: only files
# written and the machine-readable stdout of validate and inspect, plus inspect's human text.
set -uo pipefail
cd "$(dirname "$0")/.."
bin=${1:-"$(cargo metadata --format-version 1 --no-deps | sed 's/.*"target_directory":"\([^"]*\)".*/\1/')/debug/bumpbake"}
[ -x "$bin" ] || { echo "output-hashes: no bumpbake at $bin (build it, or pass its path)" >&2; exit 2; }
bin=$(realpath "$bin")
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

meshes=$(find fixtures -name '*.obj' -o -name '*.glb' -o -name '*.gltf' | sort)
images=(fixtures/bake/bumps.png fixtures/spot/spot_texture.png fixtures/blender/sphere_normal.jpg)

hash() { # label file
  if [ -s "$2" ]; then echo "$(sha256sum <"$2" | cut -c1-16) $1"; else echo "(none)           $1"; fi
}
run() { # label command... (stdout hashed; exit code recorded)
  local label=$1; shift
  "$@" >"$out/stdout" 2>"$out/stderr"
  echo "exit $? $label"
  hash "$label stdout" "$out/stdout"
}

for m in $meshes; do
  n=$(echo "$m" | tr / _)
  run "tangents $m" "$bin" tangents -q "$m" -o "$out/$n.t.glb"
  hash "tangents $m glb" "$out/$n.t.glb"
  run "tangents --all --bitangents $m" "$bin" tangents -q --all --bitangents "$m" -o "$out/$n.ta.gltf"
  hash "tangents --all $m gltf" "$out/$n.ta.gltf"
  hash "tangents --all $m bin" "$out/$n.ta.bin"
  if [ "${m##*.}" = obj ] && grep -q bump "${m%.obj}.mtl" 2>/dev/null; then
    run "bake $m" "$bin" bake -q "$m" -o "$out/$n.b.glb"
  else
    run "bake --height $m" "$bin" bake -q "$m" --height fixtures/bake/bumps.png -o "$out/$n.b.glb"
  fi
  hash "bake $m glb" "$out/$n.b.glb"
  run "validate json $m" "$bin" validate --format json "$m"
  # from inside the scratch folder, so the paths in the report do not name it
  run "validate json tangents-out $m" sh -c 'cd "$1" && "$2" validate --format json "$3"' _ "$out" "$bin" "$n.t.glb"
  run "inspect json $m" "$bin" inspect --json "$m"
  run "inspect $m" "$bin" inspect "$m"
  for v in shaded normal tangent handedness; do
    "$bin" preview "$m" -o "$out/$n.$v.png" --size 48x32 --view $v >/dev/null 2>&1
    echo "exit $? preview $v $m"
    hash "preview $v $m png" "$out/$n.$v.png"
  done
  "$bin" preview "$out/$n.b.glb" -o "$out/$n.pb.png" --size 48x32 >/dev/null 2>&1
  hash "preview baked $m png" "$out/$n.pb.png"
done

# bake --from: the torus onto itself and onto the OBJ scans' own UV layouts (OBJ and GLB HIGH)
for low in fixtures/bake/torus.obj fixtures/spot/spot.obj fixtures/khronos/NormalTangentTest.glb; do
  for high in fixtures/bake/torus.obj fixtures/real/mirror_small.glb; do
    n=$(echo "$low.$high" | tr / _)
    run "bake --from $high $low" "$bin" bake -q "$low" --from "$high" --size 64 \
      --map-out "$out/$n.map.png" --height-out "$out/$n.h.png" -o "$out/$n.glb"
    hash "bake --from $high $low glb" "$out/$n.glb"
    hash "bake --from $high $low map" "$out/$n.map.png"
    hash "bake --from $high $low height" "$out/$n.h.png"
  done
done

for i in "${images[@]}"; do
  n=$(echo "$i" | tr / _)
  run "normalmap $i" "$bin" normalmap -q "$i" -o "$out/$n.n.png"
  hash "normalmap $i png" "$out/$n.n.png"
  run "normalmap 16 central4 repeat $i" "$bin" normalmap -q "$i" --bits 16 --filter central4 --wrap repeat -o "$out/$n.n16.png"
  hash "normalmap 16 $i png" "$out/$n.n16.png"
  run "validate json image $i" "$bin" validate --format json "$i"
done
