"""`bumpbake.bake_selected_to_active`: a bumpy sphere (HIGH) baked onto a coarse one's UVs (LOW).
The map must be the one `bumpbake.bake_from` gives on the same meshes exported by Blender's own
glTF exporter, and close to Cycles' selected-to-active bake of the same pair."""

from __future__ import annotations

import time

import numpy as np
import pytest
from conftest import clear_scene, cycles_bake, new_material

bpy = pytest.importorskip("bpy")

SIZE = 512


def bumpy_pair(segments: int = 192):
    """LOW: a 48x24 UV sphere; HIGH: a `segments` x `segments/2` sphere with smooth radial bumps."""
    clear_scene()
    bpy.ops.mesh.primitive_uv_sphere_add(segments=segments, ring_count=segments // 2, radius=1.0)
    high = bpy.context.object
    high.name = "high"
    co = np.empty(len(high.data.vertices) * 3, np.float32)
    high.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    theta = np.arctan2(co[:, 1], co[:, 0])
    phi = np.arccos(np.clip(co[:, 2], -1, 1))
    r = 1.0 + 0.03 * np.sin(6 * theta) * np.sin(4 * phi)
    high.data.vertices.foreach_set("co", (co * r[:, None]).reshape(-1))
    high.data.update()
    bpy.ops.object.shade_smooth()
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=1.0)
    low = bpy.context.object
    low.name = "low"
    bpy.ops.object.shade_smooth()
    mat = new_material("LowMat")
    low.data.materials.append(mat)
    bpy.ops.object.select_all(action="DESELECT")
    high.select_set(True)
    low.select_set(True)
    bpy.context.view_layer.objects.active = low
    return low, high, mat


def pixels(img) -> np.ndarray:
    px = np.empty(img.size[0] * img.size[1] * img.channels, np.float32)
    img.pixels.foreach_get(px)
    return px.reshape(img.size[1], img.size[0], img.channels)[::-1]


def angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    na = a[..., :3].reshape(-1, 3) * 2 - 1
    nb = b[..., :3].reshape(-1, 3) * 2 - 1
    na /= np.linalg.norm(na, axis=1, keepdims=True)
    nb /= np.linalg.norm(nb, axis=1, keepdims=True)
    return np.degrees(np.arccos(np.clip((na * nb).sum(axis=1), -1, 1)))


def test_selected_to_active_is_bake_from_on_the_same_meshes(tmp_path):
    import bumpbake

    low, high, mat = bumpy_pair()
    start = time.perf_counter()
    assert "FINISHED" in bpy.ops.bumpbake.bake_selected_to_active(
        size=SIZE, extrusion=0.1, max_ray_distance=0.2, samples=2, padding=8
    )
    ours_s = time.perf_counter() - start
    nmap = next(n for n in mat.node_tree.nodes if n.type == "NORMAL_MAP")
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    assert bsdf.inputs["Normal"].links[0].from_node == nmap
    ours = pixels(nmap.inputs["Color"].links[0].from_node.image)

    # The same pair through Blender's exporter and the library's file-level call.
    for obj in (low, high):
        bpy.ops.object.select_all(action="DESELECT")
        obj.select_set(True)
        bpy.ops.export_scene.gltf(filepath=str(tmp_path / f"{obj.name}.glb"), use_selection=True)
    png = tmp_path / "map.png"
    bumpbake.bake_from(
        tmp_path / "low.glb",
        tmp_path / "high.glb",
        tmp_path / "out.glb",
        size=str(SIZE),
        samples=2,
        padding=8,
        ray_front=0.1,
        ray_back=0.1,
        map_out=png,
        bits16=True,
    )
    ref_img = bpy.data.images.load(str(png))
    ref_img.colorspace_settings.name = "Non-Color"
    ref = pixels(ref_img)
    e = angles(ours, ref)
    relief = angles(ref, np.broadcast_to(np.array([0.5, 0.5, 1.0, 1.0], np.float32), ref.shape))
    print(
        f"selected to active: {SIZE}², {ours_s:.2f} s; against bake_from: mean {e.mean():.4f}°, "
        f"p99 {np.percentile(e, 99):.3f}°; relief mean {relief.mean():.2f}°"
    )
    assert relief.mean() > 1.0
    assert e.mean() < 0.05, e.mean()


def test_selected_to_active_is_close_to_cycles():
    _, _, mat = bumpy_pair()
    ref, cycles_s = cycles_bake(
        mat, SIZE, 4, use_selected_to_active=True, cage_extrusion=0.1, max_ray_distance=0.2, margin=0, use_clear=False
    )
    start = time.perf_counter()
    assert "FINISHED" in bpy.ops.bumpbake.bake_selected_to_active(
        size=SIZE, extrusion=0.1, max_ray_distance=0.2, samples=2, padding=0
    )
    ours_s = time.perf_counter() - start
    nmap = next(n for n in mat.node_tree.nodes if n.type == "NORMAL_MAP")
    ours = pixels(nmap.inputs["Color"].links[0].from_node.image)
    mask = (ref[..., 3] > 0.5).reshape(-1)
    e = angles(ours, ref)[mask]
    print(
        f"against Cycles: mean {e.mean():.3f}°, p99 {np.percentile(e, 99):.2f}°; "
        f"bumpbake {ours_s:.2f} s, Cycles {cycles_s:.2f} s"
    )
    assert mask.sum() > SIZE * SIZE // 2
    assert e.mean() < 1.0 and np.percentile(e, 99) < 5.0
