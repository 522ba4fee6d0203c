"""Adaptive atlases: decide a coarse lattice of the grid, refine only where cell corners disagree.

The result has the dense atlas's grid and values wherever the labels have no
feature that hides inside a grid cell (docs/refine.md says exactly what that
means).  Points that were filled from their cell's corners rather than computed
carry the provenance flag ``inferred_from_cell_corners`` (``decided_by`` of a gyroscope atlas): they are not
proved.

Algorithm, in index space of the final grid (any number of axes):

1. Axis i starts at a power-of-two stride s_i; its nodes are the multiples of
   the current stride plus its last index.  Consecutive nodes bound the cells,
   so a cell is a box with 2^d corners.  Every cell starts active.
2. At each level the corners of the active cells that are not yet computed are
   decided (in chunks, through the run's runner: threads here or a dask cluster).  A cell whose corners disagree, or
   one of whose corners turned out different from the value an earlier fill
   had given it, is *split*, and so is every cell within ``margin`` cells of
   it, whether active or filled before (a filled cell is re-opened).
3. Active cells that are not split are filled with their corners' value.
   Split cells' children, at half the stride, are the next level's active cells.
4. At stride 1 every point of a cell is a corner; re-opened cells are decided
   until no cell asks for another point.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass

import numpy as np

from .. import systems
from ..errors import StabmapError, given
from ..store.dataset import empty_arrays, finished_atlas
from ..store.variables import CELL
from ..systems.base import SceneBase
from . import costs, runner, sizes
from .atlas import decide_points
from .chunks import check_chunk_points
from .progress import ProgressLine, wanted
from .tasks import evaluate_points, point_order

DEFAULT_MARGIN = 2  # cells split around a disagreeing cell; docs/refine.md has the measurements behind 2
COARSE_CELLS = 64  # default: the coarsest lattice has 64 to 127 cells (65 to 128 nodes) per long axis


def default_coarse_stride(n: int) -> int:
    """The largest power of two s with at least ``COARSE_CELLS`` cells of s steps along an axis of ``n`` points."""
    cells = (n - 1) // COARSE_CELLS
    return 1 << (cells.bit_length() - 1) if cells >= 1 else 1


def check_coarse_stride(value) -> int | None:
    """Validate a user's coarse stride (None: choose per axis)."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise StabmapError(f"{given('coarse_stride', value)}: must be a whole power of two such as 8 or 16")
    if value < 1 or value & (value - 1):
        lower = 1 << (max(1, int(value)).bit_length() - 1)
        raise StabmapError(
            f"{given('coarse_stride', value)}: must be a power of two (1, 2, 4, 8, 16, ...) so that "
            f"halving it reaches every grid point; use e.g. {lower} or {2 * lower}"
        )
    return int(value)


def check_margin(value) -> int:
    """Validate a safety margin in cells."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise StabmapError(f"{given('margin', value)}: must be a whole number of cells >= 0 (default 2; 0 and 1 are "
                           "cheaper and miss more)")
    return int(value)


@dataclass(frozen=True)
class _Level:
    """Nodes and cells of one refinement level of a box of grid points (per axis: node indices in the box)."""

    strides: tuple[int, ...]
    nodes: tuple[np.ndarray, ...]
    ncells: tuple[int, ...]

    @classmethod
    def build(cls, shape: tuple[int, ...], strides: tuple[int, ...]) -> _Level:
        nodes = []
        for n, t in zip(shape, strides, strict=True):
            idx = np.arange(0, n, t)
            if idx[-1] != n - 1:
                idx = np.append(idx, n - 1)
            nodes.append(idx)
        return cls(tuple(strides), tuple(nodes), tuple(max(1, idx.size - 1) for idx in nodes))

    @property
    def has_interior(self) -> bool:
        """Whether some cell holds points that are not its corners (only then is there anything to fill)."""
        return any(t > 1 for t in self.strides)

    def corners(self) -> list[tuple[slice, ...]]:
        """For each of the 2^d corners, the slice of the node lattice that gives it for every cell."""
        per_axis = []
        for idx, c in zip(self.nodes, self.ncells, strict=True):
            upper = slice(1, c + 1) if idx.size > 1 else slice(0, 1)  # a one-point axis: both corners coincide
            per_axis.append((slice(0, c), upper))
        return list(itertools.product(*per_axis))

    def at_nodes(self, grid_array: np.ndarray) -> np.ndarray:
        """The values of a grid array at the nodes (a view where every stride is 1)."""
        for axis, (idx, t) in enumerate(zip(self.nodes, self.strides, strict=True)):
            if t > 1:
                grid_array = np.take(grid_array, idx, axis=axis)
        return grid_array

    def on_grid(self, cell_array: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
        """A per-cell array spread over the grid points each cell owns (a point on a face goes to the upper cell)."""
        for axis, (n, t, c) in enumerate(zip(shape, self.strides, self.ncells, strict=True)):
            cell_array = np.take(cell_array, np.minimum(np.arange(n) // t, c - 1), axis=axis)
        return cell_array


def _any_corner(level: _Level, node_mask: np.ndarray) -> np.ndarray:
    """Cells with at least one corner in ``node_mask``."""
    out = np.zeros(level.ncells, dtype=bool)
    for sl in level.corners():
        out |= node_mask[sl]
    return out


def _corner_range(level: _Level, node_values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Smallest and largest corner value of every cell."""
    lo = hi = None
    for sl in level.corners():
        v = node_values[sl]
        lo = v.copy() if lo is None else np.minimum(lo, v)
        hi = v.copy() if hi is None else np.maximum(hi, v)
    return lo, hi


