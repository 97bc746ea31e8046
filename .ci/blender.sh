#!/usr/bin/env bash
# The Blender extension (blender/): the zip built by blender/build.sh around the wheel that
# .ci/python.sh built, installed into headless Blender 5.0.1 (bpy from the Python registry) and
# tested there (blender/tests/). The venv has no bumpbake of its own: the tests can only pass
# through the extension's bundled wheel.
set -euo pipefail
cd "$(dirname "$0")/.."
target=$(bash .ci/target-dir.sh)
work="$target/blender-ci"
rm -rf "$work" && mkdir -p "$work/user"
wheel=$(ls "$target"/python-ci/wheels/bumpbake-*-cp39-abi3-*.whl)
WHEEL="$wheel" bash blender/build.sh
"$target/python-ci/build/bin/ruff" check --config python/pyproject.toml blender
"$target/python-ci/build/bin/ruff" format --config python/pyproject.toml --check blender

py=$(bash .ci/python-of.sh 3.11)
"$py" -m venv "$work/venv"
"$work/venv/bin/pip" install --quiet --disable-pip-version-check -r blender/requirements-ci.txt
BLENDER_USER_RESOURCES="$work/user" BUMPBAKE_VALIDATED_DIR="$target/tmp/validated/blender" BUMPBAKE_BLENDER_ZIP="$PWD/target/blender/bumpbake.zip" \
  "$work/venv/bin/python" -m pytest -q -p no:cacheprovider blender/tests
