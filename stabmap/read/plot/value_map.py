"""The figure of a float variable of an atlas (``stabmap plot --var growth_rate``): plan -> reduce -> draw, as the
class map, with the values in colour.

- Two free axes: a map on the cells the labels are proved on, its axes as the class map's, the values on a colour
  scale with a colour bar; a log scale where every value outside the stable class is > 0 (growth rates, e-folding
  times). A point of the stable label whose value the scale cannot show (a growth rate exactly 0: every root proved
  real; an e-folding time of infinity) is in the class map's stable colour; a point without a value (NaN: not
  computed, degenerate) grey and cross-hatched as the class map's degenerate points; the stability boundary runs on
  cell edges, as on the class map, so the picture never hides where the proved label changes stability.
- One free axis: a line of the values along it (a log y axis for a log scale), the stretches of stable points and
  of points without a value shaded across the plot, the proved enclosure (``<var>_lower`` .. ``<var>_upper``, where
  the atlas has them) as a band around the line. No colour bar.
- More free axes: an error naming ``sel`` and the axes to fix; a map of values has no small multiples.
- A map with more grid points than its pixels is drawn in blocks (:func:`stabmap.read.blocks.reduce_values`, one
  pass, chunk by chunk): a block shows the largest value of its points (the fastest growth in it), the stable colour
  only where each of its points with a value is stable, black where it holds stable and unstable points (as on the
  class map); the title gives the block size.
"""

from __future__ import annotations

import textwrap

import numpy as np
import xarray as xr

from ... import systems
from ...errors import StabmapError, given, param
from ..blocks import ValueBlocks, block_factors, reduce_values
from .captions import atlas_title, captioned_figure, fill_mathtext
from .floats import check_variable, colour_norm, colour_scale, drawable, number, short_name, value_label, values_text
from .frame import map_edges, set_map_axes
from .geometry import boundary_widths, cell_edge_boundaries, rectangles, runs
from .labels import axis_label, log_axis, log_ticks, units_text, value_text
from .layout import DPI, VALUE, FigurePlan, plan_figure
from .paint import VECTOR_RUNS, hatch_cells, paint_cells
from .palette import BOUNDARY, DEGENERATE_COLOUR, HATCH_DEGENERATE, STABLE_COLOUR
from .reduce import panel_map

CMAP = "YlOrRd"  # light to dark, warm as the unstable classes: no sky blue (stable), grey (no value) or black (boundary)
LINE = "#8C1A0F"  # the line of values: the dark end of the colour map
STABLE_SHADE = "#BBE1F6"  # the stable colour, lightened: a line plot's stable stretches behind the line
MARKED = 80  # a line of at most this many points marks each
LEGEND_CHARS = 64  # two columns of the legend under a map fit under it when their entries are this short together
WIDTH = 7.5  # [inch], as the class map
# The least room the layout leaves the drawing [inch], which sets its pixels and so its blocks (checked against the
# drawn figure in tests/test_plot_variable.py): a map's width less its y label, colour bar and margins, and its
# height; a line plot's width less its y label and the legend beside it.
MAP_HEIGHT = 3.0
MAP_MARGIN = 2.3
LINE_HEIGHT = 2.0
LINE_MARGIN = 3.9


