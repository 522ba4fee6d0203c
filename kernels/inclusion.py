"""Certified count of real roots by root inclusion: Aberth approximations, Gerschgorin disks.

The Sturm sequence loses about a digit per element when roots spread over
decades, so above degree ~16 it rarely proves anything even in double-double.
Root inclusion does not chain remainders.  With approximations z_1..z_d of the
roots of p (degree d, leading coefficient a_d), the roots of p are the
eigenvalues of the Carstensen matrix diag(z) - w 1^T with

    w_i = p(z_i) / (a_d prod_{j != i} (z_i - z_j))

(Lagrange interpolation at the z_i).  Its Gerschgorin row disks lie inside the
disks D_i = {|lambda - z_i| <= d |w_i|} (Braess & Hadeler), and a connected
union of k of them that meets no other disk holds exactly k roots.  Since p is
real, an isolated disk centred on the real axis holds one root that equals its
own conjugate, a real root; a group of disks that misses the real axis holds
only non-real roots.  Any other configuration (clusters across the axis, close
or repeated roots) is UNDECIDED and goes to exact arithmetic.

|p(z_i)| is bounded for every polynomial in the coefficient intervals by
Horner's rule in the rigorous double-double intervals of ``dd`` (float64
Horner would cap the precision of clustered roots at about 1e-8).  Products
are kept as mantissa and exponent so no partial product overflows or
underflows, and every bound is rounded outward by a factor 1 + 16 (d + 4) u.
The approximations themselves need no guarantee: a bad one only makes a disk
too large to decide.
"""

from __future__ import annotations

import math

import numpy as np

from . import dd
from .options import kernel
from .status import DECIDED_INCLUSION, UNDECIDED

TINY = 2.0**-1000  # floor of a radius, so an underflowing bound never becomes zero
MAX_ITER = 120
POLISH_SWEEPS = 12  # at most; tight clusters (three identical cavities) need 6-8 sweeps
STEP_TOL = 2.0**-50  # a step below this share of |z| means z has all the digits a float holds


@kernel
def bini_start(a, d, z):
    """Initial approximations from the Newton polygon of |a_k| (Bini): circles of the right radii."""
    # Upper convex hull of (k, log2 |a_k|) over the nonzero coefficients.
    hull = np.empty(d + 1, np.int64)
    logs = np.empty(d + 1)
    m = 0
    for k in range(d + 1):
        if a[k] == 0.0:
            continue
        logs[k] = math.log2(abs(a[k]))
        while m >= 2:
            i, j = hull[m - 2], hull[m - 1]
            if (logs[j] - logs[i]) * (k - i) <= (logs[k] - logs[i]) * (j - i):
                m -= 1
            else:
                break
        hull[m] = k
        m += 1
    pos = 0
    for e in range(m - 1):
        i, j = hull[e], hull[e + 1]
        r = 2.0 ** ((logs[i] - logs[j]) / (j - i))
        for t in range(j - i):
            ang = 2.0 * math.pi * t / (j - i) + 2.0 * math.pi * e / d + 0.4
            z[pos] = complex(r * math.cos(ang), r * math.sin(ang))
            pos += 1


@kernel
def _value_and_slope(a, d, x):
    """p(x), p'(x) and sum |a_k| |x|^k (the scale of the rounding error in p(x))."""
    p = a[d] + 0.0 * x
    dp = 0.0 * x
    ax = abs(x)
    scale = abs(a[d])
    for k in range(d - 1, -1, -1):
        dp = dp * x + p
        p = p * x + a[k]
        scale = scale * ax + abs(a[k])
    return p, dp, scale


