"""The state of a block of grid points on a page: its lowest and highest label, whether it holds the stability
boundary, how its points were decided and what their cells prove, and the colour it is drawn in. A page stores
one small integer per block, an index into its table of distinct states, so that its size grows with the blocks
and not with the text shown on hover.

A state is packed into one int64 (:func:`pack`): the page gathers the distinct ones over every frame, then
writes each state's colour once (the colour mapper's palette, with a hatch per colour id) and its text once (the
hover's table).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ...store.variables import CELL, INFERRED
from ..plot.marks import CHANGE_INK, PAGE_HATCH
from ..plot.palette import BOUNDARY, CLASS_EDGE, system_colour
from .text import plain

CELL_SHIFT = 16  # provenance meanings take bits 0..15 of a point's bits, the meanings of ``cell`` the bits above
VEIL = 0.45  # share of white over a colour: "lighter" (a critical-values page's undecided gaps)
# The page's hatches (bokeh patterns) and their ink, as the PNG maps hatch (stabmap.read.plot.paint.hatch_cells): dots
# over cells proved at their node only, light diagonal lines over inferred ones, the change's dark lines.
NODE_ONLY_HATCH, INFERRED_HATCH, FAINT_INK = ".", "/", "#00000040"
HATCH_INK = {NODE_ONLY_HATCH: FAINT_INK, INFERRED_HATCH: FAINT_INK, PAGE_HATCH: CHANGE_INK}
CELL_TEXT = {
    "whole_cell": "the label holds at every point of the cell",
    "contains_change": "the cell is proved to hold a change of label (the label given is its grid point's)",
    "node_only": "proved at the grid node only, not over its cell",
    "not_proved": "not proved: inferred from the cell's corners",
}


def point_bits(ds: xr.Dataset, system) -> xr.DataArray | None:
    """Per grid point, lazily: bit p set for the p-th meaning of the system's provenance flag (``decided_by``), bit
    CELL_SHIFT + q for the q-th meaning of ``cell``; None for an atlas with neither variable. ORed over a block,
    the bits say every way its points were decided and every kind of cell it holds.

    One table look-up a variable (a value outside its flags gets no bit), so a lazy atlas's graph stays two
    operations deep however many meanings the flags have."""
    bits = None
    for name, var, shift in ((system.provenance, system.variable(system.provenance) if system.provenance else None, 0),
                             (CELL.name, CELL, CELL_SHIFT)):
        if var is None or name not in ds:
            continue
        values = np.array([v for v, _ in var.flags], dtype=np.int64)
        order = np.argsort(values)
        table = (np.int32(1) << (shift + np.arange(len(values), dtype=np.int32)))[order]
        term = xr.apply_ufunc(_look_up, ds[name], kwargs={"values": values[order], "table": table}, dask="parallelized",
                              output_dtypes=[np.int32])
        bits = term if bits is None else bits | term
    return bits


def _look_up(a: np.ndarray, *, values: np.ndarray, table: np.ndarray) -> np.ndarray:
    """``table[i]`` where ``a == values[i]`` (``values`` sorted), 0 elsewhere."""
    a = np.asarray(a, dtype=np.int64)
    i = np.clip(np.searchsorted(values, a), 0, len(values) - 1)
    return np.where(values[i] == a, table[i], np.int32(0)).astype(np.int32)


class Legend:
    """The fills a page draws, each numbered once: a colour and a hatch pattern ("" for none)."""

    def __init__(self, system, has_provenance: bool) -> None:
        self.system = system
        self.fills: list[tuple[str, str]] = []
        flags = system.variable(system.provenance).meanings if has_provenance else ()
        self.inferred_bit = (1 << flags.index(INFERRED)) if INFERRED in flags else 0

    def id(self, colour: str, hatch: str = "") -> int:
        if (colour, hatch) not in self.fills:
            self.fills.append((colour, hatch))
        return self.fills.index((colour, hatch))

    @property
    def colours(self) -> list[str]:
        """The colour of each id (the colour mapper's palette)."""
        return [c for c, _ in self.fills]

    @property
    def hatches(self) -> list[str]:
        """The hatch pattern of each id (bokeh's ``hatch_pattern``; "" for none)."""
        return [h for _, h in self.fills]

    @property
    def inks(self) -> list[str]:
        """The colour of each id's hatch (bokeh's ``hatch_color``)."""
        return [HATCH_INK.get(h, CHANGE_INK) for _, h in self.fills]


def lighter(colour: str) -> str:
    """``colour`` under a white veil of VEIL."""
    rgb = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)], dtype=float)
    return "#" + "".join(f"{int(round(c + VEIL * (255 - c))):02X}" for c in rgb)


