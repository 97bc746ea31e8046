"""bumpbake: exact MikkTSpace tangents, height maps to normal maps, validation and baking.

The engine of the ``bumpbake`` command line, on NumPy arrays and on files:

- :func:`tangents`, :func:`normalmap` and :func:`bump_to_normal` work on arrays (a DCC's mesh,
  a height field, a height field through a mesh);
- :func:`inspect`, :func:`validate`, :func:`tangents_file`, :func:`bake`, :func:`bake_from` and
  :func:`textures` work on files and return the JSON the command line prints, as dicts;
- ``python -m bumpbake`` and the ``bumpbake`` console script are the command line itself.

Options are keywords named after the command line's flags (``--height-range`` is
``height_range``). Errors raise :class:`InputError` (a file or array that cannot be used),
:class:`UsageError` (a bad option; also a ``ValueError``) or :class:`OutputError`, all
:class:`Error`. The engine runs with the GIL released; long calls take ``progress``, a callable
``progress(stage, done, total, unit)``.
"""

from __future__ import annotations

import difflib
import json
import os
from collections.abc import Sequence
from typing import Any, Callable, Union

import numpy as np

from bumpbake import _native
from bumpbake._errors import Error, InputError, OutputError, UsageError

__version__: str = _native.__version__

__all__ = [
    "Error",
    "InputError",
    "OutputError",
    "UsageError",
    "__version__",
    "bake",
    "bake_from",
    "bump_to_normal",
    "inspect",
    "normalmap",
    "tangents",
    "tangents_file",
    "textures",
    "validate",
]

PathLike = Union[str, "os.PathLike[str]"]
Progress = Callable[[str, int, int, str], Any]

FILTERS = ("central", "central4", "sobel", "scharr", "prewitt", "sobel5", "spectral")
WRAPS = ("clamp", "repeat", "mirror")
CONVENTIONS = ("opengl", "directx")
UV_ORIGINS = ("top-left", "bottom-left")


def _choice(keyword: str, value: Any, allowed: Sequence[str]) -> str:
    if not isinstance(value, str) or value not in allowed:
        raise UsageError(f"{keyword}={value!r} is not one of: {', '.join(allowed)}")
    return value


def _rows(name: str, a: Any, width: int) -> np.ndarray:
    """``a`` as a C-contiguous, aligned (N, width) float32 array, copied only if it is not one."""
    arr = np.asarray(a)
    if arr.dtype.kind not in "fiu":
        raise InputError(f"{name} holds {arr.dtype} values; give numbers (float32 or float64)")
    if arr.ndim != 2 or arr.shape[1] != width:
        raise InputError(f"{name} has shape {arr.shape}; expected (N, {width})")
    arr = np.require(arr, dtype=np.float32, requirements=["C", "A"])
    finite = np.isfinite(arr).all(axis=1)
    if not finite.all():
        row = int(np.argmin(finite))
        raise InputError(f"{name}[{row}] is {arr[row].tolist()}: every value must be finite")
    return arr


def _indices(a: Any, vertices: int) -> np.ndarray:
    arr = np.asarray(a)
    if arr.dtype.kind not in "iu":
        raise InputError(f"indices hold {arr.dtype} values; give integers")
    arr = arr.reshape(-1)
    if arr.size % 3:
        raise InputError(f"indices has {arr.size} entries; a triangle list has three per triangle")
    if arr.size and (arr.min() < 0 or arr.max() >= vertices):
        bad = int(np.argmax((arr < 0) | (arr >= vertices)))
        raise InputError(f"indices[{bad}] is {int(arr[bad])}, but there are {vertices} vertices")
    return np.require(arr, dtype=np.uint32, requirements=["C", "A"])


def _addr(a: np.ndarray | None) -> int:
    return 0 if a is None else int(a.__array_interface__["data"][0])