@kernel
def horner_dd(X, d, zr, zi):
    """Re p(z), Im p(z), Re p'(z), Im p'(z) as dd intervals, for every polynomial in X (Horner's rule)."""
    re = (X[d, 0], X[d, 1], X[d, 2])
    im = (0.0, 0.0, 0.0)
    dre = (0.0, 0.0, 0.0)
    dim = (0.0, 0.0, 0.0)
    for k in range(d - 1, -1, -1):
        # p' <- p' z + p ; p <- p z + X_k
        t = dd.add(*dd.mul(*dre, zr, 0.0, 0.0), *dd.neg(*dd.mul(*dim, zi, 0.0, 0.0)))
        dim = dd.add(*dd.add(*dd.mul(*dre, zi, 0.0, 0.0), *dd.mul(*dim, zr, 0.0, 0.0)), *im)
        dre = dd.add(*t, *re)
        t = dd.add(*dd.mul(*re, zr, 0.0, 0.0), *dd.neg(*dd.mul(*im, zi, 0.0, 0.0)))
        im = dd.add(*dd.mul(*re, zi, 0.0, 0.0), *dd.mul(*im, zr, 0.0, 0.0))
        re = dd.add(*t, X[k, 0], X[k, 1], X[k, 2])
    return re, im, dre, dim


@kernel
def _value_dd(X, d, zr, zi):
    """p(z) for the interval polynomial X at the float point z, in double-double interval arithmetic.

    Returns (p as a complex128 midpoint, an upper bound of |p(z)| over every
    polynomial in the intervals, p'(z) as a complex128 midpoint).  The bound is
    rigorous by construction of ``dd``; the derivative only steers iterations.
    """
    re, im, dre, dim = horner_dd(X, d, zr, zi)
    bre = abs(re[0]) * dd.ABS + re[2]
    bim = abs(im[0]) * dd.ABS + im[2]
    bound = math.hypot(bre, bim) * (1.0 + 4.0 * dd.U)  # hypot: the squares would underflow below 1e-154
    return complex(re[0] + re[1], im[0] + im[1]), bound, complex(dre[0] + dre[1], dim[0] + dim[1])


@kernel
def _aberth_step(z, d, i, p, dp):
    """Aberth's correction of z[i] from p(z[i]) and p'(z[i]): Newton's, repelled by the other approximations."""
    ratio = p / dp
    s = 0.0j
    for j in range(d):
        if j != i:
            s += 1.0 / (z[i] - z[j])
    return ratio / (1.0 - ratio * s)


@kernel
def _polish(X, d, z, sweeps):
    """Aberth sweeps with p and p' in double-double until no approximation moves by more than 2**-50 of itself.

    The float iteration resolves a cluster of k roots only to about u**(1/k) of
    their size; the double-double values let every sweep gain digits there.
    """
    for _ in range(sweeps):
        moved = False
        for i in range(d):
            p, _, dp = _value_dd(X, d, z[i].real, z[i].imag)
            if p == 0.0 or dp == 0.0:
                continue
            step = _aberth_step(z, d, i, p, dp)
            if math.isfinite(step.real) and math.isfinite(step.imag):
                z[i] -= step
                moved = moved or abs(step) > STEP_TOL * abs(z[i])
        if not moved:
            return


@kernel
def float_aberth(a, d, z, done):
    """Aberth-Ehrlich iteration on the float polynomial a (ascending, degree d), in place."""
    done[:d] = False
    for _ in range(MAX_ITER):
        moving = False
        for i in range(d):
            if done[i]:
                continue
            p, dp, scale = _value_and_slope(a, d, z[i])
            if abs(p) <= dd.U * scale:
                done[i] = True  # p(z) is rounding noise: no further digits to gain
                continue
            step = _aberth_step(z, d, i, p, dp)
            z[i] -= step
            if abs(step) <= STEP_TOL * abs(z[i]):
                done[i] = True
            else:
                moving = True
        if not moving:
            return


@kernel
def _snap_real(X, d, z):
    """Put approximations of simple real roots exactly on the real axis (then Newton-polish them).

    A disk can certify a real root only if its centre is real.  An approximation
    is moved only if no other one approximates its conjugate (that would be a
    genuine pair close to the axis, which must stay a pair).
    """
    for i in range(d):
        zi = z[i]
        im = abs(zi.imag)
        if im == 0.0 or im > 2.0**-20 * abs(zi):
            continue
        paired = False
        for j in range(d):
            if j != i and abs(z[j] - zi.conjugate()) <= 4.0 * im:
                paired = True
        if paired:
            continue
        x = zi.real
        for _ in range(2):
            p, _, dp = _value_dd(X, d, x, 0.0)
            if dp.real != 0.0 and p.real != 0.0:
                x -= p.real / dp.real
        z[i] = complex(x, 0.0)


