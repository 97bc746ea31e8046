#!/usr/bin/env bash
# Prints the files a mesh references (its MTL, the images an MTL or glTF names, external buffers)
# as a Starlark list for a rule's `srcs`, relative to the mesh's folder. It runs the command once
# with --depfile, so the list is exactly what bumpbake reads.
#
#   bazel/list-inputs.sh bake assets/torus.obj            # -> srcs = ["bumps.png", "torus.mtl"],
#   bazel/list-inputs.sh tangents assets/spot.obj --all
#
# The binary is $BUMPBAKE, or bumpbake on PATH.
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 bake|tangents MESH [bumpbake options]" >&2
  exit 2
fi
cmd=$1 mesh=$2
shift 2
bin=${BUMPBAKE:-bumpbake}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
dir=$(dirname "$mesh")
base=$(basename "$mesh")
(cd "$dir" && "$bin" "$cmd" "$base" -o "$tmp/out.glb" --depfile "$tmp/out.d" -q "$@")
# The depfile is "out: in1 \<newline> in2 ...", spaces in names escaped as "\ ".
sed -e '1s/^[^:]*: *//' -e 's/\\$//' -e 's/\\ /\x01/g' "$tmp/out.d" | tr ' \t' '\n\n' | tr '\001' ' ' |
  grep -v '^$' | grep -vxF "$base" | LC_ALL=C sort -u |
  { items=(); while IFS= read -r f; do items+=("\"$f\""); done
    (IFS=,; echo "srcs = [${items[*]}],") | sed 's/,"/, "/g'; }
