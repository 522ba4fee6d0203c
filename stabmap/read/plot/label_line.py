"""The class figure of one free axis (``stabmap plot ATLAS --sel K_1=10 --sel m_2=1``): the label as a line against
that axis over its classes' colours, and beneath it, where the atlas stores one, the growth rate along the same
axis (drawn as ``stabmap plot --var growth_rate`` draws a line, :mod:`.value_map`).

A class map of one axis would be a strip of colours with an empty y axis; a line says how far the label is from
stable (N_c = 2 is further from stable than N_c = 1), which a strip of colours does not.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .floats import colour_scale, drawable, value_label
from .labels import axis_label, mathtext
from .layout import FigurePlan
from .palette import legend_handles
from .ticks import set_axis

GROWTH = "growth_rate"  # the variable drawn beneath the label where the atlas stores it
LINE_INK = "#000000"
LABEL_HEIGHT, GROWTH_HEIGHT = 1.9, 1.7  # [inch] the two plots


def growth_variable(ds: xr.Dataset, system) -> str | None:
    """The growth rate's name where the atlas stores it as a float on the label's axes, else None."""
    return GROWTH if GROWTH in drawable(ds, system) else None


def line_size(ds: xr.Dataset, system, width: float, title_lines: int) -> tuple[float, float]:
    """The figure's size [inch] before the caption: the label's plot, the growth rate's beneath where stored."""
    return width, LABEL_HEIGHT + (GROWTH_HEIGHT if growth_variable(ds, system) else 0.0) + 0.9 + 0.17 * title_lines


def draw_label_line(fig, ds: xr.Dataset, plan: FigurePlan, system, reduced, xe: np.ndarray, draw_panel, cmap, norm,
                    span: tuple[float, float]):
    """Draw the label along ``plan.x`` into ``fig``: its classes' colours behind a line of the label (the lowest and
    highest of a block where the axis is reduced), the stability boundary, the growth rate beneath. Returns the
    axes (label first) and what was drawn, for the legend."""
    growth = growth_variable(ds, system)
    axes = fig.subplots(2 if growth else 1, 1, sharex=True, squeeze=False, height_ratios=[LABEL_HEIGHT, GROWTH_HEIGHT][: 2 if growth else 1])[:, 0]
    top = axes[0]
    blocks = reduced.blocks[0]
    low, high = blocks.low[0].astype(float), blocks.high[0].astype(float)
    present = [int(v) for v in reduced.present]
    lo, hi = min(present) - 0.5, max(present) + 0.5
    drawn = draw_panel(top, blocks, xe, np.array([lo, hi]), system, cmap, norm, span, (False, False))
    top.stairs(low, xe, baseline=None, color=LINE_INK, lw=1.4, zorder=5, gid="label-line")
    if (high != low).any():  # a block of several labels: its highest too
        top.stairs(high, xe, baseline=None, color=LINE_INK, lw=1.0, ls="--", zorder=5, gid="label-line-high")
    set_axis(top, "x", ds, plan.x, xe[0], xe[-1], span[1] / 72)
    top.set_ylim(lo, hi)
    top.set_yticks(present)
    if system.variable(system.label).flags:  # the codes of a flag variable order nothing: name the classes
        top.set_yticklabels([system.class_name(v) for v in present], fontsize=8)
    top.set_ylabel(mathtext(system.label_symbol))
    extra = []
    if growth:
        extra = draw_growth(axes[1], ds, plan, system, growth)
        set_axis(axes[1], "x", ds, plan.x, xe[0], xe[-1], span[1] / 72)
    shown = set_axis(axes[-1], "x", ds, plan.x, xe[0], xe[-1], span[1] / 72)
    axes[-1].set_xlabel(axis_label(ds, plan.x, shown=shown))
    return list(axes), drawn, extra


def draw_growth(ax, ds: xr.Dataset, plan: FigurePlan, system, var: str) -> list:
    """The growth rate along the axis, as ``stabmap plot --var growth_rate`` draws its line; returns its legend
    entries that the class legend has not (the line, the proved enclosure)."""
    from .frame import map_edges
    from .value_map import draw_line, marks, reduce_map, values_axis
    from .value_map import legend_handles as value_handles

    da = ds[var]
    blocks = reduce_map(ds, da, plan, system, True)
    scale = colour_scale(blocks.stats)
    xe, _ = map_edges(ds, plan, blocks.factors)
    drawn = marks(blocks, scale, True)
    draw_line(ax, ds, plan, blocks, xe, scale, drawn)
    values_axis(ax, blocks, scale)
    ax.set_ylabel(value_label(da, 30), fontsize=8)
    return [h for h in value_handles(system, da, blocks, scale, drawn, True) if h.get_label() != "stability boundary"]


def label_legend(where, system, present: list[int], drawn: dict[str, bool], change: str, extra: list) -> None:
    """The legend beside the plots: the classes and marks (as the class map's), then the growth rate's line."""
    handles = legend_handles(system, present, drawn, change) + extra
    where.legend(handles=handles, loc="outside right upper", alignment="left", frameon=False, title=system.label_title,
                 fontsize=9, title_fontsize=9)
