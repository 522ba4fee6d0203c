"""Atlases decided cell by cell: large boxes proved first, nodes computed only where no box proves.

A grid node's **cell** is the box between the midpoints to its neighbours along every axis (the scan's first
and last values close the outermost cells), so the cells tile the scanned box (``stabmap.scene.grid.edges``).  Every chunk of an
atlas is decided here (``decide_chunk``):

1. The chunk's cells, taken together as one box, go to ``System.prove_boxes``.  A proved box gives its label to
   every node inside it and ``whole_cell`` to every cell: no node of it is computed.
2. A box that does not prove is split in two along each axis it spans with more than one cell, and its parts
   are tried in the next round, down to single cells.  The rounds run all the chunk's boxes of one size in one
   call of the kernels.
3. A single cell that does not prove has its node computed (``System.evaluate``), and then its corners.  A
   corner with another label proves a change of label in the cell (``contains_change``).  Otherwise the cell
   is cut at its node into sub-boxes, proved in up to SUB_ROUNDS rounds of halving: all proved with the
   node's label is ``whole_cell``, one proved with another label is ``contains_change``, and anything left
   undecided is ``node_only``: the node is proved, the rest of the cell is not.

No label is inferred: every node's label is a box proof that holds it, or its own computation.  A system that
proves no boxes along some scanned axis gives ``node_only`` cells, every node computed.
"""

from __future__ import annotations

import itertools

import numpy as np

from .. import systems
from ..scene.grid import edges
from ..store.variables import CELL
from ..systems.base import SceneBase

SUB_ROUNDS = 2  # rounds of halving inside one cell before it is left node_only
# Box proofs stop where they fail broadly (clustered roots, say): a round of at least PAYS_MIN boxes of at most
# PAYS_CELLS cells each, of which under PAYS prove, is the last; its boxes' nodes are then computed, and its cells
# left node_only.  Larger boxes fail for their size alone (roots move past the separators), so they never stop it.
PAYS, PAYS_MIN, PAYS_CELLS = 0.25, 32, 16

NODE_ONLY, WHOLE_CELL, CONTAINS_CHANGE = (CELL.value(m) for m in ("node_only", "whole_cell", "contains_change"))


def provable(scene: SceneBase) -> bool:
    """Whether the cells of ``scene``'s grid can be proved: its system proves boxes along every scanned axis."""
    system = systems.of(scene)
    moving = {a.name for a in scene.grid if len(a.values) > 1}
    return bool(moving) and moving <= set(system.box_axes(scene))


def decide_chunk(scene: SceneBase, location: tuple[tuple[int, int], ...], evaluate, order: tuple[int, ...]) -> dict[str, np.ndarray]:
    """Every variable (and ``cell``) on the chunk ``location`` = ((start, stop) per grid axis), in grid order.

    ``evaluate(values)`` decides points given by 1-D arrays of grid-axis values (``System.evaluate``); the nodes
    it gets vary fastest along the last axes of ``order`` (``stabmap.run.tasks.point_order``).
    """
    system = systems.of(scene)
    shape = tuple(b - a for a, b in location)
    chunk = _Chunk(scene, location)
    extra = system.dims(scene)
    out = {v.name: np.empty(shape + tuple(extra[d] for d in v.dims), dtype=v.dtype) for v in system.variables}
    label = np.zeros(shape, dtype=out[system.label].dtype)
    cell = np.full(shape, NODE_ONLY, dtype=CELL.dtype)
    known = np.zeros(shape, dtype=bool)

    lo = np.zeros((1, len(shape)), dtype=np.int64)
    hi = np.array([shape], dtype=np.int64)
    pays = chunk.provable
    while lo.shape[0] and pays:
        got, proved = chunk.prove(lo, hi)
        for b in np.flatnonzero(proved):
            where = tuple(slice(a, z) for a, z in zip(lo[b], hi[b]))
            label[where], cell[where], known[where] = got[b], WHOLE_CELL, True
        pays = _pays(proved) or np.prod(hi - lo, axis=1).max() > PAYS_CELLS
        if not pays:
            break
        lo, hi = lo[~proved], hi[~proved]
        many = ~np.all(hi - lo == 1, axis=1)
        lo, hi = _halves(lo[many], hi[many])

    if known.any():
        for k, v in system.proved_box(label[known]).items():
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
        cell[where] = chunk.classify(nodes, computed[system.label], pays)
    out[CELL.name] = cell
    return out


def _pays(proved: np.ndarray) -> bool:
    """Whether a round of box proofs went well enough to split its failures and try again."""
    return proved.size < PAYS_MIN or proved.mean() >= PAYS