def tangents(
    positions: Any,
    normals: Any,
    uvs: Any,
    indices: Any = None,
    *,
    bitangents: bool = False,
    uv_origin: str = "top-left",
    corners: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """MikkTSpace tangents of a triangle list, bit for bit what ``bumpbake tangents`` writes.

    Args:
        positions: (N, 3) vertex positions, float32 or float64.
        normals: (N, 3) vertex normals, or None for flat normals (as glTF asks of a client).
        uvs: (N, 2) texture coordinates of the normal map's UV set.
        indices: (T*3,) or (T, 3) integer triangle corners; None: every three vertices are a
            triangle (per-corner arrays, as Blender's ``loops`` give them).
        bitangents: also return ``cross(N, T) * w`` per row, as ``--bitangents`` writes them.
        uv_origin: ``"top-left"``, UVs as glTF stores them (v down); ``"bottom-left"`` for
            OpenGL and Blender UVs (v up), turned over as the OBJ reader turns them.
        corners: one row per corner (``len(indices)`` rows) instead of one per vertex.

    Returns:
        (N, 4) float32 tangents ``(x, y, z, w)``, ``w`` = +1 or -1 (glTF's handedness sign);
        with ``bitangents``, a pair ``(tangents, bitangents)`` with (N, 3) bitangents. A vertex
        that no triangle uses gets a unit tangent orthogonal to its normal, ``w = 1``.

    Raises:
        InputError: arrays of the wrong shape or type, values that are not finite, indices out of
            range, or (per vertex) a vertex whose corners get different frames: a UV seam or a
            mirrored UV island runs through it, and one row cannot hold both. Pass
            ``corners=True``, or split that vertex.
        UsageError: an unknown ``uv_origin``.
    """
    _choice("uv_origin", uv_origin, UV_ORIGINS)
    pos = _rows("positions", positions, 3)
    n = len(pos)
    nor = None if normals is None else _rows("normals", normals, 3)
    uv = _rows("uvs", uvs, 2)
    for name, arr in (("normals", nor), ("uvs", uv)):
        if arr is not None and len(arr) != n:
            raise InputError(f"{name} has {len(arr)} rows but positions has {n}")
    idx = None if indices is None else _indices(indices, n)
    count = n if idx is None else idx.size
    if idx is None and n % 3:
        raise InputError(f"{n} vertices and no indices: a triangle list has three corners per triangle")
    per_vertex = idx is not None and not corners
    rows = n if per_vertex else count
    out_t = np.empty((rows, 4), dtype=np.float32)
    out_b = np.empty((rows, 3), dtype=np.float32) if bitangents else None
    report = json.loads(
        _native.tangents(
            n,
            _addr(pos),
            _addr(nor),
            _addr(uv),
            _addr(idx),
            count,
            uv_origin == "bottom-left",
            per_vertex,
            _addr(out_t),
            _addr(out_b),
        )
    )
    if report["conflicts"]:
        raise InputError(
            f"{report['conflicts']} vertices are shared by corners whose MikkTSpace frames differ "
            "(a UV seam or mirrored UVs run through them); pass corners=True for a frame per corner"
        )
    return (out_t, out_b) if out_b is not None else out_t


_mikktspace = tangents


def _height(a: Any) -> tuple[np.ndarray, str]:
    arr = np.asarray(a)
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[:, :, 0]
    if arr.ndim != 2:
        raise InputError(f"height has shape {arr.shape}; expected (rows, columns), one channel")
    if arr.dtype == np.uint8:
        kind = "u8"
    elif arr.dtype == np.uint16:
        kind = "u16"
    elif arr.dtype.kind == "f":
        kind, arr = "f32", arr.astype(np.float32, copy=False)
    else:
        raise InputError(f"height holds {arr.dtype} values; give uint8, uint16 or floats")
    if arr.size == 0:
        raise InputError(f"height has shape {arr.shape}: no texels")
    return np.require(arr, requirements=["C", "A"]), kind


def _strength(strength: float | None, height_range: float | None, texel_size: float | None) -> float:
    """The library's rule (the command line's too): one of strength, or height_range with texel_size."""
    for name, v in (("strength", strength), ("height_range", height_range), ("texel_size", texel_size)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer))):
            raise UsageError(f"{name}={v!r}: give a number")
    as_float = [None if v is None else float(v) for v in (strength, height_range, texel_size)]
    return _native.strength(*as_float)


