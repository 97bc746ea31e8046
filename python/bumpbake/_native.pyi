"""The extension module. Private: call the checked functions of ``bumpbake`` instead; these take
raw array addresses that the package makes safe."""

from typing import Any, Callable

__version__: str

def tangents(
    vertices: int,
    positions: int,
    normals: int,
    uvs: int,
    indices: int,
    corners: int,
    flip_v: bool,
    per_vertex: bool,
    out_tangents: int,
    out_bitangents: int,
) -> str: ...
def normalmap(
    height: int,
    dtype: str,
    width: int,
    rows: int,
    strength: float,
    filter: str,
    wrap: str,
    invert: bool,
    convention: str,
    bits: int,
    alpha: bool,
    out: int,
    report: bool,
    progress: Callable[[str, int, int, str], Any] | None = None,
) -> str: ...
def bump_to_normal(
    height: int,
    dtype: str,
    width: int,
    rows: int,
    corners: int,
    positions: int,
    normals: int,
    tangents: int,
    uvs: int,
    distance: float,
    strength: float,
    invert: bool,
    filter: str,
    wrap: str,
    padding: int,
    convention: str,
    bits: int,
    out: int,
) -> str: ...
def strength(strength: float | None, height_range: float | None, texel_size: float | None) -> float: ...
def run(argv: list[str], progress: Callable[[str, int, int, str], Any] | None = None) -> tuple[int, str]: ...
def main(argv: list[str]) -> int: ...
def options(command: str) -> list[tuple[str, str | None, bool, bool]]: ...