def variable_figure(ds: xr.Dataset, var: str, *, x: str | None = None, y: str | None = None, sel: dict[str, float] | None = None):
    """Draw the float variable ``var`` of an atlas into a new matplotlib Figure (nothing saved, nothing computed).

    The atlas may be lazy (``open_atlas(path, lazy=True)``): the map is read chunk by chunk and drawn in blocks no
    smaller than a pixel, so memory stays bounded at any size.

    Parameters
    ----------
    ds : xarray.Dataset
        An atlas (``stabmap.compute_atlas``, ``stabmap.open_atlas``).
    var : str
        A float variable on the atlas's grid, e.g. ``"growth_rate"`` or ``"efolding_time"`` (docs/rates.md).
    x, y : str, optional
        Axes of the map (default: the first two axes not fixed); one free axis gives a line plot along x.
    sel : dict, optional
        Axes to fix, ``{name: value}`` (nearest grid value); at most two axes may stay free.

    Returns
    -------
    matplotlib.figure.Figure
        ``fig.axes[0]`` is the map (or the line plot) in grid coordinates; a map's colour bar is ``fig.axes[1]``,
        its legend, under the map, ``fig.axes[0].get_legend()``; a line plot has no colour bar, and its legend
        beside it is ``fig.legends[0]``.

    Raises
    ------
    StabmapError
        For a variable the atlas lacks or that is not a float (a flag, the label), and for options that do not fit
        the atlas (as :func:`stabmap.read.plot.atlas_figure`), naming the parameter as the caller spelled it.
    """
    da = check_variable(ds, var)
    plan = plan_figure(ds, x=x, y=y, sel=sel)
    if plan.facet is not None:
        free = [d for d in ds[da.name].dims if d not in (sel or {})]
        fix = [d for d in free if d not in (plan.x, plan.y)]
        raise StabmapError(f"{given('var', var)} draws one map of at most two axes, and {len(free)} are free ({', '.join(free)}): "
                           f"fix {' and '.join(fix)} with {', '.join(given('sel', VALUE, d) for d in fix)}")
    system = systems.of_atlas(ds.attrs)
    strip = plan.y is None
    blocks = reduce_map(ds, da, plan, system, strip)
    scale = colour_scale(blocks.stats)
    xe, ye = map_edges(ds, plan, blocks.factors)
    title = value_title(ds, plan, da, system, blocks, scale, 56 if strip else 70)  # a line plot: clear of its legend
    drawn = marks(blocks, scale, strip)
    handles = legend_handles(system, da, blocks, scale, drawn, strip)
    lines = title.count("\n") + 1
    columns = legend_columns(handles)
    rows = 0 if strip else -(-len(handles) // columns)  # a map's legend under it
    fig = captioned_figure(ds, (WIDTH, (LINE_HEIGHT + 1.0 if strip else MAP_HEIGHT + 1.2 + 0.2 * rows) + 0.17 * lines))
    ax = fig.subplots()
    if strip:
        draw_line(ax, ds, plan, blocks, xe, scale, drawn)
        shown = set_map_axes(ax, ds, plan, xe, ye)
        values_axis(ax, blocks, scale)
        ax.set_ylabel(value_label(da, 36), fontsize=9)
    else:
        norm = colour_norm(blocks.stats, scale)
        log = (log_axis(ds, plan.x), log_axis(ds, str(plan.y)))
        span = (72 * MAP_HEIGHT, 72 * (WIDTH - MAP_MARGIN))
        mesh = draw_map(ax, blocks, xe, ye, scale, norm, span, log)
        shown = set_map_axes(ax, ds, plan, xe, ye)
        assert plan.y is not None  # a map has two axes
        ax.set_ylabel(axis_label(ds, plan.y, width=45, shown=shown[plan.y]))
        if mesh is not None:
            bar = fig.colorbar(mesh, ax=ax, pad=0.02, fraction=0.06)
            bar.set_label(value_label(da, 50), fontsize=9)
            if scale == "log":  # labelled between the decades too, as the map's log axes
                log_ticks(bar.ax.yaxis, mesh.norm.vmin, mesh.norm.vmax)
    ax.set_xlabel(axis_label(ds, plan.x, shown=shown[plan.x]))
    if handles and strip:
        fig.legend(handles=handles, loc="outside right upper", alignment="left", frameon=False, fontsize=9)
    elif handles:  # under the map's x label (the layout makes room for it), clear of the caption under the figure
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncols=columns, frameon=False, fontsize=9)
    ax.set_title(title, fontsize=10)
    return fig


def reduce_map(ds: xr.Dataset, da: xr.DataArray, plan: FigurePlan, system, strip: bool) -> ValueBlocks:
    """The variable's map (fixed axes selected) read once and reduced to blocks no smaller than the pixels of the
    drawing, with the label beside it; a line plot's also with the proved enclosure, where the atlas has one."""
    fix = {k: i for k, (i, _) in plan.fixed.items()}
    shape = (1 if strip else ds.sizes[str(plan.y)], ds.sizes[plan.x])
    pixels = (1, int(DPI * (WIDTH - LINE_MARGIN))) if strip else (int(DPI * MAP_HEIGHT), int(DPI * (WIDTH - MAP_MARGIN)))
    names = drawable(ds, system)
    bounds = [f"{da.name}_{end}" for end in ("lower", "upper")]
    bounds_maps = [panel_map(ds[b].isel(fix), plan, None, None) for b in bounds] if strip and all(b in names for b in bounds) else [None, None]
    return reduce_values(panel_map(da.isel(fix), plan, None, None), panel_map(ds[system.label].isel(fix), plan, None, None),
                         system.stable_label, block_factors(shape, pixels), *bounds_maps)


