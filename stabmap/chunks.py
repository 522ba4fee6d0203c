"""How an atlas is cut into tasks, and the task itself: one block of the grid decided.

A task is ``atlas_chunk(scene, location)``: a plain function of picklable
arguments, so the same task runs on a local thread or on a dask.distributed
worker.  The layout (points per chunk) is chosen so that a task takes a fraction
of a second: long enough that the scheduler's per-task cost (milliseconds) is
small beside it, short enough that the points' input arrays stay far below a
worker's memory and that a lost worker loses little.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from .decide import decide
from .errors import StabmapError
from .points import block_arrays, point_arrays, spin_axes_last
from .scene import Scene

TASK_SECONDS = 0.5  # aimed-for run time of one task on one core
MAX_CHUNK_POINTS = 1 << 18
MAX_CHUNK_BYTES = 64 << 20  # the points' input arrays of one task


def points_per_second(degree: int) -> float:
    """Rough single-core speed of the certified kernels by polynomial degree (fit to BENCHMARKS.md).

    Degree 16 and up are slower per point: the Sturm sequence loses sign
    certainty more often and the root-inclusion step runs.
    """
    degree = max(2, degree)
    if degree <= 12:
        return 3.0e6 / degree**1.3
    return 4.0e7 / degree**2.8


def default_chunk_points(scene: Scene, threads: int) -> int:
    """Points per task: about TASK_SECONDS of work, at most MAX_CHUNK_BYTES of inputs.

    Small atlases are cut into at least four tasks per thread (for balance)
    but never into tasks of fewer than 1024 points.
    """
    total = math.prod(scene.shape)
    by_time = points_per_second(scene.degree) * TASK_SECONDS
    one = point_arrays(scene, {})
    per_point = sum(a.nbytes for a in (one.body, one.joint, one.g, one.E, one.kappa, one.at)) + 8
    by_memory = MAX_CHUNK_BYTES // per_point
    balance = max(1024, total // (4 * max(1, threads)))
    return int(max(1, min(by_time, by_memory, MAX_CHUNK_POINTS, balance)))


def check_chunk_points(value, option: str = "chunk_points") -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not float(value).is_integer() or value < 1:
        raise StabmapError(f"{option} must be a whole number >= 1 (points per task), got {value!r}")
    return int(value)


def chunk_shape(shape: tuple[int, ...], points: int) -> tuple[int, ...]:
    """Chunk sizes per axis holding about ``points`` points, trailing axes kept whole first."""
    chunks = []
    budget = max(1, points)
    for size in reversed(shape):
        c = max(1, min(size, budget))
        chunks.append(c)
        budget = max(1, budget // c)
    return tuple(reversed(chunks))


def chunk_locations(shape: tuple[int, ...], chunks: tuple[int, ...]) -> list[tuple[tuple[int, int], ...]]:
    """Every chunk as ((start, stop) per axis), in C order of the chunk grid."""
    per_axis = [[(a, min(a + c, size)) for a in range(0, size, c)] for size, c in zip(shape, chunks)]
    return [tuple(loc) for loc in itertools.product(*per_axis)]


def atlas_chunk(scene: Scene, location: tuple[tuple[int, int], ...]) -> np.ndarray:
    """Decide the block ``location`` of the grid: int16 array (2, *block shape) of N_c and decided_by."""
    order = spin_axes_last(scene)
    # Spin axes vary fastest so the kernels reuse M and K between points (points.spin_axes_last).
    nc, decided_by = decide(block_arrays(scene, list(location), order))
    block = tuple(stop - start for start, stop in location)
    permuted = tuple(block[d] for d in order)
    back = tuple(np.argsort(order))
    nc = nc.reshape(permuted).transpose(back)
    decided_by = decided_by.reshape(permuted).transpose(back)
    return np.stack([nc, decided_by.astype(np.int16)])
