"""Proved enclosures of every root of p(lambda): growth rates and mode frequencies (docs/rates.md).

The inclusion disks of ``inclusion`` (Aberth approximations z_i, Braess-Hadeler radii R_i) hold every root of
every polynomial in the coefficient enclosures: a connected group of k disks that meets no other holds exactly
k roots.  So, for the root exponent lambda (solutions ~ e^{i lambda t}, growth rate |Im lambda|):

- max_i (|Im z_i| + R_i) bounds the largest |Im lambda| from above (every root lies in some disk);
- a group that misses the real axis lies in one half plane and holds only non-real roots, each with
  |Im lambda| >= min_{i in group} (|Im z_i| - R_i): the largest such minimum bounds it from below.

Every bound is rounded outward.  Nothing here decides a label; the caller takes the points a kernel fails on
(status ``ROOTS_FAILED``: no approximations, a radius not finite, more than ``block.LAPLACE_MAX`` bodies) to
exact arithmetic.
"""

from __future__ import annotations

import math

import numpy as np

from . import dd
from .block import LAPLACE_MAX
from .charpoly import allocate, charpoly_point, same_structure
from .inclusion import approximate, disk_radii, find_root, group_disks
from .options import kernel
from .scaling import nonzero_span, rescale, root_scale

ROOTS_OK = 0
ROOTS_FAILED = 1
REAL, NONREAL, UNSEPARATED = 0, 1, 2  # root kinds: proved real, proved non-real, a disk group that meets the axis
UP = 1.0 + 8.0 * dd.U  # a sum or difference of two floats, rounded outward by more than its one rounding
DOWN = 1.0 - 8.0 * dd.U


@kernel
def roots_block(body, joint, g, E, kappa, nmodes, free, parent, at, out_z, out_r, out_kind, out_rate, out_status):
    """Every root of p(lambda) enclosed, for a block of points; inputs as for ``block.charpoly_block``.

    Writes, D = sum(nmodes + 2) (the degree bound):

    - ``out_z`` complex128[npts, D]: root approximations lambda [rad/s]; the exact zero roots first (0 + 0j),
      NaN beyond the degree of p;
    - ``out_r`` float64[npts, D]: a radius r_i such that the group of disks of root i, which holds as many roots
      as it has members, lies in the disk |lambda - z_i| <= r_i (0 for an exact zero root, NaN padding);
    - ``out_kind`` int8[npts, D]: ``REAL`` (an exact zero, or a lone disk centred on the axis), ``NONREAL`` (its
      group misses the axis) or ``UNSEPARATED`` (its group meets the axis: not proved either way); -1 padding;
    - ``out_rate`` float64[npts, 3]: (max |Im z_i|, proved lower bound, proved upper bound) of the largest
      |Im lambda| [1/s]; the lower bound is 0 where no group misses the real axis;
    - ``out_status`` int8[npts]: ``ROOTS_OK`` or ``ROOTS_FAILED`` (outputs then undefined).
    """
    npts, n = body.shape[0], body.shape[1]
    rowdeg = nmodes + 2
    D = int(rowdeg.sum())
    laplace = n <= LAPLACE_MAX
    ws = allocate(n if laplace else 1, max(1, nmodes.max()), D if laplace else 1, parent if laplace else parent[:1])
    c = np.empty((D + 1, 3))
    X = np.empty((D + 1, 3))
    a = np.empty(D + 1)
    z = np.empty(D, np.complex128)
    R = np.empty(D)
    group = np.empty(D, np.int64)
    flags = np.empty(D, np.bool_)
    # Every point starts from Bini's circles, not from its neighbour's roots: a warm start is faster, but a point's
    # enclosure would then depend on which points shared its block, and a cluster's atlas (or a resumed one) would
    # differ in the last bits from the local one.
    for p in range(npts):
        out_status[p] = ROOTS_FAILED
        if not laplace:
            continue
        charpoly_point(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, rowdeg, free, ws, c, same_structure(body, joint, at, g, p))
        out_status[p] = point_roots(c, X, a, z, R, group, flags, out_z[p], out_r[p], out_kind[p], out_rate[p])


@kernel
def point_roots(c, X, a, z, R, group, flags, oz, orad, okind, orate):
    """One point's roots from its coefficient enclosure c (ascending, (hi, lo, rad)); see ``roots_block``."""
    oz[:] = complex(np.nan, np.nan)
    orad[:] = np.nan
    okind[:] = -1
    low, top = nonzero_span(c)
    d = top - low
    if top < 0 or not dd.certain_nonzero(c[top, 0], c[top, 1], c[top, 2]):
        return ROOTS_FAILED
    for i in range(low):  # exact zero coefficients at the bottom: exact lambda = 0 roots
        oz[i] = 0.0
        orad[i] = 0.0
        okind[i] = REAL
    orate[0] = orate[1] = orate[2] = 0.0
    if d == 0:
        return ROOTS_OK
    X[: d + 1] = c[low : top + 1]
    shift = root_scale(X, d)
    if not rescale(X, d, shift):
        return ROOTS_FAILED
    if d == 1:  # one real root, -X_0 / X_1 (the disk of a linear polynomial needs no approximations)
        z[0] = -X[0, 0] / X[1, 0]
        R[0] = 0.0
        if not disk_radii(X, 1, z, R):
            return ROOTS_FAILED
    elif not (approximate(X, d, a, z, flags) and disk_radii(X, d, z, R)):
        return ROOTS_FAILED

    group_disks(z, R, d, group)
    # back to lambda = 2**shift mu: exact scalings, unless they overflow (then no enclosure)
    for i in range(d):
        zi = complex(math.ldexp(z[i].real, shift), math.ldexp(z[i].imag, shift))
        ri = math.ldexp(R[i], shift) * UP
        if not (math.isfinite(zi.real) and math.isfinite(zi.imag) and math.isfinite(ri)):
            return ROOTS_FAILED
        z[i], R[i] = zi, ri
    best, lower, upper = 0.0, 0.0, 0.0
    for i in range(d):
        r = find_root(group, i)
        meets = False
        low_i = math.inf
        span = 0.0
        alone = True
        for j in range(d):
            if find_root(group, j) != r:
                continue
            alone = alone and j == i
            meets = meets or abs(z[j].imag) <= R[j]
            low_i = min(low_i, (abs(z[j].imag) - R[j]) * DOWN if abs(z[j].imag) - R[j] > 0.0 else 0.0)
            span = max(span, (abs(z[j] - z[i]) * UP + R[j]) * UP)
        oz[low + i] = z[i]
        orad[low + i] = span
        if not meets:
            okind[low + i] = NONREAL
        elif alone and z[i].imag == 0.0:
            okind[low + i] = REAL
        else:
            okind[low + i] = UNSEPARATED
        best = max(best, abs(z[i].imag))
        upper = max(upper, (abs(z[i].imag) + R[i]) * UP)
        if not meets:
            lower = max(lower, low_i)
    orate[0], orate[1], orate[2] = min(max(best, lower), upper), lower, upper
    return ROOTS_OK
