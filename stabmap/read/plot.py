"""Pictures of an atlas: maps of its label (for gyroscopes N_c, the number of complex root pairs), with the
boundaries between classes.

``atlas_figure`` draws an atlas Dataset into a new matplotlib Figure and computes nothing: it reads
``n_complex_pairs`` and ``decided_by`` and their coordinates, chunk by chunk when the atlas is lazy
(``open_atlas(path, lazy=True)``). ``plot_atlas`` saves that figure to PNG or PDF.

- A map with more grid points than its pixels is drawn in blocks of grid points, no smaller than a pixel
  (:func:`stabmap.read.blocks.reduce_blocks`): a block of one class shows it, a block holding stable and unstable
  points is black (the stability boundary runs through it), one holding several other classes dark grey; the
  title states the block size and this rule. Every stable/unstable boundary thus stays visible.

- A 1-D atlas is a strip, a 2-D atlas one map, and an atlas with 3 or 4 axes small multiples: one panel per
  value of the third axis (the facet), and with a fourth axis one row per value of it. Evenly spaced values are
  drawn when there are more than ``max_panels`` panels, and the figure says which. Other axes are fixed with
  ``sel`` (nearest grid value).
- Classes are coloured from the Okabe-Ito palette (stable: sky blue; 1, 2, 3 ... complex pairs: yellow, orange,
  vermillion, ...); each class always has the same colour. Degenerate points (p identically zero) are grey and
  cross-hatched, points whose class was not proved (``System.undecided_label``) dark grey and cross-hatched; points of an adaptive atlas that were inferred from their cell's corners (``decided_by`` = 3)
  carry a light diagonal hatch (a light veil in very large adaptive atlases).
- Cells (``cell``, docs/cells.md): a cell whose label is proved at its node only is dotted (a light veil when
  there are very many); a cell proved to hold a change of label is filled as a boundary (black where stable
  cells are next to it, dark grey between other classes), so a band narrower than the grid still shows.
- Boundaries are drawn on grid-cell edges, between every two neighbouring points whose N_c differ: thick where
  one side is stable and the other not, thin where only the number of pairs changes. A line is drawn only where
  two grid points differ, never interpolated between them. Cell edges are the midpoints between grid values
  (geometric midpoints on a log axis), so they follow log and irregular (``values``) grids.
"""

from __future__ import annotations

import math
import re
import textwrap
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr

from ..errors import StabmapError
from .. import systems
from ..store.files import check_writable
from ..store.variables import CELL, INFERRED
from .areas import AreaShares, area_shares
from .blocks import block_factors, reduce_blocks
from ..scene import units
from ..scene.units import unit_suffix
from .info import fixed_parameters, scene_notes

MAX_PANELS = 12  # default limit of small multiples
_LEGEND_WIDTH = 2.5  # [inch] beside small multiples

# Okabe-Ito (colour-blind safe), then Paul Tol's muted colours: stable gets the calm blue, unstable counts get
# warm colours in order of N_c, so a class has the same colour in every figure.
STABLE_COLOUR = "#56B4E9"
UNSTABLE_COLOUR = ["#F0E442", "#E69F00", "#D55E00", "#CC79A7", "#882255", "#332288", "#117733", "#44AA99", "#999933", "#AA4499"]
DEGENERATE_COLOUR = "#BBBBBB"
ABSENT_COLOUR = "#FFFFFF"  # nothing to decide (System.absent_label): left blank
UNDECIDED_COLOUR = "#707070"  # not proved (System.undecided_label): darker than degenerate, hatched like it
_BOUNDARY = "#000000"
_CLASS_EDGE = "#333333"
_HATCH_INFERRED = "////"
_HATCH_NODE_ONLY = "...."
# Bits of the flag map reduced with the labels (blocks.reduce_blocks ORs them over a block)
_FLAG_INFERRED, _FLAG_NODE_ONLY, _FLAG_CHANGE = 1, 2, 4
_HATCH_DEGENERATE = "xxxx"
_HATCH_RUNS = 100_000  # more separate runs of inferred cells than this: a light veil instead of a hatch
_VECTOR_RUNS = 20_000  # a panel with more runs of equal cells along x is filled as an image (lines and text stay vector)
_DPI = 150  # of a PNG; a map with more grid points than its pixels at this resolution is drawn in blocks
# Lower bounds of the room the layout leaves a map [inch] (checked against the drawn figures in tests/test_plot.py)
_SINGLE_MARGIN = 3.6  # a single map: figure width less the legend, the y label and the margins
_SINGLE_HEIGHT = 3.2  # a single map: figure height less the title (up to 7 lines) and the x label
_FACET_MARGIN = 0.9  # small multiples: the supylabel and margins
_PANEL_GAP = 0.35  # between panels, and their tick labels
_PANEL_HEIGHT = 2.3  # a row of small multiples
_PANEL_TITLE = 0.75  # the panel's title and tick labels



def colour(value: int, stable: int | None = 0, absent: int | None = None, undecided: int | None = None) -> str:
    """The colour of the label ``value`` (``absent``: white; ``undecided``: dark grey; other negatives: degenerate;
    ``stable``: the stable class) in every figure."""
    if absent is not None and value == absent:
        return ABSENT_COLOUR
    if undecided is not None and value == undecided:
        return UNDECIDED_COLOUR
    if value < 0:
        return DEGENERATE_COLOUR
    if stable is None:  # classes without a stable one (e.g. the critical node): one palette, blue first
        return ([STABLE_COLOUR] + UNSTABLE_COLOUR)[value % (len(UNSTABLE_COLOUR) + 1)]
    if value == stable:
        return STABLE_COLOUR
    return UNSTABLE_COLOUR[(value - 1 if stable is not None and value > stable else value) % len(UNSTABLE_COLOUR)]


def class_label(value: int, system=None) -> str:
    """Legend text of the label ``value`` of ``system`` (default: gyroscopes, where the label is N_c)."""
    return (system or systems.get(systems.DEFAULT)).class_name(value)


def class_patch(value: int, system):
    """The legend entry of one class of ``system``'s label, as every figure draws it."""
    from matplotlib.patches import Patch

    absent = system.absent_label
    return Patch(facecolor=colour(value, system.stable_label, absent, system.undecided_label),
                 edgecolor="#888888" if value == absent else "none",  # a white patch needs an outline to be seen
                 lw=0.5, hatch=_HATCH_DEGENERATE if value < 0 and value != absent else None, label=class_label(value, system))


def _mathtext(symbol: str) -> str:
    """'N_c' -> 'N$_c$' (a subscript), for legends."""
    base, _, sub = symbol.partition("_")
    return base if not sub else f"{base}$_{sub}$" if len(sub) == 1 else f"{base}$_{{{sub}}}$"


# ---------------------------------------------------------------------------------------------------------- layout
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


def _evenly(n: int, k: int) -> tuple[int, ...]:
    """``k`` evenly spaced indices of ``n`` (both ends included when k >= 2)."""
    if k >= n:
        return tuple(range(n))
    return tuple(int(i) for i in np.unique(np.round(np.linspace(0, n - 1, k)).astype(int)))


