"""The file-level calls return the command line's JSON; errors raise the typed exceptions, in
keywords."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from conftest import cli, run_cli

import bumpbake


def timeless(v):
    """The record without its run times, which differ between any two runs."""
    if isinstance(v, dict):
        return {k: timeless(x) for k, x in v.items() if k != "timings_ms"}
    if isinstance(v, list):
        return [timeless(x) for x in v]
    return v


def cli_json(*args):
    p = run_cli(*args, check=False)
    assert p.returncode in (0, 1), p.stderr
    return json.loads(p.stdout)


def test_inspect_and_validate_equal_the_cli_json(fixtures):
    mirror = fixtures / "khronos/NormalTangentMirrorTest.glb"
    assert bumpbake.inspect(mirror) == cli_json("inspect", mirror, "--json")
    got = bumpbake.validate(mirror, strict=True, max_angle_deg=0.5)
    assert got == cli_json("validate", mirror, "--format", "json", "--strict", "--max-angle-deg", "0.5")
    assert got["summary"]["errors"] == 0 and got["strict"] is True


def test_tangents_file_bake_and_textures_equal_the_cli_json(tmp_path, fixtures):
    torus = fixtures / "bake/torus.obj"
    a, b = tmp_path / "a.glb", tmp_path / "b.glb"
    got = bumpbake.tangents_file(torus, a, all=True, bitangents=True)
    want = cli_json("tangents", torus, "-o", b, "--all", "--bitangents", "--json")
    assert timeless(got) | {"output": ""} == timeless(want) | {"output": ""}
    assert a.read_bytes() == b.read_bytes()

    got = bumpbake.bake(torus, a, strength=3.0)
    want = cli_json("bake", torus, "-o", b, "--strength", "3", "--json")
    assert timeless(got) | {"output": ""} == timeless(want) | {"output": ""}
    assert a.read_bytes() == b.read_bytes()
    assert bumpbake.validate(a)["summary"]["errors"] == 0

    ka, kb = tmp_path / "a-k.glb", tmp_path / "b-k.glb"
    got = bumpbake.textures(a, ka)
    want = cli_json("textures", b, "-o", kb, "--json")
    assert timeless(got) | {"output": "", "input": ""} == timeless(want) | {"output": "", "input": ""}
    assert ka.read_bytes() == kb.read_bytes()


def test_bake_from_bakes_and_reports_progress(tmp_path, fixtures):
    torus = fixtures / "bake/torus.obj"
    out = tmp_path / "low.glb"
    calls = []
    got = bumpbake.bake_from(torus, torus, out, size=64, progress=lambda *a: calls.append(a))
    assert got["status"] == "ok" and out.exists()
    assert calls and all(isinstance(c[0], str) and c[1] <= c[2] for c in calls)
    assert bumpbake.validate(out)["summary"]["errors"] == 0


def test_a_missing_file_is_an_input_error(tmp_path):
    with pytest.raises(bumpbake.InputError) as e:
        bumpbake.validate(tmp_path / "missing.glb")
    assert "missing.glb" in str(e.value) and "--" not in str(e.value)
    bad = tmp_path / "bad.gltf"
    bad.write_text('{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 7}}]}]}')
    with pytest.raises(bumpbake.InputError):
        bumpbake.tangents_file(bad, tmp_path / "out.glb")
    assert not (tmp_path / "out.glb").exists()


@pytest.mark.parametrize(
    "call, keyword",
    [
        (lambda: bumpbake.normalmap(np.zeros((4, 4)), strength=-1), "strength"),
        (lambda: bumpbake.normalmap(np.zeros((4, 4)), convention="sideways"), "convention"),
        (lambda: bumpbake.normalmap(np.zeros((4, 4)), filter="gauss"), "filter"),
        (lambda: bumpbake.normalmap(np.zeros((4, 4)), bits=12), "bits"),
        (lambda: bumpbake.normalmap(np.zeros((4, 4)), height_range=0.1), "texel_size"),
        (lambda: bumpbake.normalmap(np.zeros((4, 4)), height_range=0.1, texel_size=-2), "texel_size"),
        (lambda: bumpbake.tangents(np.zeros((3, 3)), None, np.zeros((3, 2)), uv_origin="middle"), "uv_origin"),
    ],
)
def test_bad_options_are_usage_errors_naming_the_keyword(call, keyword):
    with pytest.raises(bumpbake.UsageError) as e:
        call()
    assert isinstance(e.value, ValueError) and isinstance(e.value, bumpbake.Error)
    assert keyword in str(e.value) and "--" not in str(e.value), str(e.value)


@pytest.mark.parametrize(
    "options, keyword",
    [
        ({"max_angle_deg": "wide"}, "max_angle_deg"),
        ({"image_convention": "sideways"}, "image_convention"),
        ({"max_angle": 2}, "max_angle_deg"),
    ],
)
def test_file_call_options_are_checked_by_the_command_lines_parser(fixtures, options, keyword):
    with pytest.raises(bumpbake.UsageError) as e:
        bumpbake.validate(fixtures / "khronos/NormalTangentMirrorTest.glb", **options)
    assert keyword in str(e.value) and "--" not in str(e.value), str(e.value)


@pytest.mark.parametrize(
    "options, words",
    [
        ({"ktx2_quality": 9}, "ktx2_quality=9: UASTC levels are 0 to 4"),
        ({"ktx2": "etc1s", "ktx2_quality": 0}, "ktx2_quality=0: ETC1S quality is 1 to 255"),
        ({"specular_aa_threshold": 3}, "specular_aa_threshold=3: give a number from 0 to 1"),
    ],
)
def test_the_librarys_value_checks_name_the_keyword(tmp_path, fixtures, options, words):
    out = tmp_path / "o.glb"
    with pytest.raises(bumpbake.UsageError) as e:
        bumpbake.textures(fixtures / "bake/torus.obj", out, **options)
    assert words in str(e.value) and "--" not in str(e.value), str(e.value)
    assert not out.exists()


def test_the_command_lines_own_checks_are_worded_in_keywords(tmp_path, fixtures):
    with pytest.raises(bumpbake.UsageError) as e:
        bumpbake.bake_from(fixtures / "bake/torus.obj", fixtures / "bake/torus.obj", tmp_path / "o.glb", samples=99)
    assert "samples" in str(e.value) and "--" not in str(e.value), str(e.value)


@pytest.mark.parametrize(
    "call",
    [
        lambda: bumpbake.tangents(np.zeros((3, 2)), None, np.zeros((3, 2))),
        lambda: bumpbake.tangents(np.zeros((3, 3)), None, np.zeros((3, 2)), [0, 1, 5]),
        lambda: bumpbake.tangents(np.full((3, 3), np.nan), None, np.zeros((3, 2))),
        lambda: bumpbake.normalmap(np.zeros((4, 4, 3))),
        lambda: bumpbake.normalmap(np.array([[0.0, np.inf]])),
    ],
)
def test_arrays_that_cannot_be_used_are_input_errors(call):
    with pytest.raises(bumpbake.InputError) as e:
        call()
    assert "--" not in str(e.value)


def test_shared_vertices_with_different_frames_are_refused_per_vertex():
    # Two triangles sharing an edge, the second's UVs mirrored: the shared vertices' corners
    # get opposite handedness, which one row per vertex cannot hold.
    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], np.float32)
    nor = np.tile([0, 0, 1], (4, 1)).astype(np.float32)
    uv = np.array([[0, 0], [1, 0], [0, 1], [0.2, 0.2]], np.float32)
    idx = np.array([0, 1, 2, 1, 3, 2], np.uint32)
    with pytest.raises(bumpbake.InputError, match="corners=True"):
        bumpbake.tangents(pos, nor, uv, idx)
    t = bumpbake.tangents(pos, nor, uv, idx, corners=True)
    assert t.shape == (6, 4) and np.allclose(np.linalg.norm(t[:, :3], axis=1), 1)


def test_the_console_script_and_python_m_run_the_command_line(fixtures):
    v = subprocess.run([*cli(), "--version"], capture_output=True, text=True, check=True)
    assert v.stdout.strip() == f"bumpbake {bumpbake.__version__}"
    m = subprocess.run(
        [sys.executable, "-m", "bumpbake", "validate", fixtures / "khronos/NormalTangentMirrorTest.glb"],
        capture_output=True,
        text=True,
    )
    assert m.returncode == 0 and "PASS" in m.stderr
    bad = subprocess.run([sys.executable, "-m", "bumpbake", "validate", "missing.glb"], capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.startswith("bumpbake: ")


def test_notes_in_the_dicts_name_keywords(tmp_path, fixtures):
    mirror = fixtures / "khronos/NormalTangentMirrorTest.glb"
    got = bumpbake.tangents_file(mirror, tmp_path / "m.glb")
    reason = got["primitives"][0]["reason"]
    assert "(overwrite replaces them)" in reason and "--" not in reason, reason
    # The command line words the same note with its flag.
    want = cli_json("tangents", mirror, "-o", tmp_path / "c.glb", "--json")
    assert "--overwrite" in want["primitives"][0]["reason"]


def test_file_calls_print_nothing(tmp_path, fixtures, capfd):
    mirror = fixtures / "khronos/NormalTangentMirrorTest.glb"
    bumpbake.validate(mirror)
    bumpbake.inspect(mirror)
    bumpbake.tangents_file(mirror, tmp_path / "m.glb", overwrite=True)
    out, err = capfd.readouterr()
    assert out == "" and err == ""
