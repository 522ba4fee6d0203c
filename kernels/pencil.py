"""The characteristic matrix of one point as float balls, evaluated without forming p(lambda).

docs/model.md: Phi(z) = z^2 M + z G - K - diag(z^2 (z + omega_k) sum_l E_kl / (z + beta_kl))
and p(z) = det Phi(z) prod_kl (z + beta_kl).  With T the path matrix of
``charpoly`` (det T = 1), K T is exact in double-double: a column of K T that
is exactly zero makes that column of Phi T divisible by z.  ``prepare`` counts
those columns, so m structural zero roots of p (rigid tilts, ideal joints,
g = 0) are known exactly, and p~(z) = p(z) / z^m = det Phi(z) prod (z + beta) / z^m.

Evaluations use Phi itself (M = (M T) T^-1 and K = (K T) T^-1, exact
column operations): T's cumulative sums would cost a factor ~n^2 in
condition, which the balls of a 32-body chain cannot afford.  For real x,
Phi(x) is real symmetric (``real_matrix``).

The workspace ``ws`` (from ``allocate``) holds, per point, the balls of M T,
K T, M, K, G, beta and sum_l E_kl (M - diag(sum_l E_kl) has the leading
coefficient of p as its determinant).
"""

from __future__ import annotations

import numpy as np

from . import ball, layout
from .charpoly import check_parent, path_matrix, structure
from .dd import two_sum
from .options import kernel


@kernel
def allocate(n, lmax, parent):
    """Scratch for one block; checks ``parent`` (ValueError unless a regular numbering)."""
    check_parent(parent, n)
    T = np.empty((n, n), np.bool_)
    path_matrix(parent, T)
    jmk = np.empty((3, n, n, 3))  # J, M T, K T in double-double intervals
    sub = np.empty((n, 3))
    mat = np.empty((layout.PENCIL_MAT, n, n))  # planes named in layout: M T, K T, M, K balls (mid, rad)
    vec = np.zeros((layout.PENCIL_VEC, n))  # rows named in layout: G, sum E balls (mid, rad)
    beta = np.zeros((2, n, max(1, lmax)))  # mid, rad
    krein = np.zeros((n, max(1, lmax)), np.int64)  # sign of c_kl (``prepare``)
    cm = np.empty((n, n), np.complex128)
    cr = np.empty((n, n))
    return layout.PencilWork(T, jmk, sub, mat, vec, beta, krein, cm, cr)


@kernel
def _to_ball(x):
    """A double-double interval (h, l, r) as a float ball."""
    return x[0], (abs(x[1]) + x[2]) * ball.INFL


