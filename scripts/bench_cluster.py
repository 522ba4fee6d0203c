"""Scale-out benchmark: threads against dask.distributed workers, per-task overhead, and the writing
process' peak memory when an atlas is streamed to its file.

    python scripts/bench_cluster.py            # about 4 minutes on 2 cores
    python scripts/bench_cluster.py --quick    # seconds; run once by the test suite

Speeds are ratios within one run (the machine may be shared).  The per-task overhead is the slope of
wall time against the number of tasks for a fixed atlas, cut into ever smaller chunks.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import textwrap
import time

import numpy as np

import stabmap
from stabmap.run.atlas import compute
from stabmap.run.runner import local_cluster
from stabmap.scene.grid import resample


def _timed(fn, repeat: int = 1) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def scaling(scene, repeat: int) -> list[dict]:
    """The same atlas on 1 and 2 threads in this process, and on local clusters of 1 and 2 worker processes."""
    rows = []
    base = None
    for label, workers, threads in (("threads", None, 1), ("threads", None, 2), ("local cluster", 1, None), ("local cluster", 2, None)):
        if workers is None:
            t = _timed(lambda: compute(scene, threads=threads, progress=False), repeat)
        else:
            with local_cluster(workers) as client:
                client.run(_warm)
                t = _timed(lambda: compute(scene, client=client, progress=False), repeat)
        base = base or t
        rows.append({"where": label, "n": workers or threads, "seconds": t, "speedup": base / t})
    return rows


def _warm() -> None:
    """Load (or compile) the kernels in a worker process, so that no timed run pays for it."""
    compute(resample(stabmap.example("paper-n3-fixed"), omega=3, m_2=3), threads=1, progress=False)


def overhead(scene, chunk_points: list[int], repeat: int) -> list[dict]:
    """Wall time of one atlas cut into more and more tasks, on 2 threads and on 2 local workers."""
    rows = []
    with local_cluster(2) as client:
        client.run(_warm)
        for where, kw in (("2 threads", {"threads": 2}), ("2 local workers", {"client": client})):
            times = [_timed(lambda: compute(scene, chunk_points=cp, progress=False, **kw), repeat) for cp in chunk_points]
            tasks = [_n_tasks(scene, cp) for cp in chunk_points]
            slope, intercept = np.polyfit(tasks, times, 1)
            for cp, n, t in zip(chunk_points, tasks, times):
                rows.append({"where": where, "chunk_points": cp, "tasks": n, "seconds": t, "per_task_ms": 1e3 * slope, "fixed_s": intercept})
    return rows


def _n_tasks(scene, cp: int) -> int:
    from stabmap.run.chunks import chunk_locations, chunk_shape

    return len(chunk_locations(scene.shape, chunk_shape(scene.shape, cp)))


PEAK = textwrap.dedent(
    """
    import os, resource, sys
    import numpy as np
    import stabmap
    from stabmap.scene.grid import resample
    from stabmap.run.atlas import compute, compute_to_file
    from stabmap.run.chunks import chunk_locations, chunk_shape
    from stabmap import systems
    from stabmap.store.checkpoint import Checkpoint, partial_dir
    from stabmap.store.dataset import atlas_dataset
    from stabmap.store.files import write_atlas, write_streamed
    how, side, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    dry = stabmap.example("paper-n1-fixed-dry")
    # Warm up every code path first, so that the growth below is the run's own memory, not imports.
    write_atlas(compute(resample(dry, omega=3, c_1=3), threads=2, progress=False), out)
    compute_to_file(resample(dry, omega=3, c_1=3), out + ".warm.nc", threads=2, progress=False)
    scene = resample(dry, omega=side, c_1=side)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    if how == "streamed":
        compute_to_file(scene, out, threads=2, progress=False)
    elif how == "in-memory":
        write_atlas(compute(scene, threads=2, progress=False), out)
    else:  # only the write, from a checkpoint (random labels): sizes beyond what this benchmark can compute
        system = systems.of(scene)
        chunks = chunk_shape(scene.shape, 1 << 18)
        saved = Checkpoint.create(partial_dir(out), system, scene, chunks)
        rng = np.random.default_rng(0)
        for i, loc in enumerate(chunk_locations(scene.shape, chunks)):
            nc = rng.integers(0, 3, size=tuple(b - a for a, b in loc), dtype=np.int16)
            block = system.inferred(nc)
            block["n_complex_pairs"] = nc
            saved.save(i, loc, block)
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        arrays, store = saved.arrays()
        with store:
            write_streamed(atlas_dataset(system, scene, arrays), out)
        saved.remove()
    after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(before, after)
    """
)


def memory(runs: list[tuple[int, str]]) -> list[dict]:
    """Peak resident memory of a fresh process making an atlas of side^2 points: streamed, in memory, or only written."""
    rows = []
    with tempfile.TemporaryDirectory() as d:
        for side, how in runs:
            out = os.path.join(d, f"a-{side}.nc")
            res = subprocess.run([sys.executable, "-c", PEAK, how, str(side), out], capture_output=True, text=True, check=True)
            before, after = (int(x) for x in res.stdout.split())
            rows.append({"points": side * side, "how": how, "peak_mib": after / 1024, "growth_mib": (after - before) / 1024,
                         "atlas_mib": side * side * 4 / 2**20, "file_mib": os.path.getsize(out) / 2**20})
    return rows


def _table(rows: list[dict], cols: list[tuple[str, str, str]]) -> str:
    lines = ["| " + " | ".join(h for h, _, _ in cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        lines.append("| " + " | ".join(format(r[k], f) for _, k, f in cols) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="small sizes, one repetition (seconds)")
    args = ap.parse_args(argv)
    n3 = stabmap.example("paper-n3-fixed")
    if args.quick:
        big, small, chunks, repeat = resample(n3, omega=60, m_2=40), resample(n3, omega=40, m_2=20), [400, 100, 25], 1
        runs = [(200, "streamed"), (200, "in-memory"), (400, "write-only")]
    else:
        big, small, chunks, repeat = resample(n3, omega=960, m_2=640), n3, [4800, 1200, 300, 75, 20], 2
        runs = [(side, how) for side in (1000, 4000, 8000) for how in ("streamed", "in-memory")] + [(16000, "write-only")]
    _warm()
    out = {"scaling": scaling(big, repeat), "overhead": overhead(small, chunks, repeat), "memory": memory(runs)}
    print(f"machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, Python {platform.python_version()}")
    print(f"\nScaling: {big.title}, {np.prod(big.shape):,} points, degree {big.degree}")
    print(_table(out["scaling"], [("where", "where", "s"), ("threads or workers", "n", "d"), ("seconds", "seconds", ".2f"), ("speed-up", "speedup", ".2f")]))
    print(f"\nPer-task overhead: {small.title}, {np.prod(small.shape):,} points")
    print(_table(out["overhead"], [("where", "where", "s"), ("chunk points", "chunk_points", ",d"), ("tasks", "tasks", ",d"), ("seconds", "seconds", ".3f"), ("fitted ms per task", "per_task_ms", ".2f")]))
    print("\nPeak memory of the writing process (fresh process, 2 threads; the atlas holds 4 bytes a point in memory)")
    print(_table(out["memory"], [("points", "points", ",d"), ("how", "how", "s"), ("peak MiB", "peak_mib", ".0f"), ("growth MiB", "growth_mib", ".0f"), ("atlas MiB", "atlas_mib", ".1f"), ("file MiB", "file_mib", ".1f")]))
    return out


if __name__ == "__main__":
    main()
