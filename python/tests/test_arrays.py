"""bumpbake.tangents and bumpbake.normalmap against what the command line writes, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import Gltf, read_png, run_cli, write_png

import bumpbake


def written_frames(path):
    """(positions, normals, uvs, indices, tangents) of every primitive the command line wrote."""
    g = Gltf(path)
    for p in g.primitives():
        a = p["attributes"]
        if "TANGENT" not in a:
            continue
        yield (
            g.accessor(a["POSITION"]),
            g.accessor(a["NORMAL"]),
            g.accessor(a["TEXCOORD_0"]),
            g.accessor(p["indices"]),
            g.accessor(a["TANGENT"]),
            g.accessor(a["_BITANGENT"]) if "_BITANGENT" in a else None,
        )


def assert_same_bits(got, want):
    assert got.shape == want.shape and got.dtype == want.dtype
    differ = got.view(np.uint32) != want.view(np.uint32)
    assert not differ.any(), (
        f"{differ.any(axis=1).sum()} of {len(got)} rows differ; first {np.argmax(differ.any(axis=1))}"
    )


@pytest.mark.parametrize(
    "fixture, extra", [("bake/torus.obj", []), ("khronos/NormalTangentMirrorTest.glb", ["--overwrite"])]
)
def test_tangents_reproduce_the_command_lines_accessor(tmp_path, fixtures, fixture, extra):
    out = tmp_path / "out.gltf"
    run_cli("tangents", fixtures / fixture, "-o", out, "--all", "--bitangents", *extra)
    checked = 0
    for pos, nor, uv, idx, tan, bit in written_frames(out):
        t, b = bumpbake.tangents(pos, nor, uv, idx, bitangents=True)
        assert_same_bits(t, tan)
        assert_same_bits(b, bit)
        assert set(np.unique(t[:, 3])) <= {-1.0, 1.0}
        checked += 1
    assert checked


def test_float64_inputs_and_bottom_left_uvs(tmp_path, fixtures):
    out = tmp_path / "torus.glb"
    run_cli("tangents", fixtures / "bake/torus.obj", "-o", out, "--all")
    pos, nor, uv, idx, tan, _ = next(written_frames(out))
    t = bumpbake.tangents(pos.astype(np.float64), nor.astype(np.float64), uv.astype(np.float64), idx.reshape(-1, 3))
    assert_same_bits(t, tan)
    # Bottom-left UVs (Blender's, OBJ's) are turned down as the OBJ reader turns them: 1 - v.
    up = uv.copy()
    up[:, 1] = np.float32(1) - up[:, 1]
    down = up.copy()
    down[:, 1] = np.float32(1) - down[:, 1]
    assert_same_bits(
        bumpbake.tangents(pos, nor, up, idx, uv_origin="bottom-left"), bumpbake.tangents(pos, nor, down, idx)
    )
    assert not np.array_equal(bumpbake.tangents(pos, nor, up, idx), tan)


def test_per_corner_arrays_and_shared_vertices_agree(tmp_path, fixtures):
    out = tmp_path / "mirror.glb"
    run_cli("tangents", fixtures / "khronos/NormalTangentMirrorTest.glb", "-o", out, "--overwrite")
    pos, nor, uv, idx, tan, _ = next(written_frames(out))
    # Blender hands over one row per corner (loops): no indices.
    t = bumpbake.tangents(pos[idx], nor[idx], uv[idx])
    assert_same_bits(t, tan[idx])
    assert_same_bits(bumpbake.tangents(pos, nor, uv, idx, corners=True), tan[idx])


def grid(n: int):
    """An n x n quad grid, 2 n^2 triangles, a wavy surface with UVs mirrored across the middle."""
    u, v = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    z = 0.05 * np.sin(7 * u) * np.cos(5 * v)
    pos = np.stack([u, v, z], -1).reshape(-1, 3).astype(np.float32)
    dzdu = 0.35 * np.cos(7 * u) * np.cos(5 * v)
    dzdv = -0.25 * np.sin(7 * u) * np.sin(5 * v)
    nor = np.stack([-dzdu, -dzdv, np.ones_like(u)], -1)
    nor = (nor / np.linalg.norm(nor, axis=-1, keepdims=True)).reshape(-1, 3).astype(np.float32)
    uv = np.stack([np.abs(u - 0.5) * 2, v * 3], -1).reshape(-1, 2).astype(np.float32)
    i = np.arange(n * n)
    a = (i // n) * (n + 1) + i % n
    quads = np.stack([a, a + 1, a + n + 2, a, a + n + 2, a + n + 1], -1)
    return pos, nor, uv, quads.reshape(-1).astype(np.uint32)


def write_gltf(path, pos, nor, uv, idx):
    import json

    blobs = [pos.tobytes(), nor.tobytes(), uv.tobytes(), idx.tobytes()]
    views, at = [], 0
    for b in blobs:
        views.append({"buffer": 0, "byteOffset": at, "byteLength": len(b)})
        at += len(b)
    (path.parent / "grid.bin").write_bytes(b"".join(blobs))
    acc = [
        {
            "bufferView": 0,
            "componentType": 5126,
            "count": len(pos),
            "type": "VEC3",
            "min": pos.min(0).tolist(),
            "max": pos.max(0).tolist(),
        },
        {"bufferView": 1, "componentType": 5126, "count": len(nor), "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": len(uv), "type": "VEC2"},
        {"bufferView": 3, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
    ]
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "grid.bin", "byteLength": at}],
        "bufferViews": views,
        "accessors": acc,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    path.write_text(json.dumps(doc))


def test_a_million_triangles(tmp_path):
    pos, nor, uv, idx = grid(708)  # 1 002 528 triangles
    src = tmp_path / "grid.gltf"
    write_gltf(src, pos, nor, uv, idx)
    out = tmp_path / "out.glb"
    run_cli("tangents", src, "-o", out, "--all")
    pos2, nor2, uv2, idx2, tan, _ = next(written_frames(out))
    assert len(idx2) // 3 == len(idx) // 3 > 1_000_000
    assert_same_bits(bumpbake.tangents(pos2, nor2, uv2, idx2), tan)


def heights(rows: int, cols: int) -> np.ndarray:
    y, x = np.mgrid[0:rows, 0:cols]
    return 0.5 + 0.25 * np.sin(x / 5.0) * np.cos(y / 7.0) + 0.2 * ((x // 16 + y // 16) % 2)


@pytest.mark.parametrize("bits, dtype", [(8, np.uint8), (16, np.uint16)])
@pytest.mark.parametrize(
    "options",
    [
        {"strength": 6.0},
        {"height_range": 0.02, "texel_size": 0.001, "convention": "directx", "filter": "scharr", "wrap": "repeat"},
        {"strength": 3.0, "invert": True, "filter": "spectral", "alpha": True},
    ],
)
def test_normalmap_equals_the_command_lines_png(tmp_path, bits, dtype, options):
    h = np.round(heights(48, 64) * np.iinfo(dtype).max).astype(dtype)
    src = tmp_path / "h.png"
    write_png(src, h)
    out = tmp_path / "n.png"
    flags = []
    for k, v in options.items():
        flag = "--" + k.replace("_", "-")
        flags += ["--alpha", "height"] if k == "alpha" else ([flag] if v is True else [flag, str(v)])
    run_cli("normalmap", src, "-o", out, "--bits", str(bits), *flags)
    want = read_png(out)
    got = bumpbake.normalmap(h, bits=bits, **options)
    assert got.dtype == dtype and got.shape == want.shape
    assert np.array_equal(got, want)


def test_normalmap_float_output_is_unit_vectors_and_the_report_warns_of_flat_maps():
    h = heights(32, 32).astype(np.float32)
    n = bumpbake.normalmap(h, bits=32, strength=4.0)
    assert n.dtype == np.float32 and n.shape == (32, 32, 3)
    assert np.allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-6)
    assert (n[..., 2] > 0).all()
    flat = np.full((16, 16), 0.5, np.float32)
    flat[8, 8] = 0.5001
    m, report = bumpbake.normalmap(flat, report=True)
    assert report["warnings"], report
    assert np.array_equal(m[0, 0], [128, 128, 255])


def test_progress_is_called_per_stage():
    calls = []
    bumpbake.normalmap(heights(256, 64).astype(np.float32), progress=lambda *a: calls.append(a))
    assert calls[0][0] == "normalmap" and calls[-1][1] == calls[-1][2] == 256
    assert all(c[3] == "rows" for c in calls)


def stretched_plane(tmp_path):
    """A plane [0, 3] x [0, 1] (z up) as an OBJ, and the same as arrays (OBJ's UVs: bottom-left)."""
    p, n, uv, idx = _plane_arrays()
    lines = [f"v {a} {b} {c}" for a, b, c in p] + [f"vt {a} {b}" for a, b in uv] + ["vn 0 0 1"]
    lines += [f"f {' '.join(f'{i + 1}/{i + 1}/1' for i in t)}" for t in idx]
    obj = tmp_path / "plane.obj"
    obj.write_text("\n".join(lines) + "\n")
    return obj, p, n, uv, idx


def test_bump_to_normal_equals_bake_with_a_height_range(tmp_path):
    obj, p, n, uv, idx = stretched_plane(tmp_path)
    h = np.round(heights(64, 64) * 65535).astype(np.uint16)
    src = tmp_path / "h.png"
    write_png(src, h)
    out = tmp_path / "out.gltf"
    bumpbake.bake(obj, out, height=src, height_range=0.05, bits16=True, images="external")
    png = next(tmp_path.glob("out_image*.png"))
    want = read_png(png).astype(np.int64)
    got = bumpbake.bump_to_normal(
        h, p, n, uv, idx, distance=0.05, uv_origin="bottom-left", filter="sobel", wrap="repeat", bits=16
    )
    assert got.dtype == np.uint16 and got.shape == want.shape
    # The command line moves the mesh to its own centre before the same float arithmetic.
    assert np.abs(got.astype(np.int64) - want).max() <= 2
    # And not a flat map: the relief is there.
    assert np.abs(want[..., 0] - 32768).max() > 1000


def test_bump_to_normal_given_tangents_and_top_left_uvs_agree():
    p, n, uv, idx = _plane_arrays()
    h = heights(32, 32).astype(np.float32)
    base = bumpbake.bump_to_normal(h, p, n, uv, idx, distance=0.1, uv_origin="bottom-left", bits=32)
    flipped = uv.copy()
    flipped[:, 1] = 1 - flipped[:, 1]
    assert np.array_equal(base, bumpbake.bump_to_normal(h, p, n, flipped, idx, distance=0.1, bits=32))
    t = bumpbake.tangents(p, n, uv, idx, uv_origin="bottom-left")
    given = bumpbake.bump_to_normal(h, p, n, uv, idx, t, distance=0.1, uv_origin="bottom-left", bits=32)
    assert np.array_equal(base, given)
    assert np.allclose(np.linalg.norm(base, axis=2), 1, atol=1e-6)
    inverted = bumpbake.bump_to_normal(h, p, n, uv, idx, distance=0.1, invert=True, uv_origin="bottom-left", bits=32)
    assert np.allclose(inverted[..., :2], -base[..., :2], atol=1e-6)
    _, info = bumpbake.bump_to_normal(h, p, n, uv, idx, distance=0.1, uv_origin="bottom-left", report=True)
    assert info["covered"] == 32 * 32 and info["uncovered"] == 0


def _plane_arrays():
    p = np.array([[0, 0, 0], [3, 0, 0], [3, 1, 0], [0, 1, 0]], np.float32)
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    n = np.tile(np.array([0, 0, 1], np.float32), (4, 1))
    return p, n, uv, np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


def test_bump_to_normal_refuses_bad_input():
    p, n, uv, idx = _plane_arrays()
    h = heights(8, 8).astype(np.float32)
    with pytest.raises(bumpbake.UsageError, match="distance"):
        bumpbake.bump_to_normal(h, p, n, uv, idx, distance=float("nan"))
    with pytest.raises(bumpbake.InputError, match="normals has 3 rows"):
        bumpbake.bump_to_normal(h, p, n[:3], uv, idx, distance=0.1)
    with pytest.raises(bumpbake.InputError, match="indices"):
        bumpbake.bump_to_normal(h, p, n, uv, idx + 4, distance=0.1)
