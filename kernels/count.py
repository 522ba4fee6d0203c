"""N_c of one interval polynomial: the Sturm sequence first, root inclusion where it cannot decide."""

from __future__ import annotations

import math

import numpy as np

from . import dd
from .boxcount import over_box, count_complex_pairs_box
from .inclusion import count_complex_pairs_inclusion
from .options import kernel
from .scaling import nonzero_span, rescale, rescale_by, root_scale
from .status import DECIDED_INCLUSION, UNDECIDED, ZERO_POLYNOMIAL
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
    one = np.zeros(1)
    return count_complex_pairs_box(X.reshape((1,) + X.shape), 1, one, 0.0, 0.0, d, a, z, R, group[:d], flags, np.empty((4, 1, 3)))


@kernel
def count_nodes(C, N, u, um, ur, ws, Xn, F):
    """(N_c, status) of every polynomial of a box whose coefficients are polynomials of degree < N in a parameter
    u in [um - ur, um + ur], enclosed at the nodes u[:N] in C[:N] (``boxcount``, "Polynomial in one parameter").

    ws from ``allocate_count``; Xn (N, deg + 1, 3) and F (4, N, 3) are scratch.  Coefficients that are exact
    zeros at every node are zero for every u (a polynomial of degree < N with N zeros), so the exact zero roots
    and the degree are the box's.
    """
    W, X, a, z, R, group, flags = ws
    low, top = C.shape[1], -1
    for k in range(N):
        lk, tk = nonzero_span(C[k])
        if tk >= 0:
            low, top = min(low, lk), max(top, tk)
    if top < 0:
        return -1, ZERO_POLYNOMIAL
    d = top - low
    for k in range(N):
        F[0, k, 0], F[0, k, 1], F[0, k, 2] = C[k, top, 0], C[k, top, 1], C[k, top, 2]
    if not dd.certain_nonzero(*over_box(F[0], N, u, um, ur)):
        return -1, UNDECIDED
    if d < 2:  # a real polynomial of degree 0 or 1 has only real roots
        return 0, DECIDED_INCLUSION
    mid = N // 2
    for k in range(N):
        Xn[k, : d + 1] = C[k, low : top + 1]
    shift = root_scale(Xn[mid], d)
    e = math.frexp(Xn[mid, d, 0])[1] + shift * d
    for k in range(N):
        if not rescale_by(Xn[k], d, shift, e):
            return -1, UNDECIDED
    return count_complex_pairs_box(Xn, N, u, um, ur, d, a, z, R, group[:d], flags, F)