def _halves(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Boxes (rows of index ranges [lo, hi)) cut in two along every axis where they hold more than one cell."""
    if lo.shape[0] == 0:
        return lo, hi
    d = lo.shape[1]
    mid = (lo + hi) // 2
    split = hi - lo > 1
    out_lo, out_hi = [], []
    for side in itertools.product((0, 1), repeat=d):
        side = np.array(side, dtype=bool)
        keep = np.all(split | ~side, axis=1)  # the upper half only along axes that split
        a = np.where(side, mid, lo)[keep]
        b = np.where(side | ~split, hi, mid)[keep]
        out_lo.append(a)
        out_hi.append(b)
    return np.concatenate(out_lo), np.concatenate(out_hi)


class _Chunk:
    """The grid axes of one chunk: node values, cell edges, and boxes between them handed to the system."""

    def __init__(self, scene: SceneBase, location):
        self.scene, self.system = scene, systems.of(scene)
        self.names = [a.name for a in scene.grid]
        self.nodes = [a.array[s:e] for a, (s, e) in zip(scene.grid, location)]
        self.edges = [edges(a.array)[s : e + 1] for a, (s, e) in zip(scene.grid, location)]
        self.provable = provable(scene)

    def values(self, index: np.ndarray) -> dict[str, np.ndarray]:
        """Grid-axis values of the nodes ``index`` (rows of chunk indices)."""
        return {name: v[index[:, d]] for d, (name, v) in enumerate(zip(self.names, self.nodes))}

    def prove(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(label, proved) of the boxes of cells [lo, hi) (chunk indices per axis)."""
        if not self.provable or lo.shape[0] == 0:
            return np.zeros(lo.shape[0], dtype=np.int64), np.zeros(lo.shape[0], dtype=bool)
        return self._prove({n: e[lo[:, d]] for d, (n, e) in enumerate(zip(self.names, self.edges))},
                           {n: e[hi[:, d]] for d, (n, e) in enumerate(zip(self.names, self.edges))})

    def _prove(self, lower: dict, upper: dict) -> tuple[np.ndarray, np.ndarray]:
        label, proved = self.system.prove_boxes(self.scene, lower, upper)
        return np.asarray(label), np.asarray(proved, dtype=bool)

    def classify(self, nodes: np.ndarray, node_label: np.ndarray, sub_boxes: bool = True) -> np.ndarray:
        """The ``cell`` flag of the cells of ``nodes`` (computed nodes, labels ``node_label``), none proved whole.

        ``sub_boxes``: try to prove parts of the cells (False where box proofs were seen to fail broadly).
        """
        cell = np.full(nodes.shape[0], NODE_ONLY, dtype=CELL.dtype)
        if not self.provable:
            return cell
        d = nodes.shape[1]
        # Corners: the labels at the cell's 2^d corners, each corner computed once however many cells share it.
        corners = np.concatenate([nodes + np.array(s) for s in itertools.product((0, 1), repeat=d)])
        unique, back = np.unique(corners, axis=0, return_inverse=True)
        at = {n: e[unique[:, k]] for k, (n, e) in enumerate(zip(self.names, self.edges))}
        corner_label = self.system.evaluate(self.scene, at)[self.system.label].reshape(-1)[back.reshape(-1)]
        changed = np.any(corner_label.reshape(2**d, -1) != node_label[None, :], axis=0)
        cell[changed] = CONTAINS_CHANGE
        # Sub-boxes between the node and the cell's edges, halved while they fail.
        todo = np.flatnonzero(~changed) if sub_boxes else np.zeros(0, dtype=np.int64)
        lower, upper, owner = self._sub_boxes(nodes[todo], todo)
        whole = np.ones(nodes.shape[0], dtype=bool)
        for _ in range(SUB_ROUNDS):
            if owner.size == 0:
                break
            got, proved = self._prove(lower, upper)
            other = proved & (got != node_label[owner])
            cell[owner[other]] = CONTAINS_CHANGE
            failed = ~proved
            if not _pays(proved):
                owner = owner[failed]
                break
            lower, upper, owner = self._halve({k: v[failed] for k, v in lower.items()},
                                              {k: v[failed] for k, v in upper.items()}, owner[failed])
        whole[owner] = False  # a sub-box still undecided after the last round
        whole[np.setdiff1d(np.arange(nodes.shape[0]), todo)] = False
        cell[(cell == NODE_ONLY) & whole] = WHOLE_CELL
        return cell

    def _sub_boxes(self, nodes: np.ndarray, owner: np.ndarray):
        """The 2^d boxes between each node and its cell's corners (one per corner), with the cell that owns them."""
        lower, upper, owners = {n: [] for n in self.names}, {n: [] for n in self.names}, []
        d = nodes.shape[1] if nodes.size else len(self.names)
        for side in itertools.product((0, 1), repeat=d):
            for k, name in enumerate(self.names):
                node = self.nodes[k][nodes[:, k]]
                edge = self.edges[k][nodes[:, k] + side[k]]
                lower[name].append(np.minimum(node, edge))
                upper[name].append(np.maximum(node, edge))
            owners.append(owner)
        return ({k: np.concatenate(v) for k, v in lower.items()}, {k: np.concatenate(v) for k, v in upper.items()},
                np.concatenate(owners) if owners else owner)

    def _halve(self, lower: dict, upper: dict, owner: np.ndarray):
        """Boxes given by their corners, cut in two along every axis they span."""
        out_lo, out_hi, owners = {n: [] for n in self.names}, {n: [] for n in self.names}, []
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


__all__ = ["CONTAINS_CHANGE", "NODE_ONLY", "WHOLE_CELL", "decide_chunk", "provable"]
