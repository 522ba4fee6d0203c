"""What the growth rate and the frequencies cost an atlas (docs/rates.md): time and memory against the plain atlas.

    python scripts/bench_rates.py           # paper-n1/n2/n3-fixed on their own grids (300 x 200 ...), one thread, best of 5
    python scripts/bench_rates.py --quick   # the same scenes resampled to 24 x 24; run once by the test suite

Each scene is computed three ways in one process, kernels loaded before any timing, one thread:
  plain        growth_rate = false (the atlas before docs/rates.md);
  growth       the default: growth_rate, its bounds, efolding_time, growth_rate_method;
  frequencies  frequencies = true as well (every root's real part, radius and kind on a ``root`` dimension).
Each way runs twice, cell by cell (the default: box proofs first) and node by node (``prove_cells=False``, every
node computed: the growth rate is then computed at every unstable node, the worst case).  Columns: CPU seconds, the
Dataset's bytes (what memory holds) and its netCDF file's (zlib level 4), as ratios to plain, and how many unstable nodes
went to exact arithmetic (growth_rate_method = exact_arb_roots).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

import stabmap
from stabmap.scene.grid import resample

SCENES = ("paper-n1-fixed", "paper-n2-fixed", "paper-n3-fixed")
WAYS = {"plain": {"growth_rate": False}, "growth": {}, "frequencies": {"frequencies": True}}


def run(scene, prove_cells: bool, repeat: int = 1) -> tuple[float, object]:
    """The least CPU seconds of ``repeat`` runs (CPU time of the process: other jobs on the machine move it less than
    the wall clock, and the least of a few runs least of all), and the atlas."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        ds = stabmap.compute_atlas(scene, progress=False, threads=1, prove_cells=prove_cells)
        best = min(best, time.process_time() - t0)
    return best, ds


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="24 x 24 grids, one run each (seconds)")
    parser.add_argument("--repeat", type=int, default=5, help="runs of each way; the least CPU time is kept (default 5)")
    args = parser.parse_args(argv)
    rows = []
    for name in SCENES:
        scene = stabmap.example(name)
        if args.quick:
            scene = resample(scene, **{a.name: 24 for a in scene.grid})
        run(resample(scene, **{a.name: 3 for a in scene.grid}), True)  # load the kernels
        for prove_cells in (True, False):
            base = None
            for way, keys in WAYS.items():
                seconds, ds = run(dataclasses.replace(scene, **keys), prove_cells, 1 if args.quick else args.repeat)
                nbytes = int(sum(v.nbytes for v in ds.data_vars.values()))
                with tempfile.TemporaryDirectory() as tmp:
                    stabmap.write_atlas(ds, Path(tmp) / "a.nc")
                    file_bytes = (Path(tmp) / "a.nc").stat().st_size
                base = base or (seconds, nbytes, file_bytes)
                exact = int((ds.growth_rate_method.values == 2).sum()) if "growth_rate_method" in ds else 0
                unstable = int((ds.n_complex_pairs.values > 0).sum())
                rows.append({"scene": name, "degree": scene.degree, "points": int(np.prod(scene.shape)), "cells": prove_cells,
                             "way": way, "seconds": seconds, "bytes": nbytes, "time_ratio": seconds / base[0],
                             "bytes_ratio": nbytes / base[1], "file": file_bytes, "file_ratio": file_bytes / base[2], "exact": exact, "unstable": unstable})
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, {platform.python_implementation()} {platform.python_version()}; one thread")
    print("| scene | degree | points | decided | way | seconds | x plain | bytes | x plain | .nc file | x plain | exact / unstable nodes |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['scene']} | {r['degree']} | {r['points']} | {'cells' if r['cells'] else 'nodes'} | {r['way']} | {r['seconds']:.2f} | "
              f"{r['time_ratio']:.2f} | {r['bytes']:,} | {r['bytes_ratio']:.2f} | {r['file']:,} | {r['file_ratio']:.2f} | {r['exact']} / {r['unstable']} |")
    return rows


if __name__ == "__main__":
    main()
