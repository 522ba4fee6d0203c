"""The frames of an atlas page: for each slider setting, the map of the two drawn axes read once (chunk by chunk
for a lazy atlas), reduced to blocks no smaller than a screen pixel (:func:`stabmap.read.blocks.reduce_blocks`),
with its blocks' states and its boundaries on cell edges, as the PNG maps draw them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from ..blocks import block_factors, compute, reduce_blocks
from ..plot.geometry import block_classes, block_edges, boundary_widths, cell_edge_boundaries, proved_cell_edges
from ..plot.labels import log_axis
from .plan import PagePlan
from .states import Legend, block_colours, pack

MAP_PIXELS = (450, 600)  # (y, x) pixels of the page's map: blocks are no smaller than one
EAGER_POINTS = 4_000_000  # a frame's map of at most this many points is read at once (a few MB), a larger one chunk by chunk
WIDEST = {"stability": 2.5, "classes": 1.0}  # [px] boundary widths between wide regions (narrower beside thin bands)


@dataclass(frozen=True)
class Frame:
    """One slider setting: every block's packed state (rows along y), the label's counts, the rectangles of one
    colour that draw the blocks (rows c0, c1, r0, r1, colour: block columns [c0, c1) and rows [r0, r1)), the
    boundary segments as columns x0, y0, x1, y1, width [px] (float32), thick (stability) and thin (other classes),
    and the marks drawn beside the classes (:func:`.states.block_colours`), for the legend."""

    keys: np.ndarray
    counts: dict[int, int]
    rects: np.ndarray
    stability: np.ndarray
    classes: np.ndarray
    marks: frozenset[str] = frozenset()

    @property
    def drawn(self) -> frozenset[str]:
        """Every legend entry this frame needs beyond its classes: its marks and its kinds of boundary."""
        lines = {name for name, segs in (("stability", self.stability), ("classes", self.classes)) if len(segs)}
        return self.marks | lines


@dataclass(frozen=True)
class MapGrid:
    """The drawn grid: block ``factors`` (y, x), block edges ``xe`` and ``ye`` in data coordinates (a strip's y runs
    from 0 to 1) and which of x, y are drawn on a log scale."""

    factors: tuple[int, int]
    xe: np.ndarray
    ye: np.ndarray
    log: tuple[bool, bool]

    @property
    def shape(self) -> tuple[int, int]:
        return len(self.ye) - 1, len(self.xe) - 1


def map_grid(ds: xr.Dataset, plan: PagePlan, pixels: tuple[int, int] = MAP_PIXELS) -> MapGrid:
    """Blocks of the drawn axes no smaller than a pixel of a map ``pixels`` (y, x) in size, and their edges."""
    shape = (ds.sizes[plan.y] if plan.y else 1, ds.sizes[plan.x])
    factors = block_factors(shape, pixels if plan.y else (1, pixels[1]))
    log = (log_axis(ds, plan.x), plan.y is not None and log_axis(ds, plan.y))
    xe = block_edges(proved_cell_edges(np.asarray(ds[plan.x], dtype=float), log[0]), factors[1])
    ye = block_edges(proved_cell_edges(np.asarray(ds[plan.y], dtype=float), log[1]), factors[0]) if plan.y else np.array([0.0, 1.0])
    return MapGrid(factors, xe, ye, log)


def colour_rectangles(colours: np.ndarray) -> np.ndarray:
    """The blocks of a map (``colours``: colour id per block, rows along y) as few rectangles of one colour, rows
    (c0, c1, r0, r1, colour): the runs of one colour along each row, merged with identical runs of the rows above.
    Drawn as one quad each, neighbouring blocks of one colour show no seam between them."""
    ny, nx = colours.shape
    done: list[tuple[int, int, int, int, int]] = []
    open_: dict[tuple[int, int, int], int] = {}  # (c0, c1, colour) of a run open since row r0
    for r in range(ny):
        row = colours[r]
        cuts = np.flatnonzero(row[1:] != row[:-1]) + 1
        now = {}
        for a, b in zip(np.r_[0, cuts], np.r_[cuts, nx], strict=True):
            key = (int(a), int(b), int(row[a]))
            now[key] = open_.pop(key, r)
        done.extend((a, b, r0, r, c) for (a, b, c), r0 in open_.items())
        open_ = now
    done.extend((a, b, r0, ny, c) for (a, b, c), r0 in open_.items())
    return np.array(done, dtype=np.int32).reshape(-1, 5)


def frame_map(da: xr.DataArray, plan: PagePlan, at: dict[str, int]):
    """``da`` at one slider setting ``at`` (fixed axes already selected), as (y, x); a strip as (1, x); lazy."""
    a = da.isel(at).transpose(*((plan.y, plan.x) if plan.y else (plan.x,))).data
    return a if plan.y else a[None, :]


def segments_table(segs: np.ndarray, grid: MapGrid, codes: np.ndarray, widest: float, pixels: tuple[int, int]) -> np.ndarray:
    """Boundary segments as rows (x0, y0, x1, y1, width [px]): widest, but a third of the narrower band beside."""
    widths = boundary_widths(segs, grid.xe, grid.ye, (float(pixels[0]), float(pixels[1])), widest, log=grid.log, codes=codes)
    return np.column_stack([segs.reshape(-1, 4), widths]).astype(np.float32)


def read_frame(label: xr.DataArray, bits: xr.DataArray | None, plan: PagePlan, at: dict[str, int], grid: MapGrid,
               legend: Legend, pixels: tuple[int, int] = MAP_PIXELS) -> Frame:
    """One frame: the map at slider setting ``at`` read once and reduced to ``grid``'s blocks, their states packed
    (colours registered in ``legend``), and the boundaries between blocks."""
    stable = legend.system.stable_label
    values, flags = frame_map(label, plan, at), None if bits is None else frame_map(bits, plan, at)
    if values.size <= EAGER_POINTS:  # one read of a small map, rather than a task graph for each of many small frames
        values, flags = compute(values, flags)
    blocks = reduce_blocks(values, flags, stable, grid.factors)
    colours, marks = block_colours(blocks, legend)
    codes, state = block_classes(blocks, stable)
    stab, other = cell_edge_boundaries(codes, grid.xe, grid.ye, stable, state=state)
    return Frame(pack(blocks, colours), dict(blocks.counts), colour_rectangles(colours),
                 segments_table(stab, grid, codes, WIDEST["stability"], pixels), segments_table(other, grid, codes, WIDEST["classes"], pixels),
                 frozenset(marks))
