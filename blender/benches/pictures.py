"""The pictures of docs/blender.md, made in headless Blender 5.0.1 with the built extension:

- blender-bump-to-normal.png: a UV sphere with a Bump material, rendered by Cycles before and
  after `bump_to_normal` (left, right), and their difference x10 (middle);
- blender-export-gltf.png: `export_gltf`'s file of that scene drawn by `bumpbake preview`;
- blender-selected-to-active.png: HIGH (left), the baked map (middle), LOW with the map (right).

    BUMPBAKE_BLENDER_ZIP=target/blender/bumpbake.zip python blender/benches/pictures.py docs/images
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="bumpbake-pictures-"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import bpy
import conftest
import numpy as np
import test_bump
import test_selected
from mathutils import Vector

OUT = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/images")
SIZE = 256


def stage(target):
    """A camera looking at the origin from the front-right, a sun, grey world."""
    scene = bpy.context.scene
    for o in [o for o in bpy.data.objects if o.type in {"CAMERA", "LIGHT"}]:
        bpy.data.objects.remove(o)
    cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
    scene.collection.objects.link(cam)
    cam.location = (2.6, -2.6, 1.6)
    d = np.array(target) - np.array(cam.location)
    cam.rotation_mode = "QUATERNION"
    cam.rotation_quaternion = Vector(d).to_track_quat("-Z", "Y")
    scene.camera = cam
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 2.0
    sun.rotation_euler = (0.9, 0.2, 0.6)
    scene.collection.objects.link(sun)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 16
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"


def render() -> np.ndarray:
    path = Path(tempfile.mkdtemp()) / "r.png"
    bpy.context.scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(str(path))
    px = np.empty(SIZE * SIZE * 4, np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    return px.reshape(SIZE, SIZE, 4)[::-1, :, :3]


def save(name: str, rgb: np.ndarray):
    h, w, _ = rgb.shape
    img = bpy.data.images.new(name, w, h)
    rgba = np.ones((h, w, 4), np.float32)
    rgba[:, :, :3] = np.clip(rgb, 0, 1)
    img.pixels.foreach_set(rgba[::-1].reshape(-1))
    img.filepath_raw = str(OUT / name)
    img.file_format = "PNG"
    img.save()
    print(OUT / name)


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    bpy.ops.extensions.package_install_files(filepath=str(conftest.ZIP), repo="user_default", enable_on_install=True)
    obj, _ = test_bump.bump_scene("sphere", distance=0.2)
    stage((0, 0, 0))
    before = render()
    obj.select_set(True)
    bpy.ops.bumpbake.bump_to_normal()
    after = render()
    gap = np.ones((SIZE, 8, 3), np.float32)
    save("blender-bump-to-normal.png", np.concatenate([before, gap, np.abs(after - before) * 10, gap, after], axis=1))

    obj, _ = test_bump.bump_scene("sphere", distance=0.2)
    glb = Path(tempfile.mkdtemp()) / "bumpy.glb"
    bpy.ops.bumpbake.export_gltf(filepath=str(glb))
    import bumpbake._native as native

    native.main(["bumpbake", "preview", str(glb), "-o", str(OUT / "blender-export-gltf.png"), "--size", "256x256"])

    low, high, mat = test_selected.bumpy_pair(384)
    bpy.ops.bumpbake.bake_selected_to_active(size=512, extrusion=0.1, max_ray_distance=0.2)
    stage((0, 0, 0))
    low.hide_render = True
    hi = render()
    low.hide_render, high.hide_render = False, True
    lo = render()
    nmap = next(n for n in mat.node_tree.nodes if n.type == "NORMAL_MAP")
    img = nmap.inputs["Color"].links[0].from_node.image
    px = np.empty(img.size[0] * img.size[1] * 4, np.float32)
    img.pixels.foreach_get(px)
    m = px.reshape(img.size[1], img.size[0], 4)[::-1, :, :3]
    m = m[:: max(1, img.size[1] // SIZE), :: max(1, img.size[0] // SIZE)][:SIZE, :SIZE]
    save("blender-selected-to-active.png", np.concatenate([hi, gap, m, gap, lo], axis=1))


main()
