"""The one task of every run: decide points of a scene's grid with the scene's system.

A task is a plain function of picklable arguments (a scene and where its points
are), so the same task runs on a local thread or on a dask.distributed worker,
and dense atlases, adaptive refinement and critical values all submit it.
"""

from __future__ import annotations

import numpy as np

from .. import systems
from ..systems.base import SceneBase


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
        view = [None] * len(location)
        view[pos] = slice(None)
        values[scene.grid[d].name] = scene.grid[d].array[start:stop][tuple(view)]
    return values


def evaluate_block(scene: SceneBase, location: tuple[tuple[int, int], ...]) -> dict[str, np.ndarray]:
    """Every variable on the block ``location`` = ((start, stop) per grid axis), in grid order."""
    order = point_order(scene)
    out = systems.of(scene).evaluate(scene, block_values(scene, location, order))
    back = tuple(np.argsort(order))
    return {k: v.transpose(back + tuple(range(len(order), v.ndim))).copy(order="C") for k, v in out.items()}


def evaluate_points(scene: SceneBase, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Every variable at points given by equal-length 1-D arrays of grid-axis values (the other axes: fixed values)."""
    return systems.of(scene).evaluate(scene, values)