def normalmap(
    height: Any,
    *,
    strength: float | None = None,
    height_range: float | None = None,
    texel_size: float | None = None,
    convention: str = "opengl",
    filter: str = "sobel",
    wrap: str = "clamp",
    invert: bool = False,
    bits: int = 8,
    alpha: bool = False,
    report: bool = False,
    progress: Progress | None = None,
) -> np.ndarray | tuple[np.ndarray, dict[str, Any]]:
    """A tangent-space normal map of a height field, texel for texel what ``bumpbake normalmap``
    writes.

    Args:
        height: (rows, columns) heights, row 0 at the top of the image. uint8 and uint16 read as
            the command line reads 8- and 16-bit images (over 255 and 65535); floats as they are.
        strength: how tall the whole 0..1 height range stands, in texels (default 1).
        height_range, texel_size: the height of the 0..1 range and the size of a texel, in
            metres (together, instead of ``strength``: strength = height_range / texel_size).
        convention: ``"opengl"`` (+Y up: glTF, Blender) or ``"directx"`` (+Y down).
        filter: the derivative filter, one of ``FILTERS`` (docs/normalmap.md measures each).
        wrap: what lies beyond the edges: ``"clamp"``, ``"repeat"`` (tiling) or ``"mirror"``.
        invert: the input is a depth map (white is deep).
        bits: 8 (uint8 texels), 16 (uint16) or 32 (float32 unit vectors, not encoded).
        alpha: a fourth channel holding the height (after ``invert``), for parallax mapping.
        report: also return a dict: the options, the steepest slope, ``engine_ms`` and the warnings (a map
            that came out nearly flat, with the strength that would show it).
        progress: ``progress(stage, done, total, unit)``, called as rows finish.

    Returns:
        (rows, columns, 3 or 4) array; with ``report``, ``(map, report_dict)``.
    """
    s = _strength(strength, height_range, texel_size)
    _choice("convention", convention, CONVENTIONS)
    _choice("filter", filter, FILTERS)
    _choice("wrap", wrap, WRAPS)
    if bits not in (8, 16, 32) or isinstance(bits, bool):
        raise UsageError(f"bits={bits!r}: use 8, 16 or 32")
    arr, kind = _height(height)
    rows, cols = arr.shape
    dtype = {8: np.uint8, 16: np.uint16, 32: np.float32}[bits]
    out = np.empty((rows, cols, 4 if alpha else 3), dtype=dtype)
    info = json.loads(
        _native.normalmap(
            _addr(arr),
            kind,
            cols,
            rows,
            s,
            filter,
            wrap,
            bool(invert),
            convention,
            bits,
            bool(alpha),
            _addr(out),
            bool(report),
            progress,
        )
    )
    return (out, info) if report else out


