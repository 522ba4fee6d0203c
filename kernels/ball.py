"""Rigorous midpoint-radius ("ball") arithmetic in plain float64, real and complex.

A real ball is ``(m, r)``: every x with |x - m| <= r; a complex ball is
``(m, r)`` with complex m: every z with |z - m| <= r.  The certificates of
``certify.py`` evaluate n x n matrices at many points, where the double-double
intervals of ``dd`` would cost 10-20x more and bring nothing: the enclosures
only need to separate roots that are already resolved in float64.

Error bounds (u = 2**-53, rounding to nearest, no fused contraction since
fastmath is off; Rump, "Fast and parallel interval arithmetic", BIT 1999, for
the real rules; Brent, Percival & Zimmermann, Math. Comp. 2007, for the complex
product, |fl(ab) - ab| <= sqrt(5) u |ab|):
  real add/mul: u |result|         -> we use 2u
  complex add : sqrt(2) u |result| -> 2u
  complex mul : sqrt(5) u |a||b|   -> 4u
  division    : through a rigorously bounded reciprocal (8u for the float
                1/b, which numba forms by Smith's algorithm), then one product.
Every radius is a sum of nonnegative float terms and is inflated by
``INFL`` = 1 + 8u, which covers the rounding of that sum (at most five terms,
to first order in u).
``ETA`` covers underflow.  ``abs`` of a complex number (hypot) is within one ulp,
covered by the same inflation.  ``excludes_zero``, the test every proof goes
through, is False for NaN or infinite midpoints and radii, so those never
decide anything.
"""

from __future__ import annotations

import math

from .options import kernel

U = 2.0**-53
INFL = 1.0 + 8.0 * U
ETA = 2.0**-1000
LOW = 1.0 - 4.0 * U  # |x| * LOW is a lower bound of the exact modulus of a float complex x


@kernel
def radd(am, ar, bm, br):
    m = am + bm
    return m, (ar + br + 2.0 * U * abs(m)) * INFL


@kernel
def rmul(am, ar, bm, br):
    m = am * bm
    return m, (abs(am) * br + ar * abs(bm) + ar * br + 2.0 * U * abs(m) + ETA) * INFL


@kernel
def rdiv(am, ar, bm, br):
    """a / b; the caller has checked ``excludes_zero(bm, br)``."""
    m = am / bm
    low = (abs(bm) - br) * LOW
    return m, ((ar + abs(m) * (1.0 + 2.0 * U) * br) / low * INFL + 2.0 * U * abs(m) + ETA) * INFL


@kernel
def excludes_zero(m, r):
    """True if the ball (real or complex) provably does not contain 0 (False for NaN and infinite midpoints)."""
    a = abs(m)
    return a * LOW > r * INFL and a < math.inf


@kernel
def cadd(am, ar, bm, br):
    m = am + bm
    return m, (ar + br + 2.0 * U * abs(m)) * INFL


@kernel
def cmul(am, ar, bm, br):
    m = am * bm
    a, b = abs(am), abs(bm)
    return m, (a * br + ar * b + ar * br + 4.0 * U * a * b + ETA) * INFL


@kernel
def cinv(bm, br):
    """1 / b; the caller has checked ``excludes_zero(bm, br)``.

    The image of the disk |y - b| <= r under 1/y is the disk with centre
    conj(b) / (|b|^2 - r^2) and radius r / (|b|^2 - r^2); we centre on the
    float 1/b instead and add the distance between the two centres,
    r^2 / (|b| (|b|^2 - r^2)).  |b|^2 - r^2 = (|b| - r)(|b| + r) is divided
    out factor by factor, so nothing overflows for huge |b|.
    """
    m = 1.0 / bm
    a = abs(bm)
    minus = (a * LOW - br * INFL) * LOW  # below |b| - r
    plus = a * LOW  # below |b| + r (and below |b|)
    disk = br / plus / minus * INFL * INFL
    shift = (br / plus) * (br / plus) / minus * INFL * INFL * INFL
    return m, (disk + shift + 8.0 * U * abs(m) + ETA) * INFL


@kernel
def cdiv(am, ar, bm, br):
    im, ir = cinv(bm, br)
    return cmul(am, ar, im, ir)


@kernel
def recip(w):
    """1 / w for a float complex w, NaN for 0 (numba raises on complex division by zero)."""
    if w == 0.0:
        return complex(math.nan, math.nan)
    return 1.0 / w
