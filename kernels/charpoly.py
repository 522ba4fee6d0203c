"""Characteristic polynomial of one parameter point, in rigorous interval arithmetic.

MODEL.md: p(lambda) = det Phi(lambda) * prod_k Q_k(lambda) with
Phi = lambda^2 M + lambda G - K - diag(liquid_k) and Q_k = prod_l (lambda + beta_kl),
beta_kl = omega_k - lambda_kl = omega_k (kappa_kl - 2) / kappa_kl.

We expand det(diag(Q) Phi T) instead, with T the lower-triangular matrix of ones
(theta = T phi, phi the relative tilts).  det T = 1, so the polynomial is the
same, but K T is exact and sparse: the elastic Laplacian maps column j of T to
K_{j-1} (e_j - e_{j-1}).  Hence every zero that the physics puts into the
constant terms (the rigid tilt of a free chain, ideal joints, g = 0) is an exact
zero, and the matching lambda = 0 roots are factored out exactly instead of
being smeared into tiny nonzero coefficients.

Every number is an interval (hi, lo, rad) of ``dd.py`` stored along a last axis
of length 3.  Per-point parameter layout (all float64):
  body[k]   = (m, A, C, c, s, omega) of body k (0-based, bottom first)
  joint[k]  = K_k, k = 0..n-1 (K_0 is the base stiffness, fixed support only)
  g         = gravity (fixed support only)
  E[k, l], kappa[k, l] for l < nmodes[k]
"""

from __future__ import annotations

import numpy as np

from . import dd
from .options import kernel


@kernel
def _set(X, i, v):
    X[i, 0], X[i, 1], X[i, 2] = v


@kernel
def _lever_arms(body, free, J):
    """Write the lever-arm matrix J (MODEL.md) into J (n, n, 3)."""
    n = body.shape[0]
    J[:] = 0.0
    for k in range(n):
        for i in range(k):
            J[k, i, 0] = body[i, 4]
        J[k, k, 0] = body[k, 3]
    if not free:
        return
    mt = (0.0, 0.0, 0.0)
    for k in range(n):
        mt = dd.add(*mt, body[k, 0], 0.0, 0.0)
    for i in range(n):
        s = (0.0, 0.0, 0.0)
        for j in range(n):
            s = dd.fma(*s, body[j, 0], 0.0, 0.0, J[j, i, 0], J[j, i, 1], J[j, i, 2])
        mh, ml, mr = dd.div(*s, *mt)
        for k in range(n):
            J[k, i, 0], J[k, i, 1], J[k, i, 2] = dd.add(J[k, i, 0], J[k, i, 1], J[k, i, 2], -mh, -ml, mr)


@kernel
def _stiffness_T(body, joint, g, free, K):
    """Write K T (see module docstring) into K (n, n, 3)."""
    n = body.shape[0]
    K[:] = 0.0
    for j in range(1, n):
        K[j, j, 0] = joint[j]
        K[j - 1, j, 0] = -joint[j]
    if free:
        return
    K[0, 0, 0] = joint[0]
    above = (0.0, 0.0, 0.0)  # mass of the bodies above body k
    for k in range(n - 1, -1, -1):
        a = dd.mul(body[k, 0], 0.0, 0.0, body[k, 3], 0.0, 0.0)
        a = dd.fma(*a, body[k, 4], 0.0, 0.0, *above)  # a_k = m_k c_k + s_k sum_{j>k} m_j
        ga = dd.mul(g, 0.0, 0.0, *a)
        for j in range(k + 1):
            K[k, j, 0], K[k, j, 1], K[k, j, 2] = dd.add(K[k, j, 0], K[k, j, 1], K[k, j, 2], *dd.neg(*ga))
        above = dd.add(*above, body[k, 0], 0.0, 0.0)


@kernel
def _inertia_T(body, J, M):
    """Write M T, M = diag(A) + J^T diag(m) J, into M (n, n, 3)."""
    n = body.shape[0]
    for i in range(n):
        for j in range(n):
            acc = (body[i, 1], 0.0, 0.0) if i == j else (0.0, 0.0, 0.0)
            for k in range(n):
                t = dd.mul(body[k, 0], 0.0, 0.0, J[k, i, 0], J[k, i, 1], J[k, i, 2])
                acc = dd.fma(*acc, *t, J[k, j, 0], J[k, j, 1], J[k, j, 2])
            _set(M[i], j, acc)
    # Column j of M T collects the columns i >= j of M.
    for k in range(n):
        for j in range(n - 2, -1, -1):
            _set(M[k], j, dd.add(M[k, j, 0], M[k, j, 1], M[k, j, 2], M[k, j + 1, 0], M[k, j + 1, 1], M[k, j + 1, 2]))