def _dilate(mask: np.ndarray, cells: int) -> np.ndarray:
    """Grow ``mask`` by ``cells`` in every direction, diagonals included (a box is separable by axis)."""
    for _ in range(cells):
        for axis in range(mask.ndim):
            grown = mask.copy()
            lower = [slice(None)] * mask.ndim
            upper = [slice(None)] * mask.ndim
            lower[axis], upper[axis] = slice(None, -1), slice(1, None)
            grown[tuple(upper)] |= mask[tuple(lower)]
            grown[tuple(lower)] |= mask[tuple(upper)]
            mask = grown
    return mask


def _children(split: np.ndarray, finer: _Level, halves: tuple[bool, ...]) -> np.ndarray:
    """Active cells of the next level: every child of a split cell (child k of an axis that halves has parent k // 2)."""
    for axis, (c, h) in enumerate(zip(finer.ncells, halves, strict=True)):
        if h:
            split = np.take(split, np.arange(c) // 2, axis=axis)
    return split


class _Progress(ProgressLine):
    """The refinement's progress line: level, points done, share of the dense grid evaluated."""

    def __init__(self, enabled: bool, total: int):
        super().__init__(enabled)
        self.total = total

    def update(self, stride: int, level_done: int, level_total: int, evaluated: int) -> None:
        pct = 100 * evaluated / max(1, self.total)
        self.show(
            f"[refine] stride {stride:>4}: {level_done:,}/{level_total:,} points | "
            f"evaluated {evaluated:,} = {pct:.1f} % of dense | {self.elapsed:.0f} s"
        )


class _Evaluator:
    """Decides grid points through the run's runner and holds the state of the whole grid."""

    def __init__(self, scene: SceneBase, run: runner.Runner, chunk_points: int | None, progress: _Progress):
        self.scene, self.run, self.chunk_points, self.progress = scene, run, chunk_points, progress
        self.system = systems.of(scene)
        shape = scene.shape
        self.arrays = empty_arrays(self.system, scene)
        self.label = self.arrays[self.system.label]
        self.label[...] = 0
        self.computed = np.zeros(shape, dtype=bool)
        self.filled = np.zeros(shape, dtype=bool)
        self.evaluated = 0
        self.order = point_order(scene)

    def evaluate(self, points: tuple[np.ndarray, ...], stride: int) -> np.ndarray:
        """Decide the grid points ``points`` (index arrays per axis); True where an earlier fill had it wrong."""
        shape = self.scene.shape
        flat = np.ravel_multi_index(points, shape)
        # Points in the order of a dense block (the system's fastest axes fastest), which its kernels may exploit.
        key = np.ravel_multi_index(tuple(points[d] for d in self.order), tuple(shape[d] for d in self.order))
        perm = np.argsort(key, kind="stable")
        results = self._decide(flat[perm], stride)
        label = results[self.system.label]
        wrong = np.zeros(flat.size, dtype=bool)
        wrong[perm] = self.filled.reshape(-1)[flat[perm]] & (self.label.reshape(-1)[flat[perm]] != label)
        for k, v in results.items():
            grid = self.arrays[k].reshape((-1,) + v.shape[1:])
            grid[flat[perm]] = v
        self.computed.reshape(-1)[flat] = True
        self.evaluated += flat.size
        return wrong

    def evaluate_point(self) -> None:
        """A scene without grid axes: its one point."""
        for k, v in evaluate_points(self.scene, {}).items():
            self.arrays[k][()] = v
        self.computed[()] = True
        self.evaluated = 1

    def finish(self) -> dict[str, np.ndarray]:
        """Every variable on the grid, the points not computed given the values their label implies."""
        rest = ~self.computed
        filled = self.system.inferred(self.label[rest])
        assert filled is not None  # compute_refined refuses a system without System.inferred before it starts
        for k, v in filled.items():
            if k in self.arrays:  # an output the scene left out (System.outputs)
                self.arrays[k][rest] = v
        self.arrays[CELL.name][...] = np.where(rest, CELL.value("not_proved"), CELL.value("node_only"))
        return self.arrays

    def _decide(self, flat: np.ndarray, stride: int) -> dict[str, np.ndarray]:
        idx = np.unravel_index(flat, self.scene.shape)
        values = {axis.name: axis.array[i] for axis, i in zip(self.scene.grid, idx, strict=True)}
        npts, before = flat.size, self.evaluated

        def show(done):
            self.progress.update(stride, done, npts, before + done)

        return decide_points(self.run, self.scene, values, chunk_points=self.chunk_points, on_progress=show)


def _step(ev: _Evaluator, level: _Level, active: np.ndarray, margin: int, box: tuple[slice, ...]) -> np.ndarray:
    """One level on a box of the grid: decide the active cells' new corners, fill the cells that agree.

    Returns the cells to split: those whose corners disagree or include a point
    an earlier fill got wrong, grown by ``margin`` cells.
    """
    computed, label = ev.computed[box], ev.label[box]
    need = np.zeros(tuple(idx.size for idx in level.nodes), dtype=bool)
    for sl in level.corners():
        need[sl] |= active
    need &= ~level.at_nodes(computed)
    wrong = np.zeros(level.ncells, dtype=bool)
    if need.any():
        sel = np.nonzero(need)
        points = tuple(idx[s] + b.start for idx, s, b in zip(level.nodes, sel, box, strict=True))
        bad = ev.evaluate(points, max(level.strides))
        if bad.any():
            wrong_nodes = np.zeros(need.shape, dtype=bool)
            wrong_nodes[tuple(s[bad] for s in sel)] = True
            wrong = _any_corner(level, wrong_nodes)
    lo, hi = _corner_range(level, level.at_nodes(label))
    split = _dilate((active & (lo != hi)) | wrong, margin)
    if level.has_interior:
        mask = level.on_grid(active & ~split, label.shape) & ~computed
        label[mask] = level.on_grid(lo, label.shape)[mask]
        ev.filled[box] |= mask
    return split


def _run_levels(ev: _Evaluator, strides: tuple[int, ...], margin: int) -> None:
    """The refinement loop (module docstring, steps 1-3) from the coarse strides down to stride 1."""
    shape = ev.scene.shape
    whole = tuple(slice(0, n) for n in shape)
    t = max(strides)
    level = _Level.build(shape, tuple(min(t, s) for s in strides))
    active = np.ones(level.ncells, dtype=bool)
    while True:
        split = _step(ev, level, active, margin, whole)
        if t == 1:
            return _reopen(ev, level, split, margin)
        t //= 2
        finer = _Level.build(shape, tuple(min(t, s) for s in strides))
        active = _children(split, finer, tuple(t < s for s in strides))
        level = finer


def _reopen(ev: _Evaluator, level: _Level, split: np.ndarray, margin: int) -> None:
    """Step 4: at stride 1, decide the points of re-opened cells until no cell asks for another.

    Each round works on the bounding box of the cells still asking, so following
    a boundary that the coarse levels missed costs little per step.
    """
    shape = ev.scene.shape
    active = split & _any_corner(level, ~ev.computed)
    while active.any():
        cell_slices, point_slices = [], []
        for axis, n in enumerate(shape):
            hit = np.flatnonzero(np.any(active, axis=tuple(a for a in range(active.ndim) if a != axis)))
            # margin + 1: a cell next to an active one can be wrong, and the margin grows from there.
            c0, c1 = max(0, hit[0] - margin - 1), min(active.shape[axis], hit[-1] + 2 + margin)
            cell_slices.append(slice(c0, c1))
            point_slices.append(slice(c0, min(n, c1 + 1)))
        cells, points = tuple(cell_slices), tuple(point_slices)
        sub = _Level.build(tuple(p.stop - p.start for p in points), (1,) * len(shape))
        again = _step(ev, sub, active[cells], margin, points)
        active = np.zeros_like(active)
        active[cells] = again & _any_corner(sub, ~ev.computed[points])


def compute_refined(
    scene: SceneBase,
    *,
    coarse_stride: int | None = None,
    margin: int = DEFAULT_MARGIN,
    client=None,
    workers: int | None = None,
    threads: int | None = None,
    progress: bool | None = None,
    chunk_points: int | None = None,
):
    """Compute the atlas of ``scene`` adaptively: coarse lattice first, refined where labels change.

    The Dataset has the same grid, variables and layout as ``compute_atlas``.
    Computed points carry their proof in the system's provenance flag; points filled from
    their cell's corners say ``inferred_from_cell_corners`` there (``System.inferred``).
    The result equals the dense atlas unless a feature (a region of another label)
    lies inside a cell whose corners agree and comes within ``margin`` cells of
    no disagreeing cell: see docs/refine.md.

    Parameters
    ----------
    scene : Scene
        Bodies, support and grid; a scene without grid is its one point, computed.
    coarse_stride : int, optional
        Grid steps between coarse nodes along every axis, a power of two. Default:
        per axis, the largest power of two that leaves at least 64 coarse cells
        (1 for axes of fewer than 129 points: no inference along them).
    margin : int, optional
        Cells around every disagreeing cell that are split too (default 2; 0 and
        1 are cheaper and miss more of the features smaller than a cell).
    client, workers, threads, progress, chunk_points
        As for ``compute_atlas``: each level's points are decided in tasks of about half a second on
        threads here (default), a cluster (``client``) or a local cluster of ``workers`` processes.

    Returns
    -------
    xarray.Dataset
        As ``compute_atlas``, with attributes ``refine_coarse_stride`` (per axis),
        ``refine_margin`` and ``n_evaluated_points`` (characteristic polynomials evaluated).
    """
    coarse_stride = check_coarse_stride(coarse_stride)
    margin = check_margin(margin)
    chunk_points = check_chunk_points(chunk_points)
    system = systems.of(scene)
    if system.inferred(np.zeros(0, dtype=np.int64)) is None:  # the system cannot say what a filled point holds
        raise StabmapError(f"adaptive refinement is not available for {system.name} atlases (the system infers no labels "
                           "from cell corners: System.inferred); compute a dense one")
    sizes.check_memory(sizes.of(scene), "an adaptive atlas, held in memory,")
    shape = scene.shape
    strides = tuple(coarse_stride or default_coarse_stride(n) for n in shape)
    total = math.prod(shape)
    t0 = time.perf_counter()
    bar = _Progress(wanted(progress), total)
    try:
        with runner.start(client, workers=workers, threads=threads, announce=bar.enabled) as run:
            spent = costs.Costs(run, costs.columns(system), t0)
            ev = _Evaluator(scene, run, chunk_points, bar)
            if shape:
                _run_levels(ev, strides, margin)
            else:
                ev.evaluate_point()
    finally:
        bar.close()
    seconds = spent.take()
    del seconds[costs.WRITE]  # written later, by the caller
    ds = finished_atlas(system, scene, ev.finish())
    ds.attrs.update(costs.attrs(seconds, run.most_threads))
    ds.attrs["history"] += (
        f"; adaptive refinement (coarse stride {list(strides)}, margin {margin}): "
        f"{ev.evaluated} of {total} points evaluated in {time.perf_counter() - t0:.1f} s"
    )
    ds.attrs["refine_coarse_stride"] = np.array(strides, dtype=np.int32)
    ds.attrs["refine_margin"] = np.int32(margin)
    ds.attrs["n_evaluated_points"] = np.int64(ev.evaluated)
    # The file says at the top that some of its labels are not proved (cell = not_proved marks which).
    ds.attrs["stabmap_inferred_labels"] = np.int64(total - ev.evaluated)
    return ds
