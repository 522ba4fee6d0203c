"""Non-real roots of p proved by disks, from Phi(z) in ball arithmetic (docs/certification.md, section 4).

Newton disks: some root of p~ = p / z^m lies within d / |p~'/p~(z)| of any z,
and p~'/p~ = trace(Phi^-1 Phi') + sum 1 / (z + beta) - m / z is enclosed by
elimination in balls.  Gerschgorin disks of Braess & Hadeler: radius
d |w_i| around every approximation, |p~(z_i)| bounded from det Phi(z_i), the
leading coefficient det(M - diag sum E) bounded below.
"""

from __future__ import annotations

import math

import numpy as np

from . import ball, elimination, layout, pencil
from .approximations import UPPER
from .inclusion import find_root, group_disks
from .options import kernel

SMALL = 8  # bodies up to which plain elimination in balls beats preconditioning (BLAS products)
SHIFTS = (2.0**-30, 2.0**-20, 2.0**-12)  # a Newton disk is centred this far (relative) above its root


@kernel
def nonreal_in_disks(z, d, m, body, E, nmodes, pws, R, group, lead_m, lead_e):
    """Roots of p~ proved non-real by the disks of Braess & Hadeler around z (module docstring)."""
    n = body.shape[0]
    cm, cr = pws.cm, pws.cr
    for i in range(d):
        zi = z[i]
        ok, qm, qr = pencil.complex_matrix(zi, 0.0, body, E, nmodes, pws)
        R[i] = np.inf
        if not ok:
            continue
        ok, mant, expo = elimination.det_bound(cm, cr, n, False)
        if not ok:
            continue
        mant, e = math.frexp(mant * (abs(qm) + qr) * ball.INFL)
        expo += e - lead_e
        mant = mant / lead_m * ball.INFL
        for _ in range(m):  # p~ = p / z^m
            if zi == 0.0:
                return 0
            mant, e = math.frexp(mant / (abs(zi) * ball.LOW) * ball.INFL)
            expo += e
        for j in range(d):
            if j == i:
                continue
            dist = abs(zi - z[j]) * ball.LOW
            if dist == 0.0:
                return 0
            mant, e = math.frexp(mant / dist * ball.INFL)
            expo += e
        if expo > 1000:
            continue
        R[i] = math.ldexp(mant * d * ball.INFL, expo) + ball.ETA
        if not R[i] <= np.inf:  # NaN: an infinite disk, which proves nothing
            R[i] = np.inf
    group_disks(z, R, d, group)
    # a group touching the axis anywhere proves nothing; count members of the others
    touches = np.zeros(d, np.bool_)
    for i in range(d):
        if abs(z[i].imag) * ball.LOW <= R[i] * ball.INFL:
            touches[find_root(group, i)] = True
    nonreal = 0
    for i in range(d):
        if not touches[find_root(group, i)]:
            nonreal += 1
    return nonreal


@kernel
def lead_bound(pws, n, Sm, Sr):
    """Lower bound of |det (M - diag(sum E))| (the leading coefficient of p) as (ok, mantissa, exponent), and the
    number of negative eigenvalues of that matrix (-1 if unproved)."""
    mat, vec = pws.mat, pws.vec
    for i in range(n):
        for j in range(i + 1):
            Sm[i, j], Sr[i, j] = mat[layout.M_MID, i, j], mat[layout.M_RAD, i, j]
        Sm[i, i], Sr[i, i] = ball.radd(Sm[i, i], Sr[i, i], -vec[layout.ESUM_MID, i], vec[layout.ESUM_RAD, i])
    neg, mant, expo = elimination.ldl(Sm, Sr, n)
    return neg >= 0, mant, expo, neg


@kernel
def newton_disk(zc, d, m, body, E, nmodes, pws, dm, dr):
    """Radius of a disk around zc that holds a root of p~, or inf: d / |p~'(zc) / p~(zc)| bounded below.

    p~'/p~ = sum over the d roots r of p~ of 1 / (z - r), so some root lies
    within d / |p~'/p~| of z; the ratio is trace(Phi^-1 Phi') + sum 1 / (z + beta)
    - m / z, solved in balls.
    """
    n = body.shape[0]
    ok, qm, qr = pencil.complex_matrix(zc, 0.0, body, E, nmodes, pws)
    if not ok:
        return np.inf
    lm, lr = pencil.complex_derivative(zc, body, E, nmodes, pws, dm, dr)
    if not math.isfinite(lr) or not ball.excludes_zero(zc, 0.0):
        return np.inf
    if n <= SMALL:
        ok, tm, tr = elimination.trace_bound(pws.cm, pws.cr, dm, dr, n)
    else:
        ok, tm, tr = elimination.trace_preconditioned(pws.cm, pws.cr, dm, dr, n)
    if not ok:
        return np.inf
    sm, sr = ball.cadd(tm, tr, lm, lr)
    zm, zr = ball.cdiv(float(m) + 0.0j, 0.0, zc, 0.0)
    sm, sr = ball.cadd(sm, sr, -zm, zr)
    low = abs(sm) * ball.LOW - sr * ball.INFL
    if not low > 0.0:
        return np.inf
    return d / (low * ball.LOW) * ball.INFL


@kernel
def nonreal_newton(z, d, m, body, E, nmodes, pws, dm, dr, R, centre):
    """Non-real roots proved by disjoint Newton disks in the upper half plane (twice their number: conjugates)."""
    k = 0
    for i in range(d):
        zi = z[i]
        if not zi.imag > UPPER * abs(zi):
            continue
        found = False
        r, zc = np.inf, zi
        for shift in SHIFTS:
            zc = complex(zi.real, zi.imag + shift * abs(zi))
            r = newton_disk(zc, d, m, body, E, nmodes, pws, dm, dr)
            if r * ball.INFL < zc.imag * ball.LOW:
                found = True
                break
        if not found:
            continue
        alone = True
        for j in range(k):
            if abs(zc - centre[j]) * ball.LOW <= (r + R[j]) * ball.INFL:
                alone = False
                break
        if alone:
            centre[k], R[k] = zc, r
            k += 1
    return 2 * k
