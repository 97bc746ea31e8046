#!/usr/bin/env bash
# Runs examples/build.ninja on a copy of the fixtures, then touches one input and checks that
# exactly the outputs depending on it rebuild (Ninja learns the dependencies from bumpbake's
# depfiles). Needs the debug bumpbake in cargo's target directory (cargo test or cargo build makes it).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v ninja >/dev/null 2>&1; then
  echo "== installing ninja-build"
  apt-get update -qq && apt-get install -y -qq ninja-build
fi
bin="$(bash .ci/target-dir.sh)/debug/bumpbake"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp -r fixtures "$work/fixtures"
cp examples/build.ninja "$work/build.ninja"
sed -i "s|^bumpbake = .*|bumpbake = $bin|; s|^out = .*|out = out|" "$work/build.ninja"

run() { ninja -C "$work" "$@" | tee "$work/log" | sed 's/^/  /'; }
steps() { grep -cE '^\[[0-9]+/[0-9]+\] (BAKE|TANGENTS|VALIDATE)' "$work/log" || true; }
expect() { # expect N DESCRIPTION...
  local n=$1; shift
  local got; got=$(steps)
  if [ "$got" != "$n" ]; then echo "ninja-check: expected $n steps ($*), ran $got"; exit 1; fi
  echo "ok: $n steps ($*)"
}

echo "== first build"; run; expect 4 "everything"
echo "== no change"; run; grep -q "no work to do" "$work/log" || { echo "ninja-check: a rebuild with no change did work"; exit 1; }; echo "ok: nothing to do"
sleep 1
echo "== touch the torus height map (read through its MTL)"; touch "$work/fixtures/bake/bumps.png"; run
expect 2 "torus + validate"
grep -q "BAKE out/torus.glb" "$work/log" || { echo "ninja-check: torus did not rebuild"; exit 1; }
echo "== touch spot's texture (read through its MTL)"; touch "$work/fixtures/spot/spot_texture.png"; run
expect 2 "spot + validate"
grep -q "TANGENTS out/spot.glb" "$work/log" || { echo "ninja-check: spot did not rebuild"; exit 1; }
echo "ninja example: incremental rebuilds ok"
