"""Scale-out benchmark: threads against dask.distributed workers, per-task overhead, the per-round latency
of refinement and critical values on a cluster, the cost of the Zarr checkpoint, and the writing process'
peak memory when an atlas is streamed to its file.

    python scripts/bench_cluster.py            # about 6 minutes on 2 cores
    python scripts/bench_cluster.py --quick    # seconds; run once by the test suite

Speeds are ratios within one run (the machine may be shared).  The per-task overhead is the slope of
wall time against the number of tasks for a fixed atlas, cut into ever smaller chunks.  Refinement and
critical values work in dependent rounds (one batch of tasks per refinement level or bisection step, each
waiting for the one before), so on a cluster each round adds the scheduler's round trip: the overhead per
round is (cluster - threads) / rounds, with the two timed in turn and the median taken.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import platform
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

import stabmap
from stabmap.run import runner
from stabmap.run.atlas import compute
from stabmap.run.critical import critical
from stabmap.run.refine import compute_refined
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


def overhead(client, scene, chunk_points: list[int], repeat: int) -> list[dict]:
    """Wall time of one atlas cut into more and more tasks, on 2 threads and on 2 local workers (``client``)."""
    rows = []
    for where, kw in (("2 threads", {"threads": 2}), ("2 local workers", {"client": client})):
        times = [_timed(lambda: compute(scene, chunk_points=cp, progress=False, **kw), repeat) for cp in chunk_points]
        tasks = [_n_tasks(scene, cp) for cp in chunk_points]
        slope, intercept = np.polyfit(tasks, times, 1)
        for cp, n, t in zip(chunk_points, tasks, times):
            rows.append({"where": where, "chunk_points": cp, "tasks": n, "seconds": t, "per_task_ms": 1e3 * slope, "fixed_s": intercept})
    return rows


@contextlib.contextmanager
def _count_rounds():
    """Count the batches handed to the runner (``Runner.run`` calls): one per refinement level or bisection step."""
    calls = [0]
    original = runner.Runner.run

    def run(self, *args, **kwargs):
        calls[0] += 1
        return original(self, *args, **kwargs)

    runner.Runner.run = run
    try:
        yield calls
    finally:
        runner.Runner.run = original


def _round_cases(refine_scene, critical_scene) -> list[tuple[str, object, object]]:
    """(what, scene, run(scene, **where)) of the dense atlases and the round-based runs on the same grids."""
    return [
        ("dense atlas", refine_scene, lambda s, **kw: compute(s, progress=False, **kw)),
        ("compute_refined", refine_scene, lambda s, **kw: compute_refined(s, progress=False, **kw)),
        ("dense atlas", critical_scene, lambda s, **kw: compute(s, progress=False, **kw)),
        ("critical along omega", critical_scene, lambda s, **kw: critical(s, "omega", progress=False, **kw)),
    ]


def _warm_rounds() -> None:
    """Load the kernels of both scenes of ``rounds`` (degrees 6 and 12) in a worker process."""
    _warm()
    compute(resample(stabmap.example("paper-n2-fixed"), omega=3, K_1=3), threads=1, progress=False)


def rounds(client, refine_scene, critical_scene, repeat: int) -> list[dict]:
    """Refinement of ``refine_scene`` (paper-n2-fixed) and critical values of ``critical_scene`` (paper-n3-fixed),
    and the dense atlases of their grids, on 2 threads and on ``client``.

    Each case is run ``repeat`` times on threads and on the cluster in turn (A B A B ...); the medians are
    reported.  Rounds are the batches of tasks that wait for each other: the dense atlas is one.
    """
    client.run(_warm_rounds)
    for what, scene, fn in _round_cases(resample(refine_scene, omega=9, K_1=9), resample(critical_scene, omega=9, m_2=3)):
        fn(scene, threads=2), fn(scene, client=client)  # imports and pickling paths, here and on the workers
    rows = []
    for (what, scene, fn), name in zip(_round_cases(refine_scene, critical_scene), ["paper-n2-fixed"] * 2 + ["paper-n3-fixed"] * 2):
        with _count_rounds() as calls:
            ds = fn(scene, threads=2)
        threads, cluster = [], []
        for _ in range(repeat):
            threads.append(_timed(lambda fn=fn, scene=scene: fn(scene, threads=2)))
            cluster.append(_timed(lambda fn=fn, scene=scene: fn(scene, client=client)))
        t, c = float(np.median(threads)), float(np.median(cluster))
        evaluated = int(ds.attrs.get("n_evaluated_points", ds.attrs.get("critical_evaluated_points", np.prod(scene.shape))))
        rows.append({
            "what": what, "scene": name, "grid": " x ".join(str(n) for n in scene.shape), "points": int(np.prod(scene.shape)),
            "evaluated": evaluated, "rounds": calls[0], "bisection_steps": int(ds.attrs.get("critical_bisection_steps", 0)),
            "threads_s": t, "cluster_s": c, "ratio": c / t, "per_round_ms": 1e3 * (c - t) / calls[0],
        })
    return rows


def checkpoint_saves(cases: list[tuple[int, int, int]]) -> list[dict]:
    """Median wall time of ``Checkpoint.save`` of one chunk, for (chunk points, grid side, chunks saved) cases.

    The chunks hold random labels of ``paper-n1-fixed-dry`` on side x side points, and every variable the
    run would save (``n_complex_pairs``, ``stability``, ``decided_by``).
    """
    from stabmap import systems
    from stabmap.run.chunks import chunk_locations, chunk_shape
    from stabmap.store.checkpoint import Checkpoint

    dry = stabmap.example("paper-n1-fixed-dry")
    rng = np.random.default_rng(0)
    rows = []
    with tempfile.TemporaryDirectory() as d:
        for k, (points, side, count) in enumerate(cases):
            scene = resample(dry, omega=side, c_1=side)
            system = systems.of(scene)
            chunks = chunk_shape(scene.shape, points)
            t0 = time.perf_counter()
            saved = Checkpoint.create(Path(d) / f"c{k}.nc.partial", system, scene, chunks)
            create = time.perf_counter() - t0
            times = []
            for i, loc in enumerate(chunk_locations(scene.shape, chunks)[:count]):
                nc = rng.integers(0, 3, size=tuple(b - a for a, b in loc), dtype=np.int16)
                # the outputs this scene keeps, as the runner does (System.outputs): no frequencies by default
                block = {k: v for k, v in system.inferred(nc).items() if k in saved.dims}
                block["n_complex_pairs"] = nc
                times.append(_timed(lambda saved=saved, i=i, loc=loc, block=block: saved.save(i, loc, block)))
            saved.remove()
            n = int(np.prod(chunks))
            ms = 1e3 * float(np.median(times))
            rows.append({"chunk_points": n, "grid_points": side * side, "saves": len(times), "create_s": create,
                         "save_ms": ms, "us_per_point": 1e3 * ms / n})
    return rows


def _n_tasks(scene, cp: int) -> int:
    from stabmap.run.chunks import chunk_locations, chunk_shape

    from stabmap.run.tasks import point_order

    return len(chunk_locations(scene.shape, chunk_shape(scene.shape, cp, point_order(scene))))


PEAK = textwrap.dedent(
    """
    import os, resource, sys, time
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
    t0 = time.perf_counter()
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
            block = {k: v for k, v in system.inferred(nc).items() if k in saved.dims}  # the scene's outputs only
            block["n_complex_pairs"] = nc
            saved.save(i, loc, block)
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        t0 = time.perf_counter()
        arrays, store = saved.arrays()
        with store:
            write_streamed(atlas_dataset(system, scene, arrays), out)
    seconds = time.perf_counter() - t0  # the atlas (if computed) and the file, not the checkpoint's removal
    if how == "write-only":
        saved.remove()
    after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(before, after, seconds)
    """
)


def memory(runs: list[tuple[int, str]]) -> list[dict]:
    """Peak resident memory of a fresh process making an atlas of side^2 points: streamed, in memory, or only written."""
    rows = []
    with tempfile.TemporaryDirectory() as d:
        for side, how in runs:
            out = os.path.join(d, f"a-{side}.nc")
            res = subprocess.run([sys.executable, "-c", PEAK, how, str(side), out], capture_output=True, text=True, check=True)
            before, after, seconds = res.stdout.split()
            before, after = int(before), int(after)
            rows.append({"points": side * side, "how": how, "seconds": float(seconds), "peak_mib": after / 1024, "growth_mib": (after - before) / 1024,
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
    n3, n2 = stabmap.example("paper-n3-fixed"), stabmap.example("paper-n2-fixed")
    if args.quick:
        big, small, chunks, repeat = resample(n3, omega=60, m_2=40), resample(n3, omega=40, m_2=20), [400, 100, 25], 1
        refine_scene, critical_scene, round_repeat = resample(n2, omega=129, K_1=65), resample(n3, omega=30, m_2=10), 1
        saves = [(1 << 18, 1024, 2), (1024, 256, 10)]
        runs = [(200, "streamed"), (200, "in-memory"), (400, "write-only")]
    else:
        big, small, chunks, repeat = resample(n3, omega=960, m_2=640), n3, [4800, 1200, 300, 75, 20], 2
        refine_scene, critical_scene, round_repeat = resample(n2, omega=513, K_1=257), resample(n3, omega=120, m_2=40), 7
        saves = [(1 << 18, 4096, 16), (1024, 1024, 200)]
        runs = [(side, how) for side in (1000, 4000, 8000) for how in ("streamed", "in-memory")] + [(4000, "write-only"), (16000, "write-only")]
    _warm()
    out = {"scaling": scaling(big, repeat)}
    with local_cluster(2) as client:
        client.run(_warm)
        out["overhead"] = overhead(client, small, chunks, repeat)
        out["rounds"] = rounds(client, refine_scene, critical_scene, round_repeat)
    out["checkpoint"] = checkpoint_saves(saves)
    out["memory"] = memory(runs)
    print(f"machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, Python {platform.python_version()}, {time.strftime('%Y-%m-%d')}")
    print(f"\nScaling: {big.title}, {np.prod(big.shape):,} points, degree {big.degree}")
    print(_table(out["scaling"], [("where", "where", "s"), ("threads or workers", "n", "d"), ("seconds", "seconds", ".2f"), ("speed-up", "speedup", ".2f")]))
    print(f"\nPer-task overhead: {small.title}, {np.prod(small.shape):,} points")
    print(_table(out["overhead"], [("where", "where", "s"), ("chunk points", "chunk_points", ",d"), ("tasks", "tasks", ",d"), ("seconds", "seconds", ".3f"), ("fitted ms per task", "per_task_ms", ".2f")]))
    print(f"\nRounds on a cluster: 2 threads against 2 local workers (median of {round_repeat}, in turn); rounds = batches of tasks that wait for each other")
    print(_table(out["rounds"], [("run", "what", "s"), ("scene", "scene", "s"), ("grid", "grid", "s"), ("points evaluated", "evaluated", ",d"),
                                 ("rounds", "rounds", "d"), ("bisection steps", "bisection_steps", "d"), ("2 threads s", "threads_s", ".3f"),
                                 ("2 workers s", "cluster_s", ".3f"), ("cluster / threads", "ratio", ".2f"), ("overhead per round ms", "per_round_ms", ".1f")]))
    print("\nZarr checkpoint: Checkpoint.save of one chunk (random labels, every variable; median)")
    print(_table(out["checkpoint"], [("chunk points", "chunk_points", ",d"), ("grid points", "grid_points", ",d"), ("saves", "saves", "d"),
                                     ("create s", "create_s", ".3f"), ("ms per save", "save_ms", ".2f"), ("us per point", "us_per_point", ".3f")]))
    print("\nPeak memory of the writing process (fresh process, 2 threads; the atlas holds 4 bytes a point in memory)")
    print(_table(out["memory"], [("points", "points", ",d"), ("how", "how", "s"), ("seconds", "seconds", ".2f"), ("peak MiB", "peak_mib", ".0f"), ("growth MiB", "growth_mib", ".0f"), ("atlas MiB", "atlas_mib", ".1f"), ("file MiB", "file_mib", ".1f")]))
    return out


if __name__ == "__main__":
    main()
