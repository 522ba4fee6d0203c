"""The frame of a map: the edges of its drawn cells and its axes, shared by the class maps (:mod:`.atlas`), the
maps of a float variable (:mod:`.value_map`) and the line of one free axis (:mod:`.label_line`)."""

from __future__ import annotations

import numpy as np
import xarray as xr

from .geometry import block_edges, proved_cell_edges
from .labels import log_axis
from .layout import FigurePlan
from .ticks import set_axis


def map_edges(ds: xr.Dataset, plan: FigurePlan, factors: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """The edges of the drawn cells along x and y: the cells the atlas proves its labels on, merged into blocks of
    ``factors`` (y, x); a strip's y runs from 0 to 1."""
    xe = proved_cell_edges(np.asarray(ds[plan.x], dtype=float), log_axis(ds, plan.x))
    ye = proved_cell_edges(np.asarray(ds[plan.y], dtype=float), log_axis(ds, plan.y)) if plan.y else np.array([0.0, 1.0])
    return block_edges(xe, factors[1]), block_edges(ye, factors[0]) if plan.y else ye


def set_map_axes(first, ds: xr.Dataset, plan: FigurePlan, xe: np.ndarray, ye: np.ndarray,
                 inches: tuple[float, float] | None = None) -> dict[str, str]:
    """Scales, limits and ticks of the maps (shared, so set on the ``first``; :func:`stabmap.read.plot.ticks.set_axis`,
    the rule a page follows too): log axes labelled between decades, ticks at a few listed values, spin rates in
    their display units. ``inches``: the maps' size (y, x) in the layout. Returns the unit each axis is shown in."""
    shown = {plan.x: set_axis(first, "x", ds, plan.x, xe[0], xe[-1], None if inches is None else inches[1])}
    if plan.y:
        shown[plan.y] = set_axis(first, "y", ds, plan.y, ye[0], ye[-1], None if inches is None else inches[0])
    else:
        first.set_ylim(0, 1)
        first.set_yticks([])
    return shown
