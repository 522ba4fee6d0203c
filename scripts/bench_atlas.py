"""Whole atlases: cold start, growth with grid size, and a 4000 x 4000 map written to disk.

    python scripts/bench_atlas.py            # about 5 minutes
    python scripts/bench_atlas.py --quick    # seconds; run once by the test suite

- Cold start: ``stabmap atlas --example paper-n1-fixed`` in a fresh process, once with an
  empty kernel cache (the first run after an install: compilation included) and once with
  the cache filled (every later run).  Quick mode measures only the second.
- Growth: ``compute_atlas`` on N x N regriddings of two bundled scenes, all cores.
- End to end (full mode): ``stabmap atlas`` on 4000 x 4000 points, compute and write timed apart.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import stabmap

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_refine import regrid  # noqa: E402


def cold_start(cache_dir: str | None, workdir: str) -> float:
    env = dict(os.environ)
    if cache_dir is not None:
        env["STABMAP_CACHE_DIR"] = cache_dir
    cmd = [sys.executable, "-m", "stabmap", "atlas", "--example", "paper-n1-fixed", "-o", os.path.join(workdir, "a.nc"), "-q", "--overwrite"]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, capture_output=True)
    return time.perf_counter() - t0


def growth(name: str, sizes: list[int]) -> list[dict]:
    scene = stabmap.example(name)
    stabmap.compute_atlas(regrid(scene, 4), progress=False)  # compile or load kernels outside the timing
    rows = []
    for num in sizes:
        sc = regrid(scene, num)
        t0 = time.perf_counter()
        ds = stabmap.compute_atlas(sc, progress=False)
        dt = time.perf_counter() - t0
        by = stabmap.summary(ds)["decided_by"] if hasattr(stabmap, "summary") else {}
        rows.append({"scene": name, "degree": sc.degree, "points": num * num, "seconds": dt, "pts_per_s": num * num / dt,
                     "exact": by.get("exact_rational_arithmetic", 0)})
    return rows


def end_to_end(name: str, num: int, workdir: str) -> dict:
    sc = regrid(stabmap.example(name), num)
    t0 = time.perf_counter()
    ds = stabmap.compute_atlas(sc, progress=False)
    t_compute = time.perf_counter() - t0
    path = os.path.join(workdir, "big.nc")
    t0 = time.perf_counter()
    stabmap.write_atlas(ds, path)
    t_write = time.perf_counter() - t0
    return {"scene": name, "points": num * num, "compute_s": t_compute, "write_s": t_write,
            "file_mb": os.path.getsize(path) / 1e6}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, for the test suite")
    args = ap.parse_args(argv)
    out = {}
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    with tempfile.TemporaryDirectory() as work:
        if not args.quick:
            out["cold_first_s"] = cold_start(os.path.join(work, "empty-cache"), work)
            print(f"cold start, empty kernel cache (first run after install): {out['cold_first_s']:.1f} s")
        cold_start(None, work)  # make sure the default cache is filled
        out["cold_cached_s"] = cold_start(None, work)
        print(f"cold start, kernel cache filled (every later run): {out['cold_cached_s']:.1f} s")

        sizes = [8, 16] if args.quick else [100, 200, 400, 800, 1600]
        print("\n| scene | degree | points | seconds | points/s | decided exactly |")
        print("|---|---|---|---|---|---|")
        out["growth"] = []
        for name in ("paper-n2-fixed", "paper-n3-fixed"):
            for r in growth(name, sizes if name == "paper-n2-fixed" or args.quick else sizes[:-1]):
                out["growth"].append(r)
                print(f"| {r['scene']} | {r['degree']} | {r['points']:,} | {r['seconds']:.2f} | {r['pts_per_s']:,.0f} | {r['exact']} |", flush=True)

        if not args.quick:
            r = end_to_end("paper-n2-fixed", 4000, work)
            out["end_to_end"] = r
            print(f"\nend to end, paper-n2-fixed on 4000 x 4000 = {r['points']:,} points: compute {r['compute_s']:.1f} s, "
                  f"write {r['write_s']:.1f} s ({r['file_mb']:.1f} MB netCDF4)")
    return out


if __name__ == "__main__":
    main()
