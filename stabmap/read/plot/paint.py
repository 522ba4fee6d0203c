"""Painting the cells of a map onto matplotlib axes: the classes as merged vector rectangles (or an image when
the map is too busy), hatches over degenerate, inferred, node-only cells and cells holding a change, and solid
fills of blocks that mix classes below a pixel."""

from __future__ import annotations

import numpy as np

from .geometry import rectangles, runs
from .marks import CHANGE_INK, HATCH_CHANGE
from .palette import HATCH_DEGENERATE, HATCH_INFERRED, HATCH_NODE_ONLY, system_colour

HATCH_RUNS = 100_000  # more separate runs of inferred cells than this: a light veil instead of a hatch
VECTOR_RUNS = 20_000  # a panel with more runs of equal cells along x is filled as an image (lines and text stay vector)


def fill_classes(ax, values: np.ndarray, xe: np.ndarray, ye: np.ndarray, system, cmap, norm) -> None:
    """Colour the cells by their label of ``system``: one vector rectangle per block of equal cells, or an image
    (``cmap``, ``norm``: :func:`stabmap.read.plot.palette.class_colours`) when the map is too busy.

    Rectangles are outlined in their own colour, so no hairline seams show between them in a PDF viewer.
    """
    from matplotlib.collections import PolyCollection

    change = np.ones(values.shape, dtype=bool)
    change[:, 1:] = values[:, 1:] != values[:, :-1]
    if int(change.sum()) > VECTOR_RUNS:
        ax.pcolormesh(xe, ye, values, cmap=cmap, norm=norm, shading="flat", rasterized=True)
        return
    for v in np.unique(values):
        c = system_colour(int(v), system)
        cells = PolyCollection(rectangles(values == v, xe, ye), facecolors=c, edgecolors=c, linewidths=0.3, antialiaseds=False, zorder=1)
        cells.set_gid(f"cells-{int(v)}")
        ax.add_collection(cells, autolim=False)


def hatch_cells(ax, mask: np.ndarray, xe: np.ndarray, ye: np.ndarray, gid: str) -> bool:
    """Hatch the marked cells (one compound path, so the hatch is drawn once); returns True if it had to lighten.

    Degenerate cells are cross-hatched, cells holding a change ("change-cells") get dark diagonal lines over their
    class colour (never a veil, which would hide it). Inferred cells get a light diagonal hatch, or, when they form
    more than ``HATCH_RUNS`` separate runs (a large adaptive atlas), a light white veil drawn as an image.
    """
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    if gid in ("inferred-cells", "node-only-cells") and len(runs(mask)[0]) > HATCH_RUNS:
        veil = np.ma.masked_where(~mask, np.ones(mask.shape))
        mesh = ax.pcolormesh(xe, ye, veil, cmap=_white_cmap(), vmin=0, vmax=1, alpha=0.45, shading="flat", rasterized=True, zorder=2)
        mesh.set_gid(gid)
        return True
    hatch, colour_ = {"inferred-cells": (HATCH_INFERRED, "#00000066"), "node-only-cells": (HATCH_NODE_ONLY, "#00000066"),
                      "change-cells": (HATCH_CHANGE, CHANGE_INK)}.get(gid, (HATCH_DEGENERATE, "#000000AA"))
    path = MplPath.make_compound_path_from_polys(np.array(rectangles(mask, xe, ye)))
    patch = PathPatch(path, facecolor="none", edgecolor=colour_, linewidth=0, hatch=hatch, zorder=2)
    if hasattr(patch, "set_hatchcolor"):  # matplotlib >= 3.10
        patch.set_hatchcolor(colour_)
        patch.set_hatch_linewidth(0.8 if gid == "change-cells" else 0.5)  # the change's lines a little bolder
    patch.set_gid(gid)
    ax.add_patch(patch)
    return False


def paint_cells(ax, mask: np.ndarray, xe: np.ndarray, ye: np.ndarray, colour_: str, gid: str) -> None:
    """Fill the marked blocks of a reduced map in one colour, as an image (a block is about one pixel): blocks of
    several classes, which no single class colour could show."""
    from matplotlib.colors import ListedColormap

    cells = np.ma.masked_where(~mask, np.ones(mask.shape))
    mesh = ax.pcolormesh(xe, ye, cells, cmap=ListedColormap([colour_]), vmin=0, vmax=1, shading="flat", rasterized=True, zorder=2.5)
    mesh.set_gid(gid)


def _white_cmap():
    from matplotlib.colors import ListedColormap

    return ListedColormap(["#FFFFFF"])
