"""Which axis of an atlas goes where on a page (:func:`plan_page`): two on the map, one slider for each further
axis, the rest fixed by ``sel``; and which slider positions fit the page's size bound (:func:`thin`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from ..plot.layout import evenly, free_to_draw, nearest


@dataclass(frozen=True)
class PagePlan:
    """The map's axes ``x`` and ``y`` (None: a strip), the ``sliders`` with the grid indices each shows
    (``positions``), the axes fixed by ``sel`` (``fixed``: name -> (index, asked)) and the notes to show."""

    x: str
    y: str | None
    sliders: tuple[str, ...] = ()
    positions: dict[str, tuple[int, ...]] = field(default_factory=dict)
    fixed: dict[str, tuple[int, float]] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    @property
    def frames(self) -> list[dict[str, int]]:
        """Every slider setting as {axis: grid index}, the first slider turning slowest (row-major)."""
        if not self.sliders:
            return [{}]
        counts = [len(self.positions[s]) for s in self.sliders]
        return [{s: self.positions[s][i] for s, i in zip(self.sliders, idx, strict=True)} for idx in np.ndindex(*counts)]


def plan_page(ds: xr.Dataset, dims: list[str], *, x: str | None = None, y: str | None = None, sel: dict | None = None) -> PagePlan:
    """Check ``x``, ``y`` and ``sel`` against the axes ``dims`` of ``ds`` and decide the page's layout: the map's
    axes (default: the first two free axes), a slider for every other free axis, every value on it."""
    sel = dict(sel or {})
    free = free_to_draw(ds, dims, sel, {"x": x, "y": y})
    rest = [d for d in free if d not in (x, y)]
    x = x or rest.pop(0)
    if len(free) >= 2:
        y = y or rest.pop(0)
    fixed, notes = nearest(ds, sel)
    return PagePlan(x, y, tuple(rest), {d: tuple(range(ds.sizes[d])) for d in rest}, fixed, tuple(notes))


def thin(plan: PagePlan, sizes: dict[str, int], frames_allowed: int, why: str) -> PagePlan:
    """``plan`` with at most ``frames_allowed`` slider settings: the slider with the most values loses values first,
    evenly spaced values kept (both ends), and a note saying what was left out and ``why``."""
    counts = {s: len(plan.positions[s]) for s in plan.sliders}
    frames_allowed = max(1, frames_allowed)
    while math.prod(counts.values()) > frames_allowed:
        s = max(counts, key=lambda k: counts[k])
        others = math.prod(counts.values()) // counts[s]
        counts[s] = max(1, min(counts[s] - 1, frames_allowed // max(1, others)))
    if all(counts[s] == len(plan.positions[s]) for s in plan.sliders):
        return plan
    positions = {s: tuple(plan.positions[s][i] for i in evenly(len(plan.positions[s]), counts[s])) for s in plan.sliders}
    left = [f"{s}: {len(positions[s])} of {sizes[s]} values on its slider, evenly spaced" for s in plan.sliders
            if len(positions[s]) < sizes[s]]
    note = "; ".join(left) + f" ({why})"
    return PagePlan(plan.x, plan.y, plan.sliders, positions, plan.fixed, (*plan.notes, note))
