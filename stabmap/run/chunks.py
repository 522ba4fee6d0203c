"""How a run is cut into tasks: chunks of the grid sized from a measured cost, and the blocks of a grid.

Nothing here models what a point costs: a dense atlas first times a probe of a
few hundred points spread over the grid (``stabmap.run.tasks.probe``), and
cuts the grid into chunks of about BLOCK_SECONDS of work each, long along the axes the kernels run fastest.  The runner then
hands out tasks of several chunks (or, for lists of points, of several points),
sized from the run times of the tasks that finished (``stabmap.run.runner.Pace``),
so each task lasts about TASK_SECONDS whatever the scene: long enough that the
scheduler's per-task cost (milliseconds) is small beside it, short enough that
Ctrl-C, a lost worker or the end of the run waits for little.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from .. import systems
from ..errors import StabmapError, given
from ..systems.base import SceneBase

TASK_SECONDS = 0.5  # aimed-for run time of one task on one core
BLOCK_SECONDS = TASK_SECONDS / 2  # aimed-for run time of one chunk of the grid (a task holds one or several)
# A chunk decided cell by cell proves its boxes round by round, one call of the kernels per round for all its tiles,
# and a call costs a few milliseconds of Python besides its boxes: chunks of several tiles make fewer, fuller calls.
CELL_BLOCK_SECONDS = 4 * BLOCK_SECONDS
MAX_CHUNK_POINTS = 1 << 18
MAX_CHUNK_BYTES = 64 << 20  # the points' input arrays of one task
MIN_CHUNK_POINTS = 16  # the time rule never cuts chunks smaller than this (balance may, on tiny grids)
PROBE_RUNS, PROBE_RUN = 8, 64  # the probe: 8 runs of 64 neighbouring points along the fastest axis


def chunk_points_for(scene: SceneBase, seconds_per_point: float, threads: int, npoints: int | None = None,
                     seconds: float = BLOCK_SECONDS) -> int:
    """Points per chunk: about ``seconds`` of work (BLOCK_SECONDS; CELL_BLOCK_SECONDS for an atlas decided cell by
    cell) at the measured ``seconds_per_point``, at most MAX_CHUNK_BYTES of inputs and MAX_CHUNK_POINTS points, and
    at least eight chunks per thread.

    ``npoints`` is the number of points to cut (default: the whole grid).
    """
    total = math.prod(scene.shape) if npoints is None else npoints
    by_time = max(MIN_CHUNK_POINTS, seconds / max(seconds_per_point, 1e-9))
    by_memory = MAX_CHUNK_BYTES // max(1, systems.of(scene).input_bytes(scene))
    balance = max(1, total // (8 * max(1, threads)))
    return int(max(1, min(by_time, by_memory, MAX_CHUNK_POINTS, balance)))


def probe_points(scene: SceneBase, order: tuple[int, ...], seed: int = 0) -> dict[str, np.ndarray]:
    """Grid-axis values of the probe's points: PROBE_RUNS runs of PROBE_RUN neighbouring points along the fastest
    axis of ``order`` (as the kernels meet them in a chunk), at random places of the grid (seeded: repeatable)."""
    if not scene.grid:
        return {}
    rng = np.random.default_rng(seed)
    fast = order[-1]
    run = min(PROBE_RUN, scene.shape[fast])
    index = [rng.integers(0, n, PROBE_RUNS) for n in scene.shape]
    index[fast] = rng.integers(0, scene.shape[fast] - run + 1, PROBE_RUNS)
    values = {}
    for d, axis in enumerate(scene.grid):
        i = np.repeat(index[d], run) + (np.tile(np.arange(run), PROBE_RUNS) if d == fast else 0)
        values[axis.name] = axis.array[i]
    return values


def tile_locations(shape: tuple[int, ...], tile: tuple[int, ...], seed: int = 0) -> list[tuple[tuple[int, int], ...]]:
    """Locations ((start, stop) per axis) of PROBE_RUNS whole tiles at random places of the grid (seeded: repeatable),
    for an atlas decided cell by cell: its points cost what their tile's proofs cost, not what a point's does."""
    rng = np.random.default_rng(seed)
    counts = [-(-n // t) for n, t in zip(shape, tile, strict=True)]
    picks = [rng.integers(0, c, PROBE_RUNS) for c in counts]
    return [tuple((int(i) * t, min(n, (int(i) + 1) * t)) for i, t, n in zip(at, tile, shape, strict=True)) for at in zip(*picks, strict=True)]


def check_chunk_points(value) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not float(value).is_integer() or value < 1:
        raise StabmapError(f"{given('chunk_points', value)}: must be a whole number >= 1 (points per task)")
    return int(value)


def chunk_shape(shape: tuple[int, ...], points: int, order: tuple[int, ...] | None = None,
                tile: tuple[int, ...] | None = None) -> tuple[int, ...]:
    """Chunk sizes per axis holding about ``points`` points, the axes last in ``order`` kept whole first.

    ``order`` is the order the kernels visit the axes, the fastest last (``stabmap.run.tasks.point_order``;
    default: the grid's): a chunk then holds long runs along the fastest axes, the runs the kernels are quick
    on (work shared by neighbouring points, such as a cavity's liquid modes or a chain's matrices).
    ``tile``: each size is rounded up to a multiple of it (or the whole axis), so that chunks hold whole tiles
    (``stabmap.run.cells``).
    """
    order = tuple(range(len(shape))) if order is None else tuple(order)
    tile = (1,) * len(shape) if tile is None else tuple(tile)
    # counted in tiles: a chunk of whole tiles, about ``points`` points (at least one tile)
    ntiles = [-(-n // t) for n, t in zip(shape, tile, strict=True)]
    chunks = list(ntiles)
    budget = max(1, points // math.prod(tile))
    for d in reversed(order):
        chunks[d] = max(1, min(ntiles[d], budget))
        budget = max(1, budget // chunks[d])
    return tuple(min(n, c * t) for n, c, t in zip(shape, chunks, tile, strict=True))


def chunk_locations(shape: tuple[int, ...], chunks: tuple[int, ...]) -> list[tuple[tuple[int, int], ...]]:
    """Every chunk as ((start, stop) per axis), in C order of the chunk grid."""
    per_axis = [[(a, min(a + c, size)) for a in range(0, size, c)] for size, c in zip(shape, chunks, strict=True)]
    return [tuple(loc) for loc in itertools.product(*per_axis)]


def spans(npoints: int, points: int) -> list[tuple[int, int]]:
    """A list of ``npoints`` points cut into runs of ``points``: (start, stop) each."""
    return [(a, min(a + points, npoints)) for a in range(0, npoints, max(1, points))]
