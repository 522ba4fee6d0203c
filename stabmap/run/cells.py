"""Atlases decided cell by cell: large boxes proved first, nodes computed only where no box proves.

A grid node's **cell** is the box between the midpoints to its neighbours along every scanned axis (the scan's
first and last values close the outermost cells), so the cells tile the scanned box (``cell_edges``: the CF
bounds of ``stabmap.store.dataset``).  Along a discrete axis (``Axis.discrete``: listed, separate cases) a cell is
the node's value alone.  Every chunk of an atlas is decided here (``decide_chunk``):

1. The grid is cut into **tiles** of up to TILE_CELLS cells (``tile_shape``, fixed by the grid alone; one value
   along a discrete axis); a chunk holds whole tiles (``stabmap.run.chunks.chunk_shape``), and each tile is
   decided on its own, so the file is the same whatever the chunks, threads or workers.  Each tile's cells, taken
   together as one box, go to ``System.prove_boxes``.  A proved box gives its label to every node inside it and
   ``whole_cell`` to every cell: no node of it is computed.
2. A box that does not prove is split in two along each of its long axes (those with at least half as many cells
   as its longest), or along the one axis the system names (``System.prove_and_cut_boxes``: for gyroscopes, the
   axis along which its corners' polynomials moved most), and its parts are tried in the next round, down to
   single cells.  The rounds run all the chunk's boxes of one round in one call of the kernels.
3. A single cell that does not prove has its node computed (``System.evaluate``).  Where two neighbouring nodes of
   a tile have other labels, the label at the point where the segment between them crosses their cells' shared
   face differs from one of them at least: that node's cell holds a change of label (``contains_change``).
   Otherwise a cell whose own box failed is cut at its node into sub-boxes, proved in up to SUB_ROUNDS rounds of
   halving: all proved with the node's label is ``whole_cell``, one proved with another label is
   ``contains_change``, and anything left undecided is ``node_only``: the node is proved, the rest of the cell
   is not.

Everything beyond the nodes is paid from each tile's credit (SPARE, plus what its proved boxes saved), so that a
cell-by-cell atlas never costs much more than a node-by-node one; box proofs also stop where they fail broadly
(PAYS).  What the credit leaves is ``node_only``, never guessed.

No label is inferred: every node's label is a box proof that holds it, or its own computation.  A system that
proves no boxes along some scanned axis gives ``node_only`` cells, every node computed.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from .. import systems
from ..store.dataset import bounds
from ..store.variables import CELL
from ..systems.base import SceneBase
from ..systems.stages import CELLS, stage

SUB_ROUNDS = 2  # rounds of halving inside one cell before it is left node_only
# Box proofs stop where they fail broadly (clustered roots, say): a round of at least PAYS_MIN boxes of at most
# PAYS_CELLS cells each, of which under PAYS prove, is the last; its boxes' nodes are then computed, and its cells
# left node_only.  Larger boxes fail for their size alone (roots move past the separators), so they never stop it.
PAYS, PAYS_MIN, PAYS_CELLS = 0.25, 32, 4
# What a tile may spend beyond its nodes, in node proofs (``System.box_cost`` prices a box; a label at a point
# between nodes costs one): SPARE a cell, plus one for every cell its boxes proved whole (a node it need not
# compute).  So a tile never costs more than 1 + SPARE times its nodes computed one by one, whether its boxes
# prove or not, and where they prove it goes on trying them.  Boxes leave RESERVE a cell of it to the labels that
# prove a change in the cells beside one (``_Chunk.classify``), which need the nodes' labels and so come last.
SPARE, RESERVE = 0.2, 0.05
TILE_CELLS = 1024  # cells of a tile: 1024 along one axis, 32 x 32, 8 x 8 x 8 (a power of two along every axis)

NODE_ONLY, WHOLE_CELL, CONTAINS_CHANGE = (CELL.value(m) for m in ("node_only", "whole_cell", "contains_change"))


def provable(scene: SceneBase) -> bool:
    """Whether the cells of ``scene``'s grid can be proved: its system proves boxes along every axis the cells span
    (``Axis.continuous``; a discrete axis is a set of separate cases, each a point of every cell)."""
    system = systems.of(scene)
    moving = {a.name for a in scene.grid if a.continuous}
    return bool(moving) and moving <= set(system.box_axes(scene))


def tile_shape(scene: SceneBase) -> tuple[int, ...]:
    """Cells of a tile along each grid axis: the same power of two along every axis the cells span (TILE_CELLS in
    all), 1 along a discrete axis or one of one value, so that no box spans two cases."""
    moving = [a.continuous for a in scene.grid]
    side = 2 ** int(math.log2(TILE_CELLS) // max(1, sum(moving)))
    return tuple(side if m else 1 for m in moving)


def cell_edges(axis) -> tuple[np.ndarray, np.ndarray]:
    """The lower and upper edge of each grid cell along ``axis`` (its CF bounds, in the axis's order)."""
    b = bounds(axis.array, bool(axis.discrete))
    return b[:, 0].copy(), b[:, 1].copy()


def decide_chunk(scene: SceneBase, location: tuple[tuple[int, int], ...], evaluate, order: tuple[int, ...]) -> dict[str, np.ndarray]:
    """Every variable (and ``cell``) on the chunk ``location`` = ((start, stop) per grid axis), in grid order.

    ``evaluate(values)`` decides points given by 1-D arrays of grid-axis values (``System.evaluate``); the nodes
    it gets vary fastest along the last axes of ``order`` (``stabmap.run.tasks.point_order``).
    """
    system = systems.of(scene)
    shape = tuple(b - a for a, b in location)
    chunk = _Chunk(scene, location)
    extra = system.dims(scene)
    out = {v.name: np.empty(shape + tuple(extra[d] for d in v.dims), dtype=v.dtype) for v in system.outputs(scene)}
    label = np.zeros(shape, dtype=out[system.label].dtype)
    cell = np.full(shape, NODE_ONLY, dtype=CELL.dtype)
    known = np.zeros(shape, dtype=bool)
    failed_cell = np.zeros(shape, dtype=bool)  # single cells whose own box was tried and failed

    lo, hi = chunk.tiles()
    with stage(CELLS):
        while lo.shape[0] and chunk.provable:
            tile = chunk.tile_of(lo)
            got, proved, tried, along = chunk.prove(lo, hi, tile)
            chunk.credit += np.bincount(tile[proved], weights=np.prod(hi - lo, axis=1)[proved], minlength=chunk.credit.size)
            for b in np.flatnonzero(proved):
                where = tuple(slice(a, z) for a, z in zip(lo[b], hi[b], strict=True))
                label[where], cell[where], known[where] = got[b], WHOLE_CELL, True
            one = np.all(hi - lo == 1, axis=1)
            failed_cell[tuple(lo[one & tried & ~proved].T)] = True
            small = np.prod(hi - lo, axis=1) <= PAYS_CELLS
            chunk.stop(tile, tried, proved, small)
            go = ~proved & ~one & ~chunk.stopped[tile]
            lo, hi = _halves(lo[go], hi[go], along[go])

    if known.any():
        for k, v in system.proved_box(label[known]).items():
            if k in out:  # an output the scene left out (System.outputs)
                out[k][known] = v
        # what the system computes at such nodes given their proved label (cheaper than deciding them)
        for k, v in (system.at_proved_nodes(scene, chunk.values(np.argwhere(known)), label[known]) or {}).items():
            out[k][known] = v
        out[system.label][known] = label[known]
    # Nodes no box holds: computed, in the order the kernels are quickest on, then their cells classified.
    nodes = np.argwhere(~known)
    if nodes.size:
        nodes = nodes[np.lexsort([nodes[:, d] for d in reversed(order)])]
        where = tuple(nodes.T)
        computed = evaluate(chunk.values(nodes))
        for k, v in computed.items():
            out[k][where] = v
        label[where] = computed[system.label]
        sub_boxes = failed_cell[where] & ~chunk.stopped[chunk.tile_of(nodes)]
        with stage(CELLS):
            cell[where] = chunk.classify(nodes, label, sub_boxes)
    out[CELL.name] = cell
    return out


def _pairs_beside_change(label: np.ndarray, nodes: np.ndarray, tile: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pairs of neighbouring nodes in one tile (``tile``: each index's tile along its axis) with other labels, one
    of them among ``nodes`` (rows of indices into ``label``), each pair once: (lower node, upper node, axis)."""
    lows, axes = [], []
    for d in range(label.ndim):
        for step in (-1, 1):
            other = nodes.copy()
            other[:, d] += step
            inside = (other[:, d] >= 0) & (other[:, d] < label.shape[d])
            inside[inside] &= tile[d][other[inside, d]] == tile[d][nodes[inside, d]]
            differ = np.zeros(nodes.shape[0], dtype=bool)
            differ[inside] = label[tuple(other[inside].T)] != label[tuple(nodes[inside].T)]
            lows.append(np.minimum(nodes[differ], other[differ]))
            axes.append(np.full(int(differ.sum()), d, dtype=np.int64))
    low, axis = np.concatenate(lows), np.concatenate(axes)
    if low.shape[0]:
        key = np.unique(np.column_stack([low, axis]), axis=0)
        low, axis = key[:, :-1], key[:, -1]
    high = low.copy()
    high[np.arange(low.shape[0]), axis] += 1
    return low, high, axis


def _halves(lo: np.ndarray, hi: np.ndarray, along: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Boxes (rows of index ranges [lo, hi)) cut in two along their long axes among those ``along`` allows (rows
    of bools; all if None, or if it allows none of more than one cell): those holding at least half as many cells
    as the longest (a chunk's long, thin boxes become square before they are cut across)."""
    if lo.shape[0] == 0:
        return lo, hi
    d = lo.shape[1]
    mid = (lo + hi) // 2
    size = hi - lo
    if along is None:
        along = np.ones(size.shape, dtype=bool)
    along = along & (size > 1)
    along[~along.any(axis=1)] = True
    size_along = np.where(along, size, 0)
    split = along & (size > 1) & (2 * size >= size_along.max(axis=1, keepdims=True))
    out_lo, out_hi = [], []
    for side in itertools.product((0, 1), repeat=d):
        side = np.array(side, dtype=bool)
        keep = np.all(split | ~side, axis=1)  # the upper half only along axes that split
        out_lo.append(np.where(side, mid, lo)[keep])
        out_hi.append(np.where(side | ~split, hi, mid)[keep])
    return np.concatenate(out_lo), np.concatenate(out_hi)


class _Chunk:
    """The grid axes of one chunk: node values, cell edges, and boxes between them handed to the system."""

    def __init__(self, scene: SceneBase, location):
        self.scene, self.system = scene, systems.of(scene)
        self.names = [a.name for a in scene.grid]
        self.nodes = [a.array[s:e] for a, (s, e) in zip(scene.grid, location, strict=True)]
        # each cell's two edges per axis (equal along a discrete axis): a box of cells [lo, hi) spans lower[lo] to upper[hi - 1]
        cut = [cell_edges(a) for a in scene.grid]
        self.lower = [lo[s:e] for (lo, _), (s, e) in zip(cut, location, strict=True)]
        self.upper = [hi[s:e] for (_, hi), (s, e) in zip(cut, location, strict=True)]
        self.spans = np.array([a.continuous for a in scene.grid], dtype=bool)
        self.provable = provable(scene)
        self.cost = self.system.box_cost(scene) if self.provable else 1.0
        self.cheap = self.system.cheap_box_cost(scene) if self.provable else 0.0  # 0: no cheap proof first
        # tiles: index along each axis of the chunk's cells; tiles numbered in C order of the chunk's tile grid
        size = tile_shape(scene)
        self.axis_tile = [(np.arange(s, e) // t) - s // t for (s, e), t in zip(location, size, strict=True)]
        self.tile_grid = tuple(int(a[-1]) + 1 for a in self.axis_tile)
        starts = [np.flatnonzero(np.diff(a, prepend=-1)) for a in self.axis_tile]
        stops = [np.append(st[1:], len(a)) for st, a in zip(starts, self.axis_tile, strict=True)]
        self._tiles = (np.array(list(itertools.product(*starts)), dtype=np.int64).reshape(-1, len(location)),
                       np.array(list(itertools.product(*stops)), dtype=np.int64).reshape(-1, len(location)))
        cells = np.prod(self._tiles[1] - self._tiles[0], axis=1)
        self.credit = SPARE * cells.astype(np.float64)  # per tile, in node proofs (SPARE)
        self.reserve = RESERVE * cells.astype(np.float64)  # credit that only the labels beside a change may spend
        self.stopped = np.zeros(cells.size, dtype=bool)

    def tiles(self) -> tuple[np.ndarray, np.ndarray]:
        """The chunk's tiles as boxes of cells [lo, hi) (chunk indices), numbered as ``tile_of`` numbers them."""
        return self._tiles[0].copy(), self._tiles[1].copy()

    def tile_of(self, index: np.ndarray) -> np.ndarray:
        """The tile of each row of chunk indices (a box's lower corner, or a node)."""
        if index.shape[0] == 0:
            return np.zeros(0, dtype=np.int64)
        return np.ravel_multi_index(tuple(self.axis_tile[d][index[:, d]] for d in range(index.shape[1])), self.tile_grid)

    def stop(self, tile: np.ndarray, tried: np.ndarray, proved: np.ndarray, small: np.ndarray) -> None:
        """Stop the tiles whose budget ran out in this round, or whose small boxes failed broadly (PAYS)."""
        n = self.stopped.size
        self.stopped |= np.bincount(tile[~tried], minlength=n) > 0
        attempts = np.bincount(tile[tried & small], minlength=n)
        wins = np.bincount(tile[tried & small & proved], minlength=n)
        self.stopped |= (attempts >= PAYS_MIN) & (wins < PAYS * attempts)

    def afford(self, tile: np.ndarray, cost: float, keep: np.ndarray | None = None) -> np.ndarray:
        """Which of several proofs, each of ``cost`` node proofs in the tiles ``tile``, their tiles' credit (less
        ``keep``, per tile) pays for (the k-th of a tile, in the given order, if it pays for k), charged to it."""
        order = np.argsort(tile, kind="stable")
        first = np.searchsorted(tile[order], tile[order], side="left")
        rank = np.empty(tile.size, dtype=np.int64)
        rank[order] = np.arange(tile.size) - first
        paid = (rank + 1) * cost <= self.credit[tile] - (0.0 if keep is None else keep[tile])
        self.credit -= cost * np.bincount(tile[paid], minlength=self.credit.size)
        return paid

    def values(self, index: np.ndarray) -> dict[str, np.ndarray]:
        """Grid-axis values of the nodes ``index`` (rows of chunk indices)."""
        return {name: v[index[:, d]] for d, (name, v) in enumerate(zip(self.names, self.nodes, strict=True))}

    def prove(self, lo: np.ndarray, hi: np.ndarray, tile: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(label, proved, tried, along) of the boxes of cells [lo, hi) (chunk indices per axis) in the tiles ``tile``
        (``tile_of(lo)``), each tried while its tile's budget lasts (in the given order within a tile); along (boxes,
        axes): the axes a box not proved is worth cutting along (``System.prove_and_cut_boxes``)."""
        return self._prove({n: e[lo[:, d]] for d, (n, e) in enumerate(zip(self.names, self.lower, strict=True))},
                           {n: e[hi[:, d] - 1] for d, (n, e) in enumerate(zip(self.names, self.upper, strict=True))}, tile)

    def _prove(self, lower: dict, upper: dict, tile: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        npts = tile.size
        label, proved = np.zeros(npts, dtype=np.int64), np.zeros(npts, dtype=bool)
        tried = np.zeros(npts, dtype=bool)
        along = np.ones((npts, len(self.names)), dtype=bool)
        if not self.provable or npts == 0:
            return label, proved, tried, along
        left = np.ones(npts, dtype=bool)  # boxes for the full proof
        if self.cheap > 0.0:
            # the cheap proof first, each box charged its price; those it leaves pay the full price on top
            tried = self.afford(tile, self.cheap, self.reserve)
            rows = np.flatnonzero(tried)
            if rows.size:
                # one batch a tile: a box steered by its neighbour's proof only within its tile, so that what a tile
                # proves does not depend on the chunk it lies in (System.prove_boxes_cheaply)
                got, ok = self.system.prove_boxes_cheaply(self.scene, {k: v[rows] for k, v in lower.items()},
                                                          {k: v[rows] for k, v in upper.items()}, tile[rows])
                label[rows], proved[rows] = got, ok
            left = tried & ~proved
        full = np.zeros(npts, dtype=bool)
        full[left] = self.afford(tile[left], self.cost, self.reserve)
        rows = np.flatnonzero(full)
        if rows.size:
            got, ok, cut = self.system.prove_and_cut_boxes(self.scene, {k: v[rows] for k, v in lower.items()},
                                                           {k: v[rows] for k, v in upper.items()})
            label[rows], proved[rows] = got, ok
            for d, name in enumerate(self.names):
                along[rows, d] = cut[name]
        # tried: every proof the box has was paid (a box the cheap proof left, with no credit for the full one, was not)
        return label, proved, proved | full, along

    def classify(self, nodes: np.ndarray, label: np.ndarray, sub_boxes: np.ndarray) -> np.ndarray:
        """The ``cell`` flag of the cells of ``nodes`` (computed; ``label`` holds the chunk's labels), none proved whole.

        Corners are computed for the cells beside a change of label; sub-boxes are tried in the cells marked in
        ``sub_boxes`` (those whose own box failed where box proofs pay).
        """
        cell = np.full(nodes.shape[0], NODE_ONLY, dtype=CELL.dtype)
        if not self.provable:
            return cell
        node_label = label[tuple(nodes.T)]
        tile = self.tile_of(nodes)
        # A change between two neighbouring nodes lies on the segment joining them, which crosses their shared face
        # at one point: its label differs from one node's at least, and proves a change in that node's cell.  One
        # label a pair of neighbours (a cell's corners would take 2^d, each shared by fewer cells).
        a, b, axis = _pairs_beside_change(label, nodes, self.axis_tile)
        paid = self.afford(self.tile_of(a), 1.0)
        self.reserve[:] = 0.0  # spent or not, what is left now pays for sub-boxes
        a, b, axis = a[paid], b[paid], axis[paid]
        if a.size:
            face = np.column_stack([self.nodes[k][a[:, k]] for k in range(len(self.names))])
            rows = np.arange(a.shape[0])
            face[rows, axis] = np.array([self.upper[k][a[r, k]] for r, k in zip(rows, axis, strict=True)])
            at = {n: face[:, k] for k, n in enumerate(self.names)}
            mid = self.system.evaluate(self.system.labels_only(self.scene), at)[self.system.label].reshape(-1)
            changed = np.zeros(label.shape, dtype=bool)
            for side in (a, b):
                other = mid != label[tuple(side.T)]
                changed[tuple(side[other].T)] = True
            cell[changed[tuple(nodes.T)]] = CONTAINS_CHANGE
        # Sub-boxes between the node and the cell's edges, halved while they fail and pay.
        todo = np.flatnonzero(sub_boxes & (cell == NODE_ONLY))
        lower, upper, owner = self._sub_boxes(nodes[todo], todo)
        whole = np.zeros(nodes.shape[0], dtype=bool)
        whole[todo] = True
        for _ in range(SUB_ROUNDS):
            if owner.size == 0:
                break
            got, proved, tried, _ = self._prove(lower, upper, tile[owner])
            other = proved & (got != node_label[owner])
            cell[owner[other]] = CONTAINS_CHANGE
            failed = ~proved
            self.stop(tile[owner], tried, proved, np.ones(owner.size, dtype=bool))
            go = failed & tried & ~self.stopped[tile[owner]]
            whole[owner[failed & ~go]] = False  # undecided, and not tried further
            lower, upper, owner = self._halve({k: v[go] for k, v in lower.items()},
                                              {k: v[go] for k, v in upper.items()}, owner[go])
        whole[owner] = False  # a sub-box still undecided after the last round
        cell[(cell == NODE_ONLY) & whole] = WHOLE_CELL
        return cell

    def _sides(self) -> list[np.ndarray]:
        """The corners of a cell as sides (0: lower edge, 1: upper) per axis, both only along the axes it spans."""
        return [np.array(s) for s in itertools.product(*[(0, 1) if spans else (0,) for spans in self.spans])]

    def _corner(self, nodes: np.ndarray, side: np.ndarray) -> np.ndarray:
        """The corner ``side`` of the cells of ``nodes``: grid-axis values, one column per axis."""
        return np.column_stack([(self.upper[k] if side[k] else self.lower[k])[nodes[:, k]] for k in range(len(self.names))])

    def _sub_boxes(self, nodes: np.ndarray, owner: np.ndarray):
        """The boxes between each node and its cell's corners (one per corner), with the cell that owns them."""
        lower: dict[str, list[np.ndarray]] = {n: [] for n in self.names}
        upper: dict[str, list[np.ndarray]] = {n: [] for n in self.names}
        owners = []
        for side in self._sides():
            corner = self._corner(nodes, side)
            for k, name in enumerate(self.names):
                node = self.nodes[k][nodes[:, k]]
                lower[name].append(np.minimum(node, corner[:, k]))
                upper[name].append(np.maximum(node, corner[:, k]))
            owners.append(owner)
        return ({k: np.concatenate(v) for k, v in lower.items()}, {k: np.concatenate(v) for k, v in upper.items()},
                np.concatenate(owners) if owners else owner)

    def _halve(self, lower: dict, upper: dict, owner: np.ndarray):
        """Boxes given by their corners, cut in two along every axis they span."""
        out_lo: dict[str, list[np.ndarray]] = {n: [] for n in self.names}
        out_hi: dict[str, list[np.ndarray]] = {n: [] for n in self.names}
        owners = []
        for side in itertools.product((0, 1), repeat=len(self.names)):
            keep = np.ones(owner.size, dtype=bool)
            for k, name in enumerate(self.names):
                spans = lower[name] != upper[name]
                keep &= spans | (side[k] == 0)
            for k, name in enumerate(self.names):
                a, b = lower[name][keep], upper[name][keep]
                m = 0.5 * a + 0.5 * b
                spans = a != b
                out_lo[name].append(np.where(spans & (side[k] == 1), m, a))
                out_hi[name].append(np.where(spans & (side[k] == 0), m, b))
            owners.append(owner[keep])
        return ({k: np.concatenate(v) for k, v in out_lo.items()}, {k: np.concatenate(v) for k, v in out_hi.items()},
                np.concatenate(owners))


__all__ = ["CONTAINS_CHANGE", "NODE_ONLY", "TILE_CELLS", "WHOLE_CELL", "decide_chunk", "provable", "tile_shape"]
