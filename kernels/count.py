"""N_c of one interval polynomial: the Sturm sequence first, root inclusion where it cannot decide."""

from __future__ import annotations

import math

import numpy as np

from . import dd, layout
from .boxcount import count_complex_pairs_box, middle, over_grid, separators_spread
from .inclusion import count_complex_pairs_inclusion
from .options import kernel
from .scaling import nonzero_span, rescale, rescale_by, root_scale
from .status import DECIDED_INCLUSION, UNDECIDED, ZERO_POLYNOMIAL
from .sturm import count_complex_pairs

SPLIT = 4.0  # a box whose probed values move this many times more along one axis than the other is cut across it alone


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
    return layout.CountWork(W, X, a, z, R, group, flags)


@kernel
def count_point(c, ws, inclusion=True):
    """(N_c, status) of the interval polynomial c (ascending, (hi, lo, rad)); ws from ``allocate_count``.

    The Sturm sequence is cheap and decides nearly every point up to degree ~12;
    root inclusion (unless ``inclusion`` is False) needs no remainder chain and
    decides well-separated roots at any degree.  Whatever neither proves is UNDECIDED.
    """
    W, X, a, z, R, group, flags = ws.W, ws.X, ws.a, ws.z, ws.R, ws.group, ws.flags
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
    W, X, a, z, R, group, flags = ws.W, ws.X, ws.a, ws.z, ws.R, ws.group, ws.flags
    nc, status = count_complex_pairs(c, W)
    if status != UNDECIDED:
        return nc, status
    d = _reduced(c, X)
    if d < 0:
        return nc, status
    one = np.zeros(1)
    point = (1, one, 0.0, 0.0, 1, one, 0.0, 0.0)  # one node: X encloses p over the whole box
    return count_complex_pairs_box(X.reshape((1,) + X.shape), point, d, a, z, R, group[:d], flags, np.empty((4, 1, 3)), np.empty((1, 3)))


@kernel
def count_nodes(C, grid, ws, Xn, F, G, low0=-1, top0=-1):
    """(N_c, status) of every polynomial of a box whose coefficients are polynomials of degree < N1 in t1 and < N2
    in t2, enclosed at the N = N1 N2 nodes of ``grid`` in C[:N] (``boxcount``, "Polynomial in one parameter" and
    "in two parameters").

    ws from ``allocate_count``; Xn (N, deg + 1, 3), F (4, N, 3) and G (N1, 3) are scratch.  Coefficients that are
    exact zeros at every node are zero on the whole box (a polynomial of degree < N1 in t1 and < N2 in t2 that
    vanishes on the grid: each row's interpolant is zero, then each column's), so the exact zero roots and the
    degree are the box's.  (low0, top0): the span ``fails_at_nodes`` left root approximations for; reused if it is
    the box's.
    """
    a, z, R, group, flags = ws.a, ws.z, ws.R, ws.group, ws.flags
    N = grid[0] * grid[4]
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
    if not dd.certain_nonzero(*over_grid(F[0], grid, G)):
        return -1, UNDECIDED
    if d < 2:  # a real polynomial of degree 0 or 1 has only real roots
        return 0, DECIDED_INCLUSION
    mid = middle(grid)
    for k in range(N):
        Xn[k, : d + 1] = C[k, low : top + 1]
    shift = root_scale(Xn[mid], d)
    e = math.frexp(Xn[mid, d, 0])[1] + shift * d
    for k in range(N):
        if not rescale_by(Xn[k], d, shift, e):
            return -1, UNDECIDED
    return count_complex_pairs_box(Xn, grid, d, a, z, R, group[:d], flags, F, G, low == low0 and top == top0)


@kernel
def fails_at_nodes(C, probe, grid, ws, Xn):
    """True if ``count_nodes`` would, or would nearly always, return UNDECIDED, from the nodes ``probe`` alone (C[k]
    computed for k in probe, the grid's middle node among them).  Would: two of them differ in proved sign at a
    separator of the count, or one is not proved nonzero there; the enclosure over the box holds every node's
    value, so it holds 0.  Nearly always: their values at a separator spread by more than SPREAD times the middle
    node's (``boxcount.separators_spread``).

    A screen, never a proof: True only leaves the box unproved (the caller splits it), False proves nothing.
    Where the probed nodes disagree on the exact zero coefficients (the box's degree needs every node) it answers
    False.  ws, Xn as for ``count_nodes``.  Returns (that answer, low, top, split): low, top the span of the
    coefficients whose scaled middle node's root approximations it left in ws (``count_nodes``), top = -1 if
    none; split where it answers True: 1 if the probed values moved mostly along t1 (SPLIT times more than along
    t2), 2 if mostly along t2, else 0: the box is best cut across that axis alone.
    """
    a, z, R, flags = ws.a, ws.z, ws.R, ws.flags
    mid = middle(grid)
    low, top = nonzero_span(C[mid])
    if top < 0:
        return False, -1, -1, 0
    for k in probe:
        lk, tk = nonzero_span(C[k])
        if lk != low or tk != top:
            return False, -1, -1, 0
    d = top - low
    if d < 2:
        return False, -1, -1, 0
    for k in probe:
        Xn[k, : d + 1] = C[k, low : top + 1]
    shift = root_scale(Xn[mid], d)
    e = math.frexp(Xn[mid, d, 0])[1] + shift * d
    for i in range(probe.size):
        k = probe[i]
        if k in probe[:i]:
            continue  # a node probed twice (a box along one parameter): scaled once
        if not rescale_by(Xn[k], d, shift, e):
            return False, -1, -1, 0
    fails, along1, along2 = separators_spread(Xn, probe, mid, d, a, z, R, flags)
    split = 1 if along1 > SPLIT * along2 else 2 if along2 > SPLIT * along1 else 0
    return fails, low, top, split
