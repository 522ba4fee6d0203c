"""Reading benchmark: peak memory of ``stabmap info``, ``query`` (every mode) and ``plot`` on big atlases.

    python scripts/bench_read.py                # 16 M and 256 M points, netCDF and Zarr (about 30 minutes on 2 cores)
    python scripts/bench_read.py --quick        # 1 M points; run once by the test suite
    python scripts/bench_read.py --points 16e6  # one size

Big atlases are not computed (256 M points would take hours): :func:`make_atlas` writes one directly, with the
variables, attributes, coordinates and scene of a real atlas (``paper-n2-fixed`` resampled to the size asked),
and synthetic labels with the features a reader must keep (a curved stability boundary, bands of 1 and 2
complex pairs, an unstable line one grid value thin inside the stable region, a degenerate patch and an inferred
patch) and growth rates to match (0 where stable, NaN where degenerate or inferred), chunked as ``stabmap atlas`` writes them (``MAX_CHUNK_POINTS`` points a chunk).

Each command runs in a fresh process: it first runs the same command on a 1 M-point atlas of the same kind
(imports, matplotlib and dask loaded, and a figure of the same size drawn), then on the big one. ``start-up MiB``
is the peak resident memory (``ru_maxrss``) after the first run, ``peak MiB`` after the big one, ``growth MiB``
the difference: what the size of the big atlas cost.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

QUICK_COMMANDS = ("info", "query --boundaries omega", "plot")

#: The commands measured, as ``stabmap`` arguments after the atlas ({png}: a figure file).
COMMANDS = [
    ("info", ["info", "{atlas}"]),
    ("query label", ["query", "{atlas}", "omega=42.5", "K_1=3"]),
    ("query --fraction", ["query", "{atlas}", "--fraction"]),
    ("query --fraction K_1=3", ["query", "{atlas}", "--fraction", "K_1=3"]),
    ("query --boundaries omega", ["query", "{atlas}", "--boundaries", "omega", "--limit", "3"]),
    ("query --boundaries K_1", ["query", "{atlas}", "--boundaries", "K_1", "--limit", "3"]),
    ("query --smallest-stable --over K_1", ["query", "{atlas}", "--smallest-stable", "omega", "--over", "K_1", "--limit", "3"]),
    ("plot", ["plot", "{atlas}", "-o", "{png}"]),
]


def labels(omega_index: np.ndarray, k_index: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Synthetic N_c on grid indices (omega, K_1): the features a reader of the atlas must keep.

    - stable (0) above a curved threshold in omega, 1 complex pair below it, 2 pairs at the lowest spin rates;
    - one unstable grid line (N_c = 1), a single omega grid value thin, across the stable region;
    - a degenerate patch (N_c = -1).
    """
    u = omega_index / max(1, shape[0] - 1)
    v = k_index / max(1, shape[1] - 1)
    nc = np.where(u > 0.35 - 0.15 * v + 0.05 * np.sin(9 * v), 0, np.where(u > 0.12 + 0.04 * np.cos(5 * v), 1, 2)).astype(np.int16)
    nc[omega_index == int(0.8 * (shape[0] - 1))] = 1
    nc[(np.abs(u - 0.6) < 0.01) & (np.abs(v - 0.2) < 0.01)] = -1
    return nc


def _block(shape, variable, block_info=None):
    from stabmap.systems.gyroscopes.outputs import stability_from_pairs

    (a0, b0), (a1, b1) = block_info[None]["array-location"]
    i, k = np.meshgrid(np.arange(a0, b0), np.arange(a1, b1), indexing="ij")
    nc = labels(i, k, shape)
    if variable == "n_complex_pairs":
        return nc
    if variable == "stability":
        return stability_from_pairs(nc)
    u, v = i / (shape[0] - 1), k / (shape[1] - 1)
    patch = (u > 0.5) & (u < 0.7) & (v > 0.6) & (v < 0.8)
    if variable in ("growth_rate", "growth_rate_lower", "growth_rate_upper", "efolding_time"):
        # as a real atlas stores them: 0 where stable, a rate that falls towards the stable region where not, NaN where
        # degenerate or inferred (not computed)
        rate = np.where(nc > 0, 0.1 + nc * (1.0 - u), 0.0)
        rate = np.where((nc < 0) | patch, np.nan, rate).astype(np.float32)
        if variable == "efolding_time":
            with np.errstate(divide="ignore"):
                return (np.float32(1) / rate).astype(np.float32)
        step = {"growth_rate_lower": -np.inf, "growth_rate_upper": np.inf}.get(variable)
        return rate if step is None else np.where(rate > 0, np.nextafter(rate, np.float32(step)), rate).astype(np.float32)
    if variable == "cell":  # the inferred patch not proved, every other cell node_only
        return np.where(patch, 3, 0).astype(np.int8)
    return np.where(patch, 3, 0).astype(np.int8)  # decided_by, growth_rate_method: an inferred patch


