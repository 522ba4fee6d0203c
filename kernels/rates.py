"""Proved growth rates from the non-real roots only (docs/rates.md).

The growth rate max |Im lambda| needs the non-real roots and nothing else: the label has proved that p has
exactly 2 N_c of them (N_c conjugate pairs, counted with multiplicity), so the real roots contribute exactly 0
however clustered or repeated they are.  With approximations z_1..z_Nc in the upper half plane:

- a Newton disk |lambda - z_i| <= d |q(z_i)| / |q'(z_i)| holds a root of q (q'/q = sum 1 / (z - r) over its d
  roots; Henrici, *Applied and Computational Complex Analysis* I, 1974, section 6.4); with |q| bounded above and
  |q'| below over every polynomial in the coefficient enclosures, it holds a root of p's q;
- N_c such disks, pairwise disjoint and clear of the real axis, hold N_c distinct roots in the upper half plane;
  there are only N_c there, so they are all, one in each.

Then max_i (Im z_i - R_i) <= growth rate <= max_i (Im z_i + R_i), every bound rounded outward.  Where the
coefficients' enclosure, amplified by Horner's cancellation beside a cluster of real roots, gives no narrow disk,
the pair takes the Newton disk of ``disks.newton_disk`` instead (p~'/p~ from Phi(z) itself, in balls).  The disks of the
real roots, which are what clusters and repeated roots widen, never enter.  Where this falls short (approximations
that do not show N_c pairs, a pair closer to the axis or to another than its disks, no coefficients) the point
takes the all-roots enclosure of ``roots`` (status ``RATE_ALL_ROOTS``), and the caller exact arithmetic after it.
"""

from __future__ import annotations

import math

import numpy as np

from . import approximations, dd, disks, pencil
from .block import LAPLACE_MAX
from .certify import moderate
from .charpoly import allocate, charpoly_point, same_structure
from .inclusion import approximate, bini_start, horner_dd
from .options import kernel
from .roots import ROOTS_FAILED, point_roots
from .scaling import nonzero_span, rescale, root_scale

RATE_PAIRS, RATE_ALL_ROOTS, RATE_FAILED = 0, 1, 2  # statuses of ``rate_block``
WARM, COLD, POLISHED = 0, 1, 2  # starts of ``_pairs``
NARROW = 2.0**-22  # a disk wider than this share of Im z is not taken (the rate's relative width stays below 1e-6)
PHI_NEWTON = 4  # float Newton steps on det Phi before a disk from Phi
PHI_SHIFTS = (2.0**-44, 2.0**-36, 2.0**-28)  # a disk from Phi is centred this far (relative) above its root
UPPER_SHARE = 2.0**-30  # an approximation this far above the axis (relative) is taken for a non-real root
MAX_SWEEPS = 120  # float Aberth sweeps at most
FLOAT_TOL = 2.0**-40  # a float approximation this close (relative) is left to the double-double Newton steps
POLISH = 6  # double-double Newton steps at most on each non-real approximation
STEP_TOL = 2.0**-52
WARM_WIDTH = 2.0**-40  # a warm start's disks at most this wide (relative), as wide as a cold start's usually are
DOWN = 1.0 - 8.0 * dd.U  # a float product, sum or hypot rounded toward zero by more than its rounding
UP = 1.0 + 8.0 * dd.U


