"""The one task of every run: decide points of a scene's grid with the scene's system.

A task is a plain function of picklable arguments (a scene and where its points
are), so the same task runs on a local thread or on a dask.distributed worker,
and dense atlases, adaptive refinement and critical values all submit it.

Every task goes through ``run_task``, which checks the worker's stabmap version,
loads the system's kernels once per process (untimed: compiling or loading them
is not the cost of the points), and returns the task's result with its measured
run time, from which the runner sizes the next tasks (``stabmap.run.runner``),
and that time split by stage (``stabmap.systems.stages``): the seconds travel
with the result, so a worker in another process reports them alike.
"""

from __future__ import annotations

import math
import threading
import time

import numpy as np

from .. import systems
from ..errors import StabmapError
from ..store.variables import CELL
from ..systems import stages
from ..systems.base import SceneBase
from ..version import __version__
from . import cells

PROBE_SECONDS = 0.2  # a probe stops once it has timed this much work
PROBE_PART = 4  # a probe of cells times the first quarter of a tile along each axis (a sixteenth of a 2-D tile)

_warm: set[str] = set()  # the systems whose kernels this process has loaded
_warm_lock = threading.Lock()


def run_task(version: str, function, scene: SceneBase, *args) -> tuple[object, float, dict[str, float]]:
    """``function(scene, *args)``, its run time [s] and that time by stage, on a worker of stabmap ``version`` with
    warm kernels."""
    if version != __version__:
        raise StabmapError(
            f"a worker runs stabmap {__version__}, the calling process {version}; install the same stabmap on every worker"
        )
    warm_up(scene)
    t0 = time.perf_counter()
    with stages.timed() as by_stage:
        result = function(scene, *args)
    return result, time.perf_counter() - t0, by_stage


def warm_up(scene: SceneBase) -> None:
    """Load (or compile) the kernels of ``scene``'s system in this process, by deciding its first grid point once."""
    name = systems.of(scene).name
    if name in _warm:
        return
    with _warm_lock:
        if name not in _warm:
            systems.of(scene).evaluate(scene, {a.name: a.array[:1] for a in scene.grid})
            _warm.add(name)


def point_order(scene: SceneBase) -> tuple[int, ...]:
    """The grid axes in the order points are visited, the last varying fastest (the system's fastest axes last)."""
    fastest = systems.of(scene).fastest_axes(scene)
    return tuple(d for d in range(len(scene.grid)) if d not in fastest) + tuple(fastest)


def block_values(scene: SceneBase, location, order: tuple[int, ...] | None = None) -> dict[str, np.ndarray]:
    """The grid-axis values of the block ``location`` = ((start, stop) per grid axis), as arrays that broadcast
    to the block's points with the axes taken in ``order`` (default: the grid's; the last varies fastest)."""
    order = tuple(range(len(location))) if order is None else tuple(order)
    values = {}
    for pos, d in enumerate(order):
        start, stop = location[d]
        view: list[slice | None] = [None] * len(location)
        view[pos] = slice(None)
        values[scene.grid[d].name] = scene.grid[d].array[start:stop][tuple(view)]
    return values


def evaluate_block(scene: SceneBase, location: tuple[tuple[int, int], ...], prove_cells: bool = True) -> dict[str, np.ndarray]:
    """Every variable and ``cell`` on the block ``location`` = ((start, stop) per grid axis), in grid order.

    ``prove_cells``: by boxes where the system proves them (``stabmap.run.cells``); otherwise (or False) every
    node is computed and every cell is ``node_only``.
    """
    system = systems.of(scene)
    order = point_order(scene)
    if prove_cells and cells.provable(scene):
        return cells.decide_chunk(scene, location, lambda values: system.evaluate(scene, values), order)
    out = system.evaluate(scene, block_values(scene, location, order))
    back = tuple(np.argsort(order))
    out = {k: v.transpose(back + tuple(range(len(order), v.ndim))).copy(order="C") for k, v in out.items()}
    out[CELL.name] = np.full(tuple(b - a for a, b in location), cells.NODE_ONLY, dtype=CELL.dtype)
    return out


def evaluate_blocks(scene: SceneBase, locations: list, prove_cells: bool = True) -> list[dict[str, np.ndarray]]:
    """``evaluate_block`` of each of ``locations``: one task may decide several chunks of the grid."""
    return [evaluate_block(scene, location, prove_cells) for location in locations]


def probe(scene: SceneBase, values: dict[str, np.ndarray]) -> tuple[int, float]:
    """Time the points ``values`` (1-D arrays of grid-axis values) in growing batches, for up to PROBE_SECONDS.

    The batches run twice and only the second pass is timed: the first loads whatever the kernels load lazily
    (paths that the first point did not take).  Returns the points timed and their run time [s]: the seconds a
    point costs, measured, not modelled.
    """
    npts = len(next(iter(values.values()))) if values else 1
    stop = npts
    for _pass in ("untimed", "timed"):  # the second pass's numbers are returned
        done, spent, n = 0, 0.0, 1
        while done < stop and spent < PROBE_SECONDS:
            end = min(stop, done + n)
            t0 = time.perf_counter()
            evaluate_points(scene, {k: v[done:end] for k, v in values.items()})
            spent += time.perf_counter() - t0
            done, n = end, 4 * n
        stop = max(done, 1)
    return done, spent


def probe_tiles(scene: SceneBase, locations: list) -> tuple[int, float]:
    """Time parts of tiles decided cell by cell (``evaluate_block``; ``stabmap.run.chunks.tile_locations``) for up to
    PROBE_SECONDS, after a few untimed cells that load what the kernels load lazily.  Returns (points, seconds).

    Each part is the tile's first PROBE_PART along every axis it spans: the probe's work is thrown away, and a whole
    tile of a long chain takes seconds."""
    evaluate_block(scene, tuple((a, min(b, a + 2)) for a, b in locations[0]))
    done, spent = 0, 0.0
    for location in locations:
        if spent >= PROBE_SECONDS:
            break
        part = _part(location, PROBE_PART)
        t0 = time.perf_counter()
        evaluate_block(scene, part)
        spent += time.perf_counter() - t0
        done += math.prod(b - a for a, b in part)
    return done, spent


def _part(location: tuple[tuple[int, int], ...], share: float) -> tuple[tuple[int, int], ...]:
    """The first 1/share of ``location`` along each axis (at least one point, and at least two where it has two)."""
    return tuple((a, a + max(min(b - a, 2), int((b - a) / share))) for a, b in location)


def evaluate_points(scene: SceneBase, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Every variable at points given by equal-length 1-D arrays of grid-axis values (the other axes: fixed values)."""
    return systems.of(scene).evaluate(scene, values)



def prove_boxes(scene: SceneBase, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """``System.prove_boxes`` of boxes given by equal-length 1-D arrays of their corners: {"label", "proved"}."""
    label, proved = systems.of(scene).prove_boxes(scene, lower, upper)
    return {"label": label, "proved": proved}