def _rows_cols(n_rows: int, n_cols: int, max_panels: int) -> tuple[int, int]:
    """Rows and columns for a 4-axis atlas: as many panels as allowed, as square as possible, wider than tall."""
    best = (1, 1)
    for r in range(1, min(n_rows, max_panels) + 1):
        c = min(n_cols, max_panels // r)
        if (r * c, -abs(c - r), c) > (best[0] * best[1], -abs(best[1] - best[0]), best[1]):
            best = (r, c)
    return best


def plan_figure(
    ds: xr.Dataset,
    *,
    x: str | None = None,
    y: str | None = None,
    sel: dict[str, float] | None = None,
    facet: str | None = None,
    max_panels: int = MAX_PANELS,
) -> FigurePlan:
    """Check the options of :func:`atlas_figure` against ``ds`` and decide the layout (see there)."""
    label = systems.of_atlas(ds.attrs).label
    if label not in ds:
        raise StabmapError(f"not a stabmap atlas: the Dataset has no {label!r} variable")
    if isinstance(max_panels, bool) or not isinstance(max_panels, (int, np.integer)) or max_panels < 1:
        raise StabmapError(f"--max-panels must be a whole number >= 1, got {max_panels!r}")
    dims = list(ds[label].dims)
    if not dims:
        raise StabmapError("this atlas has no axis to plot (a single point); use 'stabmap info' or 'stabmap query'")
    sel = dict(sel or {})
    for k, v in sel.items():
        if k in ds.coords and ds[k].ndim == 0 and k not in dims:
            raise StabmapError(f"--sel {k}: fixed at {float(ds[k]):g}{unit_suffix(ds[k].attrs.get('units'))} in this atlas, not a grid axis; its axes are: {', '.join(dims)}")
        if k not in dims:
            raise StabmapError(f"--sel {k}: not an axis of this atlas; its axes are: {', '.join(dims)}")
        if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v):
            raise StabmapError(f"--sel {k}={v!r}: give a finite number, e.g. --sel {k}={float(ds[k][0]):g}")
    roles = [(opt, name) for opt, name in (("--x", x), ("--y", y), ("--facet", facet)) if name is not None]
    for opt, name in roles:
        if name not in dims:
            raise StabmapError(f"{opt} {name}: not an axis of this atlas; choose from {', '.join(dims)}")
        if name in sel:
            raise StabmapError(f"{opt} {name}: this axis is also fixed by --sel {name}=...; drop one of the two")
    for i, (opt, name) in enumerate(roles):
        for opt2, name2 in roles[i + 1 :]:
            if name == name2:
                raise StabmapError(f"{opt} and {opt2} both name {name}; give each axis one place in the figure")
    free = [d for d in dims if d not in sel]
    if not free:
        raise StabmapError(f"--sel fixes every axis ({', '.join(dims)}); leave one or two free to draw, or use 'stabmap query'")
    if len(free) == 1 and y is not None:
        raise StabmapError(f"--y {y}: only one axis is left to draw ({free[0]}), along x; drop --y")
    if len(free) <= 2 and facet is not None:
        raise StabmapError(
            f"--facet {facet}: only {len(free)} ax{'is' if len(free) == 1 else 'es'} left to draw ({', '.join(free)}), "
            "all on the map; facets need a third axis, so drop --facet"
        )
    rest = [d for d in free if d not in (x, y, facet)]
    x = x or rest.pop(0)
    if len(free) >= 2:
        y = y or rest.pop(0)
    if len(free) >= 3:
        facet = facet or rest.pop(0)
    row = rest.pop(0) if len(free) >= 4 else None

    fixed, notes = {}, []
    for k, v in sel.items():
        values = np.asarray(ds[k], dtype=float)
        fixed[k] = (int(np.argmin(np.abs(values - v))), float(v))
        if not values.min() <= v <= values.max():
            notes.append(f"{k} = {v:g} lies outside the grid ({values.min():g} .. {values.max():g}{unit_suffix(ds[k].attrs.get('units'))}): "
                         f"drawn at its nearest end, {k} = {values[fixed[k][0]]:g}")
    for d in rest:  # a figure shows at most four axes
        fixed[d] = (0, None)
        notes.append(f"{d} fixed at its first value (choose with --sel {d}=VALUE)")

    facet_index = row_index = ()
    panel_notes = []
    if facet is not None:
        n_f = ds.sizes[facet]
        if row is None:
            facet_index = _evenly(n_f, max_panels)
        else:
            r, c = _rows_cols(ds.sizes[row], n_f, max_panels)
            facet_index, row_index = _evenly(n_f, c), _evenly(ds.sizes[row], r)
        for d, index in ((facet, facet_index), (row, row_index)):
            if d is not None and len(index) < ds.sizes[d]:
                panel_notes.append(f"{d}: {len(index)} of {ds.sizes[d]} values drawn, evenly spaced")
        if panel_notes:
            panel_notes[-1] += f" (more with --max-panels, now {max_panels}; one with --sel)"
    notes = panel_notes + notes
    return FigurePlan(x, y, facet, row, facet_index, row_index, fixed, tuple(notes))


# ------------------------------------------------------------------------------------------------------ geometry
def _edges(centres: np.ndarray, scale: str | None) -> np.ndarray:
    """Cell edges around grid values: midpoints (geometric midpoints on a log axis), half a step beyond the ends."""
    centres = np.asarray(centres, dtype=float)
    if len(centres) == 1:
        c = centres[0]
        if scale == "log" and c > 0:
            return np.array([c / 1.1, c * 1.1])
        h = 0.5 * abs(c) if c != 0 else 0.5
        return np.array([c - h, c + h])
    if scale == "log" and np.all(centres > 0):
        lc = np.log(centres)
        mid = (lc[1:] + lc[:-1]) / 2
        return np.exp(np.concatenate([[2 * lc[0] - mid[0]], mid, [2 * lc[-1] - mid[-1]]]))
    mid = (centres[1:] + centres[:-1]) / 2
    return np.concatenate([[2 * centres[0] - mid[0]], mid, [2 * centres[-1] - mid[-1]]])


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Runs of True along the last axis of a 2-D mask: (line, start, stop) with stop exclusive."""
    padded = np.zeros((mask.shape[0], mask.shape[1] + 2), dtype=np.int8)
    padded[:, 1:-1] = mask
    d = np.diff(padded, axis=1)
    line, start = np.nonzero(d == 1)
    _, stop = np.nonzero(d == -1)
    return line, start, stop


def _segments(mask_v: np.ndarray, mask_h: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> np.ndarray:
    """Line segments, shape (k, 2, 2), along the marked cell edges, collinear neighbours joined.

    ``mask_v[j, i]``: the edge between cells (j, i) and (j, i + 1), at x = xe[i + 1] from ye[j] to ye[j + 1].
    ``mask_h[j, i]``: the edge between cells (j, i) and (j + 1, i), at y = ye[j + 1] from xe[i] to xe[i + 1].
    """
    i, j0, j1 = _runs(mask_v.T)
    vertical = np.stack([np.stack([xe[i + 1], ye[j0]], -1), np.stack([xe[i + 1], ye[j1]], -1)], 1)
    j, i0, i1 = _runs(mask_h)
    horizontal = np.stack([np.stack([xe[i0], ye[j + 1]], -1), np.stack([xe[i1], ye[j + 1]], -1)], 1)
    return np.concatenate([vertical.reshape(-1, 2, 2), horizontal.reshape(-1, 2, 2)])


def cell_edge_boundaries(
    values: np.ndarray, xedges: np.ndarray, yedges: np.ndarray, stable: int | None = 0, *, state: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Boundaries of a 2-D class map on the edges of its grid cells.

    Parameters
    ----------
    values : array of int, shape (ny, nx)
        N_c per grid point, rows along y.
    xedges, yedges : arrays of float, shapes (nx + 1,) and (ny + 1,)
        Cell edges in data coordinates (see ``_edges``).

    Returns
    -------
    state : array of int, shape (ny, nx), optional
        Stability per cell (default: ``values == stable``); a thick line runs where it differs.

    Returns
    -------
    stability, classes : arrays of float, shape (k, 2, 2)
        Segments ``[[x0, y0], [x1, y1]]`` on every edge between two neighbouring cells where exactly one is
        stable (N_c = 0), and on every other edge where N_c differs. Collinear neighbouring segments are joined.
    """
    v = np.asarray(values)
    xe, ye = np.asarray(xedges, dtype=float), np.asarray(yedges, dtype=float)
    stable = v == stable if state is None else np.asarray(state)
    dv, dh = v[:, 1:] != v[:, :-1], v[1:, :] != v[:-1, :]
    sv, sh = stable[:, 1:] != stable[:, :-1], stable[1:, :] != stable[:-1, :]
    return _segments(sv, sh, xe, ye), _segments(dv & ~sv, dh & ~sh, xe, ye)