def kinds(blocks: ValueBlocks, scale: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Which blocks show a value in colour, which are drawn stable (each of their points with a value is stable,
    at a value the scale cannot show) and which have no value to show."""
    shown = ~np.isnan(blocks.top[scale])
    stable = ~shown & blocks.off[scale]
    return shown, stable, ~shown & ~stable


def marks(blocks: ValueBlocks, scale: str, strip: bool) -> dict[str, bool]:
    """What the figure draws besides the values, for its legend and its size: stable and valueless stretches, a
    stability boundary, blocks of stable and unstable points (a map), the band of the proved enclosure and whether
    it is narrower than the line, and the markers at the points (a line plot)."""
    shown, stable, empty = kinds(blocks, scale)
    state = blocks.state
    band = strip and blocks.lower is not None and blocks.upper is not None and bool(shown.any())
    thin = False
    if band:
        assert blocks.lower is not None and blocks.upper is not None  # band says so
        with np.errstate(invalid="ignore", divide="ignore"):
            width = np.where(shown, (blocks.upper - blocks.lower) / blocks.top[scale], np.nan)
        thin = bool(np.nanmax(width) < 0.01)  # a band narrower than the line: the legend says why it is not seen
    return {
        "stable": bool(stable.any()), "empty": bool(empty.any()), "mixed": not strip and bool((state == 2).any()),
        "stability": bool((state[:, 1:] != state[:, :-1]).any() or (state[1:] != state[:-1]).any()),
        "band": band, "thin": thin, "markers": strip and not blocks.reduced and state.shape[1] <= MARKED,
    }


def fill(ax, mask: np.ndarray, xe: np.ndarray, ye: np.ndarray, colour: str, gid: str, transform=None) -> None:
    """Fill the marked cells in one colour: merged vector rectangles, or an image when there are very many."""
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import ListedColormap

    where = {} if transform is None else {"transform": transform}
    if len(runs(mask)[0]) > VECTOR_RUNS:
        cells = ax.pcolormesh(xe, ye, np.ma.masked_where(~mask, np.ones(mask.shape)), cmap=ListedColormap([colour]), vmin=0, vmax=1,
                              shading="flat", rasterized=True, zorder=1, **where)
    else:
        cells = PolyCollection(rectangles(mask, xe, ye), facecolors=colour, edgecolors=colour, linewidths=0.3, antialiaseds=False,
                               zorder=1, **where)
        ax.add_collection(cells, autolim=False)
    cells.set_gid(gid)


def draw_map(ax, blocks: ValueBlocks, xe: np.ndarray, ye: np.ndarray, scale: str, norm, span: tuple[float, float],
             log: tuple[bool, bool]):
    """Draw the blocks of a map: values in colour, stable and valueless blocks, blocks of stable and unstable points
    (black), then the stability boundary on cell edges. Returns the values' mesh (None: none in colour)."""
    from matplotlib.collections import LineCollection

    shown, stable, empty = kinds(blocks, scale)
    mesh = None
    if norm is not None and shown.any():
        top = np.ma.masked_invalid(blocks.top[scale])
        busy = top.size > VECTOR_RUNS  # a PDF of many cells as an image; small ones stay vector, without seams
        mesh = ax.pcolormesh(xe, ye, top, cmap=CMAP, norm=norm, shading="flat", rasterized=busy, zorder=1,
                             **({} if busy else {"edgecolors": "face", "linewidth": 0.2}))
        mesh.set_gid("values")
    if stable.any():
        fill(ax, stable, xe, ye, STABLE_COLOUR, "stable-cells")
    if empty.any():
        fill(ax, empty, xe, ye, DEGENERATE_COLOUR, "no-value-cells")
        hatch_cells(ax, empty, xe, ye, "no-value-hatch")
    mixed = blocks.state == 2
    if mixed.any():
        paint_cells(ax, mixed, xe, ye, BOUNDARY, "mixed-stability-blocks")
    stab, _ = cell_edge_boundaries(blocks.state, xe, ye, state=blocks.state)
    lines = LineCollection(stab, colors=BOUNDARY, linewidths=boundary_widths(stab, xe, ye, span, 1.5, log=log, codes=blocks.state),
                           capstyle="projecting", joinstyle="miter", zorder=4)
    lines.set_gid("stability-boundary")
    ax.add_collection(lines, autolim=False)
    return mesh


def draw_line(ax, ds: xr.Dataset, plan: FigurePlan, blocks: ValueBlocks, xe: np.ndarray, scale: str, drawn: dict[str, bool]) -> None:
    """Draw the values along x as a line (a block's largest value as a step where the axis is reduced), the proved
    enclosure as a band (``drawn``: :func:`marks`), and, across the plot, the stretches of stable points and of
    points without a value and the stability boundary between stretches."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    across = ax.get_xaxis_transform()  # x in data, y from 0 to 1 over the plot
    shown, stable, empty = (k[0] for k in kinds(blocks, scale))
    ye = np.array([0.0, 1.0])
    if stable.any():
        fill(ax, stable[None, :], xe, ye, STABLE_SHADE, "stable-cells", across)
    if empty.any():
        fill(ax, empty[None, :], xe, ye, DEGENERATE_COLOUR, "no-value-cells", across)
        hatch = PathPatch(MplPath.make_compound_path_from_polys(np.array(rectangles(empty[None, :], xe, ye))), facecolor="none",
                          edgecolor="#000000AA", linewidth=0, hatch=HATCH_DEGENERATE, zorder=2, transform=across)
        hatch.set_gid("no-value-hatch")
        ax.add_patch(hatch)
    state = blocks.state[:1]
    stab, _ = cell_edge_boundaries(state, xe, ye, state=state)
    lines = LineCollection(stab, colors=BOUNDARY, linewidths=1.5, zorder=4, transform=across)
    lines.set_gid("stability-boundary")
    ax.add_collection(lines, autolim=False)

    top = blocks.top[scale][0]
    lower, upper = (None, None) if not drawn["band"] else (blocks.lower[0], blocks.upper[0])  # type: ignore[index]
    if not blocks.reduced:
        x = np.asarray(ds[plan.x], dtype=float)
        (line,) = ax.plot(x, top, color=LINE, lw=1.2, marker="o" if drawn["markers"] else None, ms=3, zorder=3)
    else:  # a step per block, at its largest value
        x = np.repeat(xe, 2)[1:-1]
        line = ax.stairs(top, xe, baseline=None, color=LINE, lw=1.0, zorder=3)
        shown = np.repeat(shown, 2)
        lower, upper = (None if a is None else np.repeat(a, 2) for a in (lower, upper))
    line.set_gid("values")
    if lower is not None and upper is not None:
        ax.fill_between(x, lower, upper, where=shown, color=LINE, alpha=0.3, lw=0, zorder=2.5, gid="enclosure")


def values_axis(ax, blocks: ValueBlocks, scale: str) -> None:
    """The y axis of a line plot: log for a log scale, from the least to the largest value drawn (bounds included);
    without a value drawn (every point stable, say), an empty axis."""
    drawn = [blocks.top[scale][0]] + [b[0] for b in (blocks.lower, blocks.upper) if b is not None]
    values = np.concatenate(drawn)
    values = values[np.isfinite(values) & ((values > 0) if scale == "log" else True)]
    if not values.size:  # a log axis over nothing cannot be drawn
        ax.set_yscale("linear")
        ax.set_ylim(0, 1)
        ax.set_yticks([])
        return
    ax.set_yscale(scale)  # also drops the ticks a strip of classes has none of
    lo, hi = float(values.min()), float(values.max())
    if scale == "log":
        ax.set_ylim(lo / 1.6, hi * 1.6)
        log_ticks(ax.yaxis, lo / 1.6, hi * 1.6)
    else:
        pad = 0.06 * (hi - lo) or max(abs(hi), 1.0) * 0.1
        ax.set_ylim(lo - pad, hi + pad)


def value_title(ds: xr.Dataset, plan: FigurePlan, da: xr.DataArray, system, blocks: ValueBlocks, scale: str, chars: int) -> str:
    """The title: the atlas's, then the headline of the values (the largest, and where; the share of stable points,
    at which value; the points without one), the fixed axes, the notes and the rule that reduced a large grid."""
    s = blocks.stats
    units = units_text(str(da.attrs.get("units", "")))
    parts = []
    if s.argmax is not None and (scale == "linear" or s.finite_max > 0):  # a largest value the scale shows
        row, col = s.argmax
        where = [value_text(ds, plan.x, float(ds[plan.x][col]))] + ([value_text(ds, plan.y, float(ds[plan.y][row]))] if plan.y else [])
        parts.append(f"max {short_name(da)} {number(s.finite_max)}" + (f" {units}" if units else "") + f" at {', '.join(where)}")
    elif s.argmax is None:
        parts.append(f"no finite {short_name(da)}")
    grid = f"the {s.points:,} grid points shown" if plan.fixed else f"{s.points:,} grid points"
    if system.stable_label is not None:
        n = s.off[scale]
        parts.append(f"{100 * n / s.points:.1f} % of {grid} {system.stable_word} ({values_text(da, *s.off_range[scale])})" if n
                     else f"no grid point drawn {system.stable_word}")  # the labels may say stable where no value is
    if s.nan:
        parts.append(f"{s.nan:,} without a value (NaN)")
    headline = ";\n".join(fill_mathtext(part, chars) for part in parts)  # mathtext counted as it shows
    title = atlas_title(ds, plan, headline, chars, filled=True)
    if blocks.reduced:
        title += "\n" + textwrap.fill(reduction_note(ds, plan, da, system, blocks), chars)
    return title


def reduction_note(ds: xr.Dataset, plan: FigurePlan, da: xr.DataArray, system, blocks: ValueBlocks) -> str:
    """The caption line of a reduced map: how many grid points a block holds and what it shows."""
    fy, fx = blocks.factors
    size = f"{fx} × {fy}" if plan.y else f"{fx}"
    grid = f"{ds.sizes[plan.x]:,} × {ds.sizes[plan.y]:,}" if plan.y else f"{ds.sizes[plan.x]:,}"
    text = f"{grid} grid points drawn in blocks of {size}: a block shows the largest {short_name(da)} of its points"
    if system.stable_label is None:
        return text
    return (text + f", {system.stable_word} only where each of its points with a value is"
            + (", black if it holds stable and unstable points" if plan.y else ""))


def legend_columns(handles: list) -> int:
    """Columns of the legend under a map: two where the longest entries of both fit under the map side by side, else
    one (a legend wider than the map would push its colour bar away from it)."""
    longest = sorted((len(h.get_label()) for h in handles), reverse=True)[:2]
    return 2 if sum(longest) <= LEGEND_CHARS else 1


def legend_handles(system, da: xr.DataArray, blocks: ValueBlocks, scale: str, drawn: dict[str, bool], strip: bool) -> list:
    """The legend's entries for what the figure draws besides the colours of values (``drawn``: :func:`marks`): the
    line and band of a line plot, stable points and their value, points without a value, the stability boundary,
    blocks holding both."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    def words(text: str) -> str:  # beside a line plot in lines as narrow as its legend; under a map on one line
        return textwrap.fill(text, 30, break_on_hyphens=False) if strip else text

    handles = []
    if strip:
        handles.append(Line2D([], [], color=LINE, lw=1.2, marker="o" if drawn["markers"] else None, ms=3, label=short_name(da)))
        if drawn["band"]:
            said = ("proved enclosure: a block's least lower to largest upper bound" if blocks.reduced
                    else "proved enclosure, lower to upper bound" + (" (narrower than the line)" if drawn["thin"] else ""))
            handles.append(Patch(facecolor=LINE, alpha=0.3, label=words(said)))
    if drawn["stable"] and system.stable_label is not None:
        said = f"{system.class_name(system.stable_label)}: {values_text(da, *blocks.stats.off_range[scale])}"
        handles.append(Patch(facecolor=STABLE_SHADE if strip else STABLE_COLOUR, label=words(said)))
    if drawn["empty"]:
        handles.append(Patch(facecolor=DEGENERATE_COLOUR, hatch=HATCH_DEGENERATE, edgecolor="#000000AA", lw=0,
                             label=words("no value (NaN): not computed or degenerate")))
    if drawn["stability"]:
        handles.append(Line2D([], [], color=BOUNDARY, lw=1.5, label="stability boundary"))
    if drawn["mixed"]:
        handles.append(Patch(facecolor=BOUNDARY, label="stable and unstable in one block"))
    return handles


def check_value_options(var: str | None, facet: str | None, max_panels_given: bool) -> None:
    """``var`` draws one map or line: a facet or a panel count is an error naming both."""
    if var is None:
        return
    extra = "facet" if facet is not None else "max_panels" if max_panels_given else None
    if extra is not None:
        raise StabmapError(f"{param(extra)} applies to the class map; {given('var', var)} draws one map of at most two axes "
                           f"(fix the others with {param('sel')})")
