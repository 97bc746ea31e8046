#!/usr/bin/env bash
# Builds the Blender extension: the add-on in blender/bumpbake_blender/ with the abi3 wheel of
# python/ inside, as target/blender/bumpbake.zip (Install from Disk, or
# bpy.ops.extensions.package_install_files). WHEEL=path reuses a wheel already built.
set -euo pipefail
cd "$(dirname "$0")/.."
out="$PWD/target/blender"
mkdir -p "$out"
wheel="${WHEEL:-}"
if [ -z "$wheel" ]; then
  maturin build --release --manifest-path python/Cargo.toml --out "$out/wheels"
  wheel=$(ls -t "$out"/wheels/bumpbake-*-cp39-abi3-*.whl | head -n 1)
fi
python3 - "$wheel" "$out/bumpbake.zip" <<'PY'
import pathlib, re, sys, zipfile
wheel, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
version = re.match(r"bumpbake-([^-]+)-", wheel.name).group(1)
src = pathlib.Path("blender/bumpbake_blender")
manifest = (src / "blender_manifest.toml.in").read_text().replace("@VERSION@", version).replace("@WHEEL@", wheel.name)
tmp = out.with_suffix(".zip.tmp")
with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
    z.writestr("blender_manifest.toml", manifest)
    for f in sorted(src.glob("*.py")):
        z.write(f, f.name)
    z.write(wheel, f"wheels/{wheel.name}")
tmp.replace(out)
print(f"{out} ({out.stat().st_size // 1024} KiB, wheel {wheel.name})")
PY
