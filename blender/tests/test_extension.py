"""The Blender extension in headless Blender (bpy 5.0.1): installed from the zip
`blender/build.sh` makes, run on scenes built here, its files checked by bumpbake's validator
against what the stock exporter writes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import clear_scene, findings, glb_json, keep_for_khronos, new_material

bpy = pytest.importorskip("bpy")


def suzanne_with_a_normal_map(tmp: Path):
    clear_scene()
    bpy.ops.mesh.primitive_monkey_add()
    obj = bpy.context.object
    bpy.ops.object.shade_smooth()
    mat = new_material("Skin")
    nt = mat.node_tree
    size = 64
    y, x = np.mgrid[0:size, 0:size] / size
    n = np.stack([0.3 * np.sin(12 * x), 0.3 * np.cos(9 * y), np.ones_like(x)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    rgba = np.concatenate([n * 0.5 + 0.5, np.ones((size, size, 1))], -1).astype(np.float32)
    img = bpy.data.images.new("bumps", size, size)
    img.pixels.foreach_set(rgba.reshape(-1))
    img.filepath_raw = str(tmp / "bumps.png")
    img.file_format = "PNG"
    img.save()
    img.colorspace_settings.name = "Non-Color"
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = img
    nm = nt.nodes.new("ShaderNodeNormalMap")
    bsdf = nt.nodes["Principled BSDF"]
    nt.links.new(tex.outputs["Color"], nm.inputs["Color"])
    nt.links.new(nm.outputs["Normal"], bsdf.inputs["Normal"])
    obj.data.materials.append(mat)
    return obj


def test_export_gltf_writes_mikktspace_tangents_where_the_stock_exporter_does_not(tmp_path):
    suzanne_with_a_normal_map(tmp_path)
    stock = tmp_path / "stock.glb"
    bpy.ops.export_scene.gltf(filepath=str(stock), export_tangents=True)
    assert "TANGENT_MIKK_ANGLE" in findings(stock)

    ours = tmp_path / "ours.glb"
    assert "FINISHED" in bpy.ops.bumpbake.export_gltf(filepath=str(ours))
    got = findings(ours)
    assert "TANGENT_MIKK_ANGLE" not in got
    assert not [c for c, f in got.items() if f["severity"] == "error"], got
    doc = glb_json(ours)
    prim = doc["meshes"][0]["primitives"][0]
    assert "TANGENT" in prim["attributes"] and "normalTexture" in doc["materials"][prim["material"]]
    assert "bumpbake validate: 0 error(s)" in bpy.context.window_manager["bumpbake_last_report"]
    keep_for_khronos(ours, "suzanne.glb")


def test_the_stock_dialogs_checkbox_does_the_same(tmp_path):
    suzanne_with_a_normal_map(tmp_path)
    bpy.context.scene.bumpbake_export.enabled = True
    try:
        out = tmp_path / "hooked.glb"
        bpy.ops.export_scene.gltf(filepath=str(out), export_tangents=True)
    finally:
        bpy.context.scene.bumpbake_export.enabled = False
    assert "TANGENT_MIKK_ANGLE" not in findings(out)


def test_ktx2_normal_maps(tmp_path):
    suzanne_with_a_normal_map(tmp_path)
    out = tmp_path / "ktx2.glb"
    assert "FINISHED" in bpy.ops.bumpbake.export_gltf(filepath=str(out), textures="ktx2")
    doc = glb_json(out)
    assert "KHR_texture_basisu" in doc.get("extensionsUsed", [])
    got = findings(out)
    assert "TANGENT_MIKK_ANGLE" not in got
    assert not [c for c, f in got.items() if f["severity"] == "error"], got


def test_a_path_that_is_not_gltf_is_refused(tmp_path):
    with pytest.raises(RuntimeError, match=r"give a \.glb or \.gltf path"):
        bpy.ops.bumpbake.export_gltf(filepath=str(tmp_path / "model.fbx"))


def test_the_panels_are_in_material_and_render_bake():
    material = bpy.types.Panel.bl_rna_get_subclass_py("BUMPBAKE_PT_material")
    bake = bpy.types.Panel.bl_rna_get_subclass_py("BUMPBAKE_PT_bake")
    assert material is not None and material.bl_context == "material"
    assert bake is not None and bake.bl_parent_id == "CYCLES_RENDER_PT_bake"
