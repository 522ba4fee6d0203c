"""N_c proved for every polynomial of a wide interval polynomial: sign changes for the real roots, Newton disks
for the others.

A box of parameters gives coefficient intervals far wider than one point's.  The Sturm sequence chains
remainders, and its widths grow with every one, so it proves only tiny boxes.  This count chains nothing:

* **real roots from below.** At real separators s_1 < ... < s_{r-1} between the real approximations (and
  -inf, +inf, where the signs are those of the leading coefficient), p(s_j) is enclosed by Horner's rule in
  ``dd`` intervals.  Where the sign of p(s_j) is proved for the whole enclosure, every member polynomial has
  a real root in each gap whose ends differ in sign: at least that many real roots.
* **non-real roots from below.** For any polynomial of degree d and any z, some root lies within
  d |p(z)| / |p'(z)| of z (p'/p = sum 1/(z - r)).  With |p(z)| bounded above and |p'(z)| below over the
  enclosure, the disk around an approximation z in the upper half plane holds a root of every member;
  pairwise disjoint disks clear of the real axis hold distinct non-real roots, and their conjugates as many
  again.

If the two bounds add up to the degree d, both are exact for every member: N_c is proved for every
polynomial in the enclosure, so for every parameter point of the box (docs/certification.md, "Boxes").
The approximations (Aberth iterations on the midpoint polynomial) prove nothing themselves: a poor one
only leaves the box undecided, and the caller splits it.
"""

from __future__ import annotations

import math

from . import dd
from .inclusion import approximate, horner_dd
from .options import kernel
from .status import DECIDED_INCLUSION, UNDECIDED

MU = 1.0 + 64.0 * dd.U  # outward rounding of the float bounds formed from the dd enclosures


@kernel
def _real_value(X, d, x):
    """Enclosure (h, l, r) of p(x) at the float x for every polynomial in X (Horner in dd intervals)."""
    v = (X[d, 0], X[d, 1], X[d, 2])
    for k in range(d - 1, -1, -1):
        v = dd.add(*dd.mul(*v, x, 0.0, 0.0), X[k, 0], X[k, 1], X[k, 2])
    return v


@kernel
def _sign(h, l, r):
    """+1 or -1 if the interval excludes zero, else 0."""
    if not dd.certain_nonzero(h, l, r):
        return 0
    return 1 if h > 0.0 else -1


@kernel
def _newton_radius(X, d, zr, zi):
    """d |p(z)| / |p'(z)| bounded above over every polynomial in X; inf where |p'(z)| may vanish."""
    re, im, dre, dim = horner_dd(X, d, zr, zi)
    upper = math.hypot(abs(re[0]) * dd.ABS + re[2], abs(im[0]) * dd.ABS + im[2]) * MU
    # |p'| >= |midpoint| - radius, each part: the midpoint's modulus rounded down, the radii up
    mid = math.hypot(dre[0] + dre[1], dim[0] + dim[1]) / MU
    rad = (abs(dre[1]) + dre[2] + abs(dim[1]) + dim[2]) * MU + 8.0 * dd.U * (abs(dre[0]) + abs(dim[0]))
    lower = (mid - rad) / MU
    if not (lower > 0.0 and math.isfinite(upper)):
        return math.inf
    return d * upper / lower * MU * MU


@kernel
def count_complex_pairs_box(X, d, a, z, R, order, flags):
    """N_c of every polynomial in the interval polynomial X (rows 0..d, no zero root, lc proved nonzero).

    X should be scaled so that its roots have modulus near one (``scaling.rescale``).  Scratch: a (d + 1
    floats), z (d complex), R (d floats), order (d ints), flags (d bools).  Returns (N_c, DECIDED_INCLUSION) or (-1, UNDECIDED).
    """
    if not approximate(X, d, a, z, flags):
        return -1, UNDECIDED
    # Real approximations in increasing order.
    r = 0
    for i in range(d):
        if z[i].imag == 0.0:
            R[r] = z[i].real
            r += 1
    R[:r].sort()
    lead = 1 if X[d, 0] > 0.0 else -1
    previous = lead if d % 2 == 0 else -lead  # the sign of p at -inf
    real = 0
    for j in range(r):
        if j == r - 1:
            s = lead  # at +inf
        else:
            h, l, rad = _real_value(X, d, 0.5 * R[j] + 0.5 * R[j + 1])
            s = _sign(h, l, rad)
        if s == 0:
            return -1, UNDECIDED
        if s != previous:
            real += 1
        previous = s
    if (d - real) % 2:
        return -1, UNDECIDED
    # Non-real roots: disjoint Newton disks in the upper half plane.
    k = 0
    for i in range(d):
        if z[i].imag > 0.0:
            rho = _newton_radius(X, d, z[i].real, z[i].imag)
            if not rho * MU < z[i].imag:
                return -1, UNDECIDED
            for j in range(k):
                c = z[order[j]]
                if not abs(z[i] - c) / MU > (rho + R[d - 1 - j]) * MU:
                    return -1, UNDECIDED
            order[k] = i
            R[d - 1 - k] = rho
            k += 1
    if real + 2 * k != d:
        return -1, UNDECIDED
    return k, DECIDED_INCLUSION
