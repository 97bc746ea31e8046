"""Shared by the extension's tests: Blender's user folders in a temporary directory, the built
zip installed once, and readers of what the operators write."""

from __future__ import annotations

import json
import os
import struct
import tempfile
import time
import warnings
from pathlib import Path

import pytest

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="bumpbake-blender-"))

bpy = pytest.importorskip("bpy")

ZIP = Path(os.environ.get("BUMPBAKE_BLENDER_ZIP", Path(__file__).resolve().parents[2] / "target/blender/bumpbake.zip"))


@pytest.fixture(scope="session", autouse=True)
def installed():
    assert ZIP.exists(), f"{ZIP}: run blender/build.sh first"
    result = bpy.ops.extensions.package_install_files(filepath=str(ZIP), repo="user_default", enable_on_install=True)
    assert "FINISHED" in result
    assert hasattr(bpy.ops.bumpbake, "export_gltf")
    yield


def findings(path: Path) -> dict:
    import bumpbake

    report = bumpbake.validate(path)
    codes = {}
    for f in report["files"]:
        for s in f.get("subjects", []):
            for fi in s.get("findings", []):
                codes[fi["code"]] = fi
    return codes


def glb_json(path: Path) -> dict:
    data = path.read_bytes()
    n = struct.unpack_from("<I", data, 12)[0]
    return json.loads(data[20 : 20 + n])


def clear_scene():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    for m in list(bpy.data.materials):
        bpy.data.materials.remove(m)
    for i in list(bpy.data.images):
        bpy.data.images.remove(i)


def new_material(name: str):
    mat = bpy.data.materials.new(name)
    with warnings.catch_warnings():
        # Blender 5 gives every material nodes and deprecates the switch; 4.2 needs it.
        warnings.simplefilter("ignore", DeprecationWarning)
        mat.use_nodes = True
    return mat


def keep_for_khronos(path: Path, name: str):
    """A copy of an output where CI runs the Khronos glTF-Validator after these tests
    (`BUMPBAKE_VALIDATED_DIR`, set by .ci/blender.sh)."""
    import shutil

    folder = os.environ.get("BUMPBAKE_VALIDATED_DIR")
    if folder:
        os.makedirs(folder, exist_ok=True)
        shutil.copyfile(path, Path(folder) / name)


def cycles_bake(mat, size: int, samples: int, **bake) -> tuple:
    """Cycles' own tangent-space NORMAL bake into a new float image on `mat`: of the active object
    as its material stands, or selected to active with `use_selected_to_active=True` and the
    ray settings in `bake`. Returns the pixels, (rows, cols, 4) from the top (alpha 0 where no
    texel was baked), and the bake's seconds."""
    import numpy as np

    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    target = bpy.data.images.new("cycles", size, size, alpha=True, float_buffer=True)
    target.colorspace_settings.name = "Non-Color"
    target.generated_color = (0, 0, 0, 0)
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = target
    mat.node_tree.nodes.active = node
    start = time.perf_counter()
    bpy.ops.object.bake(type="NORMAL", normal_space="TANGENT", target="IMAGE_TEXTURES", **bake)
    seconds = time.perf_counter() - start
    px = np.empty(size * size * 4, np.float32)
    target.pixels.foreach_get(px)
    mat.node_tree.nodes.remove(node)
    bpy.data.images.remove(target)
    return px.reshape(size, size, 4)[::-1], seconds