def _rectangles(mask: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> list[np.ndarray]:
    """The marked cells as few rectangles: runs along x, merged with identical runs in the rows above."""
    line, start, stop = _runs(mask)
    open_, done = {}, []
    previous = -1
    for j, a, b in zip(line, start, stop):
        if j != previous:  # close runs that did not continue into this row
            for key, (j0, j1) in list(open_.items()):
                if j1 < j:
                    done.append((key[0], key[1], j0, j1))
                    del open_[key]
            previous = j
        key = (int(a), int(b))
        if key in open_ and open_[key][1] == j:
            open_[key] = (open_[key][0], j + 1)
        else:
            if key in open_:
                done.append((key[0], key[1], *open_[key]))
            open_[key] = (j, j + 1)
    done.extend((k[0], k[1], j0, j1) for k, (j0, j1) in open_.items())
    return [np.array([[xe[a], ye[j0]], [xe[b], ye[j0]], [xe[b], ye[j1]], [xe[a], ye[j1]]]) for a, b, j0, j1 in done]


def _fill(ax, values: np.ndarray, xe: np.ndarray, ye: np.ndarray, cmap, norm, stable: int | None, absent: int | None = None,
          undecided: int | None = None) -> None:
    """Colour the cells: one vector rectangle per block of equal cells, or an image when the map is too busy.

    Rectangles are outlined in their own colour, so no hairline seams show between them in a PDF viewer.
    """
    from matplotlib.collections import PolyCollection

    change = np.ones(values.shape, dtype=bool)
    change[:, 1:] = values[:, 1:] != values[:, :-1]
    if int(change.sum()) > _VECTOR_RUNS:
        ax.pcolormesh(xe, ye, values, cmap=cmap, norm=norm, shading="flat", rasterized=True)
        return
    for v in np.unique(values):
        c = colour(int(v), stable, absent, undecided)
        cells = PolyCollection(_rectangles(values == v, xe, ye), facecolors=c, edgecolors=c, linewidths=0.3, antialiaseds=False, zorder=1)
        cells.set_gid(f"cells-{int(v)}")
        ax.add_collection(cells, autolim=False)


def _overlay(ax, mask: np.ndarray, xe: np.ndarray, ye: np.ndarray, gid: str) -> bool:
    """Hatch the marked cells (one compound path, so the hatch is drawn once); returns True if it had to lighten.

    Degenerate cells are cross-hatched. Inferred cells get a light diagonal hatch, or, when they form more than
    ``_HATCH_RUNS`` separate runs (a large adaptive atlas), a light white veil drawn as an image.
    """
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    if gid in ("inferred-cells", "node-only-cells") and len(_runs(mask)[0]) > _HATCH_RUNS:
        veil = np.ma.masked_where(~mask, np.ones(mask.shape))
        mesh = ax.pcolormesh(xe, ye, veil, cmap=_white_cmap(), vmin=0, vmax=1, alpha=0.45, shading="flat", rasterized=True, zorder=2)
        mesh.set_gid(gid)
        return True
    hatch, colour_ = {"inferred-cells": (_HATCH_INFERRED, "#00000066"), "node-only-cells": (_HATCH_NODE_ONLY, "#00000066")}.get(
        gid, (_HATCH_DEGENERATE, "#000000AA"))
    path = MplPath.make_compound_path_from_polys(np.array(_rectangles(mask, xe, ye)))
    patch = PathPatch(path, facecolor="none", edgecolor=colour_, linewidth=0, hatch=hatch, zorder=2)
    if hasattr(patch, "set_hatchcolor"):  # matplotlib >= 3.10
        patch.set_hatchcolor(colour_)
        patch.set_hatch_linewidth(0.5)
    patch.set_gid(gid)
    ax.add_patch(patch)
    return False


def _flag_map(ds: xr.Dataset, system) -> xr.DataArray | None:
    """The bits drawn over the classes, per grid point: _FLAG_INFERRED (decided_by says inferred, or cell says
    not_proved), _FLAG_NODE_ONLY and _FLAG_CHANGE (``cell``); None for an atlas with neither variable."""
    bits = None
    if system.provenance in ds:
        flags = system.variable(system.provenance)
        if INFERRED in flags.meanings:
            bits = (ds[system.provenance] == flags.value(INFERRED)).astype(np.int8) * _FLAG_INFERRED
    if CELL.name in ds:
        cell = ds[CELL.name]
        more = ((cell == CELL.value("not_proved")) * _FLAG_INFERRED + (cell == CELL.value("node_only")) * _FLAG_NODE_ONLY
                + (cell == CELL.value("contains_change")) * _FLAG_CHANGE).astype(np.int8)
        bits = more if bits is None else bits | more
    return bits


def _touches_stability(blocks, stable: int) -> np.ndarray:
    """Blocks next to (or holding) both stable and not stable points: where a change of label is a stability
    boundary."""
    from scipy.ndimage import maximum_filter

    some_stable = (blocks.low == stable) | (blocks.high == stable) | blocks.mixed_stability
    some_other = (blocks.low != stable) | (blocks.high != stable)
    return maximum_filter(some_stable, size=3, mode="nearest") & maximum_filter(some_other, size=3, mode="nearest")


def _paint(ax, mask: np.ndarray, xe: np.ndarray, ye: np.ndarray, colour_: str, gid: str, vector: bool = False) -> None:
    """Fill the marked cells in one colour, as an image (blocks of a reduced map: about one pixel each), or with
    ``vector`` as rectangles unless they form too many runs (grid cells of a map drawn point for point)."""
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import ListedColormap

    if vector and len(_runs(mask)[0]) <= _VECTOR_RUNS:
        cells = PolyCollection(_rectangles(mask, xe, ye), facecolors=colour_, edgecolors=colour_, linewidths=0.3,
                               antialiaseds=False, zorder=2.5)
        cells.set_gid(gid)
        ax.add_collection(cells, autolim=False)
        return
    cells = np.ma.masked_where(~mask, np.ones(mask.shape))
    mesh = ax.pcolormesh(xe, ye, cells, cmap=ListedColormap([colour_]), vmin=0, vmax=1, shading="flat", rasterized=True, zorder=2.5)
    mesh.set_gid(gid)


def _white_cmap():
    from matplotlib.colors import ListedColormap

    return ListedColormap(["#FFFFFF"])


# -------------------------------------------------------------------------------------------------------- labels
def _units(units: str) -> str:
    """CF units as text: 'rad s-1' -> 'rad s⁻¹' (mathtext), '1' -> ''; spaces do not break lines."""
    if units in ("", "1"):
        return ""
    words = []
    for w in units.split():
        m = re.fullmatch(r"([A-Za-z]+)(-?\d+)", w)
        words.append(f"{m.group(1)}$^{{{m.group(2)}}}$" if m else w)
    return "\u00a0".join(words)


def _symbol(ds: xr.Dataset, name: str) -> str:
    """'omega' -> '$\\omega$', 'm_2' -> '$m_{2}$' (the system's ``symbols``); other names are returned as they are."""
    symbols = systems.of_atlas(ds.attrs).symbols
    if name in symbols:  # a whole name with its own symbol: omega, c1sq -> c_1^2
        return f"${symbols[name]}$"
    m = re.fullmatch(r"([A-Za-z]+)(?:_(\d+|[a-z]))?", name)  # m_2, and components such as c_x
    if not m or m.group(1) not in symbols:
        return name
    base, k = symbols[m.group(1)], m.group(2)
    return f"${base}_{{{k}}}$" if k else f"${base}$"


def axis_label(ds: xr.Dataset, dim: str, width: int = 60, shown: str = "") -> str:
    """'common spin rate ω [rad s⁻¹]': the coordinate's long_name (parentheses dropped), symbol and units
    (``shown``: the units its tick labels are shown in, see :func:`display_ticks`)."""
    attrs = ds[dim].attrs
    name = re.sub(r"\s*\([^)]*\)", "", attrs.get("long_name", "")).replace(" about its centre of mass", "").strip()
    sym = _symbol(ds, dim)
    if not name:
        text = sym
    elif sym == dim:
        text = f"{name} ({dim})"
    else:
        text = f"{name} {sym}"
    units = shown or _units(str(attrs.get("units", "")))
    if units:
        text += f" [{units}]"
    return textwrap.fill(text, width, break_long_words=False, break_on_hyphens=False)


def display_ticks(ds: xr.Dataset, dim: str, axis) -> str:
    """Tick labels of a linear spin-rate axis in its ``display_units`` (rpm, Hz), at round values of that unit; the
    data stay in rad/s.  Returns the unit shown, or "" (no display unit, or a log axis: left as it is)."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, MaxNLocator

    unit = str(ds[dim].attrs.get("display_units", ""))
    if not unit or axis.get_scale() == "log":
        return ""
    k = units.factor(unit)

    class Scaled(MaxNLocator):
        def tick_values(self, vmin, vmax):
            return super().tick_values(vmin / k, vmax / k) * k

    if not isinstance(axis.get_major_locator(), FixedLocator):  # ticks at listed values stay there
        axis.set_major_locator(Scaled(nbins="auto", steps=[1, 2, 2.5, 5, 10]))
    axis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v / k:g}"))
    return unit


def _value_text(ds: xr.Dataset, dim: str, value: float) -> str:
    units = _units(str(ds[dim].attrs.get("units", "")))
    return f"{_symbol(ds, dim)} = {value:.4g}" + (f" {units}" if units else "")


def _log_axis(ds: xr.Dataset, dim: str) -> bool:
    return ds[dim].attrs.get("scale") == "log" and bool(np.all(np.asarray(ds[dim]) > 0))


# --------------------------------------------------------------------------------------------------------- figure
def atlas_figure(
    ds: xr.Dataset,
    *,
    x: str | None = None,
    y: str | None = None,
    sel: dict[str, float] | None = None,
    facet: str | None = None,
    max_panels: int = MAX_PANELS,
):
    """Draw an atlas into a new matplotlib Figure (nothing is saved, nothing computed).

    The atlas may be lazy (``open_atlas(path, lazy=True)``): each panel is read chunk by chunk, and a panel with
    more grid points than pixels is drawn in blocks (module docstring), so memory stays bounded at any size.

    Parameters
    ----------
    ds : xarray.Dataset
        An atlas (``stabmap.compute_atlas``, ``stabmap.open_atlas``).
    x, y : str, optional
        Axes of the map (default: the first two axes of the atlas that are not fixed or faceted, in order).
    sel : dict, optional
        Axes to fix, ``{name: value}``; the nearest grid value is used and shown.
    facet : str, optional
        The axis whose values become panels (default: the third remaining axis). A fourth remaining axis gives
        the rows; further axes are fixed at their first value, and the figure says so.
    max_panels : int
        At most this many panels; evenly spaced values are drawn from longer axes (default 12).

    Returns
    -------
    matplotlib.figure.Figure
        Not registered with pyplot: save it with ``fig.savefig``. ``fig.axes[0]`` is the first map (for a 2-D
        atlas the only one) in data coordinates, x and y being the grid values, so curves can be overlaid with
        ``fig.axes[0].plot(x, y)``; its limits are fixed to the grid. The legend is ``fig.legends[0]``.

    Raises
    ------
    StabmapError
        For an option that does not fit the atlas (unknown axis, an axis given two roles, ...).
    """
    from matplotlib.collections import LineCollection
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    plan = plan_figure(ds, x=x, y=y, sel=sel, facet=facet, max_panels=max_panels)
    fix = {k: i for k, (i, _) in plan.fixed.items()}
    system = systems.of_atlas(ds.attrs)
    nc = ds[system.label].isel(fix)
    flag_map = _flag_map(ds, system)
    flag_map = None if flag_map is None else flag_map.isel(fix)
    order = (plan.y, plan.x) if plan.y else (plan.x,)
    panels = [(r, c) for r in (plan.row_index or (None,)) for c in (plan.facet_index or (None,))]

    def cut(da, r, c):  # one panel's map as (y, x), still lazy for a lazy atlas
        sl = {}
        if r is not None:
            sl[plan.row] = r
        if c is not None:
            sl[plan.facet] = c
        a = da.isel(sl).transpose(*order).data
        return a if plan.y else a[None, :]

    if plan.row is not None:
        nrows, ncols = len(plan.row_index), len(plan.facet_index)
    elif plan.facet is not None:
        k = len(plan.facet_index)
        ncols = k if k <= 3 else math.ceil(math.sqrt(k))
        nrows = math.ceil(k / ncols)
    else:
        nrows = ncols = 1
    width = 7.5 if plan.facet is None else max(3.5, 2.6 * ncols + 0.9) + _LEGEND_WIDTH

    # Each panel is read once, chunk by chunk, and reduced to at most one block of grid points per pixel.
    stable, absent, undecided = system.stable_label, system.absent_label, system.undecided_label
    shape = (ds.sizes[plan.y] if plan.y else 1, ds.sizes[plan.x])
    factors = block_factors(shape, panel_pixels(width, nrows, ncols, facets=plan.facet is not None, strip=plan.y is None))
    data = [
        reduce_blocks(cut(nc, r, c), None if flag_map is None else cut(flag_map, r, c), stable, factors)
        for r, c in panels
    ]
    totals: dict[int, int] = {}
    for d in data:
        for v, n in d.counts.items():
            totals[v] = totals.get(v, 0) + n
    present = sorted(totals)
    points = sum(totals.values())
    top = max(1, present[-1])
    bottom = min(-1, present[0])
    cmap = ListedColormap([colour(v, stable, absent, undecided) for v in range(bottom, top + 1)])
    norm = BoundaryNorm(np.arange(bottom - 0.5, top + 1.5), cmap.N)

    xs = np.asarray(ds[plan.x], dtype=float)
    xe = _edges(xs, "log" if _log_axis(ds, plan.x) else None)
    ye = _edges(np.asarray(ds[plan.y], dtype=float), "log" if _log_axis(ds, plan.y) else None) if plan.y else np.array([0.0, 1.0])
    xe, ye = _block_edges(xe, factors[1]), _block_edges(ye, factors[0]) if plan.y else ye
    n_stable = None if stable is None else totals.get(stable, 0)
    shares = _panel_areas(ds, plan, fix, panels, cut, stable)
    title = _title(ds, plan, n_stable, points, 70 if plan.facet is None else int(12 * (width - _LEGEND_WIDTH)), factors, shape,
                   shares=None if shares is None else AreaShares.mean(shares))
    lines = title.count("\n") + 1
    if plan.facet is None:
        size = (width, 5.2) if plan.y else (width, max(1.4 + 0.17 * lines, 0.22 * (len(present) + 4)) + 0.6)
    else:
        size = (width, 2.3 * nrows + 0.8 + 0.17 * lines)
    fig = captioned_figure(ds, size)
    if plan.facet is None:
        maps = side = fig
    else:  # panels with their titles on the left, the legend on the right: the two never overlap
        maps, side = fig.subfigures(1, 2, width_ratios=[size[0] - _LEGEND_WIDTH, _LEGEND_WIDTH])
    grid = maps.subplots(nrows, ncols, sharex=True, sharey=True, squeeze=False)
    axes = [grid[n // ncols, n % ncols] for n in range(len(panels))]
    for ax in grid.ravel()[len(panels) :]:
        ax.remove()

    drawn = {"stability": False, "classes": False, "inferred": False, "light": False, "node-only": False,
             "node-only-light": False, "change": False}
    for n, (ax, blocks, (r, c)) in enumerate(zip(axes, data, panels)):
        values, mixed = blocks.low, blocks.mixed
        _fill(ax, values, xe, ye, cmap, norm, stable, absent, undecided)
        bits = np.zeros(values.shape, dtype=np.int32) if blocks.any_flag is None else blocks.any_flag
        inferred = (bits & _FLAG_INFERRED) > 0
        node_only = ((bits & _FLAG_NODE_ONLY) > 0) & ~inferred
        for mask, gid in ((inferred, "inferred-cells"), (node_only, "node-only-cells"),
                          ((values < 0) & (values != absent) & ~mixed, "degenerate-cells")):
            if mask.any():
                light = _overlay(ax, mask, xe, ye, gid)
                if gid == "inferred-cells":
                    drawn["inferred"], drawn["light"] = True, drawn["light"] | light
                elif gid == "node-only-cells":
                    drawn["node-only"], drawn["node-only-light"] = True, drawn["node-only-light"] | light
        codes, state = _block_classes(blocks, stable)
        change = (bits & _FLAG_CHANGE) > 0
        near_stable = _touches_stability(blocks, stable) if stable is not None else np.zeros(values.shape, dtype=bool)
        drawn["change"] |= bool(change.any())
        for mask, col, gid in ((mixed & ~blocks.mixed_stability, _CLASS_EDGE, "mixed-class-blocks"), (blocks.mixed_stability, _BOUNDARY, "mixed-stability-blocks"),
                               (change & ~near_stable, _CLASS_EDGE, "change-cells"), (change & near_stable, _BOUNDARY, "stability-change-cells")):
            if mask.any():
                _paint(ax, mask, xe, ye, col, gid, vector=gid.endswith("-cells") and tuple(blocks.factors) == (1, 1))
        stab, other = cell_edge_boundaries(codes, xe, ye, stable, state=state)
        span = panel_points(width, nrows, ncols, facets=plan.facet is not None, strip=plan.y is None)
        for segs, width_, col, gid in ((other, 0.6, _CLASS_EDGE, "class-boundary"), (stab, 1.5, _BOUNDARY, "stability-boundary")):
            widths = boundary_widths(segs, xe, ye, span, width_, log=(_log_axis(ds, plan.x), bool(plan.y) and _log_axis(ds, plan.y)), codes=codes)
            lines = LineCollection(segs, colors=col, linewidths=widths, capstyle="projecting", joinstyle="miter", zorder=3 + (gid == "stability-boundary"))
            lines.set_gid(gid)
            ax.add_collection(lines, autolim=False)
        drawn["stability"] |= len(stab) > 0
        drawn["classes"] |= len(other) > 0
        if plan.facet is not None:
            parts = [_value_text(ds, plan.facet, float(ds[plan.facet][c]))]
            if plan.row is not None:
                parts.append(_value_text(ds, plan.row, float(ds[plan.row][r])))
            if stable is not None:
                parts.append(f"{100 * shares[n].stable:.0f} % of its area proved stable" if shares is not None  # as the title
                             else f"{100 * blocks.counts.get(stable, 0) / sum(blocks.counts.values()):.0f} % {system.stable_word}")
                two_lines = plan.row is not None or shares is not None  # the longer text of areas needs its own line
                ax.set_title("\n".join([", ".join(parts[:-1]), parts[-1]]) if two_lines else f"{parts[0]}  ({parts[1]})", fontsize=9)
            else:  # a system without stability: the panel's coordinates only
                ax.set_title("\n".join(parts), fontsize=9)

    first = axes[0]
    if _log_axis(ds, plan.x):
        first.set_xscale("log")
    first.set_xlim(min(xe[0], xe[-1]), max(xe[0], xe[-1]))
    if plan.y:
        if _log_axis(ds, plan.y):
            first.set_yscale("log")
        first.set_ylim(min(ye[0], ye[-1]), max(ye[0], ye[-1]))
    else:
        first.set_ylim(0, 1)
        first.set_yticks([])
    for dim, axis in ((plan.x, first.xaxis), (plan.y, first.yaxis)):
        if dim and axis.get_scale() == "log":
            log_ticks(axis, *sorted(np.asarray(ds[dim], dtype=float)[[0, -1]]))
    for dim, setter, log in ((plan.x, first.set_xticks, first.get_xscale() == "log"), (plan.y, first.set_yticks, first.get_yscale() == "log")):
        if dim and ds[dim].attrs.get("scale") == "values" and 1 < ds.sizes[dim] <= 8:  # ticks at listed values ...
            v = np.sort(np.asarray(ds[dim], dtype=float))
            v_ = np.log(v) if log else v
            if np.min(np.diff(v_)) >= (v_[-1] - v_[0]) / 12:  # ... unless their labels would collide
                setter(v)

    shown = {dim: display_ticks(ds, dim, axis) for dim, axis in ((plan.x, first.xaxis), (plan.y, first.yaxis)) if dim}
    if plan.facet is None:
        first.set_xlabel(axis_label(ds, plan.x, shown=shown[plan.x]))
        if plan.y:
            first.set_ylabel(axis_label(ds, plan.y, width=45, shown=shown[plan.y]))
    else:
        for n, ax in enumerate(axes):  # tick labels only where no panel is below / to the left
            ax.tick_params(labelbottom=n + ncols >= len(panels), labelleft=n % ncols == 0)
        maps.supxlabel(axis_label(ds, plan.x, width=int(12 * (size[0] - _LEGEND_WIDTH)), shown=shown[plan.x]), fontsize=10)
        maps.supylabel(axis_label(ds, plan.y, width=int(10 * size[1]), shown=shown.get(plan.y, "")), fontsize=10)

    handles = [class_patch(v, system) for v in present]
    if drawn["stability"]:
        handles.append(Line2D([], [], color=_BOUNDARY, lw=1.5, label="stability boundary"))
    if drawn["classes"]:
        handles.append(Line2D([], [], color=_CLASS_EDGE, lw=0.6, label=f"{_mathtext(system.label_symbol)} changes"))
    if drawn["inferred"] and not drawn["light"]:
        handles.append(Patch(facecolor="white", edgecolor="#00000066", lw=0, hatch=_HATCH_INFERRED, label="inferred from cell\ncorners (not computed)"))
    elif drawn["inferred"]:
        handles.append(Patch(facecolor="#DDDDDD", edgecolor="none", label="lighter: inferred from cell\ncorners (not computed)"))
    if drawn["node-only"] and not drawn["node-only-light"]:
        handles.append(Patch(facecolor="white", edgecolor="#00000066", lw=0, hatch=_HATCH_NODE_ONLY, label="proved at the grid node,\nnot over its cell"))
    elif drawn["node-only"]:
        handles.append(Patch(facecolor="#DDDDDD", edgecolor="none", label="lighter: proved at the grid\nnode, not over its cell"))
    if drawn["change"]:
        handles.append(Patch(facecolor=_CLASS_EDGE, edgecolor="none", label="cell proved to hold\na change of label"))
    legend = {"frameon": False, "title": system.label_title, "fontsize": 9, "title_fontsize": 9}
    if plan.facet is None:
        fig.legend(handles=handles, loc="outside right upper", alignment="left", **legend)
    else:
        side.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.0, 0.97), alignment="left", **legend)

    if plan.facet is None:
        first.set_title(title, fontsize=10)
    else:
        maps.suptitle(title, fontsize=10)
    return fig


def _panel_areas(ds: xr.Dataset, plan: FigurePlan, fix: dict, panels: list, cut, stable: int | None) -> list[AreaShares] | None:
    """Each panel's shares of its area proved stable, unstable, ... (:mod:`stabmap.read.areas`); None where the atlas
    proves no class over a whole cell here (no ``cell``, no stability, or a grid too coarse for box proofs): the
    title then counts grid points."""
    if stable is None or CELL.name not in ds:
        return None
    from .summary import cell_sizes

    cell = ds[CELL.name].isel(fix)
    wy = cell_sizes(ds, plan.y) if plan.y else np.ones(1)
    label = ds[systems.of_atlas(ds.attrs).label].isel(fix)
    shares = area_shares([cut(label, r, c) for r, c in panels], [cut(cell, r, c) for r, c in panels], wy, cell_sizes(ds, plan.x), stable)
    return shares if any(s.proved_any for s in shares) else None


def _area_text(s: AreaShares, part: bool) -> str:
    """'69.2 % of the scanned area proved stable, 28.5 % unstable; 2.3 % undecided (...)'."""
    text = f"{100 * s.stable:.1f} % of the {'area shown' if part else 'scanned area'} proved stable, {100 * s.unstable:.1f} % unstable"
    if s.other > 0:
        text += f", {100 * s.other:.1f} % degenerate"
    text += f"; {100 * (s.change + s.undecided):.1f} % undecided"
    if s.change > 0:
        text += f" ({100 * s.change:.1f} % in cells holding a boundary)"
    return text


def _title(
    ds: xr.Dataset, plan: FigurePlan, stable: int | None, points: int, chars: int, factors: tuple[int, int] = (1, 1), shape: tuple[int, int] = (1, 1),
    shares: AreaShares | None = None,
) -> str:
    """The atlas title, the share of the area drawn that its cells prove stable (``shares``), or else the stable
    fraction of the ``points`` shown (``stable``: how many are stable; None for a system without stability), the
    fixed axes, the panels, the notes and the rule that reduced a large grid."""
    title = [_fill_title(ds.attrs.get("title", "") or "stabmap atlas", chars)]
    part = plan.facet is not None or bool(plan.fixed)
    if shares is not None:
        title.append(textwrap.fill(_area_text(shares, part), min(chars, 60)))  # narrower: clear of the legend beside it
    elif stable is not None:
        word = systems.of_atlas(ds.attrs).stable_word
        title.append(f"{100 * stable / points:.1f} % of {'the ' if part else ''}{points:,} grid points{' shown' if part else ''} {word}")
    else:
        title.append(f"{points:,} grid points{' shown' if part else ''}")
    if plan.fixed:
        fixed = []
        for k, (i, asked) in plan.fixed.items():
            text = _value_text(ds, k, float(ds[k][i]))
            if asked is not None and not math.isclose(asked, float(ds[k][i]), rel_tol=1e-9, abs_tol=1e-300):
                text += f" (nearest to {asked:g})"
            fixed.append(text)
        title.append(textwrap.fill("fixed: " + ", ".join(t.replace(" ", "\u00a0") for t in fixed), chars))
    if plan.facet is not None:
        title.append(textwrap.fill("panels: " + " × ".join(axis_label(ds, d, width=500) for d in (plan.facet, plan.row) if d), chars))
    title.extend(textwrap.fill(note, chars) for note in plan.notes)
    if factors != (1, 1):
        title.append(textwrap.fill(reduction_note(ds, plan, factors, shape), chars))
    return "\n".join(title)


def captioned_figure(ds: xr.Dataset, size: tuple[float, float]):
    """A constrained-layout Figure of ``size`` [in] for the plot, taller by the caption of the fixed parameters,
    which sits below everything else: the layout keeps the bottom strip free for it."""
    from matplotlib.figure import Figure

    caption = fixed_caption(ds, int(15.5 * size[0]))
    caption_height = 0.13 * (caption.count("\n") + 1) + 0.1 if caption else 0.0
    size = (size[0], size[1] + caption_height)
    fig = Figure(figsize=size, layout="constrained")
    if caption:
        fig.get_layout_engine().set(rect=(0, caption_height / size[1], 1, 1 - caption_height / size[1]))
        fig.text(0.01, 0.02 / size[1], caption, fontsize=7, va="bottom", ha="left", color="#333333", gid="fixed-caption")
    return fig


def _fill_title(text: str, chars: int) -> str:
    """The atlas title in lines of ``chars``, never broken between "eq." and its number."""
    text = re.sub(r"\b(eqs?\.|No\.) (?=\S)", "\\1\u00a0", text)
    return textwrap.fill(text, chars, break_on_hyphens=False, break_long_words=False)


def fixed_caption(ds: xr.Dataset, chars: int) -> str:
    """The atlas's fixed parameters (its scalar coordinates), grouped as ``stabmap info`` groups them (per body for
    gyroscopes) with each group's liquid modes, symbols and units as in the titles, in lines of at most ``chars``
    characters (mathtext markup not counted); ``""`` if there are none.

    Axes fixed by ``sel`` are in the title, not here.
    """

    def item(name: str, value: float, units: str) -> str:
        return f"{_symbol(ds, name)} = {value:.6g}" + (f" {_units(units)}" if _units(units) else "")

    system = systems.of_atlas(ds.attrs)
    groups = fixed_parameters(ds, system, item)
    caveats = [_fill_mathtext(c, chars) for c in system.caveats(ds)]  # e.g. where the model's assumptions fail
    if not groups:
        return "\n".join(caveats)
    notes = scene_notes(ds.attrs)
    parts = []
    for head, items in groups:
        liquid = [re.sub(r"(?<= )(kg|m|s|rad)(-?\d+)\b", r"\1$^{\2}$", t) for t in notes.get(head, [])]
        parts.append((f"{head}: " if head else "") + ", ".join(items + liquid))
    return "\n".join([_fill_mathtext("fixed: " + "; ".join(parts), chars), *caveats])


def _fill_mathtext(text: str, chars: int) -> str:
    """Wrap ``text`` at spaces into lines of at most ``chars`` shown characters: ``$...$`` markup counts as the
    characters it shows, and spaces inside an entry (``m = 1 kg``) do not break."""
    def shown(word: str) -> int:  # '$\\kappa_{2}$' shows as two characters
        return len(re.sub(r"[${}^_]", "", re.sub(r"\\[A-Za-z]+", "x", word)))

    lines, line, width = [], [], 0
    for word in re.split(r"(?<=[,;:]) (?![\d-])", text):  # a list of values (E = 1e-4, 2e-5) stays on one line
        word = word.replace(" ", "\u00a0")
        w = shown(word)
        if line and width + 1 + w > chars:
            lines.append(" ".join(line))
            line, width = [], 0
        line.append(word)
        width += w + (1 if width else 0)
    return "\n".join(lines + [" ".join(line)])


def log_ticks(axis, lo: float, hi: float) -> None:
    """Label a log axis between its decades too: at 2 and 5 times a power of ten over up to three decades, at 3
    over up to one (unlabelled minor ticks at every integer multiple); numbers as ``0.2``, ``50``, or, on an axis
    that reaches below 10⁻³ or to 10⁴, all as powers of ten (``2×10⁻⁵``)."""
    from matplotlib.ticker import FuncFormatter, LogLocator

    decades = math.log10(hi / lo) if lo > 0 and hi > lo else 0.0
    labelled = (2, 3, 5) if decades <= 1.2 else (2, 5) if decades <= 3.5 else ()

    plain = 1e-3 <= lo and hi < 1e4  # one style an axis: "1000" beside "10⁴" would read as two scales

    def text(v: float, _pos=None) -> str:
        e = math.floor(math.log10(v) + 1e-9)
        mantissa = round(v / 10.0**e, 6)
        if plain:
            return f"{v:g}"
        return f"$10^{{{e}}}$" if mantissa == 1 else f"${mantissa:g}\\times10^{{{e}}}$"

    def minor(v: float, pos=None) -> str:
        e = math.floor(math.log10(v) + 1e-9)
        return text(v) if round(v / 10.0**e, 6) in labelled else ""

    axis.set_major_locator(LogLocator(base=10))
    axis.set_minor_locator(LogLocator(base=10, subs=tuple(range(2, 10))))
    axis.set_major_formatter(FuncFormatter(text))
    axis.set_minor_formatter(FuncFormatter(minor))
    axis.set_tick_params(which="minor", labelsize=8)


def panel_points(width: float, nrows: int, ncols: int, *, facets: bool, strip: bool) -> tuple[float, float]:
    """A lower bound of one map's size in points along (y, x) (:func:`panel_pixels` at 72 dots an inch)."""
    return panel_pixels(width, nrows, ncols, facets=facets, strip=strip, dpi=72)


