#!/usr/bin/env bash
# The Python package (python/): the abi3 wheel built once with maturin, ruff, then the wheel
# installed into fresh virtual environments of two CPython versions and tested there with no
# Rust or C++ toolchain on PATH, against the command line cargo built ($1).
set -euo pipefail
cd "$(dirname "$0")/.."
bin="$1"
target=$(bash .ci/target-dir.sh)
work="$target/python-ci"
rm -rf "$work" && mkdir -p "$work"
pins="$PWD/python/requirements-ci.txt"

"$(bash .ci/python-of.sh 3.11)" -m venv "$work/build"
"$work/build/bin/pip" install --quiet --disable-pip-version-check -r "$pins"
"$work/build/bin/ruff" check python
"$work/build/bin/ruff" format --check python
"$work/build/bin/maturin" build --release --manifest-path python/Cargo.toml --out "$work/wheels"
wheel=$(ls "$work"/wheels/bumpbake-*-cp39-abi3-*.whl)
echo "wheel: $(basename "$wheel") ($(du -h "$wheel" | cut -f1))"

# A PATH with nothing but the venv and the few tools the tests' subprocesses need: no cargo,
# rustc, cc or c++ is reachable, so the wheel is proven to need none.
plain="$work/plain-bin"
mkdir -p "$plain"
for tool in sh env uname; do ln -sf "$(command -v "$tool")" "$plain/$tool"; done

for version in 3.11 3.12; do
  venv="$work/venv-$version"
  "$(bash .ci/python-of.sh "$version")" -m venv "$venv"
  "$venv/bin/pip" install --quiet --disable-pip-version-check "$wheel" "$(grep '^numpy' "$pins")" "$(grep '^pytest' "$pins")"
  echo "== CPython $version: the wheel with no toolchain on PATH"
  env -i HOME="$HOME" PATH="$venv/bin:$plain" sh -c '
    for t in cargo rustc cc c++ gcc g++; do
      if command -v "$t" >/dev/null; then echo "toolchain on PATH: $t" >&2; exit 1; fi
    done
    python -c "import bumpbake; print(\"bumpbake\", bumpbake.__version__, \"on\", __import__(\"sys\").version.split()[0])"
    bumpbake --version
  '
  env -i HOME="$HOME" PATH="$venv/bin:$plain" BUMPBAKE_BIN="$bin" \
    "$venv/bin/python" -m pytest -q -p no:cacheprovider python/tests
done
