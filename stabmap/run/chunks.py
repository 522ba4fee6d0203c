"""How a run is cut into tasks: one rule for the size of every task, and the blocks of a grid.

The size is chosen so that a task takes a fraction of a second: long enough
that the scheduler's per-task cost (milliseconds) is small beside it, short
enough that the points' input arrays stay far below a worker's memory and that
a lost worker loses little.  Dense atlases cut the grid into blocks of that
many points; refinement and critical values cut their lists of points.
"""

from __future__ import annotations

import itertools
import math

from .. import systems
from ..errors import StabmapError
from ..systems.base import SceneBase

TASK_SECONDS = 0.5  # aimed-for run time of one task on one core
MAX_CHUNK_POINTS = 1 << 18
MAX_CHUNK_BYTES = 64 << 20  # the points' input arrays of one task
MIN_CHUNK_POINTS = 1024  # balance never cuts tasks smaller than this


def default_chunk_points(scene: SceneBase, threads: int, npoints: int | None = None) -> int:
    """Points per task: about TASK_SECONDS of work, at most MAX_CHUNK_BYTES of inputs.

    ``npoints`` points (default: the whole grid) are cut into at least four
    tasks per thread (for balance) but never into tasks of fewer than
    MIN_CHUNK_POINTS points.
    """
    total = math.prod(scene.shape) if npoints is None else npoints
    cost = systems.of(scene).cost(scene)
    by_time = TASK_SECONDS / cost.seconds
    by_memory = MAX_CHUNK_BYTES // max(1, cost.bytes)
    balance = max(MIN_CHUNK_POINTS, total // (4 * max(1, threads)))
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


def spans(npoints: int, points: int) -> list[tuple[int, int]]:
    """A list of ``npoints`` points cut into runs of ``points``: (start, stop) each."""
    return [(a, min(a + points, npoints)) for a in range(0, npoints, max(1, points))]
