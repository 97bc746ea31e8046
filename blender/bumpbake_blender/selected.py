"""Selected to active: the selected meshes (HIGH) baked onto the active one's UV layout (LOW) by
bumpbake's `bake --from`, as Cycles' "Selected to Active" normal bake does, the map loaded and
wired into the active object's material.

The meshes go to bumpbake as files written here with NumPy, as the viewport shows them
(modifiers applied, world space), as binary PLY: LOW a vertex per corner with its normal and UV,
HIGH with shared vertices when its corner normals are its vertex normals, else a vertex per corner."""

from __future__ import annotations

import os
import tempfile
import time
from dataclasses import dataclass

import bpy
import numpy as np

from . import mesh_arrays


@dataclass
class Result:
    image: bpy.types.Image
    report: dict
    seconds: float


def write_low_ply(path: str, c: mesh_arrays.Corners):
    """A vertex per corner, with its normal and UV (bumpbake's MikkTSpace finds the shared
    vertices by value, as the reference does)."""
    n = len(c.positions)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {n}\nproperty float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n"
        f"element face {n // 3}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    vert = np.concatenate([c.positions, c.normals, c.uvs], axis=1).astype("<f4")
    _write_ply(path, header, vert, np.arange(n, dtype=np.int32).reshape(-1, 3))


def _write_ply(path: str, header: str, vert: np.ndarray, tris: np.ndarray):
    face = np.empty(len(tris), dtype=[("n", "u1"), ("i", "<i4", 3)])
    face["n"] = 3
    face["i"] = tris
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(vert.tobytes())
        f.write(face.tobytes())


def high_arrays(obj, depsgraph) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World-space positions, unit normals and triangles of `obj` as shown."""
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    try:
        mesh.calc_loop_triangles()
        tris = mesh_arrays._get(mesh.loop_triangles, "loops", 3, np.int32)
        verts = mesh_arrays._get(mesh.loops, "vertex_index", 1, np.int32)
        co = mesh_arrays._get(mesh.vertices, "co", 3)
        corner_n = mesh_arrays._get(mesh.corner_normals, "vector", 3)
        vert_n = mesh_arrays._get(mesh.vertex_normals, "vector", 3)
    finally:
        ev.to_mesh_clear()
    m = np.array(obj.matrix_world, dtype=np.float64)
    lin = m[:3, :3]
    nm = np.linalg.inv(lin).T
    loops = tris.reshape(-1)
    if np.allclose(corner_n, vert_n[verts], atol=1e-6):
        positions, normals, triangles = co, vert_n, verts[tris]
    else:
        positions, normals, triangles = co[verts[loops]], corner_n[loops], np.arange(len(loops)).reshape(-1, 3)
    p = positions.astype(np.float64) @ lin.T + m[:3, 3]
    nn = normals.astype(np.float64) @ nm.T
    nn /= np.maximum(np.linalg.norm(nn, axis=1, keepdims=True), 1e-30)
    if np.linalg.det(lin) < 0:
        triangles = triangles[:, ::-1]
    return p.astype(np.float32), nn.astype(np.float32), np.ascontiguousarray(triangles, dtype=np.int32)


def write_high_ply(path: str, p: np.ndarray, n: np.ndarray, tris: np.ndarray):
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(p)}\nproperty float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    _write_ply(path, header, np.concatenate([p, n], axis=1).astype("<f4"), tris)


def bake(
    active,
    selected,
    size: int = 1024,
    extrusion: float = 0.0,
    max_ray_distance: float = 0.0,
    samples: int = 1,
    uv_map: str | None = None,
    padding: int = 16,
) -> Result:
    """Bakes `selected` onto `active`'s UVs with bumpbake; returns the image (packed, Non-Color).

    Blender's rays start `extrusion` outside LOW and reach `max_ray_distance` from there (0: no
    limit); bumpbake's reach is `ray_front` outside and `ray_back` inside LOW, so `ray_front` =
    extrusion and `ray_back` = max_ray_distance - extrusion (LOW's diagonal when unlimited).
    With both at 0, bumpbake's default reach (5% of LOW's diagonal each way) is used."""
    import bumpbake

    start = time.perf_counter()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    uv = uv_map or next((u.name for u in active.data.uv_layers if u.active_render), None)
    if uv is None:
        raise ValueError(f"{active.name} has no UV map to bake into")
    low = mesh_arrays.corners(active, uv, None, depsgraph)
    with tempfile.TemporaryDirectory(prefix="bumpbake-") as tmp:
        low_path = os.path.join(tmp, "low.ply")
        write_low_ply(low_path, low)
        highs = []
        for k, obj in enumerate(selected):
            path = os.path.join(tmp, f"high{k}.ply")
            write_high_ply(path, *high_arrays(obj, depsgraph))
            highs.append(path)
        options = {"size": f"{size}", "samples": samples, "padding": padding}
        if extrusion > 0 or max_ray_distance > 0:
            lo, hi = low.positions.min(axis=0), low.positions.max(axis=0)
            diagonal = float(np.linalg.norm(hi - lo))
            options["ray_front"] = float(extrusion)
            options["ray_back"] = float(max_ray_distance - extrusion) if max_ray_distance > 0 else diagonal
            options["ray_back"] = max(options["ray_back"], 0.0)
        png = os.path.join(tmp, "map.png")
        report = bumpbake.bake_from(
            low_path, highs, os.path.join(tmp, "out.glb"), map_out=png, bits16=True, matching="none", **options
        )
        img = bpy.data.images.load(png)
        img.name = f"{active.name}_baked_normal"
        img.colorspace_settings.name = "Non-Color"
        img.pack()
    return Result(img, report, time.perf_counter() - start)


def wire_into(obj, image, uv_map: str | None = None):
    """A Normal Map node with `image` into the Normal of the active material's first BSDF (a
    new material with a Principled BSDF when the object has none)."""
    mat = obj.active_material
    if mat is None:
        mat = bpy.data.materials.new(f"{obj.name}_baked")
        obj.data.materials.append(mat)
    nt = mat.node_tree
    bsdf = next((n for n in nt.nodes if n.type == "BSDF_PRINCIPLED"), None)
    if bsdf is None:
        bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
        out = next((n for n in nt.nodes if n.type == "OUTPUT_MATERIAL"), None) or nt.nodes.new(
            "ShaderNodeOutputMaterial"
        )
        nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    uv = uv_map or next((u.name for u in obj.data.uv_layers if u.active_render), "")
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.location = (bsdf.location.x - 500, bsdf.location.y - 400)
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nmap.space = "TANGENT"
    nmap.uv_map = uv
    nmap.location = (bsdf.location.x - 220, bsdf.location.y - 400)
    nt.links.new(tex.outputs["Color"], nmap.inputs["Color"])
    nt.links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])
    for n in nt.nodes:
        n.select = False
    tex.select = True
    nt.nodes.active = tex
    return mat


__all__ = ["Result", "bake", "wire_into"]