@kernel
def prepare(body, joint, at, g, E, kappa, nmodes, parent, free, ws, reuse):
    """Fill ``ws`` for one point; ``reuse``: M T and K T are those of the previous point.

    Returns the number m of exact zero roots: columns of K T that are exactly zero, and modes with beta exactly 0
    (kappa = 2, or omega_k = 0), each a factor z of prod Q with no pole in Phi (``_liquid_real``).

    ``ws.krein[k, l]`` gets the sign of c_kl = E_kl beta_kl^2 (omega_k - beta_kl), the bordering entry of the
    pole-free form H (docs/certification.md, section 4): omega_k - beta_kl = 2 omega_k / kappa_kl, so it is the sign
    of E_kl omega_k kappa_kl, read off the inputs with no arithmetic; 0 where the mode has no pole term (beta exactly
    0, or E exactly 0: then p has the exact factor x + beta_kl and H no row for it).
    """
    jmk, sub, mat, vec, beta, krein = ws.jmk, ws.sub, ws.mat, ws.vec, ws.beta, ws.krein
    n = body.shape[0]
    if not reuse:
        structure(body, joint, at, g, parent, free, sub, jmk[0], jmk[1], jmk[2])
        for i in range(n):
            for j in range(n):
                mat[layout.MT_MID, i, j], mat[layout.MT_RAD, i, j] = _to_ball(jmk[1, i, j])
                mat[layout.KT_MID, i, j], mat[layout.KT_RAD, i, j] = _to_ball(jmk[2, i, j])
        # M and K themselves: (X T) T^-1 subtracts from column i the columns of the children of i
        mat[layout.M_MID : layout.K_RAD + 1] = mat[layout.MT_MID : layout.KT_RAD + 1]
        for c in range(n - 1, 0, -1):
            for k in range(n):
                for a in (6, 8):
                    mat[a, k, parent[c]], mat[a + 1, k, parent[c]] = ball.radd(
                        mat[a, k, parent[c]], mat[a + 1, k, parent[c]], -mat[a - 6, k, c], mat[a - 5, k, c]
                    )
    m = 0
    for k in range(n):
        vec[layout.G_MID, k], vec[layout.G_RAD, k] = ball.rmul(body[k, layout.C], 0.0, body[k, layout.OMEGA], 0.0)
        sm, sr = 0.0, 0.0
        for l in range(nmodes[k]):
            sm, sr = ball.radd(sm, sr, E[k, l], 0.0)
            # kappa - 2 exactly as a float pair, so beta is an exact zero when kappa == 2
            h, lo = two_sum(kappa[k, l], -2.0)
            t = ball.rmul(body[k, layout.OMEGA], 0.0, h, abs(lo))
            krein[k, l] = 0
            if h == 0.0 or body[k, layout.OMEGA] == 0.0:
                beta[0, k, l], beta[1, k, l] = 0.0, 0.0
                m += 1
            else:
                beta[0, k, l], beta[1, k, l] = ball.rdiv(t[0], t[1], kappa[k, l], 0.0)
                krein[k, l] = _sign(E[k, l]) * _sign(body[k, layout.OMEGA]) * _sign(kappa[k, l])
        vec[layout.ESUM_MID, k], vec[layout.ESUM_RAD, k] = sm, sr
    # the exact zero roots: a column of K T that is exactly zero makes that column of Phi T divisible by z
    for j in range(n):
        if not _column_nonzero(mat[layout.KT_MID], mat[layout.KT_RAD], j):
            m += 1
    return m


@kernel
def _sign(x):
    return 1 if x > 0.0 else (-1 if x < 0.0 else 0)


@kernel
def _column_nonzero(m, r, j):
    for i in range(m.shape[0]):
        if m[i, j] != 0.0 or r[i, j] != 0.0:
            return True
    return False


@kernel
def _liquid_real(x, k, E, nmodes, beta):
    """(sum_l E_kl / (x + beta_kl) over the modes with beta_kl != 0, sum_l E_kl over those with beta_kl = 0) as
    balls at real x; ok False if x may be a pole.

    A mode with beta exactly 0 (kappa = 2, the sphere's) has no pole: its term x^2 (x + omega) E / x of Phi is
    x (x + omega) E, and dividing by x near 0 would only lose the enclosure there, next to the exact zero roots.
    """
    am, ar, em, er = 0.0, 0.0, 0.0, 0.0
    for l in range(nmodes[k]):
        if beta[0, k, l] == 0.0 and beta[1, k, l] == 0.0:
            em, er = ball.radd(em, er, E[k, l], 0.0)
            continue
        dm, dr = ball.radd(x, 0.0, beta[0, k, l], beta[1, k, l])
        if not ball.excludes_zero(dm, dr):
            return am, ar, em, er, False
        qm, qr = ball.rdiv(E[k, l], 0.0, dm, dr)
        am, ar = ball.radd(am, ar, qm, qr)
    return am, ar, em, er, True


@kernel
def real_matrix(x, body, E, nmodes, parent, ws, Sm, Sr):
    """Balls of Phi(x) (symmetric) at the real float x into Sm, Sr; False if x may be a pole.

    In the original coordinates, not T^t Phi T: next to a pole only one
    diagonal entry is huge, where T^t Phi T would spread it over a block whose
    elimination then cancels it away with its radius left behind.
    """
    mat, vec, beta = ws.mat, ws.vec, ws.beta
    n = body.shape[0]
    x2, x2r = ball.rmul(x, 0.0, x, 0.0)  # with ETA: x * x may underflow
    for k in range(n):
        am, ar, em, er, ok = _liquid_real(x, k, E, nmodes, beta)
        if not ok:
            return False
        # d_k = x G_k - x^2 (x + omega_k) a_k - x (x + omega_k) e_k   (e_k: the modes without a pole)
        wm, wr = ball.radd(x, 0.0, body[k, layout.OMEGA], 0.0)
        t = ball.rmul(x2, x2r, wm, wr)
        t = ball.rmul(t[0], t[1], am, ar)
        gm, gr = ball.rmul(x, 0.0, vec[layout.G_MID, k], vec[layout.G_RAD, k])
        dm, dr = ball.radd(gm, gr, -t[0], t[1])
        if em != 0.0:
            t = ball.rmul(x, 0.0, wm, wr)
            t = ball.rmul(t[0], t[1], em, er)
            dm, dr = ball.radd(dm, dr, -t[0], t[1])
        for j in range(k + 1):
            m, r = ball.rmul(x2, x2r, mat[layout.M_MID, k, j], mat[layout.M_RAD, k, j])
            m, r = ball.radd(m, r, -mat[layout.K_MID, k, j], mat[layout.K_RAD, k, j])
            if j == k:
                m, r = ball.radd(m, r, dm, dr)
            Sm[k, j], Sr[k, j] = m, r
    return True


