"""Gaussian elimination on small matrices: inertia and determinant bounds in balls, a float trace.

All three work in place on n x n scratch and allocate nothing.
"""

from __future__ import annotations

import math

import numpy as np

from . import ball
from .options import kernel


@kernel
def ldl(Sm, Sr, n):
    """Inertia and |det| of the symmetric matrix enclosed by the balls Sm, Sr (lower triangle read).

    Returns (number of negative eigenvalues, mantissa, exponent) with a lower
    bound mantissa * 2**exponent of |det|; the count is -1 if unproved.
    Symmetric elimination with diagonal pivoting (the largest remaining diagonal
    midpoint; without it the balls grow until a pivot is unprovable):
    P S P^t = L D L^t is a congruence, so by Sylvester's law the inertia of S is
    that of the pivots D.  Each pivot's ball encloses the exact pivot of the
    exact matrix as long as the earlier pivots exclude zero, so a pivot that
    excludes zero has a proved sign; one that does not leaves the count
    unproved.  The upper triangle is neither read nor written.
    """
    neg, mant, expo = 0, 1.0, 0
    for step in range(n):
        p, best = step, -1.0
        for i in range(step, n):
            a = abs(Sm[i, i])
            if a > best:
                p, best = i, a
        if p != step:
            _swap_symmetric(Sm, Sr, n, step, p)
        pm, pr = Sm[step, step], Sr[step, step]
        if not ball.excludes_zero(pm, pr):
            return -1, mant, expo
        if pm < 0.0:
            neg += 1
        mant, e = math.frexp(mant * (abs(pm) * ball.LOW - pr * ball.INFL) * ball.LOW)
        expo += e
        for i in range(step + 1, n):
            lm, lr = ball.rdiv(Sm[i, step], Sr[i, step], pm, pr)
            for j in range(step + 1, i + 1):
                t = ball.rmul(lm, lr, Sm[j, step], Sr[j, step])
                Sm[i, j], Sr[i, j] = ball.radd(Sm[i, j], Sr[i, j], -t[0], t[1])
    return neg, mant, expo


@kernel
def inertia(Sm, Sr, n):
    """Number of negative eigenvalues of the symmetric ball matrix (Sm, Sr); -1 if unproved (``ldl``)."""
    return ldl(Sm, Sr, n)[0]


@kernel
def _swap_symmetric(Sm, Sr, n, a, b):
    """Swap rows and columns a < b of the symmetric matrix kept in its lower triangle (O(n))."""
    for X in (Sm, Sr):
        X[a, a], X[b, b] = X[b, b], X[a, a]
        for j in range(a):
            X[a, j], X[b, j] = X[b, j], X[a, j]
        for i in range(a + 1, b):
            X[i, a], X[b, i] = X[b, i], X[i, a]
        for i in range(b + 1, n):
            X[i, a], X[i, b] = X[i, b], X[i, a]


@kernel
def _pivot(A, step, n):
    """The row at or below ``step`` with the largest |A[row, step]| (partial pivoting)."""
    p, best = step, -1.0
    for i in range(step, n):
        a = abs(A[i, step])
        if a > best:
            p, best = i, a
    return p, best


@kernel
def _swap_rows(X, a, b):
    for j in range(X.shape[1]):
        X[a, j], X[b, j] = X[b, j], X[a, j]


@kernel
def det_bound(cm, cr, n, lower):
    """A bound of |det| over the complex ball matrix (cm, cr) as (ok, mantissa, exponent).

    Upper bound, or with ``lower`` a lower bound (then ok also proves det != 0).
    Partial pivoting on the midpoints; every pivot but the last must exclude
    zero (it divides); for the upper bound the last one only contributes
    |pivot| + radius.
    """
    mant, expo = 1.0, 0
    for step in range(n):
        p = _pivot(cm, step, n)[0]
        if p != step:
            _swap_rows(cm, step, p)
            _swap_rows(cr, step, p)
        pm, pr = cm[step, step], cr[step, step]
        if lower:
            if not ball.excludes_zero(pm, pr):
                return False, mant, expo
            mant, e = math.frexp(mant * (abs(pm) * ball.LOW - pr * ball.INFL) * ball.LOW)
        else:
            mant, e = math.frexp(mant * (abs(pm) + pr) * ball.INFL)
        expo += e
        if step == n - 1:
            break
        if not ball.excludes_zero(pm, pr):
            return False, mant, expo
        im, ir = ball.cinv(pm, pr)
        for i in range(step + 1, n):
            lm, lr = ball.cmul(cm[i, step], cr[i, step], im, ir)
            for j in range(step + 1, n):
                t = ball.cmul(lm, lr, cm[step, j], cr[step, j])
                cm[i, j], cr[i, j] = ball.cadd(cm[i, j], cr[i, j], -t[0], t[1])
    return math.isfinite(mant), mant, expo


@kernel
def trace_solve(F, dF, n):
    """trace(F^-1 dF) in floats (LU with partial pivoting), destroying F and dF; nan if F is singular.

    With F = Phi T this is (d/dz) log det Phi T: the Newton direction of the determinant.
    """
    for step in range(n):
        p, best = _pivot(F, step, n)
        if best == 0.0:
            return complex(math.nan, math.nan)
        if p != step:
            _swap_rows(F, step, p)
            _swap_rows(dF, step, p)
        inv = 1.0 / F[step, step]
        for i in range(step + 1, n):
            f = F[i, step] * inv
            for j in range(step + 1, n):
                F[i, j] -= f * F[step, j]
            for j in range(n):
                dF[i, j] -= f * dF[step, j]
    # back substitution, column by column; only the diagonal of F^-1 dF is summed, and
    # entry (c, c) needs the rows below c only
    tr = 0.0j
    for c in range(n):
        for i in range(n - 1, c - 1, -1):
            s = dF[i, c]
            for j in range(i + 1, n):
                s -= F[i, j] * dF[j, c]
            dF[i, c] = s / F[i, i]
        tr += dF[c, c]
    return tr