def boundary_widths(segs: np.ndarray, xe: np.ndarray, ye: np.ndarray, span: tuple[float, float], widest: float,
                    log: tuple[bool, bool] = (False, False), codes: np.ndarray | None = None) -> np.ndarray:
    """Line widths [pt] of boundary segments: ``widest``, but at most a third of the narrower of the two bands a
    segment separates (at least 0.35 pt), so that a band one cell wide keeps its class colour between its two
    boundary lines instead of turning into a black bar, while a boundary between wide regions stays thick.

    A band is the run of cells of one class in ``codes`` (shape (ny, nx)) across the segment, measured along the
    whole segment (its narrowest place counts); without ``codes`` every cell is a band of its own.
    ``span`` is the map's size in points along (y, x); ``log`` says which of (x, y) is drawn on a log scale.
    """
    segs = np.asarray(segs, dtype=float).reshape(-1, 2, 2)
    if not len(segs):
        return np.full(0, widest)
    if codes is None:
        codes = np.arange((len(ye) - 1) * (len(xe) - 1)).reshape(len(ye) - 1, len(xe) - 1)

    def cells(edges: np.ndarray, is_log: bool, points: float) -> np.ndarray:
        e = np.log(edges) if is_log else np.asarray(edges, dtype=float)
        return np.abs(np.diff(e)) / max(abs(e[-1] - e[0]), 1e-300) * points

    def bands(c: np.ndarray, size: np.ndarray) -> np.ndarray:
        """Per cell, the width [pt] of its run of equal codes along the last axis."""
        start = np.ones(c.shape, dtype=bool)
        start[:, 1:] = c[:, 1:] != c[:, :-1]  # a run never crosses into the next line
        run = np.cumsum(start.ravel()) - 1
        width = np.bincount(run, weights=np.broadcast_to(size, c.shape).ravel())
        return width[run].reshape(c.shape)

    def narrowest(table: np.ndarray, line: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """min of table[line, a:b] for every segment, in one pass."""
        flat = np.append(table.ravel(), np.inf)
        starts = np.stack([line * table.shape[1] + a, line * table.shape[1] + b], 1).ravel()
        return np.minimum.reduceat(flat, starts)[::2]

    def index(edges: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The edge nearest each of ``v`` (a segment's ends lie on edges), by bisection: no segments x edges table."""
        order = np.argsort(edges)
        e = edges[order]
        i = np.clip(np.searchsorted(e, v), 1, len(e) - 1)
        i -= (v - e[i - 1]) < (e[i] - v)
        return order[i]

    codes = np.asarray(codes)
    along_x = bands(codes, cells(xe, log[0], span[1]))
    along_y = bands(codes.T, cells(ye, log[1], span[0])).T
    vertical = segs[:, 0, 0] == segs[:, 1, 0]
    out = np.empty(len(segs))
    for mask, table, edges, ends, at, pos in (
        (vertical, np.minimum(along_x[:, :-1], along_x[:, 1:]).T, xe, ye, 0, 1),
        (~vertical, np.minimum(along_y[:-1, :], along_y[1:, :]), ye, xe, 1, 0),
    ):
        if mask.any():
            s = segs[mask]
            i0, i1 = index(ends, s[:, 0, pos]), index(ends, s[:, 1, pos])
            out[mask] = narrowest(table, index(edges, s[:, 0, at]) - 1, np.minimum(i0, i1), np.maximum(i0, i1))
    return np.clip(out / 3.0, 0.35, widest)


def reduction_note(ds: xr.Dataset, plan: FigurePlan, factors: tuple[int, int], shape: tuple[int, int]) -> str:
    """The caption line of a reduced map: how many grid points a block holds and how a block is coloured."""
    fy, fx = factors
    size = f"{fx} × {fy}" if plan.y else f"{fx}"
    grid = f"{shape[1]:,} × {shape[0]:,}" if plan.y else f"{shape[1]:,}"
    stable = systems.of_atlas(ds.attrs).stable_label is not None
    mixed = "black if it holds stable and unstable points, dark grey if several other classes" if stable else "dark grey if it holds several classes"
    return f"{grid} grid points drawn in blocks of {size}: a block shows its class where all its points agree, {mixed}"


def panel_pixels(width: float, nrows: int, ncols: int, *, facets: bool, strip: bool, dpi: int = _DPI) -> tuple[int, int]:
    """Pixels of one map of a figure ``width`` inches wide, along (y, x): a lower bound of what the layout gives.

    A map of more grid points than this is drawn in blocks (:func:`stabmap.read.blocks.block_factors`), so that
    no block is smaller than a pixel and none can vanish between pixels.
    """
    if not facets:
        maps = (1 if strip else _SINGLE_HEIGHT, width - _SINGLE_MARGIN)
    else:
        maps = ((_PANEL_HEIGHT - _PANEL_TITLE) * 1.0, (width - _LEGEND_WIDTH - _FACET_MARGIN) / ncols - _PANEL_GAP)
    return tuple(max(1, int(dpi * v)) for v in maps)


def _block_edges(edges: np.ndarray, k: int) -> np.ndarray:
    """Edges of blocks of ``k`` cells from the cells' edges: every k-th edge and the last."""
    n = len(edges) - 1
    return edges[np.r_[0:n:k, n]]


def _block_classes(blocks, stable: int | None) -> tuple[np.ndarray, np.ndarray]:
    """Codes and stability states of the blocks, for drawing boundaries between blocks.

    A block of one label keeps it as its code; a block of several labels gets a code of its own (one for those
    holding stable and unstable points, one for the others), so that a line runs wherever the codes of
    neighbouring blocks differ. The state is 1 for a stable block, 2 for a block holding stable and unstable
    points, 0 otherwise: a thick line runs wherever the states differ, so a block holding a stability boundary is
    drawn black between two thick lines.
    """
    codes = blocks.low.astype(np.int64)
    top = int(max(blocks.high.max(initial=0), 0))
    codes[blocks.mixed] = top + 1
    codes[blocks.mixed_stability] = top + 2
    if stable is None:
        return codes, np.zeros(codes.shape, dtype=np.int8)
    state = np.where(blocks.mixed_stability, 2, (blocks.low == stable) & ~blocks.mixed).astype(np.int8)
    return codes, state


def plot_atlas(
    ds: xr.Dataset,
    path: str | Path,
    *,
    x: str | None = None,
    y: str | None = None,
    sel: dict[str, float] | None = None,
    facet: str | None = None,
    max_panels: int = MAX_PANELS,
) -> Path:
    """Draw ``ds`` with :func:`atlas_figure` and write it to ``path`` (.png or .pdf) atomically; returns the path.

    Every check runs before anything is written, so bad options leave no file.
    """
    path = check_figure_path(path)
    return save_figure(atlas_figure(ds, x=x, y=y, sel=sel, facet=facet, max_panels=max_panels), path)


def check_figure_path(path: str | Path) -> Path:
    """A figure file that can be written: a .png or .pdf name in a writable directory."""
    path = check_writable(path)
    if path.suffix.lower() not in (".png", ".pdf"):
        raise StabmapError(f"plot file {str(path)!r}: use a .png or .pdf name")
    return path


def save_figure(fig, path: Path) -> Path:
    """Write the figure atomically (a temporary file renamed into place), then close it."""
    import matplotlib.pyplot as plt

    tmp = path.with_name(f".{path.name}.tmp{path.suffix}")
    try:
        fig.savefig(tmp, dpi=150 if path.suffix.lower() == ".png" else 300)
        tmp.replace(path)
    finally:
        plt.close(fig)
        tmp.unlink(missing_ok=True)
    return path


def plot_critical(ds: xr.Dataset, path: str | Path, *, sel: dict[str, float] | None = None) -> Path:
    """Draw a critical-values Dataset to a file (:func:`critical_figure`): PNG or PDF, written atomically."""
    path = check_figure_path(path)
    return save_figure(critical_figure(ds, sel=sel), path)


def _scanned(ds: xr.Dataset, system, along: str, lower: xr.DataArray) -> dict:
    """long_name and units of the scanned parameter, as an atlas's axis has them (from the stored scene)."""
    try:
        info = system.parameter(systems.loads_scene(str(ds.attrs["scene"]), "the file's scene"), along)
        return {"long_name": info.long_name, "units": info.units}
    except (KeyError, StabmapError):  # no scene, or one this version does not read: the symbol and units only
        return {"units": lower.attrs.get("units", "")}


def critical_figure(ds: xr.Dataset, *, sel: dict[str, float] | None = None):
    """Draw a critical-values Dataset into a new Figure: the scanned parameter along x (as on the atlas maps),
    each stretch between located boundaries in the colour of its class (as on the maps), the boundaries as dots,
    against the one other axis (y) left free by ``sel``.

    A file without ``<label>_at_scan_start`` (written before it existed) shows its stable intervals only.
    """
    from matplotlib.collections import PolyCollection
    from matplotlib.lines import Line2D

    system = systems.of_atlas(ds.attrs)
    along, lab = ds.attrs["critical_along"], system.label
    lower = ds[f"{along}_stable_lower"]
    dims = [d for d in lower.dims if d != "interval"]
    for k in sel or {}:
        if k not in dims:
            raise StabmapError(f"--sel {k}: not an axis of this file; its axes are: {', '.join(dims) or '(none)'}")
    chosen = dict(sel or {})
    free = [d for d in dims if d not in chosen]
    if len(free) > 1:
        raise StabmapError(f"this file has {len(free)} other axes ({', '.join(free)}); fix all but one with --sel NAME=VALUE")
    names = ["boundary_lower", "boundary_upper", f"{lab}_below", f"{lab}_above", f"{along}_stable_lower", f"{along}_stable_upper"]
    start = f"{lab}_at_scan_start" if f"{lab}_at_scan_start" in ds else None
    picked = ds[names + ([start] if start else [])]
    if chosen:
        picked = picked.sel(chosen, method="nearest")
    rows = picked.transpose(*free, ...) if free else picked.expand_dims(row=[0])
    b_lo, b_hi = (np.asarray(rows[n]) for n in names[:2])
    below, above = (np.asarray(rows[n]) for n in names[2:4])
    s_lo, s_hi = (np.asarray(rows[n]) for n in names[4:])
    scan = [float(v) for v in ds.attrs["critical_scan_range"]]
    stable, absent, undecided = system.stable_label, system.absent_label, system.undecided_label

    # (row, x0, x1, class) of every stretch the file proves; the few-ulp brackets between them are left blank
    stretches = []
    for r in range(b_lo.shape[0]):
        if start is None:  # an old file: its stable intervals only
            stretches += [(r, lo, hi, stable) for lo, hi in zip(s_lo[r], s_hi[r]) if np.isfinite(lo)]
            continue
        ok = np.isfinite(b_lo[r])
        cuts = [scan[0], *[v for pair in zip(b_lo[r][ok], b_hi[r][ok]) for v in pair], scan[1]]
        classes = [int(np.asarray(rows[start])[r]), *above[r][ok].astype(int)]
        stretches += [(r, cuts[2 * i], cuts[2 * i + 1], c) for i, c in enumerate(classes)]

    one_d = not free
    fig = captioned_figure(ds, (7.5, 2.4 if one_d else 5.5))
    ax = fig.subplots()
    if free:
        y = np.asarray(ds[free[0]])
        edges = _edges(y, ds[free[0]].attrs.get("scale"))
    else:
        edges = np.array([0.0, 1.0])
    # One box per point and stretch: joining neighbouring points would draw boundaries (and shade regions) that
    # were never computed wherever the classes change between points.
    present = sorted({c for *_, c in stretches})
    for c in present:
        boxes = [[(x0, edges[r]), (x0, edges[r + 1]), (x1, edges[r + 1]), (x1, edges[r])] for r, x0, x1, cc in stretches if cc == c]
        hatch = _HATCH_DEGENERATE if c < 0 and c != absent else None
        ax.add_collection(PolyCollection(boxes, facecolors=colour(c, stable, absent, undecided), edgecolors="none", hatch=hatch))
    ends = np.concatenate([b_lo.ravel(), b_hi.ravel()])
    ys = np.broadcast_to(((edges[:-1] + edges[1:]) / 2 if free else np.array([0.5]))[:, None], b_lo.shape).ravel()
    ax.plot(ends, np.concatenate([ys, ys]), "k.", ms=2.5 if free else 6)
    ax.set_xlim(scan[0], scan[1])
    ax.set_ylim(edges[0], edges[-1])
    if free:
        ax.set_ylabel(axis_label(ds, free[0], width=45))
        if ds[free[0]].attrs.get("scale") == "log":
            ax.set_yscale("log")
            log_ticks(ax.yaxis, float(np.min(y)), float(np.max(y)))
    else:
        ax.set_yticks([])
    ax.set_xlabel(axis_label(xr.Dataset(coords={along: ((), 0.0, _scanned(ds, system, along, lower))}, attrs=ds.attrs), along, width=60))
    handles = [class_patch(c, system) for c in present]
    handles.append(Line2D([], [], color="k", marker=".", ls="none", label=f"a change of {_mathtext(system.label_symbol)},\nlocated"))
    fig.legend(handles=handles, loc="outside right upper", alignment="left", frameon=False, title=system.label_title,
               fontsize=9, title_fontsize=9)
    title = _fill_title(ds.attrs.get("title", "stabmap critical values"), 70)
    title += f"\n{_symbol(ds, along)} scanned, every change located to rtol {ds.attrs['critical_rtol']:g}"
    if start is None:
        title += " (stable intervals only: an older file)"
    if chosen:
        title += "; " + ", ".join(_value_text(ds, k, float(ds[k].sel({k: v}, method="nearest"))) if k in ds.coords else f"{k} = {v:.4g}" for k, v in chosen.items())
    ax.set_title(title, fontsize=10)
    return fig
