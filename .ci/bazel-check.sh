#!/usr/bin/env bash
# The Bazel example (bazel/example) against a shared HTTP remote cache (nginx with WebDAV PUT on
# 127.0.0.1): "machine" A builds and tests it, "machine" B (another checkout, another output base)
# must then be all remote cache hits with byte-identical outputs; editing one input re-runs exactly
# the actions that depend on it; an undeclared input fails in the sandbox with bumpbake's message.
# Needs the debug bumpbake in cargo's target directory (cargo test or cargo build makes it).
set -euo pipefail
cd "$(dirname "$0")/.."
echo "== Bazel example: a shared HTTP remote cache across two output bases"
export PATH="$PATH:/usr/sbin:/sbin"
t0=$(date +%s)
need=()
command -v bazel >/dev/null 2>&1 || need+=(bazel-bootstrap)
command -v nginx >/dev/null 2>&1 || need+=(nginx)
if [ ${#need[@]} -gt 0 ]; then
  echo "== installing ${need[*]}"
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}" >/dev/null
fi
t_install=$(( $(date +%s) - t0 ))

bin="$(bash .ci/target-dir.sh)/debug/bumpbake"
[ -x "$bin" ] || { echo "bazel-check: no $bin (run cargo build first)"; exit 1; }
work=$(mktemp -d)
chmod 755 "$work"
bases=()
cleanup() {
  for b in "${bases[@]}"; do bazel --output_base="$b" shutdown >/dev/null 2>&1 || true; done
  [ -f "$work/nginx/nginx.pid" ] && kill "$(cat "$work/nginx/nginx.pid")" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

want='srcs = ["bumps.png", "torus.mtl"],'
got=$(BUMPBAKE="$bin" bazel/list-inputs.sh bake fixtures/bake/torus.obj)
[ "$got" = "$want" ] || { echo "bazel-check: list-inputs.sh printed $got, not $want"; exit 1; }
echo "ok: list-inputs.sh lists the torus's MTL and height map"

# Two checkouts at different paths, as on two machines.
for m in a b; do
  mkdir -p "$work/$m"
  cp -r bazel fixtures "$work/$m/"
done

echo "== HTTP cache: nginx on 127.0.0.1"
mkdir -p "$work/nginx/cache" "$work/nginx/body"
chmod 777 "$work/nginx" "$work/nginx/cache" "$work/nginx/body"
port=""
for p in $(seq 18480 18499); do
  sed "s|@ROOT@|$work/nginx|g; s|@PORT@|$p|g" .ci/bazel-cache.nginx.conf >"$work/nginx/nginx.conf"
  if nginx -p "$work/nginx" -c "$work/nginx/nginx.conf" 2>"$work/nginx/start.log"; then port=$p; break; fi
done
[ -n "$port" ] || { echo "bazel-check: nginx did not start"; cat "$work/nginx/start.log"; exit 1; }
cache="http://127.0.0.1:$port"
echo "cache at $cache"

# bz MACHINE ARGS...: bazel in that checkout's example workspace, its own output base; the log
# goes to $work/log.
bz() {
  local m=$1; shift
  local base="$work/base-$m"
  [[ " ${bases[*]} " == *" $base "* ]] || bases+=("$base")
  (cd "$work/$m/bazel/example" && BUMPBAKE="$bin" bazel --output_base="$base" "$@") >"$work/log" 2>&1
}
# The summary line of the last command: "INFO: 9 processes: 3 internal, 6 linux-sandbox."
processes() { grep -E '^INFO: [0-9]+ process(es)?[:.]' "$work/log" | tail -1; }
count() { processes | grep -oE "[0-9]+ $1" | grep -oE '^[0-9]+' || echo 0; }
fail() { echo "bazel-check: $*"; sed 's/^/  /' "$work/log" | tail -40; exit 1; }
outs="bumps_normal.png torus.glb torus_from_normal.glb spot.glb normal_tangent_test.glb"
digests() { (cd "$work/$1/bazel/example/bazel-bin" && sha256sum $outs); }
flags=(--remote_cache="$cache" --spawn_strategy=sandboxed)

echo "== machine A: build and test, cache empty"
t=$(date +%s)
bz a test "${flags[@]}" //... || fail "machine A's build failed"
t_a=$(( $(date +%s) - t ))
echo "  $(processes)"
ran=$(( $(count linux-sandbox) + $(count processwrapper-sandbox) ))
[ "$ran" = 6 ] || fail "expected the 5 actions and the test to run, got: $(processes)"
[ "$(count 'remote cache hit')" = 0 ] || fail "an empty cache gave hits"
bazel --output_base="$work/base-a" shutdown >/dev/null 2>&1 || true

echo "== machine B: another checkout and output base, same cache"
t=$(date +%s)
bz b test "${flags[@]}" //... || fail "machine B's build failed"
t_b=$(( $(date +%s) - t ))
echo "  $(processes)"
hits=$(count 'remote cache hit')
[ "$hits" = "$ran" ] || fail "expected $ran remote cache hits, got: $(processes)"
processes | grep -qE 'sandbox|local|worker' && fail "machine B ran actions itself: $(processes)"
diff <(digests a) <(digests b) >/dev/null || { digests a; digests b; fail "outputs differ between machines"; }
echo "ok: 100% remote cache hits ($hits), outputs byte-identical"

echo "== machine B: edit the torus's MTL (its bump strength)"
sed -i 's/-bm 6.0/-bm 5.0/' "$work/b/fixtures/bake/torus.mtl"
before=$(digests b)
bz b test "${flags[@]}" --execution_log_json_file="$work/exec.json" //... || fail "the build after the edit failed"
echo "  $(processes)"
ran=$(( $(count linux-sandbox) + $(count processwrapper-sandbox) ))
# torus and torus_from_normal read the MTL; the test reads torus.glb, which changed.
[ "$ran" = 3 ] || fail "expected 3 actions to re-run (2 bakes that read the MTL, the test), got: $(processes)"
spawns=$(grep -oE '"progressMessage": "[^"]*"' "$work/exec.json" | cut -d'"' -f4 | LC_ALL=C sort | tr '\n' ';')
[ "$spawns" = "Testing //:validate;bumpbake bake torus.glb;bumpbake bake torus_from_normal.glb;" ] ||
  fail "expected the torus bakes and the test to re-run, ran: $spawns"
changed=$(diff <(echo "$before") <(digests b) | sed -n 's/^> [0-9a-f]*  //p' | tr '\n' ' ' || true)
[ "$changed" = "torus.glb " ] || fail "expected only torus.glb to change, changed: ${changed:-nothing}"
echo "ok: exactly the 3 actions depending on the MTL re-ran; only torus.glb changed"

echo "== an undeclared input fails in the sandbox"
bz b build "${flags[@]}" //:torus_undeclared && fail "a bake without its MTL declared succeeded"
grep -q "bumpbake: external/fixtures/bake/torus.obj: cannot read 'torus.mtl'" "$work/log" ||
  fail "no clear message naming the missing MTL"
echo "ok: $(grep '^bumpbake: ' "$work/log")"

echo "== bumpbake_validate_test fails on a file with findings"
bz b test "${flags[@]}" //:validate_raw_fails && fail "validating the raw Khronos model (no tangents) passed"
grep -q "TANGENT_MISSING" "$work/b/bazel/example/bazel-testlogs/validate_raw_fails/test.log" ||
  fail "the test log does not name TANGENT_MISSING"
echo "ok: validate_raw_fails fails with TANGENT_MISSING"

echo "bazel example: remote cache across machines ok; install ${t_install}s, machine A ${t_a}s, machine B ${t_b}s, total $(( $(date +%s) - t0 ))s"