@kernel
def complex_matrix(z, zr, body, E, nmodes, ws):
    """Balls of Phi(z) at the ball (z, zr) into ws.cm, ws.cr (original coordinates, as ``real_matrix``).

    Returns (ok, prod_kl (z + beta_kl) as a ball): ok False if z may be a pole.
    """
    mat, vec, beta, cm, cr = ws.mat, ws.vec, ws.beta, ws.cm, ws.cr
    n = body.shape[0]
    z2 = ball.cmul(z, zr, z, zr)
    qm, qr = 1.0 + 0.0j, 0.0
    for k in range(n):
        am, ar = 0.0j, 0.0
        for l in range(nmodes[k]):
            dm, dr = ball.cadd(z, zr, beta[0, k, l] + 0.0j, beta[1, k, l])
            if not ball.excludes_zero(dm, dr):
                return False, qm, qr
            qm, qr = ball.cmul(qm, qr, dm, dr)
            im, ir = ball.cdiv(E[k, l] + 0.0j, 0.0, dm, dr)
            am, ar = ball.cadd(am, ar, im, ir)
        # d_k = z G_k - z^2 (z + omega_k) a_k
        wm, wr = ball.cadd(z, zr, body[k, layout.OMEGA] + 0.0j, 0.0)
        t = ball.cmul(z2[0], z2[1], wm, wr)
        t = ball.cmul(t[0], t[1], am, ar)
        g = ball.cmul(z, zr, vec[layout.G_MID, k] + 0.0j, vec[layout.G_RAD, k])
        d = ball.cadd(g[0], g[1], -t[0], t[1])
        for j in range(k + 1):
            m, r = ball.cmul(z2[0], z2[1], mat[layout.M_MID, k, j] + 0.0j, mat[layout.M_RAD, k, j])
            m, r = ball.cadd(m, r, -mat[layout.K_MID, k, j] + 0.0j, mat[layout.K_RAD, k, j])
            if j == k:
                m, r = ball.cadd(m, r, d[0], d[1])
            cm[k, j], cr[k, j] = m, r
            cm[j, k], cr[j, k] = m, r
    return True, qm, qr


@kernel
def complex_derivative(z, body, E, nmodes, ws, dm, dr):
    """Balls of Phi'(z) at the float z into dm, dr.

    Returns sum_kl 1 / (z + beta_kl) as a ball (the logarithmic derivative of
    prod (z + beta_kl)); its radius is inf if z may be a pole.
    """
    mat, vec, beta = ws.mat, ws.vec, ws.beta
    n = body.shape[0]
    lm, lr = 0.0j, 0.0
    for k in range(n):
        am, ar = 0.0j, 0.0
        bm, br = 0.0j, 0.0  # sum E / (z + beta)^2 = -a'
        for l in range(nmodes[k]):
            qm, qr = ball.cadd(z, 0.0, beta[0, k, l] + 0.0j, beta[1, k, l])
            if not ball.excludes_zero(qm, qr):
                return lm, np.inf
            im, ir = ball.cinv(qm, qr)
            lm, lr = ball.cadd(lm, lr, im, ir)
            em, er = ball.cmul(E[k, l] + 0.0j, 0.0, im, ir)
            am, ar = ball.cadd(am, ar, em, er)
            em, er = ball.cmul(em, er, im, ir)
            bm, br = ball.cadd(bm, br, em, er)
        # d_k' = G_k - (3 z^2 + 2 z omega_k) a_k + z^2 (z + omega_k) b_k
        w = body[k, layout.OMEGA]
        # 3 z + 2 w in floats errs by at most u |3 z| + u |3 z + 2 w| (2 w is exact)
        c3 = ball.cmul(z, 0.0, 3.0 * z + 2.0 * w, 2.0 * ball.U * (abs(3.0 * z) + abs(3.0 * z + 2.0 * w)) + ball.ETA)
        t1 = ball.cmul(c3[0], c3[1], am, ar)
        zz = ball.cmul(z, 0.0, z, 0.0)
        c2 = ball.cmul(zz[0], zz[1], z + w, 2.0 * ball.U * abs(z + w))
        t2 = ball.cmul(c2[0], c2[1], bm, br)
        d = ball.cadd(vec[layout.G_MID, k] + 0.0j, vec[layout.G_RAD, k], -t1[0], t1[1])
        d = ball.cadd(d[0], d[1], t2[0], t2[1])
        for j in range(k + 1):
            m, r = ball.cmul(2.0 * z, 0.0, mat[layout.M_MID, k, j] + 0.0j, mat[layout.M_RAD, k, j])
            if j == k:
                m, r = ball.cadd(m, r, d[0], d[1])
            dm[k, j], dr[k, j] = m, r
            dm[j, k], dr[j, k] = m, r
    return lm, lr


