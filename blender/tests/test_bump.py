"""`bumpbake.bump_to_normal` against Cycles: a Bump node fed by a height image, baked by Cycles'
own NORMAL bake (tangent space) in this test, and converted by the operator, on a flat plane, a
plane whose UVs are stretched 3:1 and a UV sphere. Both maps are float images, compared where
Cycles baked a texel."""

from __future__ import annotations

import time

import numpy as np
import pytest
from conftest import clear_scene, cycles_bake, findings, glb_json, keep_for_khronos, new_material

bpy = pytest.importorskip("bpy")

SIZE = 1024


def height_image(size: int = SIZE):
    """Smooth periodic bumps, a float Non-Color image (no 8-bit steps in the slopes)."""
    y, x = (np.mgrid[0:size, 0:size] + 0.5) / size
    h = 0.5 + 0.25 * np.sin(2 * np.pi * 4 * x) * np.sin(2 * np.pi * 3 * y) + 0.1 * np.cos(2 * np.pi * 7 * (x + y))
    img = bpy.data.images.new("height", size, size, alpha=False, float_buffer=True)
    img.colorspace_settings.name = "Non-Color"
    rgba = np.ones((size, size, 4), np.float32)
    rgba[:, :, :3] = h[:, :, None]
    img.pixels.foreach_set(rgba.reshape(-1))
    img.pack()
    return img


def bump_scene(kind: str, distance: float = 0.02, strength: float = 1.0, invert: bool = False):
    """One object of `kind` with a Bump material: Image Texture -> Bump -> Principled BSDF."""
    clear_scene()
    if kind == "sphere":
        bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0)
        bpy.ops.object.shade_smooth()
    else:
        bpy.ops.mesh.primitive_plane_add(size=2.0)
        if kind == "stretched":
            bpy.context.object.scale = (3.0, 1.0, 1.0)
            bpy.ops.object.transform_apply(scale=True)
    obj = bpy.context.object
    mat = new_material("Bumpy")
    nt = mat.node_tree
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = height_image()
    b = nt.nodes.new("ShaderNodeBump")
    b.inputs["Distance"].default_value = distance
    b.inputs["Strength"].default_value = strength
    b.invert = invert
    nt.links.new(tex.outputs["Color"], b.inputs["Height"])
    nt.links.new(b.outputs["Normal"], nt.nodes["Principled BSDF"].inputs["Normal"])
    obj.data.materials.append(mat)
    return obj, mat


def cycles_normal_bake(obj, mat, samples: int = 4) -> tuple[np.ndarray, float]:
    """Cycles' bake of `obj` with its material as it is (`conftest.cycles_bake`)."""
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    return cycles_bake(mat, SIZE, samples, margin=0, use_clear=False)


def converted_map(mat) -> np.ndarray:
    nmap = next(n for n in mat.node_tree.nodes if n.type == "NORMAL_MAP")
    img = nmap.inputs["Color"].links[0].from_node.image
    px = np.empty(img.size[0] * img.size[1] * 4, np.float32)
    img.pixels.foreach_get(px)
    return px.reshape(img.size[1], img.size[0], 4)[::-1]


def angles(a: np.ndarray, b: np.ndarray, mask: np.ndarray) -> np.ndarray:
    na = a[..., :3][mask] * 2 - 1
    nb = b[..., :3][mask] * 2 - 1
    na /= np.linalg.norm(na, axis=1, keepdims=True)
    nb /= np.linalg.norm(nb, axis=1, keepdims=True)
    return np.degrees(np.arccos(np.clip((na * nb).sum(axis=1), -1, 1)))


def convert_and_compare(kind: str, **bump) -> dict:
    obj, mat = bump_scene(kind, **bump)
    ref, cycles_s = cycles_normal_bake(obj, mat)
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    start = time.perf_counter()
    assert "FINISHED" in bpy.ops.bumpbake.bump_to_normal(padding=0)
    ours_s = time.perf_counter() - start
    got = converted_map(mat)
    mask = ref[..., 3] > 0.5
    e = angles(got, ref, mask)
    # What the relief is: Cycles' map against flat, so a map that did nothing cannot pass.
    flat = np.zeros_like(ref)
    flat[..., :3] = (0.5, 0.5, 1.0)
    relief = angles(flat, ref, mask)
    return {
        "mean": float(e.mean()),
        "p99": float(np.percentile(e, 99)),
        "relief_mean": float(relief.mean()),
        "texels": int(mask.sum()),
        "cycles_s": cycles_s,
        "ours_s": ours_s,
    }


@pytest.mark.parametrize(
    ("kind", "mean", "p99"),
    [("plane", 0.1, 1.0), ("stretched", 0.5, 3.0), ("sphere", 0.5, 3.0)],
)
def test_converted_map_equals_cycles_bake(kind, mean, p99):
    r = convert_and_compare(kind, distance=0.02 if kind != "sphere" else 0.05)
    print(f"{kind}: {r}")
    assert r["texels"] > SIZE * SIZE // 2
    assert r["relief_mean"] > 2.0, r
    assert r["mean"] < mean and r["p99"] < p99, r


def test_strength_and_invert_follow_the_bump_node():
    r = convert_and_compare("plane", distance=0.03, strength=0.6, invert=True)
    print(f"strength 0.6, invert: {r}")
    assert r["relief_mean"] > 1.0, r
    assert r["mean"] < 0.1 and r["p99"] < 1.0, r


def test_the_bump_chain_is_kept_muted_and_other_bumps_are_reported():
    obj, mat = bump_scene("plane")
    nt = mat.node_tree
    noise = nt.nodes.new("ShaderNodeTexNoise")
    other = nt.nodes.new("ShaderNodeBump")
    nt.links.new(noise.outputs["Fac"], other.inputs["Height"])
    nt.links.new(other.outputs["Normal"], nt.nodes["Principled BSDF"].inputs["Coat Normal"])
    obj.select_set(True)
    assert "FINISHED" in bpy.ops.bumpbake.bump_to_normal()
    last = bpy.context.window_manager["bumpbake_last_report"]
    assert "1 Bump node(s) converted" in last and "Noise Texture" in last, last
    bumps = [n for n in nt.nodes if n.type == "BUMP"]
    kept = next(n for n in bumps if n.mute)
    assert kept.parent is not None and kept.parent.type == "FRAME"
    assert not kept.outputs["Normal"].is_linked
    bsdf = nt.nodes["Principled BSDF"]
    assert bsdf.inputs["Normal"].links[0].from_node.type == "NORMAL_MAP"
    assert bsdf.inputs["Coat Normal"].links[0].from_node == other


def test_export_gltf_bakes_bump_nodes_for_the_file_and_leaves_the_scene(tmp_path):
    _, mat = bump_scene("sphere", distance=0.05)
    before = sorted(n.bl_idname for n in mat.node_tree.nodes)
    out = tmp_path / "bumpy.glb"
    assert "FINISHED" in bpy.ops.bumpbake.export_gltf(filepath=str(out))
    assert sorted(n.bl_idname for n in mat.node_tree.nodes) == before
    doc = glb_json(out)
    m = doc["materials"][0]
    assert "normalTexture" in m, m
    assert "TANGENT" in doc["meshes"][0]["primitives"][0]["attributes"]
    got = findings(out)
    assert not [c for c, f in got.items() if f["severity"] == "error"], got
    import bumpbake

    assert bumpbake.validate(out, strict=True)["summary"]["errors"] == 0
    keep_for_khronos(out, "bump_sphere.glb")