@kernel
def _liquid_polys(omega, E, kappa, L, q, w):
    """Q = prod_l (lambda + beta_l) into q and R = sum_l E_l prod_{l' != l} (lambda + beta_l') into w."""
    q[: L + 1] = 0.0
    w[: L + 1] = 0.0
    q[0, 0] = 1.0
    for l in range(L):
        kap = kappa[l]
        # two_sum makes kappa - 2 exact, so beta is an exact zero when kappa == 2.
        h, lo = dd.two_sum(kap, -2.0)
        beta = dd.mul(omega, 0.0, 0.0, h, lo, 0.0)
        beta = dd.div(*beta, kap, 0.0, 0.0)
        # w <- w (lambda + beta) + E_l q ; q <- q (lambda + beta)   (w uses the old q)
        for a in range(l + 1, 0, -1):
            t = dd.mul(w[a, 0], w[a, 1], w[a, 2], *beta)
            t = dd.add(*t, w[a - 1, 0], w[a - 1, 1], w[a - 1, 2])
            _set(w, a, dd.fma(*t, E[l], 0.0, 0.0, q[a, 0], q[a, 1], q[a, 2]))
        t = dd.mul(w[0, 0], w[0, 1], w[0, 2], *beta)
        _set(w, 0, dd.fma(*t, E[l], 0.0, 0.0, q[0, 0], q[0, 1], q[0, 2]))
        for a in range(l + 1, 0, -1):
            _set(q, a, dd.fma(q[a - 1, 0], q[a - 1, 1], q[a - 1, 2], q[a, 0], q[a, 1], q[a, 2], *beta))
        _set(q, 0, dd.mul(q[0, 0], q[0, 1], q[0, 2], *beta))


@kernel
def _matrix(body, joint, g, E, kappa, nmodes, free, J, M, K, q, w, P, reuse):
    """Write P = diag(Q) Phi T as interval polynomials into P (n, n, 3 + Lmax, 3).

    Row k has degree 2 + nmodes[k]; unused trailing coefficients are exact zeros.
    ``reuse``: M T and K T in M, K are those of this point already (only omega
    or the liquid changed since the previous point).
    """
    n = body.shape[0]
    if not reuse:
        _lever_arms(body, free, J)
        _inertia_T(body, J, M)
        _stiffness_T(body, joint, g, free, K)
    P[:] = 0.0
    for k in range(n):
        L = nmodes[k]
        omega = body[k, 5]
        _liquid_polys(omega, E[k], kappa[k], L, q, w)
        G = dd.mul(body[k, 2], 0.0, 0.0, omega, 0.0, 0.0)  # C_k omega_k
        for j in range(n):
            e = P[k, j]
            # P_kj = Q (lambda^2 MT_kj + lambda GT_kj - KT_kj) - [j <= k] lambda^2 (lambda + omega) R
            mk = (M[k, j, 0], M[k, j, 1], M[k, j, 2])
            kk = (-K[k, j, 0], -K[k, j, 1], K[k, j, 2])
            for a in range(L + 1):
                qa = (q[a, 0], q[a, 1], q[a, 2])
                if dd.is_zero(*qa):
                    continue
                _set(e, a, dd.fma(e[a, 0], e[a, 1], e[a, 2], *qa, *kk))
                if j <= k:
                    _set(e, a + 1, dd.fma(e[a + 1, 0], e[a + 1, 1], e[a + 1, 2], *qa, *G))
                _set(e, a + 2, dd.fma(e[a + 2, 0], e[a + 2, 1], e[a + 2, 2], *qa, *mk))
            if j <= k:
                for a in range(L):
                    wa = (w[a, 0], w[a, 1], w[a, 2])
                    _set(e, a + 3, dd.add(e[a + 3, 0], e[a + 3, 1], e[a + 3, 2], *dd.neg(*wa)))
                    _set(e, a + 2, dd.fma(e[a + 2, 0], e[a + 2, 1], e[a + 2, 2], -omega, 0.0, 0.0, *wa))


@kernel
def _popcount(x):
    c = 0
    while x:
        x &= x - 1
        c += 1
    return c


