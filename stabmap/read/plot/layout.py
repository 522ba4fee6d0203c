"""Which axis of an atlas goes where in a figure (:func:`plan_figure`), checked before anything is drawn, and the
room the layout leaves each map (:func:`panel_pixels`), which decides how finely a map can be drawn."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from ... import systems
from ...errors import StabmapError, given, param
from ...scene.units import unit_suffix

MAX_PANELS = 12  # default limit of small multiples
LEGEND_WIDTH = 2.5  # [inch] beside small multiples
SINGLE_WIDTH = 7.5  # [inch] a figure of a single map
DPI = 150  # of a PNG; a map with more grid points than its pixels at this resolution is drawn in blocks
# Lower bounds of the room the layout leaves a map [inch] (checked against the drawn figures in tests/test_plot.py)
_SINGLE_MARGIN = 3.6  # a single map: figure width less the legend, the y label and the margins
_SINGLE_HEIGHT = 3.2  # a single map: figure height less the title (up to 7 lines) and the x label
_FACET_MARGIN = 0.9  # small multiples: the supylabel and margins
_PANEL_GAP = 0.35  # between panels, and their tick labels
_PANEL_HEIGHT = 2.3  # a row of small multiples
_PANEL_TITLE = 0.75  # the panel's title and tick labels


class _Value:
    """The placeholder of a value to choose, ``VALUE`` both in Python (``sel={'K_1': VALUE}``) and on the command
    line (``--sel K_1=VALUE``)."""

    def __repr__(self) -> str:
        return "VALUE"

    __str__ = __repr__


VALUE = _Value()


@dataclass(frozen=True)
class FigurePlan:
    """Which axis of the atlas goes where in the figure; made by :func:`plan_figure`, checked, nothing drawn.

    ``fixed`` maps each axis not drawn to ``(index, requested)``: the grid index used and the value asked for
    with ``sel`` (None when the axis was left at its first value because a figure shows at most four axes).
    """

    x: str
    y: str | None = None
    facet: str | None = None
    row: str | None = None
    facet_index: tuple[int, ...] = ()
    row_index: tuple[int, ...] = ()
    fixed: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    @property
    def n_panels(self) -> int:
        return max(1, len(self.facet_index)) * max(1, len(self.row_index))


def evenly(n: int, k: int) -> tuple[int, ...]:
    """``k`` evenly spaced indices of ``n`` (both ends included when k >= 2)."""
    if k >= n:
        return tuple(range(n))
    return tuple(int(i) for i in np.unique(np.round(np.linspace(0, n - 1, k)).astype(int)))


def rows_cols(n_rows: int, n_cols: int, max_panels: int) -> tuple[int, int]:
    """Rows and columns for a 4-axis atlas: as many panels as allowed, as square as possible, wider than tall."""
    best = (1, 1)
    for r in range(1, min(n_rows, max_panels) + 1):
        c = min(n_cols, max_panels // r)
        if (r * c, -abs(c - r), c) > (best[0] * best[1], -abs(best[1] - best[0]), best[1]):
            best = (r, c)
    return best


def _check_sel(ds: xr.Dataset, dims: list[str], sel: dict) -> None:
    """Each axis fixed by ``sel`` is a grid axis of ``dims`` and its value a finite number."""
    for k, v in sel.items():
        if k in ds.coords and ds[k].ndim == 0 and k not in dims:
            raise StabmapError(f"{given('sel', ..., k)}: fixed at {float(ds[k]):g}{unit_suffix(ds[k].attrs.get('units'))} in this atlas, "
                               f"not a grid axis; its axes are: {', '.join(dims)}")
        if k not in dims:
            raise StabmapError(f"{given('sel', ..., k)}: not an axis of this atlas; its axes are: {', '.join(dims)}")
        if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v):
            raise StabmapError(f"{given('sel', v, k)}: give a finite number, e.g. {given('sel', float(ds[k][0]), k)}")


def _check_roles(dims: list[str], sel: dict, roles: list[tuple[str, str]]) -> None:
    """Each of x, y and facet (``roles``: parameter, axis) names an axis of ``dims`` not fixed by ``sel``, once."""
    for opt, name in roles:
        if name not in dims:
            raise StabmapError(f"{given(opt, name)}: not an axis of this atlas; choose from {', '.join(dims)}")
        if name in sel:
            raise StabmapError(f"{given(opt, name)}: this axis is also fixed by {given('sel', ..., name)}; drop one of the two")
    for i, (opt, name) in enumerate(roles):
        for opt2, _ in (r for r in roles[i + 1 :] if r[1] == name):
            raise StabmapError(f"{param(opt)} and {param(opt2)} both name {name}; give each axis one place in the figure")


def free_to_draw(ds: xr.Dataset, dims: list[str], sel: dict, roles: dict[str, str | None]) -> list[str]:
    """The axes of ``dims`` that ``sel`` leaves free, after checking ``sel`` and the ``roles`` (option -> axis or None:
    x, y, facet) against them: at least one is left, and two where ``y`` is given."""
    _check_sel(ds, dims, sel)
    _check_roles(dims, sel, [(opt, name) for opt, name in roles.items() if name is not None])
    free = [d for d in dims if d not in sel]
    if not free:
        raise StabmapError(f"{param('sel')} fixes every axis ({', '.join(dims)}); leave one or two free to draw, or use 'stabmap query'")
    if len(free) == 1 and roles.get("y") is not None:
        raise StabmapError(f"{given('y', roles['y'])}: only one axis is left to draw ({free[0]}), along x; drop {param('y')}")
    return free


def nearest(ds: xr.Dataset, sel: dict) -> tuple[dict[str, tuple[int, float]], list[str]]:
    """Each axis of ``sel`` at its grid value nearest to the one asked, as ``{name: (index, asked)}``, and a note for
    each value asked outside the grid."""
    fixed, notes = {}, []
    for k, v in sel.items():
        values = np.asarray(ds[k], dtype=float)
        fixed[k] = (int(np.argmin(np.abs(values - v))), float(v))
        if not values.min() <= v <= values.max():
            notes.append(f"{k} = {v:g} lies outside the grid ({values.min():g} .. {values.max():g}{unit_suffix(ds[k].attrs.get('units'))}): "
                         f"drawn at its nearest end, {k} = {values[fixed[k][0]]:g}")
    return fixed, notes


def plan_figure(
    ds: xr.Dataset,
    *,
    x: str | None = None,
    y: str | None = None,
    sel: dict[str, float] | None = None,
    facet: str | None = None,
    max_panels: int = MAX_PANELS,
) -> FigurePlan:
    """Check the options of :func:`stabmap.read.plot.atlas_figure` against ``ds`` and decide the layout (see there)."""
    label = systems.of_atlas(ds.attrs).label
    if label not in ds:
        raise StabmapError(f"not a stabmap atlas: the Dataset has no {label!r} variable")
    if isinstance(max_panels, bool) or not isinstance(max_panels, (int, np.integer)) or max_panels < 1:
        raise StabmapError(f"{param('max_panels')} must be a whole number >= 1, got {max_panels!r}")
    dims = list(ds[label].dims)
    if not dims:
        raise StabmapError("this atlas has no axis to plot (a single point); use 'stabmap info' or 'stabmap query'")
    sel = dict(sel or {})
    free = free_to_draw(ds, dims, sel, {"x": x, "y": y, "facet": facet})
    if len(free) <= 2 and facet is not None:
        raise StabmapError(
            f"{given('facet', facet)}: only {len(free)} ax{'is' if len(free) == 1 else 'es'} left to draw ({', '.join(free)}), "
            f"all on the map; facets need a third axis, so drop {param('facet')}"
        )
    rest = [d for d in free if d not in (x, y, facet)]
    x = x or rest.pop(0)
    if len(free) >= 2:
        y = y or rest.pop(0)
    if len(free) >= 3:
        facet = facet or rest.pop(0)
    row = rest.pop(0) if len(free) >= 4 else None

    chosen, notes = nearest(ds, sel)
    fixed: dict[str, tuple[int, float | None]] = dict(chosen)
    for d in rest:  # a figure shows at most four axes
        fixed[d] = (0, None)
        notes.append(f"{d} fixed at its first value (choose with {given('sel', VALUE, d)})")

    facet_index: tuple[int, ...] = ()
    row_index: tuple[int, ...] = ()
    panel_notes = []
    if facet is not None:
        n_f = ds.sizes[facet]
        if row is None:
            facet_index = evenly(n_f, max_panels)
        else:
            r, c = rows_cols(ds.sizes[row], n_f, max_panels)
            facet_index, row_index = evenly(n_f, c), evenly(ds.sizes[row], r)
        for axis, index in ((facet, facet_index), (row, row_index)):
            if axis is not None and len(index) < ds.sizes[axis]:
                panel_notes.append(f"{axis}: {len(index)} of {ds.sizes[axis]} values drawn, evenly spaced")
        if panel_notes:
            panel_notes[-1] += f" (more with {param('max_panels')}, now {max_panels}; one with {param('sel')})"
    notes = panel_notes + notes
    return FigurePlan(x, y, facet, row, facet_index, row_index, fixed, tuple(notes))


def panel_grid(plan: FigurePlan) -> tuple[int, int, float]:
    """Rows and columns of the maps of ``plan``, and the figure's width [inch]."""
    if plan.row is not None:
        nrows, ncols = len(plan.row_index), len(plan.facet_index)
    elif plan.facet is not None:
        k = len(plan.facet_index)
        ncols = k if k <= 3 else math.ceil(math.sqrt(k))
        nrows = math.ceil(k / ncols)
    else:
        nrows = ncols = 1
    width = SINGLE_WIDTH if plan.facet is None else max(3.5, 2.6 * ncols + 0.9) + LEGEND_WIDTH
    return nrows, ncols, width


