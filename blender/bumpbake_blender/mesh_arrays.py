"""An object's evaluated mesh as the per-corner NumPy arrays bumpbake takes: world-space
positions, corner normals and MikkTSpace tangents (Blender's own, the ones Cycles' Normal Map node
draws with) and the UVs of one map, over the triangles of the chosen material slots."""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np


@dataclass
class Corners:
    positions: np.ndarray  # (N, 3) float32, world space
    normals: np.ndarray  # (N, 3)
    tangents: np.ndarray  # (N, 4): xyz, w = bitangent sign
    uvs: np.ndarray  # (N, 2), Blender's (origin bottom-left)

    @property
    def triangles(self) -> int:
        return len(self.positions) // 3


def _get(seq, attr: str, width: int, dtype=np.float32) -> np.ndarray:
    out = np.empty(len(seq) * width, dtype=dtype)
    seq.foreach_get(attr, out)
    return out.reshape(-1, width) if width > 1 else out


def corners(obj: bpy.types.Object, uv_map: str, slots: set[int] | None, depsgraph=None) -> Corners:
    """The triangles of `obj` whose material slot is in `slots` (None: all), as the viewport and
    Cycles see it (modifiers applied), placed by its world matrix."""
    depsgraph = depsgraph or bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    try:
        if uv_map not in mesh.uv_layers:
            raise ValueError(f"{obj.name} has no UV map '{uv_map}'")
        mesh.calc_loop_triangles()
        mesh.calc_tangents(uvmap=uv_map)
        tris = _get(mesh.loop_triangles, "loops", 3, np.int32)
        if slots is not None:
            mats = _get(mesh.loop_triangles, "material_index", 1, np.int32)
            tris = tris[np.isin(mats, list(slots))]
        loops = tris.reshape(-1)
        verts = _get(mesh.loops, "vertex_index", 1, np.int32)
        co = _get(mesh.vertices, "co", 3)
        nor = _get(mesh.corner_normals, "vector", 3)
        tan = _get(mesh.loops, "tangent", 3)
        sign = _get(mesh.loops, "bitangent_sign", 1)
        uv = _get(mesh.uv_layers[uv_map].uv, "vector", 2)
    finally:
        ev.to_mesh_clear()
    m = np.array(obj.matrix_world, dtype=np.float64)
    lin = m[:3, :3]
    p = co[verts[loops]].astype(np.float64) @ lin.T + m[:3, 3]
    normal_matrix = np.linalg.inv(lin).T
    n = nor[loops].astype(np.float64) @ normal_matrix.T
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    t = tan[loops].astype(np.float64) @ lin.T
    t /= np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-30)
    # A mirroring transform turns the frame's handedness over.
    w = sign[loops] * (1.0 if np.linalg.det(lin) >= 0 else -1.0)
    return Corners(
        positions=p.astype(np.float32),
        normals=n.astype(np.float32),
        tangents=np.concatenate([t, w[:, None]], axis=1).astype(np.float32),
        uvs=uv[loops].astype(np.float32),
    )