@kernel
def float_matrices(z, body, E, nmodes, ws, F, dF):
    """Phi(z) and Phi'(z) in floats (as ``complex_matrix``); returns sum_kl 1 / (z + beta_kl)."""
    mat, vec, beta = ws.mat, ws.vec, ws.beta
    n = body.shape[0]
    logq = 0.0j
    z2 = z * z
    for k in range(n):
        a, b = 0.0j, 0.0j
        for l in range(nmodes[k]):
            inv = ball.recip(z + beta[0, k, l])
            logq += inv
            a += E[k, l] * inv
            b += E[k, l] * inv * inv
        w = body[k, layout.OMEGA]
        d = z * vec[layout.G_MID, k] - z2 * (z + w) * a
        dd_ = vec[layout.G_MID, k] - (3.0 * z2 + 2.0 * z * w) * a + z2 * (z + w) * b
        for j in range(k + 1):
            f = z2 * mat[layout.M_MID, k, j] - mat[layout.K_MID, k, j]
            df = 2.0 * z * mat[layout.M_MID, k, j]
            if j == k:
                f += d
                df += dd_
            F[k, j], dF[k, j] = f, df
            F[j, k], dF[j, k] = f, df
    return logq


@kernel
def linearisation(body, E, nmodes, parent, ws, C, Mo):
    """The D x D first-order companion of Phi in original coordinates into C (D = sum(nmodes + 2)).

    State (theta, v = z theta, y_kl = z v_k / (z + beta_kl)):
        z theta = v
        z M' v  = K theta - G v + sum_kl E_kl gamma_kl y_kl e_k,  M' = M - diag(sum_l E_kl)
        z y_kl  = z v_k - beta_kl y_kl,                            gamma_kl = omega_k - beta_kl
    Its eigenvalues are the roots of p; only approximations are needed (they
    steer the certificate, they prove nothing), so floats.  Mo (n, n) is scratch.
    False if M' is singular in floats.
    """
    mat, vec, beta = ws.mat, ws.vec, ws.beta
    n = body.shape[0]
    C[:] = 0.0
    for i in range(n):
        for k in range(n):
            Mo[k, i] = mat[layout.M_MID, k, i]
        Mo[i, i] -= vec[layout.ESUM_MID, i]
    try:
        Minv = np.linalg.inv(Mo)
    except Exception:  # numba catches no narrower class; singular in floats: no approximations
        return False
    MK = Minv @ mat[layout.K_MID]
    for k in range(n):
        C[k, n + k] = 1.0
        for j in range(n):
            C[n + k, j] = MK[k, j]
            C[n + k, n + j] = -Minv[k, j] * vec[layout.G_MID, j]
    col = 2 * n
    for j in range(n):
        for l in range(nmodes[j]):
            gamma = body[j, layout.OMEGA] - beta[0, j, l]
            for k in range(n):
                C[n + k, col] = Minv[k, j] * E[j, l] * gamma
            col += 1
    row = 2 * n
    for k in range(n):
        for l in range(nmodes[k]):
            C[row] = C[n + k]
            C[row, row] -= beta[0, k, l]
            row += 1
    return True
