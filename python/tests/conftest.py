"""Shared helpers: the command line to compare against, fixtures, and small readers of what it
writes (glTF accessors, PNG texels) that use nothing but NumPy and the standard library."""

from __future__ import annotations

import json
import os
import shutil
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "fixtures"


def cli() -> list[str]:
    """The command line: $BUMPBAKE_BIN (the cargo-built binary, in CI), else the console script
    this wheel installed, else `python -m bumpbake`."""
    if os.environ.get("BUMPBAKE_BIN"):
        return [os.environ["BUMPBAKE_BIN"]]
    script = shutil.which("bumpbake")
    return [script] if script else [sys.executable, "-m", "bumpbake"]


def run_cli(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    p = subprocess.run([*cli(), *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"bumpbake {' '.join(map(str, args))} exited {p.returncode}: {p.stderr}")
    return p


@pytest.fixture
def fixtures() -> Path:
    return FIXTURES


_COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


class Gltf:
    """A glTF or GLB file's JSON and buffers, enough to read float and index accessors."""

    def __init__(self, path: Path):
        data = path.read_bytes()
        self.buffers: list[bytes] = []
        if data[:4] == b"glTF":
            n = struct.unpack_from("<I", data, 12)[0]
            self.json = json.loads(data[20 : 20 + n])
            at = 20 + n
            bin_chunk = b""
            if at < len(data):
                m = struct.unpack_from("<I", data, at)[0]
                bin_chunk = data[at + 8 : at + 8 + m]
        else:
            self.json = json.loads(data)
            bin_chunk = b""
        for b in self.json.get("buffers", []):
            uri = b.get("uri")
            self.buffers.append(bin_chunk if uri is None else (path.parent / uri).read_bytes())

    def accessor(self, index: int) -> np.ndarray:
        a = self.json["accessors"][index]
        view = self.json["bufferViews"][a["bufferView"]]
        dtype = np.dtype(_COMPONENTS[a["componentType"]])
        width = _WIDTH[a["type"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        stride = view.get("byteStride", dtype.itemsize * width)
        buf = self.buffers[view["buffer"]]
        rows = (
            [np.frombuffer(buf, dtype, width, start + i * stride) for i in range(a["count"])]
            if stride != (dtype.itemsize * width)
            else [np.frombuffer(buf, dtype, width * a["count"], start).reshape(-1, width)]
        )
        return np.vstack(rows) if width > 1 else np.concatenate(rows).reshape(-1)

    def primitives(self):
        for m in self.json["meshes"]:
            yield from m["primitives"]


def read_png(path: Path) -> np.ndarray:
    """Texels of a non-interlaced 8- or 16-bit gray/RGB/RGBA PNG, as (rows, cols, channels)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    at, idat = 8, b""
    while at < len(data):
        n, kind = struct.unpack_from(">I4s", data, at)
        body = data[at + 8 : at + 8 + n]
        if kind == b"IHDR":
            w, h, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert interlace == 0
        elif kind == b"IDAT":
            idat += body
        at += 12 + n
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[colour]
    bpp = channels * depth // 8
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(h, 1 + w * bpp)
    out = np.zeros((h, w * bpp), np.int32)
    prev = np.zeros(w * bpp, np.int32)
    for y in range(h):
        f, line = raw[y, 0], raw[y, 1:].astype(np.int32)
        if f == 0:
            cur = line
        elif f == 2:
            cur = (line + prev) & 255
        else:
            cur = np.zeros_like(line)
            for x in range(w * bpp):
                a = cur[x - bpp] if x >= bpp else 0
                b = prev[x]
                c = prev[x - bpp] if x >= bpp else 0
                if f == 1:
                    p = a
                elif f == 3:
                    p = (a + b) // 2
                else:
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + p) & 255
        out[y] = cur
        prev = cur
    texels = out.astype(np.uint8)
    if depth == 16:
        texels = texels.reshape(h, w * channels, 2)
        return (texels[..., 0].astype(np.uint16) << 8 | texels[..., 1]).reshape(h, w, channels)
    return texels.reshape(h, w, channels)


def write_png(path: Path, gray: np.ndarray) -> None:
    """A gray PNG of uint8 or uint16 samples (filter 0)."""
    h, w = gray.shape
    depth = 16 if gray.dtype == np.uint16 else 8
    rows = gray.astype(">u2").tobytes() if depth == 16 else gray.astype(np.uint8).tobytes()
    line = w * depth // 8
    raw = b"".join(b"\0" + rows[y * line : (y + 1) * line] for y in range(h))

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, 0, 0, 0, 0))
        + chunk(b"IDAT", zlib.compress(raw))
        + chunk(b"IEND", b"")
    )