@kernel
def trace_bound(cm, cr, dm, dr, n):
    """Ball of trace(F^-1 dF) for the ball matrices F = (cm, cr), dF = (dm, dr), destroying both.

    As ``trace_solve`` in balls; (ok, midpoint, radius), ok False if a pivot may vanish.
    """
    for step in range(n):
        p = _pivot(cm, step, n)[0]
        if p != step:
            for X in (cm, dm):
                _swap_rows(X, step, p)
            for X in (cr, dr):
                _swap_rows(X, step, p)
        if not ball.excludes_zero(cm[step, step], cr[step, step]):
            return False, 0.0j, 0.0
        im, ir = ball.cinv(cm[step, step], cr[step, step])
        for i in range(step + 1, n):
            fm, fr = ball.cmul(cm[i, step], cr[i, step], im, ir)
            for j in range(step + 1, n):
                t = ball.cmul(fm, fr, cm[step, j], cr[step, j])
                cm[i, j], cr[i, j] = ball.cadd(cm[i, j], cr[i, j], -t[0], t[1])
            for j in range(n):
                t = ball.cmul(fm, fr, dm[step, j], dr[step, j])
                dm[i, j], dr[i, j] = ball.cadd(dm[i, j], dr[i, j], -t[0], t[1])
    tm, tr = 0.0j, 0.0
    for c in range(n):
        for i in range(n - 1, c - 1, -1):
            sm, sr = dm[i, c], dr[i, c]
            for j in range(i + 1, n):
                t = ball.cmul(cm[i, j], cr[i, j], dm[j, c], dr[j, c])
                sm, sr = ball.cadd(sm, sr, -t[0], t[1])
            dm[i, c], dr[i, c] = ball.cdiv(sm, sr, cm[i, i], cr[i, i])
        tm, tr = ball.cadd(tm, tr, dm[c, c], dr[c, c])
    return True, tm, tr


@kernel
def _float_inverse(A, X, n):
    """X = A^-1 in floats by Gauss-Jordan with partial pivoting; False if a pivot is 0 or not finite.

    (numba's np.linalg.inv raises on a singular matrix, which a kernel must not.)
    """
    W = A.copy()
    X[:] = 0.0
    for i in range(n):
        X[i, i] = 1.0
    for step in range(n):
        p, best = _pivot(W, step, n)
        if not (best > 0.0 and math.isfinite(best)):
            return False
        if p != step:
            _swap_rows(W, step, p)
            _swap_rows(X, step, p)
        inv = 1.0 / W[step, step]
        for j in range(n):
            W[step, j] *= inv
            X[step, j] *= inv
        for i in range(n):
            if i != step:
                f = W[i, step]
                if f != 0.0:
                    for j in range(n):
                        W[i, j] -= f * W[step, j]
                        X[i, j] -= f * X[step, j]
    return True


@kernel
def trace_preconditioned(cm, cr, dm, dr, n):
    """Ball of trace(F^-1 G) for the ball matrices F = (cm, cr), G = (dm, dr) by preconditioning.

    X ~ inverse of F's midpoint in floats; A = X F and B = X G as balls from
    float matrix products (Rump: a float sum of n products errs by at most
    gamma = (2 n + 8) u times the sum of the products' moduli, and the float
    sums of nonnegative terms are inflated by 1 + 2 (n + 2) u).  With
    E = I - A and eta >= ||E||_inf < 1, A is invertible (so is F) and
        trace(F^-1 G) = trace(A^-1 B) = trace(B) + trace(E B) + trace(E^2 (I - E)^-1 B),
    the last term bounded by n eta^2 ||B||_inf / (1 - eta) (|trace M| <= n ||M||).
    Only the products are O(n^3), and those run at BLAS speed.
    (ok, midpoint, radius); ok False if the midpoint is singular or eta >= 1/2.
    """
    X = np.empty((n, n), np.complex128)
    if not _float_inverse(cm, X, n):
        return False, 0.0j, 0.0
    aX = np.abs(X)
    gamma = (2.0 * n + 8.0) * ball.U
    grow = (1.0 + 2.0 * (n + 2) * ball.U) * ball.INFL
    am = X @ cm
    ar = (aX @ cr + gamma * (aX @ np.abs(cm))) * grow + ball.ETA
    bm = X @ dm
    br = (aX @ dr + gamma * (aX @ np.abs(dm))) * grow + ball.ETA
    eta, bnorm = 0.0, 0.0
    for i in range(n):
        re, rb = 0.0, 0.0
        for j in range(n):
            e = -am[i, j] + (1.0 if i == j else 0.0)
            re += abs(e) + ar[i, j] + (2.0 * ball.U if i == j else 0.0)
            rb += abs(bm[i, j]) + br[i, j]
        eta = max(eta, re * grow)
        bnorm = max(bnorm, rb * grow)
    if not eta < 0.5:
        return False, 0.0j, 0.0
    tm, tr = 0.0j, 0.0
    for i in range(n):
        tm, tr = ball.cadd(tm, tr, bm[i, i], br[i, i])
        for j in range(n):
            em, er = ball.cadd(-am[i, j], ar[i, j], 1.0 + 0.0j if i == j else 0.0j, 0.0)
            t = ball.cmul(em, er, bm[j, i], br[j, i])
            tm, tr = ball.cadd(tm, tr, t[0], t[1])
    tail = n * eta * eta * bnorm / (1.0 - eta) * grow / ball.LOW
    return True, tm, (tr + tail) * ball.INFL
