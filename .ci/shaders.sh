#!/usr/bin/env bash
# Compiles the GLSL reference shaders (the preview's shading model for real GPUs) with the
# Khronos reference compiler, installing it (Debian/Ubuntu package glslang-tools) when missing.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v glslangValidator >/dev/null 2>&1; then
  echo "== installing glslang-tools"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq glslang-tools
fi

echo "== glslangValidator $(glslangValidator --version | head -n 1)"
for s in shaders/bump.vert shaders/bump.frag; do
  glslangValidator "$s"
done
# Link both stages: the vertex outputs must match the fragment inputs.
glslangValidator -l shaders/bump.vert shaders/bump.frag
echo "shaders: ok"
