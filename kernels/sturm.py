"""Certified count of real roots by a Sturm sequence in interval arithmetic.

The count V(-inf) - V(+inf) needs only the signs of the leading coefficients
of the sequence and their degrees.  Every leading coefficient must be proved
nonzero (its interval excludes zero).  A remainder that is an exact zero proves
a repeated root; the count then restarts on the gcd, so roots are counted with
multiplicity.  Anything the intervals cannot prove returns UNDECIDED and the
caller decides that point in exact rational arithmetic: nothing is decided by a
tolerance.

Remainders are formed division-free (pseudo-remainders, lc(B)**(da-db+1) rem)
with the sign of that factor corrected, and every element is rescaled by an
exact power of two.
"""

from __future__ import annotations

from . import dd
from .options import kernel
from .scaling import nonzero_span, rescale, root_scale
from .status import DECIDED_FLOAT, UNDECIDED, ZERO_POLYNOMIAL


@kernel
def _discriminant(a0, a1, a2):
    """An enclosure of a1^2 - 4 a0 a2 for intervals (hi, lo, rad); ``certain_nonzero`` refuses one out of range."""
    sq = dd.mul(a1[0], a1[1], a1[2], a1[0], a1[1], a1[2])
    ac = dd.mul(a0[0], a0[1], a0[2], a2[0], a2[1], a2[2])
    return dd.add(*sq, *dd.neg(*dd.mul(*ac, 4.0, 0.0, 0.0)))


@kernel
def count_complex_pairs(c, W):
    """Number of complex-conjugate root pairs of p from an interval enclosure.

    Parameters
    ----------
    c : float64[deg + 1, 3]
        Coefficient intervals (hi, lo, rad), ascending powers of lambda.
    W : float64[2, deg + 1, 3]
        Scratch for two sequence elements.

    Returns
    -------
    (n_complex_pairs, status)
        status is DECIDED_FLOAT, UNDECIDED (n_complex_pairs = -1) or ZERO_POLYNOMIAL
        (p identically zero, n_complex_pairs = -1).
    """
    z, top = nonzero_span(c)
    if top < 0:
        return -1, ZERO_POLYNOMIAL
    if not dd.certain_nonzero(c[top, 0], c[top, 1], c[top, 2]):
        return -1, UNDECIDED
    real = z  # exact zeros at the bottom are lambda = 0 roots
    d = top - z
    if d == 2:  # one top, or a chain's quadratic factor: the discriminant's sign is the whole count
        disc = _discriminant(c[z], c[z + 1], c[top])
        if dd.certain_nonzero(*disc):
            real += 2 if disc[0] > 0 else 0
            return (top - real) // 2, DECIDED_FLOAT
    a, b = 0, 1
    A = W[a]
    A[: d + 1] = c[z : top + 1]
    if d >= 1 and not rescale(A, d, root_scale(A, d)):
        return -1, UNDECIDED
    while d >= 1:
        # The Sturm sequence of the current polynomial (degree d) starts with it and its derivative.
        A, B = W[a], W[b]
        for i in range(d):
            B[i, 0], B[i, 1], B[i, 2] = dd.mul(A[i + 1, 0], A[i + 1, 1], A[i + 1, 2], float(i + 1), 0.0, 0.0)
        da, db = d, d - 1
        sign_plus = 1 if A[da, 0] > 0 else -1
        sign_minus = sign_plus if da % 2 == 0 else -sign_plus
        v_plus = 0
        v_minus = 0
        gcd_deg = 0
        while True:
            A, B = W[a], W[b]
            lb = (B[db, 0], B[db, 1], B[db, 2])
            if not dd.certain_nonzero(*lb):
                return -1, UNDECIDED
            s_plus = 1 if lb[0] > 0 else -1
            s_minus = s_plus if db % 2 == 0 else -s_plus
            v_plus += s_plus != sign_plus
            v_minus += s_minus != sign_minus
            sign_plus, sign_minus = s_plus, s_minus
            if db == 0:
                break
            # A <- lc(B)^(da-db+1) rem(A, B), eliminating A's top coefficients one by one.
            for j in range(da, db - 1, -1):
                t = (A[j, 0], A[j, 1], A[j, 2])
                shift = j - db
                for i in range(j):
                    x = dd.mul(A[i, 0], A[i, 1], A[i, 2], *lb)
                    if i >= shift:
                        y = dd.mul(*t, B[i - shift, 0], B[i - shift, 1], B[i - shift, 2])
                        x = dd.add(*x, *dd.neg(*y))
                    A[i, 0], A[i, 1], A[i, 2] = x
            dr = db - 1
            while dr >= 0 and dd.is_zero(A[dr, 0], A[dr, 1], A[dr, 2]):
                dr -= 1
            if dr < 0:
                gcd_deg = db  # B divides A exactly: B is the gcd and p has repeated roots
                break
            if not dd.certain_nonzero(A[dr, 0], A[dr, 1], A[dr, 2]):
                return -1, UNDECIDED
            # Next element -rem(A, B): undo the sign of lc(B)^(da-db+1).
            flip = lb[0] > 0 or (da - db) % 2 == 1
            if flip:
                for i in range(dr + 1):
                    A[i, 0] = -A[i, 0]
                    A[i, 1] = -A[i, 1]
            if not rescale(A, dr, 0):
                return -1, UNDECIDED
            a, b = b, a
            da, db = db, dr
        real += v_minus - v_plus
        if gcd_deg == 0:
            break
        # The roots of the gcd are the multiple roots: count them once more.
        a, b = b, a
        d = gcd_deg
    if real > top or (top - real) % 2 != 0:
        return -1, UNDECIDED
    return (top - real) // 2, DECIDED_FLOAT