def figure_size(plan: FigurePlan, width: float, nrows: int, title_lines: int, n_classes: int) -> tuple[float, float]:
    """The figure's size [inch] before the caption: a map, a strip (tall enough for the legend of ``n_classes``)
    or ``nrows`` rows of small multiples, under a title of ``title_lines`` lines."""
    if plan.facet is None:
        return (width, 5.2) if plan.y else (width, max(1.4 + 0.17 * title_lines, 0.22 * (n_classes + 4)) + 0.6)
    return (width, 2.3 * nrows + 0.8 + 0.17 * title_lines)


def panel_pixels(width: float, nrows: int, ncols: int, *, facets: bool, strip: bool, dpi: int = DPI) -> tuple[int, int]:
    """Pixels of one map of a figure ``width`` inches wide, along (y, x): a lower bound of what the layout gives.

    A map of more grid points than this is drawn in blocks (:func:`stabmap.read.blocks.block_factors`), so that
    no block is smaller than a pixel and none can vanish between pixels.
    """
    if not facets:
        maps = (1 if strip else _SINGLE_HEIGHT, width - _SINGLE_MARGIN)
    else:
        maps = ((_PANEL_HEIGHT - _PANEL_TITLE) * 1.0, (width - LEGEND_WIDTH - _FACET_MARGIN) / ncols - _PANEL_GAP)
    return max(1, int(dpi * maps[0])), max(1, int(dpi * maps[1]))


def panel_points(width: float, nrows: int, ncols: int, *, facets: bool, strip: bool) -> tuple[float, float]:
    """A lower bound of one map's size in points along (y, x) (:func:`panel_pixels` at 72 dots an inch)."""
    return panel_pixels(width, nrows, ncols, facets=facets, strip=strip, dpi=72)
