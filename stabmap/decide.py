"""Decide N_c for a block of points: the certified kernel first, exact arithmetic for the rest."""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import kernels

from . import exact
from .points import PointArrays, point_arrays

# Values of the ``decided_by`` flag variable.
BY_STURM = 0
BY_EXACT = 1
BY_INCLUSION = 2
# Not a decision: an adaptive atlas (stabmap.refine) filled the point from its grid cell's agreeing corners.
BY_INFERRED = 3


def decided_by_from_status(status: np.ndarray) -> np.ndarray:
    """The ``decided_by`` flag from the kernels' status codes (UNDECIDED points are those decided exactly)."""
    by = np.where(status == kernels.DECIDED_INCLUSION, BY_INCLUSION, BY_STURM)
    return np.where(status == kernels.UNDECIDED, BY_EXACT, by).astype(np.int8)


def decide(points: PointArrays) -> tuple[np.ndarray, np.ndarray]:
    """Return (n_complex_pairs int16, decided_by int8) for every point; -1 marks p identically zero."""
    npts = points.body.shape[0]
    nc = np.empty(npts, dtype=np.int16)
    status = np.empty(npts, dtype=np.int8)
    kernels.count_block(*points.kernel_args(), nc, status)
    undecided = np.flatnonzero(status == kernels.UNDECIDED)
    if undecided.size:
        nc[undecided] = exact.decide_points(*points.kernel_args(), undecided)
    return nc, decided_by_from_status(status)


def decide_values(scene, values: dict[str, np.ndarray], *, threads: int | None = None, chunk_points: int = 32768):
    """``decide`` for points given by equal-length 1-D arrays of axis values, in chunks on a thread pool.

    The kernels release the GIL, so threads run the chunks in parallel.
    """
    npts = len(next(iter(values.values()))) if values else 1
    threads = threads or os.cpu_count() or 1
    size = max(1, min(chunk_points, -(-npts // threads)))
    bounds = [(a, min(a + size, npts)) for a in range(0, npts, size)]

    def run(bound):
        a, b = bound
        return decide(point_arrays(scene, {k: v[a:b] for k, v in values.items()}))

    nc = np.empty(npts, dtype=np.int16)
    by = np.empty(npts, dtype=np.int8)
    with ThreadPoolExecutor(threads) as pool:
        for (a, b), (n, d) in zip(bounds, pool.map(run, bounds)):
            nc[a:b], by[a:b] = n, d
    return nc, by
