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
polynomial in the enclosure, so for every parameter point of the box (docs/certification.md, section 6).
The approximations (Aberth iterations on the midpoint polynomial) prove nothing themselves: a poor one
only leaves the box undecided, and the caller splits it.

**Polynomial in one parameter.** Where p is a polynomial of degree < N in one parameter u of the box (the
spin-scaled model: degree <= n in u = 1 / omega^2), its coefficients are enclosed at N nodes u_k instead,
each as narrowly as at a point.  Every value the count needs (p(s), p(z), p'(z)) is then a polynomial of
degree < N in u, equal to its interpolant through the N nodes: the divided differences of the node values,
in ``dd`` intervals, and the Newton form evaluated on the interval of u enclose it over the whole box.  This
follows the values themselves, where Horner's rule on independent coefficient intervals would add up their
widths (the coefficients move together).  One node (N = 1) is the plain enclosure.

**Polynomial in two parameters.** Where p has degree < N1 in t1 and < N2 in t2 (a box moving two axes), it is
enclosed on the tensor grid of N1 x N2 nodes (t1[i], t2[j]), node k = i N2 + j.  Its tensor interpolant is p:
p(t1, t2) = sum_a N_a(t1) q_a(t2), q_a(t2) = sum_b c_ab M_b(t2), with N_a, M_b the Newton bases of the two node
sets and c_ab the divided differences of the node values along t2, then along t1 (linear in the node values, so
enclosed from their enclosures).  The Newton form of each q_a, evaluated on the interval of t2, encloses q_a
there; the Newton form in t1 with those intervals as coefficients, on the interval of t1, encloses p on the whole
box (``over_grid``).  N2 = 1 is the one-parameter case, operation for operation.
"""

from __future__ import annotations

import math

import numpy as np

from . import dd
from .inclusion import approximate, horner_dd
from .options import kernel
from .status import DECIDED_INCLUSION, UNDECIDED

MU = 1.0 + 64.0 * dd.U  # outward rounding of the float bounds formed from the dd enclosures
# A box whose probed nodes spread at a separator by more than their middle's value there is not worth its other
# nodes: the enclosure over the box holds that spread, widened, and nearly always 0 with it (``fails_at_nodes``).
# Measured on paper-n3-fixed (2 of 9,600 provable boxes skipped, failures at about half their cost): 1.
SPREAD = 1.0


@kernel
def _real_value(X, d, x):
    """Enclosure (h, l, r) of p(x) at the float x for every polynomial in X (Horner in dd intervals)."""
    v = (X[d, 0], X[d, 1], X[d, 2])
    for k in range(d - 1, -1, -1):
        v = dd.add(*dd.mul(*v, x, 0.0, 0.0), X[k, 0], X[k, 1], X[k, 2])
    return v


@kernel
def _divided(F, N, u):
    """F[:N] (dd intervals, the values at the distinct nodes u[:N]) overwritten by their divided differences."""
    for j in range(1, N):
        for i in range(N - 1, j - 1, -1):
            t = dd.add(F[i, 0], F[i, 1], F[i, 2], *dd.neg(F[i - 1, 0], F[i - 1, 1], F[i - 1, 2]))
            sh, sl = dd.two_sum(u[i], -u[i - j])  # the nodes are floats: their difference is exact
            F[i, 0], F[i, 1], F[i, 2] = dd.div(*t, sh, sl, 0.0)


@kernel
def _newton(F, N, u, um, ur):
    """Enclosure over u in [um - ur, um + ur] of the Newton form with the divided differences F[:N] at the nodes u."""
    acc = (F[N - 1, 0], F[N - 1, 1], F[N - 1, 2])
    for j in range(N - 2, -1, -1):
        sh, sl = dd.two_sum(um, -u[j])
        acc = dd.fma(F[j, 0], F[j, 1], F[j, 2], sh, sl, ur, *acc)
    return acc


@kernel
def over_box(F, N, u, um, ur):
    """Enclosure over u in [um - ur, um + ur] of the polynomial of degree < N whose values at the nodes u[:N]
    lie in F[:N] (dd intervals); F is overwritten by the divided differences.  N = 1: F[0] itself."""
    _divided(F, N, u)
    return _newton(F, N, u, um, ur)


@kernel
def over_grid(F, grid, G):
    """Enclosure over the box ``grid`` = (N1, t1, m1, r1, N2, t2, m2, r2) (t_a in [m_a - r_a, m_a + r_a]) of the
    polynomial of degree < N1 in t1 and < N2 in t2 whose values at the nodes (t1[i], t2[j]) lie in F[i N2 + j]
    (module docstring).  F and the scratch G (>= N1, 3) are overwritten.  N2 = 1: ``over_box`` along t1, operation
    for operation."""
    N1, t1, m1, r1, N2, t2, m2, r2 = grid
    # The tensor divided differences first, on the narrow node values (they are linear in them, so the order of the
    # two axes does not matter); only then the Newton form on the intervals.  Evaluating along t2 first and
    # interpolating the resulting wide intervals along t1 would divide their widths by the node gaps.
    for i in range(N1):
        _divided(F[i * N2 : (i + 1) * N2], N2, t2)
    for j in range(N2):
        _divided(F[j::N2], N1, t1)
    for i in range(N1):
        G[i, 0], G[i, 1], G[i, 2] = _newton(F[i * N2 : (i + 1) * N2], N2, t2, m2, r2)
    return _newton(G, N1, t1, m1, r1)


@kernel
def middle(grid):
    """The node nearest the middle of the grid: the one whose polynomial the approximations start from."""
    return (grid[0] // 2) * grid[4] + grid[4] // 2


@kernel
def _sign(h, l, r):
    """+1 or -1 if the interval excludes zero, else 0."""
    if not dd.certain_nonzero(h, l, r):
        return 0
    return 1 if h > 0.0 else -1


@kernel
def _upper(h, l, r):
    """An upper bound of |x| over the interval."""
    return abs(h) * dd.ABS + r


@kernel
def _newton_radius(X, grid, d, zr, zi, F, G):
    """d |p(z)| / |p'(z)| bounded above over every polynomial of the box; inf where |p'(z)| may vanish."""
    for k in range(grid[0] * grid[4]):
        re, im, dre, dim = horner_dd(X[k], d, zr, zi)
        for part, v in enumerate((re, im, dre, dim)):
            F[part, k, 0], F[part, k, 1], F[part, k, 2] = v
    re = over_grid(F[0], grid, G)
    im = over_grid(F[1], grid, G)
    dre = over_grid(F[2], grid, G)
    dim = over_grid(F[3], grid, G)
    upper = math.hypot(_upper(*re), _upper(*im)) * MU
    # |p'| >= |midpoint| - radius, each part: the midpoint's modulus rounded down, the radii up
    mid = math.hypot(dre[0] + dre[1], dim[0] + dim[1]) / MU
    rad = (abs(dre[1]) + dre[2] + abs(dim[1]) + dim[2]) * MU + 8.0 * dd.U * (abs(dre[0]) + abs(dim[0]))
    lower = (mid - rad) / MU
    if not (lower > 0.0 and math.isfinite(upper)):
        return math.inf
    return d * upper / lower * MU * MU


@kernel
def _separators(X, d, a, z, R, flags, ready):
    """The real approximations of X's roots (``approximate``; ``ready``: z holds them already), increasing, in
    R[:r]; r, or -1 if none."""
    if not ready and not approximate(X, d, a, z, flags):
        return -1
    r = 0
    for i in range(d):
        if z[i].imag == 0.0:
            R[r] = z[i].real
            r += 1
    R[:r].sort()
    return r


@kernel
def separators_spread(X, probe, mid, d, a, z, R, flags):
    """(fails, along1, along2).  fails: at a separator between the real approximations of X[mid]'s roots (those
    ``count_complex_pairs_box`` takes), some X[k], k in ``probe``, is not proved of X[mid]'s proved sign (or
    X[mid]'s is not proved), or the X[k] spread about X[mid] by more than SPREAD times its value there; or there
    are no approximations.  along1, along2: at the separator that failed, how far the probed corners (probe[1:],
    ``block.corners``) differ along t1 and along t2, relative to X[mid]'s value (0 if unknown).  Leaves X[mid]'s
    approximations in z for ``count_complex_pairs_box`` (``ready``)."""
    r = _separators(X[mid], d, a, z, R, flags, False)
    if r < 0:
        return True, 0.0, 0.0
    v = np.empty(probe.size)  # the probed nodes' values at one separator (midpoints)
    for j in range(r - 1):
        x = 0.5 * R[j] + 0.5 * R[j + 1]
        h, l, rad = _real_value(X[mid], d, x)
        s = _sign(h, l, rad)
        if s == 0:
            return True, 0.0, 0.0
        fails = False
        for i in range(probe.size):
            hk, lk, rk = _real_value(X[probe[i]], d, x)
            v[i] = hk
            fails = fails or _sign(hk, lk, rk) != s or abs(hk - h) > SPREAD * abs(h)
        if fails:
            # corners v[1:] at (i, j) = (0, 0), (0, N2 - 1), (N1 - 1, 0), (N1 - 1, N2 - 1): i indexes t1, j t2
            along1 = (abs(v[1] - v[3]) + abs(v[2] - v[4])) / abs(h)
            along2 = (abs(v[1] - v[2]) + abs(v[3] - v[4])) / abs(h)
            return True, along1, along2
    return False, 0.0, 0.0


@kernel
def count_complex_pairs_box(X, grid, d, a, z, R, order, flags, F, G, ready=False):
    """N_c of every polynomial of a box: X[:N] (rows 0..d each, no zero root, lc proved nonzero and the same)
    enclose p at the N = N1 N2 nodes of ``grid`` (``over_grid``), p of degree < N1 in t1 and < N2 in t2 (module
    docstring); N = 1: X[0] encloses p over the whole box.

    The polynomials should share one exact power-of-two scaling that puts the roots near modulus one
    (``scaling.rescale``).  Scratch: a (d + 1 floats), z (d complex), R (d floats), order (d ints), flags (d
    bools), F (4, N, 3), G (N1, 3).  ``ready``: z holds the approximations of X[middle(grid)]'s roots already
    (``separators_spread`` made them).  Returns (N_c, DECIDED_INCLUSION) or (-1, UNDECIDED).
    """
    N = grid[0] * grid[4]
    r = _separators(X[middle(grid)], d, a, z, R, flags, ready)  # real approximations in increasing order
    if r < 0:
        return -1, UNDECIDED
    lead = 1 if X[0, d, 0] > 0.0 else -1
    previous = lead if d % 2 == 0 else -lead  # the sign of p at -inf
    real = 0
    for j in range(r):
        if j == r - 1:
            s = lead  # at +inf
        else:
            x = 0.5 * R[j] + 0.5 * R[j + 1]
            for k in range(N):
                F[0, k, 0], F[0, k, 1], F[0, k, 2] = _real_value(X[k], d, x)
            s = _sign(*over_grid(F[0], grid, G))
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
            rho = _newton_radius(X, grid, d, z[i].real, z[i].imag, F, G)
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
