"""The reduce step of an atlas figure: each panel's map read once, chunk by chunk, and reduced to at most one block
of grid points per pixel (:func:`stabmap.read.blocks.reduce_blocks`), with the flags drawn over the classes and the
shares of the area its cells prove."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from ...store.variables import CELL, INFERRED
from ..areas import AreaShares, area_shares
from ..blocks import block_factors, reduce_blocks
from .layout import FigurePlan, panel_pixels

# Bits of the flag map reduced with the labels (blocks.reduce_blocks ORs them over a block)
FLAG_INFERRED, FLAG_NODE_ONLY, FLAG_CHANGE = 1, 2, 4


@dataclass(frozen=True)
class Reduced:
    """What the panels of one figure draw: ``blocks`` per panel (``panels``: its (row, facet) indices), the block
    ``factors`` along (y, x), the ``shape`` of a panel's grid, the label's counts over all panels and each panel's
    proved shares of its area (None: the atlas has no ``cell`` variable)."""

    panels: list
    blocks: list
    factors: tuple[int, int]
    shape: tuple[int, int]
    totals: dict[int, int]
    shares: list[AreaShares] | None

    @property
    def present(self) -> list[int]:
        """The labels drawn, in order."""
        return sorted(self.totals)

    @property
    def points(self) -> int:
        return sum(self.totals.values())


def flag_map(ds: xr.Dataset, system) -> xr.DataArray | None:
    """The bits drawn over the classes, per grid point: FLAG_INFERRED (the system's provenance says inferred, or
    cell says not_proved), FLAG_NODE_ONLY and FLAG_CHANGE (``cell``); None for an atlas with neither variable."""
    bits = None
    if system.provenance in ds:
        flags = system.variable(system.provenance)
        if INFERRED in flags.meanings:
            bits = (ds[system.provenance] == flags.value(INFERRED)).astype(np.int8) * FLAG_INFERRED
    if CELL.name in ds:
        cell = ds[CELL.name]
        more = ((cell == CELL.value("not_proved")) * FLAG_INFERRED + (cell == CELL.value("node_only")) * FLAG_NODE_ONLY
                + (cell == CELL.value("contains_change")) * FLAG_CHANGE).astype(np.int8)
        bits = more if bits is None else bits | more
    return bits


def panel_map(da: xr.DataArray, plan: FigurePlan, r: int | None, c: int | None):
    """One panel's map of ``da`` (fixed axes already selected) as (y, x), a strip as (1, x); still lazy for a lazy
    atlas. ``r``, ``c``: the panel's index along the row and facet axes (None: no such axis)."""
    sl = {}
    if r is not None:
        sl[plan.row] = r
    if c is not None:
        sl[plan.facet] = c
    a = da.isel(sl).transpose(*((plan.y, plan.x) if plan.y else (plan.x,))).data
    return a if plan.y else a[None, :]


def panel_areas(ds: xr.Dataset, plan: FigurePlan, label: xr.DataArray, fix: dict, panels: list, stable: int | None) -> list[AreaShares] | None:
    """Each panel's shares of its area proved stable, unstable, ... (:mod:`stabmap.read.areas`); None for an atlas
    without ``cell``. ``label``: the atlas's label with the fixed axes (``fix``) selected."""
    if CELL.name not in ds:
        return None
    from ..summary import cell_sizes

    cell = ds[CELL.name].isel(fix)
    wy = cell_sizes(ds, plan.y) if plan.y else np.ones(1)
    return area_shares([panel_map(label, plan, r, c) for r, c in panels], [panel_map(cell, plan, r, c) for r, c in panels],
                       wy, cell_sizes(ds, plan.x), stable)


def reduce_panels(ds: xr.Dataset, plan: FigurePlan, system, width: float, nrows: int, ncols: int) -> Reduced:
    """Read every panel of ``plan`` once and reduce it to blocks no smaller than the pixels the layout gives a map
    (``width`` [inch], ``nrows`` x ``ncols`` maps)."""
    fix = {k: i for k, (i, _) in plan.fixed.items()}
    label = ds[system.label].isel(fix)
    flags = flag_map(ds, system)
    flags = None if flags is None else flags.isel(fix)
    panels = [(r, c) for r in (plan.row_index or (None,)) for c in (plan.facet_index or (None,))]
    shape = (ds.sizes[plan.y] if plan.y else 1, ds.sizes[plan.x])
    factors = block_factors(shape, panel_pixels(width, nrows, ncols, facets=plan.facet is not None, strip=plan.y is None))
    blocks = [reduce_blocks(panel_map(label, plan, r, c), None if flags is None else panel_map(flags, plan, r, c), system.stable_label, factors)
              for r, c in panels]
    totals: dict[int, int] = {}
    for b in blocks:
        for v, n in b.counts.items():
            totals[v] = totals.get(v, 0) + n
    shares = panel_areas(ds, plan, label, fix, panels, system.stable_label)
    return Reduced(panels, blocks, factors, shape, totals, shares)