@kernel
def _laplace_det(P, rowdeg, D, out):
    """Determinant of the interval polynomial matrix P by expansion in minors.

    Minors of the first k+1 rows are kept for every set of k+1 columns (bit
    masks into D of shape (2**n, deg+1, 3)); each is expanded along its last
    row.  Division-free, so exact zeros stay exact.  Writes deg+1 coefficients.
    """
    n = P.shape[0]
    full = (1 << n) - 1
    deg = 0
    for k in range(n):
        deg += rowdeg[k]
        for mask in range(1, full + 1):
            if _popcount(mask) != k + 1:
                continue
            Dm = D[mask]
            Dm[: deg + 1] = 0.0
            if k == 0:
                j = 0
                while not (mask >> j) & 1:
                    j += 1
                Dm[: rowdeg[0] + 1] = P[0, j, : rowdeg[0] + 1]
                continue
            subdeg = deg - rowdeg[k]
            pos = 0
            for j in range(n):
                if not (mask >> j) & 1:
                    continue
                S = D[mask ^ (1 << j)]
                sign = 1.0 if (k + pos) % 2 == 0 else -1.0
                pos += 1
                for a in range(rowdeg[k] + 1):
                    eh, el, er = P[k, j, a, 0], P[k, j, a, 1], P[k, j, a, 2]
                    if dd.is_zero(eh, el, er):
                        continue
                    eh *= sign
                    el *= sign
                    for b in range(subdeg + 1):
                        if dd.is_zero(S[b, 0], S[b, 1], S[b, 2]):
                            continue
                        _set(Dm, a + b, dd.fma(Dm[a + b, 0], Dm[a + b, 1], Dm[a + b, 2], eh, el, er, S[b, 0], S[b, 1], S[b, 2]))
    out[: deg + 1] = D[full, : deg + 1]


@kernel
def _zero_entry(P, i, j):
    for a in range(P.shape[2]):
        if not dd.is_zero(P[i, j, a, 0], P[i, j, a, 1], P[i, j, a, 2]):
            return False
    return True


@kernel
def _zero_rect(P, r0, r1, c0, c1):
    for i in range(r0, r1):
        for j in range(c0, c1):
            if not _zero_entry(P, i, j):
                return False
    return True


@kernel
def diagonal_blocks(P, starts):
    """Split P into diagonal blocks whose determinants multiply to det P; returns their number.

    At a split s the rectangle rows < s, columns >= s or the rectangle rows >= s,
    columns < s holds only exact zeros, so det P = det P[:s, :s] det P[s:, s:]
    (and the sub-blocks inherit the zero rectangles).  Block b is
    starts[b]:starts[b + 1]; starts needs n + 1 entries.  A chain whose upper
    bodies have a_k = 0 and ideal joints splits into n blocks (MODEL.md).
    """
    n = P.shape[0]
    nb = 0
    starts[0] = 0
    for s in range(1, n):
        if _zero_rect(P, 0, s, s, n) or _zero_rect(P, s, n, 0, s):
            nb += 1
            starts[nb] = s
    nb += 1
    starts[nb] = n
    return nb


@kernel
def allocate(n, lmax, degree):
    """Scratch arrays for one block: allocated once per block, reused for every point."""
    J = np.empty((n, n, 3))
    M = np.empty((n, n, 3))
    K = np.empty((n, n, 3))
    q = np.empty((lmax + 1, 3))
    w = np.empty((lmax + 1, 3))
    P = np.empty((n, n, lmax + 3, 3))
    D = np.empty((1 << n, degree + 1, 3))
    return J, M, K, q, w, P, D


@kernel
def same_structure(body, joint, g, p):
    """True if point p has the inertia and stiffness of point p - 1 (only omega or the liquid differ)."""
    if p == 0 or g[p] != g[p - 1]:
        return False
    for k in range(body.shape[1]):
        if joint[p, k] != joint[p - 1, k]:
            return False
        for col in range(5):  # m, A, C, c, s; column 5 is omega
            if body[p, k, col] != body[p - 1, k, col]:
                return False
    return True


@kernel
def matrix_point(body, joint, g, E, kappa, nmodes, free, ws, reuse):
    """Build P = diag(Q) Phi T of one point into ws[5]; ws from ``allocate``."""
    J, M, K, q, w, P, D = ws
    _matrix(body, joint, g, E, kappa, nmodes, free, J, M, K, q, w, P, reuse)


@kernel
def block_det(ws, rowdeg, i0, i1, out):
    """Enclosure of det P[i0:i1, i0:i1] (after ``matrix_point``) into out; returns its degree bound."""
    P, D = ws[5], ws[6]
    _laplace_det(P[i0:i1, i0:i1], rowdeg[i0:i1], D, out)
    return int(rowdeg[i0:i1].sum())


@kernel
def charpoly_point(body, joint, g, E, kappa, nmodes, rowdeg, free, ws, out, reuse=False):
    """Enclosure of p(lambda) for one point into out (deg + 1, 3); ws from ``allocate``, rowdeg = nmodes + 2."""
    matrix_point(body, joint, g, E, kappa, nmodes, free, ws, reuse)
    block_det(ws, rowdeg, 0, body.shape[0], out)
