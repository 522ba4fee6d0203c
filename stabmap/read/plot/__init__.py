"""Pictures of an atlas: maps of its label (the system's classes: for gyroscopes the number of complex root pairs),
with the boundaries between classes; maps of its float variables (``variable_figure``: growth rates, e-folding
times) with the same axes and stability boundary; and the figure of a critical-values file.

``atlas_figure`` draws an atlas Dataset into a new matplotlib Figure and computes nothing: it reads the system's
label, its provenance flags and ``cell``, and their coordinates, chunk by chunk when the atlas is lazy
(``open_atlas(path, lazy=True)``). ``plot_atlas`` saves that figure to PNG or PDF.

- A map with more grid points than its pixels is drawn in blocks of grid points, no smaller than a pixel
  (:func:`stabmap.read.blocks.reduce_blocks`): a block of one class shows it, a block holding stable and unstable
  points is black (the stability boundary runs through it), one holding several other classes dark grey; the
  title states the block size and this rule. Every stable/unstable boundary thus stays visible.
- A 1-D atlas is a strip, a 2-D atlas one map, and an atlas with 3 or 4 axes small multiples: one panel per
  value of the third axis (the facet), and with a fourth axis one row per value of it. Evenly spaced values are
  drawn when there are more than ``max_panels`` panels, and the figure says which. Other axes are fixed with
  ``sel`` (nearest grid value).
- Classes are coloured from the Okabe-Ito palette (stable: sky blue; the unstable classes in the order of the
  label: yellow, orange, vermillion, ...); each class always has the same colour. Degenerate points are grey and
  cross-hatched, points whose class was not proved (``System.undecided_label``) dark grey and cross-hatched;
  points of an adaptive atlas that were inferred from their cell's corners carry a light diagonal hatch (a light
  veil in very large adaptive atlases).
- Cells (``cell``, docs/cells.md): a grid point keeps its class colour whatever its cell proves; a cell whose
  label is proved at its node only is dotted (a light veil when there are very many); a cell proved to hold a
  change of label carries a dark diagonal hatch over its colour (:mod:`.marks`), so a band narrower than the grid
  still shows and the class of its nodes stays readable. In a slice of a larger atlas the change may lie along
  an axis not drawn: the legend names it.
- Boundaries are drawn on grid-cell edges, between every two neighbouring points whose label differs: thick
  where one side is stable and the other not, thin where only the class of the unstable side changes. A line is
  drawn only where two grid points differ, never interpolated between them.

One module an idea:

- :mod:`.palette`: colours, hatches and legend entries of the classes;
- :mod:`.marks`: the hatch of cells holding a change, its words, the axes not drawn it may lie along;
- :mod:`.layout`: which axis goes where (:class:`FigurePlan`, :func:`plan_figure`) and the room a map gets;
- :mod:`.geometry`: cell edges, runs, rectangles, boundary segments and their widths, blocks;
- :mod:`.labels`: symbols, units, axis labels and ticks;
- :mod:`.captions`: titles, the caption of fixed parameters, filling lines that hold mathtext;
- :mod:`.reduce`: each panel read once and reduced to blocks, with its flags and proved areas;
- :mod:`.paint`: cells painted onto axes (classes, hatches, fills);
- :mod:`.atlas`: the atlas figure (plan -> reduce -> draw -> legend and title);
- :mod:`.critical`: the figure of critical values;
- :mod:`.campbell`, :mod:`.campbell_page`: the Campbell diagram of an atlas with frequencies (a figure, an .html page);
- :mod:`.floats`: which float variables a figure of values can draw, why another cannot, its colour scale;
- :mod:`.value_map`: the figure of a float variable (:func:`variable_figure`): a map with a colour bar, or a line;
- :mod:`.saving`: figure files (:func:`check_figure_path`, :func:`save_figure`, :func:`plot_atlas`, :func:`plot_critical`,
  :func:`plot_campbell`); ``plot_atlas(..., var=NAME)`` saves :func:`variable_figure`.
"""

from __future__ import annotations

from .atlas import atlas_figure
from .campbell import campbell_figure
from .captions import captioned_figure, fixed_caption
from .critical import critical_figure
from .geometry import block_classes, boundary_widths, cell_edge_boundaries
from .labels import axis_label, display_ticks, log_ticks
from .layout import MAX_PANELS, FigurePlan, panel_pixels, panel_points, plan_figure
from .palette import (
    ABSENT_COLOUR,
    DEGENERATE_COLOUR,
    STABLE_COLOUR,
    UNDECIDED_COLOUR,
    UNSTABLE_COLOUR,
    class_label,
    class_patch,
    colour,
)
from .reduce import reduce_panels
from .saving import check_figure_path, plot_atlas, plot_campbell, plot_critical, save_figure
from .value_map import check_value_options, variable_figure

__all__ = [
    "ABSENT_COLOUR", "DEGENERATE_COLOUR", "MAX_PANELS", "STABLE_COLOUR", "UNDECIDED_COLOUR", "UNSTABLE_COLOUR",
    "FigurePlan", "atlas_figure", "axis_label", "block_classes", "boundary_widths", "captioned_figure",
    "cell_edge_boundaries", "check_figure_path", "check_value_options", "class_label", "class_patch", "colour", "critical_figure",
    "display_ticks", "fixed_caption", "log_ticks", "panel_pixels", "panel_points", "plan_figure", "plot_atlas",
    "plot_critical", "reduce_panels", "save_figure", "variable_figure", "campbell_figure", "plot_campbell",
]
