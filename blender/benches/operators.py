"""The extension's operators against Cycles in the same headless Blender, interleaved, medians
of RUNS: `bump_to_normal` against Cycles' NORMAL bake of the Bump material (1024², the test's
scenes), and `bake_selected_to_active` against Cycles' selected-to-active NORMAL bake of the same
pair (a bumpy sphere of HIGH triangles onto a 48x24 one, 1024², one sample each).

    BUMPBAKE_BLENDER_ZIP=target/blender/bumpbake.zip python blender/benches/operators.py [RUNS] [OUT] [PARTS] [SAMPLES]

Run with the bpy venv's Python (bpy 5.0.1); figures in docs/blender.md."""

from __future__ import annotations

import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="bumpbake-bench-"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import bpy
import conftest
import test_bump
import test_selected

RUNS = int(sys.argv[1]) if len(sys.argv) > 1 else 3
OUT = sys.argv[2] if len(sys.argv) > 2 else None
PARTS = (sys.argv[3] if len(sys.argv) > 3 else "bump,selected").split(",")
SAMPLES = tuple(int(s) for s in (sys.argv[4] if len(sys.argv) > 4 else "1,16").split(","))


def cycles_selected(mat, size: int, samples: int) -> float:
    _, seconds = conftest.cycles_bake(
        mat, size, samples, use_selected_to_active=True, cage_extrusion=0.1, max_ray_distance=0.2, margin=16
    )
    return seconds


def main():
    result = bpy.ops.extensions.package_install_files(
        filepath=str(conftest.ZIP), repo="user_default", enable_on_install=True
    )
    assert "FINISHED" in result
    rows = {"runs": RUNS, "load": os.getloadavg(), "bump_to_normal": {}, "selected_to_active": {}}
    for kind in ("plane", "stretched", "sphere") if "bump" in PARTS else ():
        for samples in SAMPLES:
            ours, cycles = [], []
            for _ in range(RUNS):
                obj, mat = test_bump.bump_scene(kind, distance=0.05)
                _, c = test_bump.cycles_normal_bake(obj, mat, samples)
                cycles.append(c)
                obj.select_set(True)
                start = time.perf_counter()
                bpy.ops.bumpbake.bump_to_normal()
                ours.append(time.perf_counter() - start)
            o, c = statistics.median(ours), statistics.median(cycles)
            rows["bump_to_normal"][f"{kind}, Cycles {samples} sample(s)"] = {
                "bumpbake_s": o,
                "cycles_s": c,
                "ratio": c / o,
            }
            print(
                f"bump_to_normal {kind}, Cycles samples {samples}: bumpbake {o:.3f} s, Cycles {c:.2f} s, {c / o:.1f}x"
            )
    for segments in (192, 768) if "selected" in PARTS else ():
        ours, cycles = [], []
        tris = 0
        for _ in range(RUNS):
            _, high, mat = test_selected.bumpy_pair(segments)
            tris = sum(len(p.vertices) - 2 for p in high.data.polygons)
            cycles.append(cycles_selected(mat, 1024, 1))
            start = time.perf_counter()
            bpy.ops.bumpbake.bake_selected_to_active(size=1024, extrusion=0.1, max_ray_distance=0.2, samples=1)
            ours.append(time.perf_counter() - start)
        o, c = statistics.median(ours), statistics.median(cycles)
        rows["selected_to_active"][f"{tris} HIGH triangles"] = {"bumpbake_s": o, "cycles_s": c, "ratio": c / o}
        print(f"selected_to_active, {tris} HIGH triangles, 1024²: bumpbake {o:.2f} s, Cycles {c:.2f} s, {c / o:.1f}x")
    if OUT:
        Path(OUT).write_text(json.dumps(rows, indent=1) + "\n")


main()
