#!/usr/bin/env bash
# Prints cargo's target directory the way cargo finds it (CARGO_TARGET_DIR, build.target-dir in
# a config file, or ./target), from `cargo metadata`: CI scripts never assume ./target.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo metadata --format-version 1 --no-deps |
  node -e 'let s = ""; process.stdin.on("data", (d) => (s += d)).on("end", () => console.log(JSON.parse(s).target_directory));'
