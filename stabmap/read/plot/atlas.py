"""The atlas figure: plan (which axis goes where) -> reduce (each panel to blocks no smaller than a pixel) ->
draw (classes, hatches, boundaries on cell edges, panel titles, axes) -> legend and title, one function a step.

``atlas_figure`` draws an atlas Dataset into a new matplotlib Figure and computes nothing: it reads the system's
label, its provenance flags and ``cell``, and their coordinates, chunk by chunk when the atlas is lazy.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ... import systems
from ..areas import AreaShares
from ..headline import Headline
from .captions import atlas_title, captioned_figure
from .frame import map_edges, set_map_axes
from .geometry import block_classes, boundary_widths, cell_edge_boundaries
from .label_line import LABEL_HEIGHT, draw_label_line, label_legend, line_size
from .labels import axis_label, log_axis, value_text
from .layout import LEGEND_WIDTH, MAX_PANELS, FigurePlan, figure_size, panel_grid, panel_points, plan_figure
from .marks import change_text, hidden_cell_axes
from .paint import fill_classes, hatch_cells, paint_cells
from .palette import BOUNDARY, CLASS_EDGE, class_colours, legend_handles
from .reduce import FLAG_CHANGE, FLAG_INFERRED, FLAG_NODE_ONLY, Reduced, reduce_panels

# What a figure's panels drew, for its legend (``palette.legend_handles``): nothing yet.
NO_MARKS = {"stability": False, "classes": False, "inferred": False, "light": False, "node-only": False,
            "node-only-light": False, "change": False}


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
    more grid points than pixels is drawn in blocks (:mod:`stabmap.read.plot`), so memory stays bounded at any size.

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
        ``fig.axes[0].plot(x, y)``; its limits are fixed to the grid. The legend is ``fig.legends[0]``. With one
        free axis, ``fig.axes[0]`` is the label's line against it and ``fig.axes[1]`` (where the atlas stores a
        growth rate) the growth rate's beneath (:mod:`stabmap.read.plot.label_line`).

    Raises
    ------
    StabmapError
        For an option that does not fit the atlas (unknown axis, an axis given two roles, ...), naming the
        parameter as the caller spelled it (``x='foo'`` in Python, ``--x foo`` from the command line).
    """
    plan = plan_figure(ds, x=x, y=y, sel=sel, facet=facet, max_panels=max_panels)
    system = systems.of_atlas(ds.attrs)
    nrows, ncols, width = panel_grid(plan)
    reduced = reduce_panels(ds, plan, system, width, nrows, ncols)
    xe, ye = map_edges(ds, plan, reduced.factors)
    if plan.y is None:  # one free axis: a line of the label (and the growth rate), not a strip with an empty y axis
        return line_figure(ds, plan, system, reduced, xe, figure_title(ds, plan, system, reduced, width, chars=52), width)
    title = figure_title(ds, plan, system, reduced, width)
    size = figure_size(plan, width, nrows, title.count("\n") + 1, len(reduced.present))
    fig = captioned_figure(ds, size)
    if plan.facet is None:
        maps = side = fig
    else:  # panels with their titles on the left, the legend on the right: the two never overlap
        maps, side = fig.subfigures(1, 2, width_ratios=[size[0] - LEGEND_WIDTH, LEGEND_WIDTH])
    grid = maps.subplots(nrows, ncols, sharex=True, sharey=True, squeeze=False)
    axes = [grid[n // ncols, n % ncols] for n in range(len(reduced.panels))]
    for ax in grid.ravel()[len(reduced.panels) :]:
        ax.remove()

    cmap, norm = class_colours(reduced.present, system)
    span = panel_points(width, nrows, ncols, facets=plan.facet is not None, strip=plan.y is None)
    log = (log_axis(ds, plan.x), plan.y is not None and log_axis(ds, plan.y))
    drawn = dict(NO_MARKS)
    for n, (ax, blocks, (r, c)) in enumerate(zip(axes, reduced.blocks, reduced.panels, strict=True)):
        for key, value in draw_panel(ax, blocks, xe, ye, system, cmap, norm, span, log).items():
            drawn[key] |= value
        if plan.facet is not None:
            ax.set_title(panel_title(ds, plan, system, blocks, r, c, None if reduced.shares is None else reduced.shares[n]), fontsize=9)

    shown = set_map_axes(axes[0], ds, plan, xe, ye, (span[0] / 72, span[1] / 72))
    if plan.facet is None:
        axes[0].set_xlabel(axis_label(ds, plan.x, shown=shown[plan.x]))
        if plan.y:
            axes[0].set_ylabel(axis_label(ds, plan.y, width=45, shown=shown[plan.y]))
    else:
        assert plan.y is not None  # plan_figure gives facets only to a map of two axes
        for n, ax in enumerate(axes):  # tick labels only where no panel is below / to the left
            ax.tick_params(labelbottom=n + ncols >= len(reduced.panels), labelleft=n % ncols == 0)
        maps.supxlabel(axis_label(ds, plan.x, width=int(12 * (size[0] - LEGEND_WIDTH)), shown=shown[plan.x]), fontsize=10)
        maps.supylabel(axis_label(ds, plan.y, width=int(10 * size[1]), shown=shown.get(plan.y, "")), fontsize=10)

    change = change_text(hidden_cell_axes(ds, system.label, (plan.x, plan.y)), ds)  # a facet is a slice too
    add_legend(fig if plan.facet is None else side, plan, system, reduced.present, drawn, change)
    if plan.facet is None:
        axes[0].set_title(title, fontsize=10)
    else:
        maps.suptitle(title, fontsize=10)
    return fig


def line_figure(ds: xr.Dataset, plan: FigurePlan, system, reduced: Reduced, xe: np.ndarray, title: str, width: float):
    """The figure of one free axis (:mod:`.label_line`): the label as a line over its classes' colours, the growth
    rate beneath where stored, the class legend beside."""
    fig = captioned_figure(ds, line_size(ds, system, width, title.count("\n") + 1))
    cmap, norm = class_colours(reduced.present, system)
    span = (72 * LABEL_HEIGHT, panel_points(width, 1, 1, facets=False, strip=True)[1])
    axes, drawn, extra = draw_label_line(fig, ds, plan, system, reduced, xe, draw_panel, cmap, norm, span)
    marks = {**NO_MARKS, **drawn}
    change = change_text(hidden_cell_axes(ds, system.label, (plan.x,)), ds)
    label_legend(fig, system, reduced.present, marks, change, extra)
    axes[0].set_title(title, fontsize=10)
    return fig


def figure_title(ds: xr.Dataset, plan: FigurePlan, system, reduced: Reduced, width: float, chars: int | None = None) -> str:
    """The title over the map or the panels (:func:`stabmap.read.plot.captions.atlas_title`), in lines as wide as
    the maps, with the headline (:mod:`stabmap.read.headline`) of the grid points and cells drawn."""
    from ..summary import scanned_axes

    stable, undecided = system.stable_label, system.undecided_label
    shares = None if reduced.shares is None else AreaShares.mean(reduced.shares)
    head = Headline(
        points=reduced.points, stable=None if stable is None else reduced.totals.get(stable, 0),
        inferred=0 if shares is None else shares.inferred,
        undecided=0 if undecided is None else reduced.totals.get(undecided, 0),
        whole=None if shares is None else shares.whole, change=0.0 if shares is None else shares.change,
        axes=scanned_axes(ds, [d for d in (plan.x, plan.y) if d]), shown=plan.facet is not None or bool(plan.fixed),
    )
    chars = chars or (70 if plan.facet is None else int(12 * (width - LEGEND_WIDTH)))
    return atlas_title(ds, plan, head.text(system), chars,
                       reduced.factors, reduced.shape)


def draw_panel(ax, blocks, xe: np.ndarray, ye: np.ndarray, system, cmap, norm, span: tuple[float, float],
               log: tuple[bool, bool]) -> dict[str, bool]:
    """Draw one panel's blocks into ``ax``: the classes, the hatches (inferred, node only, degenerate, cells holding
    a change), blocks of mixed labels, then the boundaries on cell edges, as wide as the bands allow.
    Returns which of these it drew, for the legend."""
    from matplotlib.collections import LineCollection

    stable, absent = system.stable_label, system.absent_label
    drawn: dict[str, bool] = {}
    values, mixed = blocks.low, blocks.mixed
    fill_classes(ax, values, xe, ye, system, cmap, norm)
    bits = np.zeros(values.shape, dtype=np.int32) if blocks.any_flag is None else blocks.any_flag
    inferred = (bits & FLAG_INFERRED) > 0
    node_only = ((bits & FLAG_NODE_ONLY) > 0) & ~inferred
    for mask, gid in ((inferred, "inferred-cells"), (node_only, "node-only-cells"),
                      ((values < 0) & (values != absent) & ~mixed, "degenerate-cells")):
        if mask.any():
            light = hatch_cells(ax, mask, xe, ye, gid)
            if gid == "inferred-cells":
                drawn["inferred"], drawn["light"] = True, light
            elif gid == "node-only-cells":
                drawn["node-only"], drawn["node-only-light"] = True, light
    codes, state = block_classes(blocks, stable)
    # A block of one class holding a change is hatched over its class colour; a block of several classes (below a
    # pixel) is filled, black where it holds stable and unstable points: a matter of resolution, not of cell flags.
    change = ((bits & FLAG_CHANGE) > 0) & ~mixed
    if change.any():
        hatch_cells(ax, change, xe, ye, "change-cells")
    drawn["change"] = bool(change.any())
    for mask, col, gid in ((mixed & ~blocks.mixed_stability, CLASS_EDGE, "mixed-class-blocks"),
                           (blocks.mixed_stability, BOUNDARY, "mixed-stability-blocks")):
        if mask.any():
            paint_cells(ax, mask, xe, ye, col, gid)
    stab, other = cell_edge_boundaries(codes, xe, ye, stable, state=state)
    for segs, widest, col, gid in ((other, 0.6, CLASS_EDGE, "class-boundary"), (stab, 1.5, BOUNDARY, "stability-boundary")):
        widths = boundary_widths(segs, xe, ye, span, widest, log=log, codes=codes)
        lines = LineCollection(segs, colors=col, linewidths=widths, capstyle="projecting", joinstyle="miter",
                               zorder=3 + (gid == "stability-boundary"))
        lines.set_gid(gid)
        ax.add_collection(lines, autolim=False)
    drawn["stability"], drawn["classes"] = len(stab) > 0, len(other) > 0
    return drawn


def panel_title(ds: xr.Dataset, plan: FigurePlan, system, blocks, r: int | None, c: int, share: AreaShares | None) -> str:
    """A small multiple's title: its facet (and row) value, and in the headline's order its grid points' share
    stable, then the share of its area over which its cells prove the label (``share``; left out where none does)."""
    assert plan.facet is not None  # only small multiples have panel titles
    parts = [value_text(ds, plan.facet, float(ds[plan.facet][c]))]
    if plan.row is not None:
        parts.append(value_text(ds, plan.row, float(ds[plan.row][r])))
    if system.stable_label is None:  # a system without stability: the panel's coordinates only
        return "\n".join(parts)
    text = f"{100 * blocks.counts.get(system.stable_label, 0) / sum(blocks.counts.values()):.0f} % {system.stable_word}"
    whole = 0.0 if share is None else share.whole  # a coarse grid's cells prove changes at most: nothing to add
    proved = whole > 0
    if proved:  # short: three panels side by side share a line
        text += f"; {100 * whole:.0f} % of area proved"
    parts.append(text)
    two_lines = plan.row is not None or proved  # the longer text of areas needs its own line
    return "\n".join([", ".join(parts[:-1]), parts[-1]]) if two_lines else f"{parts[0]}  ({parts[1]})"


def add_legend(where, plan: FigurePlan, system, present: list[int], drawn: dict[str, bool], change: str = "") -> None:
    """The legend of the classes ``present`` and the marks ``drawn`` (``change``: the words of the change hatch):
    beside a single map, or at the top of the right-hand subfigure of small multiples (``where``)."""
    legend = {"frameon": False, "title": system.label_title, "fontsize": 9, "title_fontsize": 9}
    handles = legend_handles(system, present, drawn, change)
    if plan.facet is None:
        where.legend(handles=handles, loc="outside right upper", alignment="left", **legend)
    else:
        where.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.0, 0.97), alignment="left", **legend)
