"""Colours, hatches and legend entries of the label's classes: one class has one colour in every figure.

Okabe-Ito (colour-blind safe), then Paul Tol's muted colours: the stable class gets the calm blue, the unstable
classes warm colours in the order of their label, so a class keeps its colour whatever other classes a figure holds.
"""

from __future__ import annotations

import textwrap

import numpy as np

from .labels import mathtext
from .marks import CHANGE_INK, HATCH_CHANGE

STABLE_COLOUR = "#56B4E9"
UNSTABLE_COLOUR = ["#F0E442", "#E69F00", "#D55E00", "#CC79A7", "#882255", "#332288", "#117733", "#44AA99", "#999933", "#AA4499"]
DEGENERATE_COLOUR = "#BBBBBB"
ABSENT_COLOUR = "#FFFFFF"  # nothing to decide (System.absent_label): left blank
UNDECIDED_COLOUR = "#707070"  # not proved (System.undecided_label): darker than degenerate, hatched like it
BOUNDARY = "#000000"
CLASS_EDGE = "#333333"
HATCH_INFERRED = "////"
HATCH_NODE_ONLY = "...."
HATCH_DEGENERATE = "xxxx"


def colour(value: int, stable: int | None = 0, absent: int | None = None, undecided: int | None = None) -> str:
    """The colour of the label ``value`` (``absent``: white; ``undecided``: dark grey; other negatives: degenerate;
    ``stable``: the stable class, by default 0 as in a count of unstable modes; None: no class is stable) in every
    figure. :func:`system_colour` takes them from a system."""
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


def system_colour(value: int, system) -> str:
    """:func:`colour` of the label ``value`` of ``system`` (its stable, absent and undecided labels)."""
    return colour(value, system.stable_label, system.absent_label, system.undecided_label)


def class_label(value: int, system) -> str:
    """Legend text of the label ``value`` of ``system`` (``System.class_name``)."""
    return system.class_name(value)


def class_patch(value: int, system):
    """The legend entry of one class of ``system``'s label, as every figure draws it."""
    from matplotlib.patches import Patch

    absent = system.absent_label
    return Patch(facecolor=colour(value, system.stable_label, absent, system.undecided_label),
                 edgecolor="#888888" if value == absent else "none",  # a white patch needs an outline to be seen
                 lw=0.5, hatch=HATCH_DEGENERATE if value < 0 and value != absent else None, label=class_label(value, system))


def class_colours(present: list[int], system):
    """A colour map and norm over every label from the lowest drawn (at most -1) to the highest (at least 1), for
    a map filled as an image."""
    from matplotlib.colors import BoundaryNorm, ListedColormap

    top, bottom = max(1, present[-1]), min(-1, present[0])
    cmap = ListedColormap([system_colour(v, system) for v in range(bottom, top + 1)])
    return cmap, BoundaryNorm(np.arange(bottom - 0.5, top + 1.5), cmap.N)


def legend_handles(system, present: list[int], drawn: dict[str, bool], change: str = "") -> list:
    """The legend's entries: the classes ``present``, then the lines and marks a map drew (``drawn``: which of
    stability, classes, inferred, light, node-only, node-only-light and change appear; ``change``: the words of the
    change hatch, :func:`stabmap.read.plot.marks.change_text`)."""

    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [class_patch(v, system) for v in present]
    if drawn["stability"]:
        handles.append(Line2D([], [], color=BOUNDARY, lw=1.5, label="stability boundary"))
    if drawn["classes"]:
        handles.append(Line2D([], [], color=CLASS_EDGE, lw=0.6, label=f"{mathtext(system.label_symbol)} changes"))
    if drawn["inferred"] and not drawn["light"]:
        handles.append(Patch(facecolor="white", edgecolor="#00000066", lw=0, hatch=HATCH_INFERRED,
                             label="inferred from cell\ncorners (not computed)"))
    elif drawn["inferred"]:
        handles.append(Patch(facecolor="#DDDDDD", edgecolor="none", label="lighter: inferred from cell\ncorners (not computed)"))
    if drawn["node-only"] and not drawn["node-only-light"]:
        handles.append(Patch(facecolor="white", edgecolor="#00000066", lw=0, hatch=HATCH_NODE_ONLY,
                             label="proved at the grid node,\nnot over its cell"))
    elif drawn["node-only"]:
        handles.append(Patch(facecolor="#DDDDDD", edgecolor="none", label="lighter: proved at the grid\nnode, not over its cell"))
    if drawn["change"]:
        words = textwrap.fill(change, 26, break_on_hyphens=False)  # as wide as the entries above
        handles.append(Patch(facecolor="white", edgecolor=CHANGE_INK, lw=0, hatch=HATCH_CHANGE, label=words))
    return handles
