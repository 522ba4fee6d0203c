"""The mark of a cell proved to hold a change of label (``cell = contains_change``), shared by figures and pages.

The mark is drawn OVER the colour of the grid point's label, never instead of it: the colour is what the node is
proved to be, the mark says that somewhere inside the cell's box the label differs. In a slice of an atlas that
scans more axes, that box spans the axes not drawn too, so the change may lie along one of them only.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .labels import symbol

HATCH_CHANGE = "\\\\\\\\\\\\"  # dark diagonal lines against the light '////' of inferred cells and the 'xxxx' of degenerate ones
CHANGE_INK = "#000000D9"  # almost black, so the hatch reads over every class colour, pale yellow as dark purple
PAGE_HATCH = "\\"  # the page's hatch (bokeh's left_diagonal_line), the same direction as the figures'


def hidden_cell_axes(ds: xr.Dataset, label: str, drawn: tuple[str | None, ...]) -> list[str]:
    """The axes of ``ds[label]`` not among ``drawn`` along which a cell spans more than its grid value: a cell
    flagged contains_change in the map drawn may change along these only.

    The atlas's CF bounds variables say what a cell spans. An axis is left out when its cells have zero width, or
    when it has no bounds while other axes have some (a discrete axis, its values listed: a slice at one of its
    values holds its own cells). An atlas with no bounds at all is read as the figures draw it: cells reach
    halfway to the neighbours along every axis."""
    def bounds_of(d) -> str:
        return ds[d].attrs.get("bounds", f"{d}_bounds")

    any_bounds = any(bounds_of(d) in ds.variables for d in ds[label].dims)
    out = []
    for d in ds[label].dims:
        if d in drawn or ds.sizes[d] < 2:
            continue
        name = bounds_of(d)
        if name in ds.variables:
            if not np.any(np.diff(np.asarray(ds[name], dtype=float), axis=-1)):
                continue
        elif any_bounds:
            continue
        out.append(str(d))
    return out


def change_text(hidden: list[str], ds: xr.Dataset, plain=None) -> str:
    """What the hatch says, in plain words (one line; the figure's legend breaks it): the change is proved inside the
    cell, the colour is still the grid point's label, and in a slice the change may lie along an axis not drawn
    (``hidden``: :func:`hidden_cell_axes`, named by their symbols; ``plain``: how to write a mathtext symbol)."""
    text = "hatched: a change of label is proved inside the cell (colour: the label at its grid point)"
    if hidden:
        names = [symbol(ds, d) if plain is None else plain(symbol(ds, d)) for d in hidden]
        text += f"; the change may lie along {' or '.join(names)} alone, which the map does not draw"
    return text