@kernel
def rate_block(body, joint, g, E, kappa, nmodes, free, parent, at, nc, out_rate, out_status):
    """Growth rate enclosures of a block of points whose N_c (``nc``, proved, > 0) is known.

    Inputs as ``block.charpoly_block``.  Writes ``out_rate`` float64[npts, 3] = (estimate, proved lower bound,
    proved upper bound) of max |Im lambda| [1/s] and ``out_status`` int8[npts]: ``RATE_PAIRS`` (disks around the
    N_c pairs), ``RATE_ALL_ROOTS`` (the all-roots enclosure of ``roots.point_roots``: its upper bound counts every
    disk) or ``RATE_FAILED`` (outputs undefined).
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
    up = np.empty(D, np.int64)
    group = np.empty(D, np.int64)
    flags = np.empty(D, np.bool_)
    oz = np.empty(D, np.complex128)
    orad = np.empty(D)
    okind = np.empty(D, np.int8)
    prev = np.empty(D, np.complex128)  # the previous point's proved pairs [rad/s]: this one's start, if it has as many
    nprev = 0
    info = np.zeros(3, np.int64)  # the last approximations' scale exponent, number of candidates, and the degree
    pws = pencil.allocate(n, max(1, nmodes.max()), parent)
    F = np.empty((n, n), np.complex128)
    dF = np.empty((n, n), np.complex128)
    dm = np.empty((n, n), np.complex128)
    dr = np.empty((n, n))
    for p in range(npts):
        out_status[p] = RATE_FAILED
        if not laplace:
            continue
        charpoly_point(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, rowdeg, free, ws, c, same_structure(body, joint, at, g, p))
        k = nc[p]
        warm = k == nprev
        nprev = 0
        done = warm and _pairs(c, X, a, z, R, up, flags, k, out_rate[p], prev, WARM, oz, info)
        if not done:
            done = _pairs(c, X, a, z, R, up, flags, k, out_rate[p], prev, COLD, oz, info)
        if not done:
            done = _pairs(c, X, a, z, R, up, flags, k, out_rate[p], prev, POLISHED, oz, info)
        if not done and info[1] >= k and moderate(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes):
            # the polished approximations again, their disks now from Phi(z) itself: next to a cluster of real roots
            # the coefficients' enclosure, amplified by Horner's cancellation, is what made the disks too wide
            m = pencil.prepare(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, pws, False)
            done = _pairs_from_phi(X, z, up, info, k, D - m, m, body[p], E[p], nmodes, pws, F, dF, dm, dr, oz, R, out_rate[p])
            nprev = 0  # these pairs stay out of the next point's warm start: it starts from the coefficients
            if done:
                out_status[p] = RATE_PAIRS
                continue
        if done:
            out_status[p] = RATE_PAIRS
            nprev = k
        elif point_roots(c, X, a, z, R, group, flags, oz, orad, okind, out_rate[p]) != ROOTS_FAILED:
            out_status[p] = RATE_ALL_ROOTS


@kernel
def _pairs(c, X, a, z, R, up, flags, nc, orate, prev, start, centre, info):
    """Rate of one point from Newton disks around its nc non-real roots in the upper half plane; False if not proved.

    ``start``: WARM from ``prev`` (the previous point's nc pairs, usually a grid neighbour's), COLD from float Aberth
    on every root, or POLISHED (every root polished in double-double as well: a cluster of nearly repeated real
    roots, which float Aberth resolves to u^(1/k) only, then no longer poses as pairs).  Whatever the start, the
    disks prove what they prove; a start only decides whether they are found.  On success ``prev`` holds this
    point's pairs.  ``info`` gets the scale exponent and the number of candidates (in ``up``) of the approximations.
    """
    warm = start == WARM
    info[1] = 0
    low, top = nonzero_span(c)
    d = top - low
    if nc <= 0 or 2 * nc > d or not dd.certain_nonzero(c[top, 0], c[top, 1], c[top, 2]):
        return False
    X[: d + 1] = c[low : top + 1]
    shift = root_scale(X, d)
    if not rescale(X, d, shift):
        return False
    if warm:
        for j in range(nc):
            z[j] = complex(math.ldexp(prev[j].real, -shift), math.ldexp(prev[j].imag, -shift))
            up[j] = j
        candidates = nc
    elif start == COLD:
        for k in range(d + 1):
            a[k] = X[k, 0]
        if a[0] == 0.0:
            return False
        bini_start(a, d, z)
        candidates = _aberth_pairs(a, d, z, flags, R, up, nc)
    else:
        candidates = _farthest(z, d, R, up) if approximate(X, d, a, z, flags) else 0
    info[0], info[1], info[2] = shift, candidates, d
    # candidates farthest above the axis first; one whose disk is not clear of the axis, or meets an accepted one,
    # is passed over (a real cluster's approximations posing as pairs): any nc accepted disks hold all nc pairs
    best, lower, upper = 0.0, 0.0, 0.0
    k = 0
    for j in range(candidates):
        if k == nc:
            break
        zi = _polish(X, d, z[up[j]])
        r = newton_radius(X, d, zi)
        if not (r < zi.imag * (WARM_WIDTH if warm else NARROW)):  # a warm start that polished badly: try cold
            if warm:
                return False
            continue
        alone = True
        for i in range(k):
            alone = alone and abs(zi - centre[i]) * DOWN > (r + R[i]) * UP
        if not alone:
            if warm:
                return False
            continue
        # back to lambda = 2**shift mu: exact scalings, unless they overflow
        im, rad = math.ldexp(zi.imag, shift), math.ldexp(r, shift) * UP
        if not (math.isfinite(im) and math.isfinite(rad)):
            return False
        centre[k], R[k] = zi, r
        k += 1
        best = max(best, im)
        upper = max(upper, (im + rad) * UP)
        lower = max(lower, (im - rad) * DOWN)
    if k < nc:
        return False
    for j in range(nc):
        prev[j] = complex(math.ldexp(centre[j].real, shift), math.ldexp(centre[j].imag, shift))
    orate[0], orate[1], orate[2] = min(max(best, lower), upper), lower, upper
    return True


@kernel
def _pairs_from_phi(X, z, up, info, nc, d, m, body, E, nmodes, pws, F, dF, dm, dr, centre, R, orate):
    """The rate from the candidates ``z[up[:info[1]]]`` (scaled by 2**info[0]) of ``_pairs``, each with its disk from
    the coefficients X where that is narrow, else with a Newton disk of ``disks.newton_disk`` (p~'/p~ from Phi(z)
    and Phi'(z) in balls; ``pws`` prepared for the point).  As ``_pairs``: nc disjoint disks clear of the axis hold
    all nc pairs.  For Phi's disk the candidate is first polished by Newton steps on det Phi in floats, and the disk
    is centred a little above it (Phi is singular at a root): the least of ``PHI_SHIFTS`` that gives a narrow disk."""
    shift = info[0]
    best, lower, upper = 0.0, 0.0, 0.0
    k = 0
    for j in range(info[1]):
        if k == nc:
            break
        zs = _polish(X, info[2], z[up[j]])
        zi = complex(math.ldexp(zs.real, shift), math.ldexp(zs.imag, shift))
        r, zc = math.ldexp(newton_radius(X, info[2], zs), shift) * UP, zi
        if not (r < zi.imag * NARROW):
            r, zi = _phi_disk(zi, d, m, body, E, nmodes, pws, F, dF, dm, dr)
            zc = zi
        if not (r * UP < zc.imag * NARROW):
            continue
        alone = True
        for i in range(k):
            alone = alone and abs(zc - centre[i]) * DOWN > (r + R[i]) * UP
        if not alone:
            continue
        centre[k], R[k] = zc, r
        k += 1
        best = max(best, zi.imag)
        upper = max(upper, (zc.imag + r) * UP)
        lower = max(lower, (zc.imag - r) * DOWN)
    if k < nc:
        return False
    orate[0], orate[1], orate[2] = min(max(best, lower), upper), lower, upper
    return True


@kernel
def _phi_disk(zi, d, m, body, E, nmodes, pws, F, dF, dm, dr):
    """(radius, centre) of a Newton disk from Phi around zi polished on det Phi: the first of ``PHI_SHIFTS`` whose
    disk is narrow; (inf, zi) if none."""
    for _ in range(PHI_NEWTON):
        step = approximations.newton_ratio(zi, m, body, E, nmodes, pws, F, dF)
        if not (math.isfinite(step.real) and math.isfinite(step.imag)):
            break
        zi = zi - step
        if abs(step) <= STEP_TOL * abs(zi):
            break
    if not zi.imag > 0.0:
        return np.inf, zi
    for s in PHI_SHIFTS:
        zc = complex(zi.real, zi.imag + s * abs(zi))
        r = disks.newton_disk(zc, d, m, body, E, nmodes, pws, dm, dr)
        if r * UP < zc.imag * NARROW:
            return r, zc
    return np.inf, zi


@kernel
def _farthest(z, d, share, up):
    """Every approximation more than UPPER_SHARE above the axis (relative) into up, farthest first; their number.

    A real cluster that float Aberth resolves only to u^(1/k) shows as near-real pairs, seldom as the farthest ones.
    """
    for i in range(d):
        share[i] = z[i].imag / abs(z[i]) if z[i].imag > 0.0 else 0.0
    for j in range(d):
        best_i, best_t = -1, UPPER_SHARE
        for i in range(d):
            if share[i] > best_t:
                best_i, best_t = i, share[i]
        if best_i < 0:
            return j
        up[j] = best_i
        share[best_i] = 0.0
    return d


@kernel
def _aberth_pairs(a, d, z, done, share, up, nc):
    """Float Aberth-Ehrlich sweeps on every approximation, until the nc farthest above the axis have converged; the
    number of candidates for pairs (``_farthest``).

    The others (the real roots, clusters among them converging slowly) only need to be good enough to repel.
    """
    done[:d] = False
    for _ in range(MAX_SWEEPS):
        moving = False
        for i in range(d):
            if done[i]:
                continue
            zr, zi = z[i].real, z[i].imag
            # p, p' by Horner and sum 1 / (z_i - z_j), in real arithmetic (numba's complex division branches)
            pr, pi, dr, di, sc = a[d], 0.0, 0.0, 0.0, abs(a[d])
            ab = math.hypot(zr, zi)
            for k in range(d - 1, -1, -1):
                dr, di = dr * zr - di * zi + pr, dr * zi + di * zr + pi
                pr, pi = pr * zr - pi * zi + a[k], pr * zi + pi * zr
                sc = sc * ab + abs(a[k])
            if math.hypot(pr, pi) <= dd.U * sc:
                done[i] = True
                continue
            den = dr * dr + di * di
            if not den > 0.0:
                done[i] = True
                continue
            qr, qi = (pr * dr + pi * di) / den, (pi * dr - pr * di) / den  # ratio p / p'
            sr, si = 0.0, 0.0
            for j in range(d):
                if j != i:
                    xr, xi = zr - z[j].real, zi - z[j].imag
                    m2 = xr * xr + xi * xi
                    if m2 > 0.0:
                        sr += xr / m2
                        si -= xi / m2
            br, bi = 1.0 - (qr * sr - qi * si), -(qr * si + qi * sr)
            den = br * br + bi * bi
            if not den > 0.0:
                done[i] = True
                continue
            tr, ti = (qr * br + qi * bi) / den, (qi * br - qr * bi) / den  # Aberth's step ratio / (1 - ratio s)
            if not (math.isfinite(tr) and math.isfinite(ti)):
                return False
            z[i] = complex(zr - tr, zi - ti)
            if math.hypot(tr, ti) <= FLOAT_TOL * abs(z[i]):
                done[i] = True
            else:
                moving = True
        if not moving:
            break
        k = _farthest(z, d, share, up)
        if k >= nc:
            settled = True
            for j in range(nc):
                settled = settled and done[up[j]]
            if settled:
                return k
    return _farthest(z, d, share, up)


@kernel
def _polish(X, d, z):
    """Newton steps on the interval polynomial's midpoint in double-double, until z has the digits a float holds."""
    for _ in range(POLISH):
        re, im, dre, dim = horner_dd(X, d, z.real, z.imag)
        p = complex(re[0] + re[1], im[0] + im[1])
        dp = complex(dre[0] + dre[1], dim[0] + dim[1])
        if p == 0.0 or dp == 0.0:
            break
        step = p / dp
        if not (math.isfinite(step.real) and math.isfinite(step.imag)):
            break
        z = z - step
        if abs(step) <= STEP_TOL * abs(z):
            break
    return z


@kernel
def newton_radius(X, d, z):
    """d |q(z)| / |q'(z)| bounded above over every polynomial q in X (degree d): a disk around z that holds a root of
    each; inf where |q'(z)| is not bounded away from 0."""
    re, im, dre, dim = horner_dd(X, d, z.real, z.imag)
    top = math.hypot(abs(re[0]) * dd.ABS + re[2], abs(im[0]) * dd.ABS + im[2]) * UP
    bre = (abs(dre[0]) * (1.0 - 4.0 * dd.U) - dre[2]) * DOWN
    bim = (abs(dim[0]) * (1.0 - 4.0 * dd.U) - dim[2]) * DOWN
    bottom = math.hypot(max(bre, 0.0), max(bim, 0.0)) * DOWN
    if not (bottom > 0.0 and math.isfinite(top)):
        return np.inf
    return d * top / bottom * UP * UP


__all__ = ["rate_block", "newton_radius", "RATE_PAIRS", "RATE_ALL_ROOTS", "RATE_FAILED"]
