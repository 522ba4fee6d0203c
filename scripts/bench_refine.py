"""Adaptive atlases against dense ones: polynomial evaluations, wall time, and whether the labels agree.

    python scripts/bench_refine.py            # 2048 x 2048, every bundled example (about 3.5 minutes on 2 cores)
    python scripts/bench_refine.py --quick    # 257 x 257, two scenes; seconds; run once by the test suite

For each scene, regridded to N x N over the same ranges: the dense atlas
(``compute_atlas``) once, then ``compute_refined`` at the default coarse stride
with safety margins 0, 1 (the default) and 2.  "mismatched" counts grid points
whose N_c differs from the dense atlas; all of them are points the refined
atlas flags as inferred (docs/refine.md).  All cores; kernels compiled or
loaded from the cache before any timing.
"""

from __future__ import annotations

import argparse
import os
import platform
import time


import stabmap
from stabmap.systems.gyroscopes.outputs import BY_INFERRED
from stabmap.scene.grid import resample

FULL_SCENES = ["paper-n3-fixed", "paper-n1-fixed", "paper-n1-free", "paper-n2-fixed", "paper-n2-free", "paper-n3-free"]
QUICK_SCENES = ["paper-n1-fixed", "paper-n2-fixed"]
MARGINS = (0, 1, 2)


def regrid(scene, num: int):
    """The scene with every grid axis resampled to ``num`` points over the same range."""
    return resample(scene, **{a.name: num for a in scene.grid})


def _timed(f, *args, **kwargs):
    t0 = time.perf_counter()
    out = f(*args, **kwargs)
    return out, time.perf_counter() - t0


def compare(name: str, num: int) -> list[dict]:
    """Dense once, refined at each margin; one row per margin."""
    scene = regrid(stabmap.example(name), num)
    den, t_dense = _timed(stabmap.compute_atlas, scene, progress=False)
    nc = den["n_complex_pairs"].values
    rows = []
    for margin in MARGINS:
        ref, t_ref = _timed(stabmap.compute_refined, scene, margin=margin, progress=False)
        evaluated = int(ref.attrs["n_evaluated_points"])
        mismatch = ref["n_complex_pairs"].values != nc
        inferred = ref["decided_by"].values == BY_INFERRED
        assert not (mismatch & ~inferred).any(), "a computed point differs from the dense atlas"
        rows.append({
            "scene": name, "points": nc.size, "degree": scene.degree,
            "stride": int(ref.attrs["refine_coarse_stride"][0]), "margin": margin,
            "evaluated": evaluated, "ratio": nc.size / evaluated,
            "dense_s": t_dense, "refined_s": t_ref, "speedup": t_dense / t_ref,
            "mismatched": int(mismatch.sum()), "equal": not mismatch.any(),
        })
    return rows


HEADER = (
    "| scene | degree | grid | coarse stride | margin | evaluated | fewer evaluations | dense s | refined s "
    "| faster | equal to dense (mismatched points) |"
)


def _row(r: dict, num: int) -> str:
    equal = "yes" if r["equal"] else f"no ({r['mismatched']})"
    return (
        f"| {r['scene']} | {r['degree']} | {num} x {num} | {r['stride']} | {r['margin']} | {r['evaluated']:,} "
        f"| {r['ratio']:.1f}x | {r['dense_s']:.2f} | {r['refined_s']:.2f} | {r['speedup']:.1f}x | {equal} |"
    )


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="257 x 257, two scenes, for the test suite")
    ap.add_argument("--size", type=int, help="grid points per axis (default 2048; 257 with --quick)")
    ap.add_argument("--scenes", help="comma-separated example names (default: all bundled examples)")
    args = ap.parse_args(argv)
    num = args.size or (257 if args.quick else 2048)
    names = args.scenes.split(",") if args.scenes else QUICK_SCENES if args.quick else FULL_SCENES
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    warm = regrid(stabmap.example(names[0]), 9)
    stabmap.compute_atlas(warm, progress=False)  # compile or load the kernels outside the timings
    stabmap.compute_refined(warm, progress=False)
    print(HEADER)
    print("|" + "---|" * (HEADER.count("|") - 1))
    rows = []
    for name in names:
        for r in compare(name, num):
            rows.append(r)
            print(_row(r, num), flush=True)
    return {"size": num, "rows": rows}


if __name__ == "__main__":
    main()
