"""Decide N_c for a block of points: the certified kernels first, exact arithmetic for the rest."""

from __future__ import annotations

import numpy as np

from ...kernels import (
    DECIDED_ALLATONCE,
    DECIDED_DISKS,
    DECIDED_INCLUSION,
    DECIDED_INERTIA,
    UNDECIDED,
    ZERO_POLYNOMIAL,
    box_block,
    decide_block,
    nodes_box_block,
)
from . import exact
from .boxes import BoxArrays, NodeBoxes, boxes, unenclosed
from .outputs import BY_ALLATONCE, BY_DISKS, BY_EXACT, BY_INCLUSION, BY_INERTIA, BY_STURM
from .points import PointArrays

_BY_STATUS = {DECIDED_ALLATONCE: BY_ALLATONCE, DECIDED_INCLUSION: BY_INCLUSION, DECIDED_INERTIA: BY_INERTIA, DECIDED_DISKS: BY_DISKS,
              UNDECIDED: BY_EXACT}


def decided_by_from_status(status: np.ndarray) -> np.ndarray:
    """The ``decided_by`` flag from the kernels' status codes (UNDECIDED points are those decided exactly)."""
    by = np.full(status.shape, BY_STURM, dtype=np.int8)
    for code, flag in _BY_STATUS.items():
        by[status == code] = flag
    return by


def kernel_args(points: PointArrays | BoxArrays | NodeBoxes) -> tuple:
    """``points.kernel_args()`` as writable C-contiguous arrays: the types ``pip install`` compiled the kernels for.

    A read-only or strided array (a broadcast view, say) is another numba signature, and
    so a second compilation of the whole kernel on the first call (about 20 s); copying
    the few such arrays is cheap (kernels/precompile.py).
    """
    return tuple(np.require(a, requirements=("C", "W")) if isinstance(a, np.ndarray) else a for a in points.kernel_args())


def decide(points: PointArrays) -> tuple[np.ndarray, np.ndarray]:
    """Return (n_complex_pairs int16, decided_by int8) for every point; -1 marks p identically zero."""
    npts = points.body.shape[0]
    nc = np.empty(npts, dtype=np.int16)
    status = np.empty(npts, dtype=np.int8)
    decide_block(*kernel_args(points), nc, status)
    undecided = np.flatnonzero(status == UNDECIDED)
    if undecided.size:
        nc[undecided] = exact.decide_points(*points.kernel_args(), undecided)
    return nc, decided_by_from_status(status)


def prove_boxes(scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray], cut: bool = False):
    """(N_c int16, proved bool) of each box: N_c at every point of box i where proved[i] (``System.prove_boxes``).
    ``cut``: also the axes each box not proved is best cut along, ``cut[name][i]`` (``System.prove_and_cut_boxes``).

    Each box goes to the kernel of its narrowest enclosure (``boxes.boxes``).  Boxes that span an axis outside
    ``box_axes`` are not proved, and not tried.  A box on the tensor grid whose probed corners moved mostly along
    one of its two axes is cut across that one alone (``kernels.count.fails_at_nodes``); every other box along
    every axis.
    """
    npts = len(next(iter(lower.values()))) if lower else 1
    spans = np.zeros(npts, dtype=bool)
    for outside in unenclosed(scene, lower, upper).values():
        spans |= outside
    nc = np.full(npts, -1, dtype=np.int16)
    proved = np.zeros(npts, dtype=bool)
    along = {k: np.ones(npts, dtype=bool) for k in lower}
    todo = np.flatnonzero(~spans)
    if todo.size == 0:
        return (nc, proved, along) if cut else (nc, proved)
    for rows, part in boxes(scene, {k: np.asarray(v)[todo] for k, v in lower.items()}, {k: np.asarray(v)[todo] for k, v in upper.items()}):
        count = np.empty(rows.size, dtype=np.int16)
        status = np.empty(rows.size, dtype=np.int8)
        if isinstance(part, NodeBoxes):
            split = np.empty(rows.size, dtype=np.int8)
            nodes_box_block(*kernel_args(part), count, status, split)
            _cut_along(along, todo[rows], split, part)
        else:
            box_block(*kernel_args(part), count, status)
        ok = (status != UNDECIDED) & (status != ZERO_POLYNOMIAL)
        nc[todo[rows[ok]]] = count[ok]
        proved[todo[rows[ok]]] = True
    return (nc, proved, along) if cut else (nc, proved)


def _cut_along(cut: dict[str, np.ndarray], rows: np.ndarray, split: np.ndarray, part: NodeBoxes) -> None:
    """Boxes ``rows`` whose kernel said 1 (along t) or 2 (along t2) in ``split`` are cut along that axis alone."""
    for code, names in ((1, part.axis1), (2, part.axis2)):
        if names is None:
            continue
        at = np.flatnonzero(split == code)
        for k in cut:
            cut[k][rows[at]] = names[at] == k
