"""The binding's cost: a 2048^2 normal map and a 1M-triangle tangent call from Python, against the
same work in the library (the time the engine reports for itself inside the same call), in the
same run. Medians of RUNS calls. `python python/benches/binding.py [RUNS]`; figures in docs/python.md."""

from __future__ import annotations

import json
import statistics
import sys
import time

import numpy as np

import bumpbake
from bumpbake import _native


def grid(n: int):
    u, v = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    z = 0.05 * np.sin(7 * u) * np.cos(5 * v)
    pos = np.stack([u, v, z], -1).reshape(-1, 3).astype(np.float32)
    nor = np.stack([-0.35 * np.cos(7 * u) * np.cos(5 * v), 0.25 * np.sin(7 * u) * np.sin(5 * v), np.ones_like(u)], -1)
    nor = (nor / np.linalg.norm(nor, axis=-1, keepdims=True)).reshape(-1, 3).astype(np.float32)
    uv = np.stack([u, v * 3], -1).reshape(-1, 2).astype(np.float32)
    i = np.arange(n * n)
    a = (i // n) * (n + 1) + i % n
    return pos, nor, uv, np.stack([a, a + 1, a + n + 2, a, a + n + 2, a + n + 1], -1).reshape(-1).astype(np.uint32)


def measure(name, call, engine_ms, runs):
    walls, engines = [], []
    for _ in range(runs):
        t = time.perf_counter()
        call()
        walls.append((time.perf_counter() - t) * 1e3)
        engines.append(engine_ms())
    w, e = statistics.median(walls), statistics.median(engines)
    return {
        "job": name,
        "python_ms": round(w, 1),
        "library_ms": round(e, 1),
        "ratio": round(w / e, 3),
        "binding_ms": round(w - e, 1),
    }


def main() -> None:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    y, x = np.mgrid[0:2048, 0:2048]
    height = (0.5 + 0.25 * np.sin(x / 9.0) * np.cos(y / 13.0)).astype(np.float32)
    last = {}

    def normalmap():
        last["n"] = bumpbake.normalmap(height, strength=8, report=True)[1]["engine_ms"]

    pos, nor, uv, idx = grid(708)
    out_t = np.empty((len(pos), 4), np.float32)

    def tangents():
        bumpbake.tangents(pos, nor, uv, idx)

    def engine_tangents():
        addr = lambda a: a.__array_interface__["data"][0]  # noqa: E731
        r = _native.tangents(len(pos), addr(pos), addr(nor), addr(uv), addr(idx), idx.size, False, True, addr(out_t), 0)
        return json.loads(r)["engine_ms"]

    rows = [measure("normalmap 2048x2048 uint8", normalmap, lambda: last["n"], runs)]
    # The library's time: the engine's own clock in the same native call the function makes.
    rows.append(measure(f"tangents {idx.size // 3} triangles", tangents, engine_tangents, runs))
    print(json.dumps({"bumpbake": bumpbake.__version__, "runs": runs, "results": rows}, indent=2))


if __name__ == "__main__":
    main()
