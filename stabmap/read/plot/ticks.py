"""The ticks of a map's axis, one rule for the PNG maps and the interactive page: the scale (log where the grid is),
log axes labelled between decades, ticks at a few listed values, spin rates in their display unit (rpm, Hz).

The PNG sets them on its own axes (:func:`set_axis`); a page asks :func:`axis_ticks` for the values and texts
the same rule gives on an axis as long as the PNG's single map, so that both show the same ticks and units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr

from .labels import display_ticks, log_axis, log_ticks

STEPS = (1, 2, 2.5, 5, 10)  # matplotlib's AutoLocator steps


def tick_count(inches: float, which: str) -> int:
    """At most this many intervals between ticks on an axis ``inches`` long: matplotlib's own rule for
    ``nbins="auto"`` (``Axis.get_tick_space``: three label heights apart along x, two along y, at most 9), taken
    from the layout's length rather than the drawn axes', so that a page can give the same ticks."""
    from matplotlib import rcParams
    from matplotlib.font_manager import FontProperties

    size = FontProperties(size=rcParams[f"{which}tick.labelsize"]).get_size_in_points()
    return max(1, min(9, math.floor(72 * inches / (size * (3 if which == "x" else 2)))))


def set_axis(ax, which: str, ds: xr.Dataset, dim: str, lo: float, hi: float, inches: float | None = None) -> str:
    """Scale, limits ``lo``..``hi`` and ticks of the ``which`` ("x", "y") axis of ``ax`` showing coordinate ``dim``.
    ``inches``: the axis's length in the layout (None: matplotlib chooses from the drawn axes). Returns the unit its
    tick labels are shown in ("" for the stored unit)."""
    from matplotlib.ticker import MaxNLocator

    axis = ax.xaxis if which == "x" else ax.yaxis
    if log_axis(ds, dim):
        (ax.set_xscale if which == "x" else ax.set_yscale)("log")
    (ax.set_xlim if which == "x" else ax.set_ylim)(min(lo, hi), max(lo, hi))
    log = axis.get_scale() == "log"
    nbins = "auto" if inches is None else tick_count(inches, which)
    if log:
        log_ticks(axis, *sorted(np.asarray(ds[dim], dtype=float)[[0, -1]]))
    elif inches is not None:
        axis.set_major_locator(MaxNLocator(nbins=nbins, steps=list(STEPS)))
    if ds[dim].attrs.get("scale") == "values" and 1 < ds.sizes[dim] <= 8:  # ticks at listed values ...
        v = np.sort(np.asarray(ds[dim], dtype=float))
        v_ = np.log(v) if log else v
        if np.min(np.diff(v_)) >= (v_[-1] - v_[0]) / 12:  # ... unless their labels would collide
            (ax.set_xticks if which == "x" else ax.set_yticks)(v)
    return display_ticks(ds, dim, axis, nbins)


@dataclass(frozen=True)
class Ticks:
    """An axis's ticks as shown: the unit of the tick labels ("" for the stored unit), labelled ticks (value, text
    in mathtext, as matplotlib draws it) and the unlabelled ones."""

    shown: str
    labelled: list[tuple[float, str]]
    unlabelled: list[float]


def axis_ticks(ds: xr.Dataset, dim: str, lo: float, hi: float, inches: float, which: str) -> Ticks:
    """The ticks :func:`set_axis` gives coordinate ``dim`` between ``lo`` and ``hi`` on an axis ``inches`` long."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(inches, inches))
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    shown = set_axis(ax, which, ds, dim, lo, hi, inches)
    axis = ax.xaxis if which == "x" else ax.yaxis
    a, b = min(lo, hi), max(lo, hi)
    slack = 1e-9 * (math.log(b / a) if a > 0 and axis.get_scale() == "log" else b - a)

    def inside(v: float) -> bool:  # matplotlib shows a tick a rounding error beyond the limits: 0.30000000000000004 of 0.3
        w = math.log(v / a) if a > 0 and axis.get_scale() == "log" else v - a
        return -slack <= w <= (math.log(b / a) if a > 0 and axis.get_scale() == "log" else b - a) + slack

    labelled, unlabelled = [], []
    for locs, fmt in ((axis.get_majorticklocs(), axis.get_major_formatter()), (axis.get_minorticklocs(), axis.get_minor_formatter())):
        locs = [float(v) for v in locs if v > 0 or axis.get_scale() != "log"]
        locs = [v for v in locs if inside(v)]
        for v, text in zip(locs, fmt.format_ticks(locs), strict=True):
            v = min(max(v, a), b)  # on the page's range, or a browser leaves it out
            (labelled.append((v, text)) if text else unlabelled.append(v))
    return Ticks(shown, labelled, unlabelled)
