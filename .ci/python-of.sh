#!/usr/bin/env bash
# The path of CPython X.Y ($1): on PATH when it runs, else pyenv's newest X.Y.* (pyenv's shims
# answer only for the versions pyenv is set to).
set -euo pipefail
if "python$1" -c '' 2>/dev/null; then
  command -v "python$1"
  exit 0
fi
found=$(ls -d "$(pyenv root 2>/dev/null)/versions/$1".* 2>/dev/null | sort -V | tail -n 1)
[ -n "$found" ] || { echo "CPython $1 is not installed" >&2; exit 1; }
echo "$found/bin/python$1"
