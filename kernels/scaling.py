"""Exact power-of-two scaling of interval polynomials, shared by both root counters."""

from __future__ import annotations

import math

from . import dd
from .options import kernel

SUBNORMAL = 2.0**-1022
HALF_ULP_CARRY = 2.0**-1074  # the largest rounding error of a result in the subnormal range, rounded up


@kernel
def nonzero_span(c):
    """(lowest, highest) index of coefficients that are not exact zeros; (0, -1) if all are.

    Exact zeros at the bottom are exact lambda = 0 roots.
    """
    top = c.shape[0] - 1
    while top >= 0 and dd.is_zero(c[top, 0], c[top, 1], c[top, 2]):
        top -= 1
    if top < 0:
        return 0, -1
    low = 0
    while dd.is_zero(c[low, 0], c[low, 1], c[low, 2]):
        low += 1
    return low, top


@kernel
def rescale(X, deg, lam_shift):
    """lambda -> 2**lam_shift mu and |lead| -> [0.5, 1), keeping the enclosure rigorous.

    Returns False if a nonzero midpoint would leave the safe range.  Low parts
    and radii that land in the subnormal range may round; the radius then
    grows by the largest possible rounding error, so the interval still
    encloses the scaled coefficient.
    """
    return rescale_by(X, deg, lam_shift, math.frexp(X[deg, 0])[1] + lam_shift * deg)


@kernel
def rescale_by(X, deg, lam_shift, e):
    """``rescale`` with the exponent e of the scale given (p -> 2**-e p), so that several polynomials can share it."""
    for i in range(deg + 1):
        s = lam_shift * i - e
        X[i, 0] = math.ldexp(X[i, 0], s)
        lo = math.ldexp(X[i, 1], s)
        r = math.ldexp(X[i, 2], s)
        if lo != 0.0 and abs(lo) < SUBNORMAL or X[i, 1] != 0.0 and lo == 0.0:
            r += HALF_ULP_CARRY
        if X[i, 2] != 0.0 and r < SUBNORMAL:
            r += HALF_ULP_CARRY
        X[i, 1] = lo
        X[i, 2] = r
        a = abs(X[i, 0])
        if a != 0.0 and (a > dd.LARGE or a < 1.0 / dd.LARGE):
            return False
    return True


@kernel
def root_scale(X, deg):
    """Power of two near the Fujiwara root bound max_i |c_i / c_deg|**(1 / (deg - i))."""
    ed = math.frexp(X[deg, 0])[1]
    best = -(1 << 30)
    for i in range(deg):
        if X[i, 0] != 0.0:
            t = (math.frexp(X[i, 0])[1] - ed) // (deg - i)
            if t > best:
                best = t
    return 0 if best == -(1 << 30) else best