@kernel
def group_disks(z, R, d, parent):
    """Join the disks |lambda - z_i| <= R_i (i < d) that meet, the test rounded outward, into the union-find
    forest ``parent``: a connected group of k disks that meets no other holds exactly k roots."""
    for i in range(d):
        parent[i] = i
    for i in range(d):
        for j in range(i + 1, d):
            # the margins of ball.LOW and ball.INFL: the float modulus and sum rounded outward
            if abs(z[i] - z[j]) * (1.0 - 4.0 * dd.U) <= (R[i] + R[j]) * (1.0 + 8.0 * dd.U):
                ri, rj = find_root(parent, i), find_root(parent, j)
                if ri != rj:
                    parent[ri] = rj


@kernel
def find_root(parent, i):
    """The representative of i in the union-find forest ``parent`` (with path halving)."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@kernel
def disk_radii(X, d, z, R):
    """Rigorous radii d |w_i| (see module docstring); False if a bound is not finite or z repeat."""
    mu = 1.0 + 16.0 * (d + 4) * dd.U
    lead = (abs(X[d, 0]) * (1.0 - 4.0 * dd.U) - abs(X[d, 1]) - X[d, 2]) / mu
    if not lead > 0.0:
        return False
    lead_m, lead_e = math.frexp(lead)
    for i in range(d):
        zi = z[i]
        num = _value_dd(X, d, zi.real, zi.imag)[1] * mu
        if not math.isfinite(num):
            return False
        num_m, num_e = math.frexp(num)
        prod_m, prod_e = 1.0, 0
        for j in range(d):
            if j == i:
                continue
            dist = abs(zi - z[j])
            if dist == 0.0:
                return False
            prod_m, e = math.frexp(prod_m * dist)
            prod_e += e
        prod_m /= mu
        e = num_e - lead_e - prod_e
        if e > 900:
            return False
        w = num_m / (lead_m * prod_m) * mu
        R[i] = max(math.ldexp(w, e), TINY) * d * mu
    return True


@kernel
def approximate(X, d, a, z, flags):
    """Approximations z of all d roots of the interval polynomial X (scaled, no zero root); False if none.

    Aberth iterations on the midpoints a from Bini's start, polished in double-double, simple real roots
    put exactly on the axis.  They prove nothing: a poor one only makes a disk or a separator useless.
    Scratch: a (d + 1 floats), flags (d bools).
    """
    for k in range(d + 1):
        a[k] = X[k, 0]
    if a[0] == 0.0 or a[d] == 0.0:
        return False
    bini_start(a, d, z)
    float_aberth(a, d, z, flags)
    for i in range(d):
        if not (math.isfinite(z[i].real) and math.isfinite(z[i].imag)):
            return False
    _polish(X, d, z, POLISH_SWEEPS)
    _snap_real(X, d, z)
    return True


@kernel
def count_complex_pairs_inclusion(X, d, a, z, R, group, flags):
    """N_c of the interval polynomial X (rows 0..d, (hi, lo, rad), no zero root) by root inclusion.

    X should be scaled so that its roots have modulus near one (exact powers of
    two, as ``sturm._rescale``).  Scratch: a (d + 1 floats), z (d complex),
    R (d floats), group (2 d ints), flags (d bools).  Returns (N_c, status).
    """
    if not approximate(X, d, a, z, flags):
        return -1, UNDECIDED
    if not disk_radii(X, d, z, R):
        return -1, UNDECIDED
    parent, size = group[:d], group[d : 2 * d]
    group_disks(z, R, d, parent)
    size[:] = 0
    flags[:d] = False  # flags[r]: the group with representative r meets the real axis
    for i in range(d):
        r = find_root(parent, i)
        size[r] += 1
        if abs(z[i].imag) <= R[i]:
            flags[r] = True
    nonreal = 0
    for i in range(d):
        r = find_root(parent, i)
        if not flags[r]:
            nonreal += 1
        elif size[r] != 1 or z[i].imag != 0.0:
            return -1, UNDECIDED
        # else: a lone disk centred on the axis holds one real root
    if nonreal % 2:
        return -1, UNDECIDED
    return nonreal // 2, DECIDED_INCLUSION