def make_atlas(path: str | Path, shape: tuple[int, int], chunk_points: int | None = None) -> Path:
    """Write a synthetic atlas of ``shape`` = (omega, K_1) points to ``path`` (.nc or .zarr), chunk by chunk.

    Variables, attributes, coordinates and scene are those of ``paper-n2-fixed`` resampled to ``shape``; the
    labels are :func:`labels`. Memory stays bounded by a few chunks whatever the shape.
    """
    import dask.array as da

    import stabmap
    from stabmap import systems
    from stabmap.run.chunks import MAX_CHUNK_POINTS, chunk_shape
    from stabmap.scene.grid import resample
    from stabmap.store.dataset import atlas_dataset
    from stabmap.store.files import write_streamed

    scene = resample(stabmap.example("paper-n2-fixed"), omega=shape[0], K_1=shape[1])
    system = systems.of(scene)
    chunks = chunk_shape(scene.shape, chunk_points or MAX_CHUNK_POINTS)
    arrays = {
        v.name: da.map_blocks(_block, scene.shape, v.name, chunks=da.core.normalize_chunks(chunks, scene.shape), dtype=v.dtype)
        for v in system.atlas_variables
    }
    ds = atlas_dataset(system, scene, arrays)
    ds.attrs["history"] += "; synthetic labels written by scripts/bench_read.py (not computed)"
    return write_streamed(ds, Path(path))


RUN = textwrap.dedent(
    """
    import resource, sys
    from stabmap.cli import main
    tiny, big = sys.argv[1], sys.argv[2]
    args = sys.argv[3:]
    def run(atlas):
        argv = [a.replace("{atlas}", atlas).replace("{png}", atlas + ".png") for a in args]
        status = main(argv)
        assert status == 0, (argv, status)
    run(tiny)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    run(big)
    after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print("@@", before, after, file=sys.stderr)
    """
)


def measure(tiny: Path, big: Path, args: list[str]) -> dict:
    """Peak RSS of one command on ``big`` in a fresh process, after the same command on ``tiny``."""
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-c", RUN, str(tiny), str(big), *args], capture_output=True, text=True, check=False)
    seconds = time.perf_counter() - t0
    if res.returncode:
        raise RuntimeError(f"{args}: {res.stderr}")
    before, after = (int(x) for x in res.stderr.split("@@")[-1].split())
    return {"startup_mib": before / 1024, "peak_mib": after / 1024, "growth_mib": (after - before) / 1024, "seconds": seconds}


def _side(points: float) -> tuple[int, int]:
    side = round(float(np.sqrt(points)))
    return side, side


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="1 M points, netCDF and Zarr (a minute)")
    ap.add_argument("--points", type=float, action="append", help="grid points (repeatable; default 16e6 and 256e6)")
    ap.add_argument("--formats", default="nc,zarr", help="comma-separated: nc, zarr")
    ap.add_argument("--dir", default=None, help="where to write the atlases (default: a temporary directory, removed after)")
    args = ap.parse_args(argv)
    sizes = [1e6] if args.quick else (args.points or [16e6, 256e6])
    commands = [c for c in COMMANDS if c[0] in QUICK_COMMANDS] if args.quick else COMMANDS
    rows = []
    work = Path(tempfile.mkdtemp(prefix="stabmap-read-", dir=args.dir))
    try:
        for fmt in args.formats.split(","):
            tiny = make_atlas(work / f"warm.{fmt}", (40, 30) if args.quick else (1000, 1000))
            for points in sizes:
                shape = _side(points)
                t0 = time.perf_counter()
                big = make_atlas(work / f"big.{fmt}", shape)
                write_s = time.perf_counter() - t0
                size = sum(f.stat().st_size for f in big.rglob("*")) if big.is_dir() else big.stat().st_size
                for name, command in commands:
                    row = {"format": fmt, "points": shape[0] * shape[1], "shape": f"{shape[0]} x {shape[1]}", "command": name,
                           "file_mib": size / 2**20, "write_s": write_s, **measure(tiny, big, command)}
                    rows.append(row)
                    print(f"{row['format']:>5} {row['points']:>12,} {name:<40} peak {row['peak_mib']:7.0f} MiB, growth {row['growth_mib']:6.0f} MiB, "
                          f"{row['seconds']:6.1f} s", flush=True)
                shutil.rmtree(big, ignore_errors=True) if big.is_dir() else big.unlink()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"\nmachine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, Python {platform.python_version()}, {time.strftime('%Y-%m-%d')}")
    print("| format | points | command | start-up MiB | peak MiB | growth MiB | seconds (whole process) |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['format']} | {r['points']:,} | `{r['command']}` | {r['startup_mib']:.0f} | {r['peak_mib']:.0f} | {r['growth_mib']:.0f} | {r['seconds']:.1f} |")
    return {"rows": rows}


if __name__ == "__main__":
    main()