def cell_bit(meaning: str) -> int:
    """The bit of a ``cell`` meaning in a point's bits."""
    return 1 << (CELL_SHIFT + CELL.meanings.index(meaning))


def block_colours(blocks, legend: Legend) -> tuple[np.ndarray, set[str]]:
    """The colour id of every block, as the PNG maps draw it: a block of one class in that class's colour (dotted
    where a cell is proved at its node only, hatched lightly where inferred, hatched dark where a cell is proved to
    hold a change, which wins where both are: the colour stays the grid points' label), a block of stable and
    unstable points black, other mixed blocks dark grey; and the marks drawn, for the legend ("inferred", "node-only", "change", "mixed-classes",
    "mixed-stability")."""
    system = legend.system
    low, mixed = blocks.low, blocks.low != blocks.high
    bits = np.zeros(low.shape, dtype=np.int64) if blocks.any_flag is None else blocks.any_flag.astype(np.int64)
    inferred = ((bits & legend.inferred_bit) > 0) | ((bits & cell_bit("not_proved")) > 0)
    node_only = ((bits & cell_bit("node_only")) > 0) & ~inferred
    change = ((bits & cell_bit("contains_change")) > 0) & ~mixed
    out = np.empty(low.shape, dtype=np.int64)
    for v in np.unique(low):
        base = system_colour(int(v), system)
        for hatch, at in ((PAGE_HATCH, change), (INFERRED_HATCH, inferred & ~change), (NODE_ONLY_HATCH, node_only & ~change),
                          ("", ~(change | inferred | node_only))):
            at = at & (low == v)
            if at.any():
                out[at] = legend.id(base, hatch)
    marks = {entry for mask, entry in ((inferred & ~mixed, "inferred"), (node_only & ~mixed, "node-only"), (change, "change"))
             if mask.any()}
    for mask, colour, entry in ((mixed & ~blocks.mixed_stability, CLASS_EDGE, "mixed-classes"),
                                (blocks.mixed_stability, BOUNDARY, "mixed-stability")):
        if mask.any():
            out[mask] = legend.id(colour)
            marks.add(entry)
    return out, marks


def pack(blocks, colour_ids: np.ndarray) -> np.ndarray:
    """Every block's state as one int64: low and high label (16 bits each), holds the stability boundary (1 bit),
    colour id (7 bits: a class may come plain, lighter, hatched and both), the ORed point bits (20 bits)."""
    low = (blocks.low.astype(np.int64) + 2**15) & 0xFFFF
    high = (blocks.high.astype(np.int64) + 2**15) & 0xFFFF
    bits = np.zeros(low.shape, dtype=np.int64) if blocks.any_flag is None else blocks.any_flag.astype(np.int64) & 0xFFFFF
    if colour_ids.max(initial=0) >= 128:
        raise ValueError("more than 128 fills on one page")
    return low | (high << 16) | (blocks.mixed_stability.astype(np.int64) << 32) | (colour_ids << 33) | (bits << 40)


def unpack(key: int) -> tuple[int, int, bool, int, int]:
    """low, high, holds the stability boundary, colour id, point bits of a packed state."""
    return ((key & 0xFFFF) - 2**15, ((key >> 16) & 0xFFFF) - 2**15, bool((key >> 32) & 1), int((key >> 33) & 127), int(key >> 40))


def state_text(key: int, system, has_provenance: bool, has_cell: bool) -> str:
    """What a block's state says on hover, in lines: its label and class, what decided it, what its cell proves."""
    low, high, boundary, _, bits = unpack(int(key))
    symbol = plain(system.label_symbol)
    if low == high:
        lines = [f"{symbol} = {low}: {system.class_name(low)}"]
    else:
        lines = [f"{symbol} from {low} to {high}: " + ("holds the stability boundary" if boundary else "holds several classes")]
    if has_provenance:
        var = system.variable(system.provenance)
        lines.append("decided by: " + ", ".join(m.replace("_", " ") for p, m in enumerate(var.meanings) if bits & (1 << p)))
    if has_cell:
        kinds = [m for q, m in enumerate(CELL.meanings) if bits & (1 << (CELL_SHIFT + q))]
        lines.append(("cell: " if len(kinds) == 1 else "cells: ") + "; ".join(f"{k.replace('_', ' ')}, {CELL_TEXT.get(k, k)}" for k in kinds))
    return "\n".join(lines)