def bump_to_normal(
    height: Any,
    positions: Any,
    normals: Any,
    uvs: Any,
    indices: Any = None,
    tangents: Any = None,
    *,
    distance: float,
    strength: float = 1.0,
    invert: bool = False,
    uv_origin: str = "top-left",
    convention: str = "opengl",
    filter: str = "central",
    wrap: str = "repeat",
    padding: int = 16,
    bits: int = 8,
    report: bool = False,
) -> np.ndarray | tuple[np.ndarray, dict[str, Any]]:
    """The tangent-space normal map of a height map through a mesh: drawn with the mesh's
    MikkTSpace frames, it shades as Blender's (Cycles') Bump node shades the mesh with that height.

    Each texel's height slope is taken on the surface, with the texel's world-space extent along
    the tangent and bitangent from the mesh's UV layout, so stretched UVs, curved meshes and
    scaled objects come out right (``normalmap`` assumes one texel size for the whole map).

    Args:
        height: (rows, columns) heights, row 0 at the top of the image (as :func:`normalmap`).
        positions, normals, uvs: (N, 3), (N, 3), (N, 2) per vertex, in world space (the object's
            transform applied) and the UV set the map is laid out in.
        indices: (T*3,) or (T, 3) triangle corners; None: every three rows are a triangle.
        tangents: (N, 4) tangents ``(x, y, z, w)`` a renderer draws the map with (Blender's
            ``calc_tangents``); None: bumpbake's MikkTSpace of the mesh, as :func:`tangents`.
        distance, strength, invert: the Bump node's Distance (mesh units for a height of 1),
            Strength (the bumped normal mixed with the unbumped one) and Invert.
        uv_origin: ``"top-left"`` (glTF) or ``"bottom-left"`` (Blender, OpenGL).
        convention: ``"opengl"`` (+Y up: glTF, Blender) or ``"directx"``.
        filter, wrap: the height's derivative filter and what lies beyond its edges.
        padding: rings of texels around the UV islands filled from the island's edge.
        bits: 8, 16 (encoded as an image stores them) or 32 (float32 unit vectors).
        report: also return a dict: coverage of the map by the mesh and ``engine_ms``.

    Returns:
        (rows, columns, 3) array; with ``report``, ``(map, report_dict)``.
    """
    _choice("uv_origin", uv_origin, UV_ORIGINS)
    _choice("convention", convention, CONVENTIONS)
    _choice("filter", filter, FILTERS)
    _choice("wrap", wrap, WRAPS)
    if bits not in (8, 16, 32) or isinstance(bits, bool):
        raise UsageError(f"bits={bits!r}: use 8, 16 or 32")
    for name, v in (("distance", distance), ("strength", strength)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
            raise UsageError(f"{name}={v!r}: must be a finite number")
    if isinstance(padding, bool) or not isinstance(padding, int) or padding < 0:
        raise UsageError(f"padding={padding!r}: must be a whole number of texels, 0 or more")
    arr, kind = _height(height)
    pos = _rows("positions", positions, 3)
    n = len(pos)
    nor = _rows("normals", normals, 3)
    uv = _rows("uvs", uvs, 2)
    tan = None if tangents is None else _rows("tangents", tangents, 4)
    for name, a in (("normals", nor), ("uvs", uv), ("tangents", tan)):
        if a is not None and len(a) != n:
            raise InputError(f"{name} has {len(a)} rows but positions has {n}")
    if indices is None and n % 3:
        raise InputError(f"{n} vertices and no indices: a triangle list has three corners per triangle")
    idx = np.arange(n, dtype=np.uint32) if indices is None else _indices(indices, n)
    if tan is None:
        tan = _mikktspace(pos, nor, uv, idx, uv_origin=uv_origin, corners=True)
    else:
        tan = tan[idx]
    pos, nor, uv = pos[idx], nor[idx], uv[idx]
    if uv_origin == "bottom-left":
        uv = np.ascontiguousarray(np.stack([uv[:, 0], 1.0 - uv[:, 1]], axis=1), dtype=np.float32)
    tan = np.require(tan, dtype=np.float32, requirements=["C", "A"])
    rows, cols = arr.shape
    out = np.empty((rows, cols, 3), dtype={8: np.uint8, 16: np.uint16, 32: np.float32}[bits])
    info = json.loads(
        _native.bump_to_normal(
            _addr(arr),
            kind,
            cols,
            rows,
            len(idx),
            _addr(pos),
            _addr(nor),
            _addr(tan),
            _addr(uv),
            float(distance),
            float(strength),
            bool(invert),
            filter,
            wrap,
            padding,
            convention,
            bits,
            _addr(out),
        )
    )
    return (out, info) if report else out


# File-level calls: the command line's parser, checks and JSON, keywords passed as its flags.

_TABLES: dict[str, dict[str, tuple[str | None, bool, bool]]] = {}
# Keywords the calls below set themselves (the JSON output, one input, one output).
_OWN = {
    "inputs",
    "files",
    "input",
    "heights",
    "output",
    "out_dir",
    "out_ext",
    "json",
    "format",
    "quiet",
    "jobs",
    "progress",
    "from",
    "depfile",
    "list_codes",
}


def _table(command: str) -> dict[str, tuple[str | None, bool, bool]]:
    if command not in _TABLES:
        _TABLES[command] = {kw: (flag, takes, many) for kw, flag, takes, many in _native.options(command)}
    return _TABLES[command]


def _text(keyword: str, v: Any) -> str:
    if isinstance(v, bool):
        raise UsageError(f"{keyword}={v!r}: give a value, not True or False")
    if isinstance(v, os.PathLike):
        return os.fspath(v)
    if isinstance(v, float):
        return repr(v)
    return str(v)


def _argv(function: str, command: str, options: dict[str, Any]) -> list[str]:
    table = _table(command)
    argv: list[str] = []
    for kw, value in options.items():
        entry = table.get(kw)
        if kw in _OWN or entry is None or entry[0] is None:
            known = sorted(k for k, e in table.items() if k not in _OWN and e[0] is not None)
            close = difflib.get_close_matches(kw, known, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else f"; it takes: {', '.join(known)}"
            raise UsageError(f"{function}() has no keyword {kw!r}{hint}")
        flag, takes, many = entry
        if not takes:
            if value is True:
                argv.append(f"--{flag}")
            elif value not in (False, None):
                raise UsageError(f"{kw}={value!r}: give True or False")
            continue
        if value is None:
            continue
        values = list(value) if many and isinstance(value, (list, tuple)) else [value]
        argv += [f"--{flag}={_text(kw, v)}" for v in values]
    return argv


def _run(
    function: str,
    command: str,
    own: list[str],
    paths: list[PathLike],
    options: dict[str, Any],
    progress: Progress | None,
) -> dict[str, Any]:
    argv = ["bumpbake", command, *own, *_argv(function, command, options), "--", *(os.fspath(p) for p in paths)]
    _code, out = _native.run(argv, progress)
    return json.loads(out)


def inspect(path: PathLike, **options: Any) -> dict[str, Any]:
    """What a mesh file holds, as ``bumpbake inspect --json`` prints it: primitives, attributes,
    materials, tangents, images. Options: ``allow_outside``."""
    return _run("inspect", "inspect", ["--json"], [path], options, None)


def validate(path: PathLike, **options: Any) -> dict[str, Any]:
    """Tangent-frame, handedness and normal-map checks of a glTF/GLB/OBJ, as
    ``bumpbake validate --format json`` prints them. Findings are in the dict (``errors`` and
    ``warnings`` counts, each finding with its code); they do not raise. Options: ``strict``,
    ``deny``/``allow`` (lists of codes), ``max_angle_deg``, ``image_convention``,
    ``allow_outside``."""
    return _run("validate", "validate", ["--format=json", "--quiet"], [path], options, None)


def tangents_file(
    input: PathLike, output: PathLike, *, progress: Progress | None = None, **options: Any
) -> dict[str, Any]:
    """``bumpbake tangents INPUT -o OUTPUT``: MikkTSpace tangents where the scene needs them,
    written to a .glb or .gltf. Returns the JSON record. Options as the command's flags:
    ``bitangents``, ``all``, ``overwrite``, ``embed``, ``images``, ``allow_outside``, ..."""
    return _run("tangents_file", "tangents", ["--json", f"--output={os.fspath(output)}"], [input], options, progress)


def bake(input: PathLike, output: PathLike, *, progress: Progress | None = None, **options: Any) -> dict[str, Any]:
    """``bumpbake bake INPUT -o OUTPUT``: mesh + height or normal map -> a render-ready glTF.
    Options as the command's flags: ``height``, ``normal``, ``strength``, ``height_range``,
    ``texel_size``, ``material``, ``convention``, ``textures``, ... Returns the JSON record."""
    return _run("bake", "bake", ["--json", f"--output={os.fspath(output)}"], [input], options, progress)


def bake_from(
    low: PathLike,
    high: PathLike | Sequence[PathLike],
    output: PathLike,
    *,
    progress: Progress | None = None,
    **options: Any,
) -> dict[str, Any]:
    """``bumpbake bake LOW --from HIGH -o OUTPUT``: HIGH's detail baked onto LOW's UV layout.
    ``high`` is one path or several. Options as the command's flags: ``size``, ``samples``,
    ``padding``, ``ray_front``, ``ray_back``, ``cage``, ``map_out``, ``height_out``, ``node``, ...
    Returns the JSON record."""
    highs = [high] if isinstance(high, (str, os.PathLike)) else list(high)
    if not highs:
        raise UsageError("bake_from() needs at least one HIGH mesh in high")
    own = ["--json", f"--output={os.fspath(output)}", *(f"--from={os.fspath(h)}" for h in highs)]
    return _run("bake_from", "bake", own, [low], options, progress)


def textures(input: PathLike, output: PathLike, *, progress: Progress | None = None, **options: Any) -> dict[str, Any]:
    """``bumpbake textures INPUT -o OUTPUT``: normal maps re-encoded as KTX2 with mips made from
    the normals, roughness widened to match (specular antialiasing). Options as the command's
    flags: ``ktx2``, ``ktx2_quality``, ``no_specular_aa``, ``images``, ... Returns the JSON record."""
    return _run("textures", "textures", ["--json", f"--output={os.fspath(output)}"], [input], options, progress)
