"""N_c of one interval polynomial: the Sturm sequence first, root inclusion where it cannot decide."""

from __future__ import annotations

import numpy as np

from . import dd
from .boxcount import count_complex_pairs_box
from .inclusion import count_complex_pairs_inclusion
from .options import kernel
from .scaling import nonzero_span, rescale, root_scale
from .status import UNDECIDED
from .sturm import count_complex_pairs


@kernel
def allocate_count(degree):
    """Scratch for ``count_point``: allocated once per block."""
    W = np.empty((2, degree + 1, 3))
    X = np.empty((degree + 1, 3))
    a = np.empty(degree + 1)
    z = np.empty(degree, np.complex128)
    R = np.empty(degree)
    group = np.empty(2 * degree, np.int64)
    flags = np.empty(degree, np.bool_)
    return W, X, a, z, R, group, flags


@kernel
def count_point(c, ws, inclusion=True):
    """(N_c, status) of the interval polynomial c (ascending, (hi, lo, rad)); ws from ``allocate_count``.

    The Sturm sequence is cheap and decides nearly every point up to degree ~12;
    root inclusion (unless ``inclusion`` is False) needs no remainder chain and
    decides well-separated roots at any degree.  Whatever neither proves is UNDECIDED.
    """
    W, X, a, z, R, group, flags = ws
    nc, status = count_complex_pairs(c, W)
    if status != UNDECIDED or not inclusion:
        return nc, status
    d = _reduced(c, X)
    if d < 0:
        return nc, status
    # The exact zero roots are real, so N_c of the reduced polynomial is N_c of p.
    return count_complex_pairs_inclusion(X, d, a, z, R, group, flags)


@kernel
def _reduced(c, X):
    """c without its exact zero roots, scaled to roots near modulus one (``rescale``), into X; returns its degree.

    -1 where the root counters cannot take it: degree below 2, a leading coefficient not proved nonzero, or
    a scaled coefficient out of the safe range.
    """
    low, top = nonzero_span(c)
    d = top - low
    if d < 2 or not dd.certain_nonzero(c[top, 0], c[top, 1], c[top, 2]):
        return -1
    X[: d + 1] = c[low : top + 1]
    if not rescale(X, d, root_scale(X, d)):
        return -1
    return d


@kernel
def count_box(c, ws):
    """(N_c, status) of every polynomial in the wide interval polynomial c (a box's); ws from ``allocate_count``.

    The Sturm sequence proves small boxes cheaply; wider ones need the sign changes and Newton disks of
    ``boxcount``, which chain no remainders.  UNDECIDED: the box must be split (or its points decided one by one).
    """
    W, X, a, z, R, group, flags = ws
    nc, status = count_complex_pairs(c, W)
    if status != UNDECIDED:
        return nc, status
    d = _reduced(c, X)
    if d < 0:
        return nc, status
    return count_complex_pairs_box(X, d, a, z, R, group[:d], flags)
