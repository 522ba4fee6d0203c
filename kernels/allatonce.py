"""N_c of one point from one approximate eigen-decomposition of the first-order pencil (docs/certification.md, 4b).

The roots of p are the eigenvalues of the pencil z B - A of ``pencil.linearisation`` (state theta, v, y_kl):

    A = [[0, I, 0], [K, -diag G, E gamma], [0, 0, -diag beta]],   B = [[I, 0, 0], [0, M', 0], [0, -S, I]]

(M' = M - diag sum E, S picks v_k for each y_kl, gamma = omega - beta).  Only rows n..2n-1 of A and the block
M' of B carry balls.  X holds real approximate eigenvectors ([Re x, Im x] for a pair a +- ib), L the block
diagonal normal form (1 x 1 blocks, 2 x 2 blocks [[a, b], [-b, a]]), Y ~ (B X)^-1.  With Z = B X,
R = A X - Z L and E1 = I - Y Z, ||E1|| <= e < 1:

    X^-1 B^-1 A X = L + Z^-1 R = L + G + E1 (I - E1)^-1 G,   G = Y R,

the last term of inf-norm at most e / (1 - e) ||G||.  Gershgorin discs of that matrix after the block similarity
T = [[1, 1], [i, -i]] on each 2 x 2 block, centred at the eigenvalues of L, hold every eigenvalue: components
clear of the axis hold non-real ones, a lone disc of a 1 x 1 block a real one.  Only float matrix products with
a priori error bounds (gamma_k |A||B|, Higham section 3.5) are O(D^3): they run at BLAS speed.

Along a grid line the last points' X and Y, extrapolated, are refined by Newton steps (``refine``: Newton-Schulz
steps for Y, pairs regrouped where roots joined or left the axis, then the off-diagonal blocks of Y A X removed
to first order by 2 x 2 Sylvester equations in closed form), so a point costs a few D x D products per step and
no eigenvalue problem; the eigenvectors of LAPACK's dgeev where that fails.
"""

from __future__ import annotations

import math

import numpy as np
from numba import types
from numba.np.linalg import _LAPACK

from . import ball, layout, pencil
from .inclusion import find_root, group_disks
from .options import kernel

_RGEEV = _LAPACK().numba_ez_rgeev(types.float64)
_KIND = ord("d")
_NO = ord("N")
_YES = ord("V")

U = ball.U
ETA = ball.ETA
SCHULZ = 0.25  # ||I - Z Y|| of a stale inverse above this: LAPACK's inverse instead of Newton-Schulz steps
SCHULZ_STEPS = 3
REFINE_STEPS = 8  # first-order steps at most per point
VERIFY_AT = 2.0**-2  # steps this small (largest entry of P) are followed by a proof attempt (``certify``)
DIVERGED = 1e3  # a step moving the eigenvectors this much (largest entry of P): Newton's method diverges
REFINE_TOL = 2.0**-20  # a step that moved the eigenvectors less than this (largest entry of P) is the last: it
# leaves an error of about its square, near the rounding of the products
CLUSTER = 2.0**-30  # eigenvalues this close (relative to their size plus the spectral radius) are a cluster:
# not separated by the refinement (the radius: exact zero roots, kappa = 2, sit at rounding noise of it)
SPLIT = 2.0**-2  # a pair's coupling to its conjugate above this (relative to |a + i b|) is removed to first order,
# not solved exactly; nor below b / 2 (``refine``)
MAX_E = 0.5  # ||I - Y B X|| proved below this, so e / (1 - e) <= 2 e


@kernel
def _gamma(k):
    """A generous gamma_k = k u / (1 - k u): any summation order, with or without FMA."""
    return (2.0 * k + 8.0) * U


@kernel
def _grow(k):
    """Inflation covering the float sum of k nonnegative products (and the products' own rounding)."""
    return (1.0 + 2.0 * (k + 4) * U) * ball.INFL


@kernel
def allocate(n, nmodes):
    """Scratch and state for one block (D = sum(nmodes + 2))."""
    D = int((nmodes + 2).sum())
    L = D - 2 * n
    mats = np.empty((11, D, D))  # X, Y, Z, AX, R, G, F (products), P (refinement), V (LAPACK), X and Y one point back
    An = np.empty((2, n, D))  # rows n..2n-1 of A: mid, rad
    Mp = np.empty((2, n, n))  # M' = M - diag sum E: mid, rad
    yk = np.empty(max(L, 1), np.int64)  # the body of each liquid row
    yb = np.empty((2, max(L, 1)))  # its beta: mid, rad
    lam = np.empty((D, 2))  # per column: (a, b) of its block; b = 0 for a 1 x 1 block
    size = np.empty(D, np.int64)  # per column: 1, or 2 for both columns of a pair
    vec = np.empty((8, D))  # weights and row radii
    disc = np.empty(D, np.complex128)
    rad = np.empty(D)
    group = np.empty(D, np.int64)
    state = np.zeros(layout.ALLATONCE_STATE, np.int64)  # slots named in layout (AAO_HELD, ...)
    return layout.AllatonceWork(mats, An, Mp, yk, yb, lam, size, vec, disc, rad, group, state)


@kernel
def pencil_balls(body, E, nmodes, pws, aw):
    """The balls of A (rows n..2n-1) and M', and the liquid rows' beta, from the pencil workspace ``pws``."""
    An, Mp, yk, yb = aw.An, aw.Mp, aw.yk, aw.yb
    mat, v, beta = pws.mat, pws.vec, pws.beta
    n = body.shape[0]
    An[:] = 0.0
    for k in range(n):
        for j in range(n):
            An[0, k, j], An[1, k, j] = mat[layout.K_MID, k, j], mat[layout.K_RAD, k, j]
            Mp[0, k, j], Mp[1, k, j] = mat[layout.M_MID, k, j], mat[layout.M_RAD, k, j]
        Mp[0, k, k], Mp[1, k, k] = ball.radd(Mp[0, k, k], Mp[1, k, k], -v[layout.ESUM_MID, k], v[layout.ESUM_RAD, k])
        An[0, k, n + k], An[1, k, n + k] = -v[layout.G_MID, k], v[layout.G_RAD, k]
    r = 0
    for j in range(n):
        for l in range(nmodes[j]):
            gm, gr = ball.radd(body[j, layout.OMEGA], 0.0, -beta[0, j, l], beta[1, j, l])
            An[0, j, 2 * n + r], An[1, j, 2 * n + r] = ball.rmul(E[j, l], 0.0, gm, gr)
            yk[r], yb[0, r], yb[1, r] = j, beta[0, j, l], beta[1, j, l]
            r += 1


@kernel
def _products(X, AX, Z, An, Mp, yk, yb, n, D):
    """Midpoints of A X and Z = B X (float; their errors are bounded by ``_radii``)."""
    AX[:n] = X[n : 2 * n]
    np.dot(An[0], X, AX[n : 2 * n])
    Z[:n] = X[:n]
    np.dot(Mp[0], X[n : 2 * n], Z[n : 2 * n])
    for r in range(D - 2 * n):
        for j in range(D):
            AX[2 * n + r, j] = -yb[0, r] * X[2 * n + r, j]
            Z[2 * n + r, j] = X[2 * n + r, j] - X[n + yk[r], j]


@kernel
def _absmv(Mat, q, out, D):
    """out >= |Mat| q for nonnegative q (float sums of nonnegative terms, inflated)."""
    k = Mat.shape[1]
    grow = _grow(k)
    for i in range(Mat.shape[0]):
        s = 0.0
        for j in range(k):
            s += abs(Mat[i, j]) * q[j]
        out[i] = s * grow + k * ETA
    return out


@kernel
def _radii(X, An, Mp, yk, yb, q, xq, ra, rz, n, D):
    """Row sums, weighted by q >= 0, of the radii of A X and of B X about their float midpoints.

    ra_i >= sum_j q_j |(A* X - fl(A X))_ij| for every A* in the balls of A, rz likewise for B; xq is scratch.
    """
    _absmv(X, q, xq, D)
    g = _gamma(D)
    grow = _grow(D)
    for i in range(n):
        ra[i], rz[i] = 0.0, 0.0
    for k in range(n):
        s, t = 0.0, 0.0
        for j in range(D):
            s += (g * abs(An[0, k, j]) + An[1, k, j]) * xq[j]
        for j in range(n):
            t += (g * abs(Mp[0, k, j]) + Mp[1, k, j]) * xq[n + j]
        ra[n + k] = s * grow * grow + D * ETA
        rz[n + k] = t * grow * grow + D * ETA
    for r in range(D - 2 * n):
        ra[2 * n + r] = (yb[1, r] + 2.0 * U * abs(yb[0, r])) * xq[2 * n + r] * grow + ETA
        rz[2 * n + r] = 2.0 * U * (xq[2 * n + r] + xq[n + yk[r]]) * grow + ETA


@kernel
def _times_l(Z, lam, size, out, D):
    """out = fl(Z L), L the block diagonal normal form of ``lam``, ``size``."""
    j = 0
    while j < D:
        a, b = lam[j, 0], lam[j, 1]
        if size[j] == 1:
            for i in range(D):
                out[i, j] = Z[i, j] * a
            j += 1
        else:
            for i in range(D):
                x, y = Z[i, j], Z[i, j + 1]
                out[i, j] = x * a - y * b
                out[i, j + 1] = x * b + y * a
            j += 2


@kernel
def _abs_l(lam, size, w, out, D):
    """out = |L| w."""
    j = 0
    while j < D:
        a, b = abs(lam[j, 0]), abs(lam[j, 1])
        if size[j] == 1:
            out[j] = a * w[j] * ball.INFL
            j += 1
        else:
            out[j] = (a * w[j] + b * w[j + 1]) * ball.INFL
            out[j + 1] = (b * w[j] + a * w[j + 1]) * ball.INFL
            j += 2


@kernel
def verify(m, aw):
    """Non-real roots of p proved from X, Y and L in ``aw`` (each counted, so twice N_c), or -1 if unproved.

    Needs ``pencil_balls`` of this point.  Every bound is rigorous for every pencil in the balls; X, Y
    and L are any floats (a poor choice only makes the discs too large to decide).
    """
    mats, An, Mp, yk, yb, lam = aw.mats, aw.An, aw.Mp, aw.yk, aw.yb, aw.lam
    size, vec, disc, rad, group = aw.size, aw.vec, aw.disc, aw.rad, aw.group
    X, Y, Z, AX, R, G, F = mats[0], mats[1], mats[2], mats[3], mats[4], mats[5], mats[6]
    n, D = An.shape[1], X.shape[0]
    w, lw, xq, ra, rz, rr, one, rho = vec[0], vec[1], vec[2], vec[3], vec[4], vec[5], vec[6], vec[7]
    _products(X, AX, Z, An, Mp, yk, yb, n, D)
    _times_l(Z, lam, size, F, D)
    for i in range(D):
        for j in range(D):
            R[i, j] = AX[i, j] - F[i, j]
    # weights: a column of a 2 x 2 block counts twice (the similarity T spreads it over both rows)
    for j in range(D):
        w[j] = float(size[j])
        one[j] = 1.0
    _abs_l(lam, size, w, lw, D)
    # radius of R about its midpoint, weighted by w: A X, then Z L (Z's radius times |L| w, Z L's rounding),
    # then the subtraction
    _radii(X, An, Mp, yk, yb, w, xq, ra, rz, n, D)
    for i in range(D):
        rr[i] = ra[i]
    _radii(X, An, Mp, yk, yb, lw, xq, ra, rz, n, D)
    _absmv(Z, lw, xq, D)
    g2 = _gamma(2)
    for i in range(D):
        rr[i] += rz[i] + g2 * xq[i]
    _absmv(R, w, xq, D)
    gD = _gamma(D)
    grow = _grow(D)
    for i in range(D):
        rr[i] = (rr[i] + (2.0 * U + gD) * xq[i]) * grow + ETA
    # G = Y R: weighted row sums of |G*| <= those of |fl(Y R)| + |Y| (radius of R + gamma_D |R|) w
    np.dot(Y, R, G)
    _absmv(Y, rr, rho, D)
    for i in range(D):
        s = 0.0
        for j in range(D):
            s += w[j] * abs(G[i, j])
        rho[i] = (rho[i] + s * grow) * grow + ETA
    # E1 = I - Y Z*: ||E1||_inf <= row sums of |I - fl(Y Z)| + |Y| (gamma_D |Z| 1 + radius of Z)
    _radii(X, An, Mp, yk, yb, one, xq, ra, rz, n, D)
    _absmv(Z, one, xq, D)
    for i in range(D):
        rr[i] = (rz[i] + gD * xq[i]) * grow + ETA
    np.dot(Y, Z, F)
    _absmv(Y, rr, ra, D)
    # every maximum below is checked row by row: max() would pass over a NaN
    e = 0.0
    for i in range(D):
        s = 0.0
        for j in range(D):
            s += abs((1.0 if i == j else 0.0) - F[i, j])
        row = (s * grow + ra[i]) * grow + 2.0 * U
        if not row < MAX_E:
            return -1
        e = max(e, row)
    gnorm = 0.0
    for i in range(D):
        if not rho[i] < math.inf:
            return -1
        gnorm = max(gnorm, rho[i])
    for j in range(D):
        if not (math.isfinite(lam[j, 0]) and math.isfinite(lam[j, 1])):
            return -1
    eta = 2.0 * e * gnorm / (1.0 - e) * grow  # the similarity T at most doubles an inf-norm
    if not math.isfinite(eta):
        return -1
    j = 0
    while j < D:
        a, b = lam[j, 0], lam[j, 1]
        if size[j] == 1:
            disc[j], rad[j] = complex(a, 0.0), (rho[j] + eta) * grow
            j += 1
        else:
            r = (0.5 * (rho[j] + rho[j + 1]) + eta) * grow
            disc[j], rad[j] = complex(a, b), r
            disc[j + 1], rad[j + 1] = complex(a, -b), r
            j += 2
    return _count(disc, rad, size, group, m, D)


@kernel
def _count(disc, rad, size, group, m, D):
    """Non-real eigenvalues proved by the discs (``verify``), or -1 unless every component decides.

    A component of k discs holds k eigenvalues: all non-real if it misses the axis, one real if it is a
    lone disc of a 1 x 1 block (its conjugate lies in it too), and the m exact zero roots if it holds 0
    and exactly m discs.
    """
    for i in range(D):
        if not (rad[i] < math.inf):
            return -1
    group_disks(disc, rad, D, group)
    # per component (at its root): members, whether it may touch the axis, whether it may hold 0
    members = np.zeros(D, np.int64)
    touches = np.zeros(D, np.bool_)
    zero = np.zeros(D, np.bool_)
    for i in range(D):
        c = find_root(group, i)
        members[c] += 1
        touches[c] = touches[c] or abs(disc[i].imag) * ball.LOW <= rad[i] * ball.INFL
        zero[c] = zero[c] or abs(disc[i]) * ball.LOW <= rad[i] * ball.INFL
    nonreal, real, zeros = 0, 0, 0
    for c in range(D):
        if members[c] == 0:
            continue
        zeros += zero[c]
        if not touches[c]:
            nonreal += members[c]
        elif members[c] == 1 and size[c] == 1:
            real += 1
        elif m > 0 and zero[c] and members[c] == m:
            real += m
        else:
            return -1
    if (m > 0 and zeros != 1) or nonreal % 2 or nonreal + real != D:
        return -1
    return nonreal


@kernel
def _normalise(X, lam, size, D):
    """Scale each eigenvector (a pair's two columns by one factor) to largest entry 1."""
    j = 0
    while j < D:
        s = size[j]
        big = 0.0
        for c in range(j, j + s):
            for i in range(D):
                big = max(big, abs(X[i, c]))
        if big > 0.0 and math.isfinite(big):
            for c in range(j, j + s):
                for i in range(D):
                    X[i, c] /= big
        j += s


@kernel
def decompose(C, aw):
    """Eigenvectors of the float linearisation C (LAPACK dgeev) into X, L into lam, size; Y = (B X)^-1.

    Needs ``pencil_balls``.  False on failure (no convergence, a singular B X); C is overwritten.
    """
    mats, An, Mp, yk, yb, lam, size, vec, rad = aw.mats, aw.An, aw.Mp, aw.yk, aw.yb, aw.lam, aw.size, aw.vec, aw.rad
    X, Y, Z, V, F = mats[0], mats[1], mats[2], mats[8], mats[6]
    n, D = An.shape[1], X.shape[0]
    # LAPACK reads Fortran order: hand it C transposed in memory
    for i in range(D):
        for j in range(D):
            F[j, i] = C[i, j]
    wr, wi = vec[0], vec[1]
    info = _RGEEV(_KIND, _NO, _YES, D, F.ctypes, D, wr.ctypes, wi.ctypes, rad.ctypes, 1, V.ctypes, D)
    if info != 0:
        return False
    j = 0
    while j < D:
        if wi[j] == 0.0 or j + 1 == D:
            lam[j, 0], lam[j, 1], size[j] = wr[j], 0.0, 1
            j += 1
        else:  # dgeev: wi[j] > 0, columns j, j + 1 hold Re x, Im x of the eigenvector of wr + i wi
            for c in (j, j + 1):
                lam[c, 0], lam[c, 1], size[c] = wr[j], wi[j], 2
            j += 2
    for i in range(D):
        for c in range(D):
            X[i, c] = V[c, i]  # row c of V (Fortran) is column c of the eigenvector matrix
    for i in range(D):
        for c in range(D):
            if not math.isfinite(X[i, c]):
                return False
    _normalise(X, lam, size, D)
    _products(X, mats[3], Z, An, Mp, yk, yb, n, D)
    try:
        Y[:] = np.linalg.inv(Z)
    except Exception:  # numba catches no narrower class; a singular B X: no decomposition
        return False
    return True


@kernel
def _cdiv(x, d):
    """x / d for complex floats, 0 where d is 0 (that block is then left unrefined: the discs decide)."""
    if d == 0.0:
        return 0.0j
    return x / d


@kernel
def _sylvester(H, P, lam, size, i, j, radius):
    """P_ij with L_i P_ij - P_ij L_j = -H_ij for the blocks at columns i and j (closed forms, module docstring).

    Left 0 for (nearly) repeated eigenvalues (``CLUSTER``; ``radius`` the largest |eigenvalue|): there the
    first-order step divides noise by a tiny gap, and the discs of the cluster then decide together, or not at all.
    """
    da, db = lam[i, 0] - lam[j, 0], lam[i, 1] - lam[j, 1]
    if i != j and abs(da) + abs(db) <= CLUSTER * (abs(lam[i, 0]) + abs(lam[i, 1]) + abs(lam[j, 0]) + abs(lam[j, 1]) + radius):
        return
    if size[i] == 1 and size[j] == 1:
        P[i, j] = -H[i, j] / da
        return
    li = complex(lam[i, 0], lam[i, 1])
    lj = complex(lam[j, 0], lam[j, 1])
    if size[i] == 2 and size[j] == 1:
        # (L_i - l_j) p = -h; L_i - l_j = [[a, b], [-b, a]] with a = a_i - l_j, b = b_i, inverse [[a, -b], [b, a]] / d
        a, b = lam[i, 0] - lam[j, 0], lam[i, 1]
        d = a * a + b * b
        if d == 0.0:
            return
        h0, h1 = -H[i, j], -H[i + 1, j]
        P[i, j] = (a * h0 - b * h1) / d
        P[i + 1, j] = (b * h0 + a * h1) / d
    elif size[i] == 1 and size[j] == 2:
        # p (l_i - L_j) = -h for the row p = (p0, p1); l_i - L_j = [[a, -b], [b, a]] with a = l_i - a_j, b = b_j
        a, b = lam[i, 0] - lam[j, 0], lam[j, 1]
        d = a * a + b * b
        if d == 0.0:
            return
        h0, h1 = -H[i, j], -H[i, j + 1]
        # [[a, -b], [b, a]]^-1 = [[a, b], [-b, a]] / d
        P[i, j] = (h0 * a - h1 * b) / d
        P[i, j + 1] = (h0 * b + h1 * a) / d
    else:
        h11, h12, h21, h22 = -H[i, j], -H[i, j + 1], -H[i + 1, j], -H[i + 1, j + 1]
        # -H = C + K Q: C = [[x, y], [-y, x]] ~ x + i y commutes with every normal form, K = diag(1, -1), and
        # Q ~ q = x' + i y'; L_i K = K conj(L_i), so p = c / (l_i - l_j), q' = q / (conj(l_i) - l_j)
        c = _cdiv(complex(0.5 * (h11 + h22), 0.5 * (h12 - h21)), li - lj)
        q = _cdiv(complex(0.5 * (h11 - h22), 0.5 * (h12 + h21)), li.conjugate() - lj)
        P[i, j] = c.real + q.real
        P[i, j + 1] = c.imag + q.imag
        P[i + 1, j] = -c.imag + q.imag
        P[i + 1, j + 1] = c.real - q.real


@kernel
def _transform(X, Y, H, j, s11, s12, s21, s22, D):
    """X_b <- X_b S, Y_b <- S^-1 Y_b, H <- S^-1 H S on the columns (rows) j, j + 1; S scaled to |det S| = 1, so
    columns keep their size from step to step (S = I once converged).  False if S is singular."""
    det = s11 * s22 - s12 * s21
    if det == 0.0 or not math.isfinite(det):
        return False
    f = 1.0 / math.sqrt(abs(det))
    s11, s12, s21, s22 = s11 * f, s12 * f, s21 * f, s22 * f
    det = s11 * s22 - s12 * s21
    i11, i12, i21, i22 = s22 / det, -s12 / det, -s21 / det, s11 / det
    for i in range(D):
        x0, x1 = X[i, j], X[i, j + 1]
        X[i, j], X[i, j + 1] = x0 * s11 + x1 * s21, x0 * s12 + x1 * s22
        h0, h1 = H[i, j], H[i, j + 1]
        H[i, j], H[i, j + 1] = h0 * s11 + h1 * s21, h0 * s12 + h1 * s22
    for c in range(D):
        y0, y1 = Y[j, c], Y[j + 1, c]
        Y[j, c], Y[j + 1, c] = i11 * y0 + i12 * y1, i21 * y0 + i22 * y1
        h0, h1 = H[j, c], H[j + 1, c]
        H[j, c], H[j + 1, c] = i11 * h0 + i12 * h1, i21 * h0 + i22 * h1
    return True


@kernel
def _regroup(X, Y, H, size, tmp, D):
    """Pair two neighbouring 1 x 1 blocks whose 2 x 2 submatrix of H has non-real eigenvalues (two real roots that
    met and left the axis) and make them neighbours: X's columns, Y's rows and H permuted alike (``tmp`` scratch).
    True if it paired any (the columns moved)."""
    # two real eigenvalues that met are neighbours in the sorted order of the 1 x 1 blocks' diagonal entries
    partner = np.full(D, -1, np.int64)
    found = False
    real = np.empty(D, np.int64)
    key = np.empty(D)
    nr = 0
    for i in range(D):
        if size[i] == 1:
            real[nr], key[nr] = i, H[i, i]
            nr += 1
    order = np.argsort(key[:nr])
    a = 0
    while a + 1 < nr:
        i, j = real[order[a]], real[order[a + 1]]
        p, q, r, s = H[i, i], H[i, j], H[j, i], H[j, j]
        if 0.25 * (p - s) * (p - s) + q * r < 0.0:
            partner[i], partner[j] = j, i
            found = True
            a += 2
        else:
            a += 1
    if not found:
        return False
    order = np.empty(D, np.int64)
    placed = np.zeros(D, np.bool_)
    t = 0
    j = 0
    while j < D:
        if placed[j]:
            j += 1
            continue
        if size[j] == 2:
            order[t], order[t + 1] = j, j + 1
            placed[j] = placed[j + 1] = True
            t += 2
            j += 2
            continue
        order[t] = j
        placed[j] = True
        t += 1
        if partner[j] >= 0:
            order[t] = partner[j]
            placed[partner[j]] = True
            t += 1
        j += 1
    newsize = np.empty(D, np.int64)
    for a in range(D):
        newsize[a] = 2 if (size[order[a]] == 2 or partner[order[a]] >= 0) else 1
    size[:] = newsize
    for M, rows, cols in ((X, False, True), (Y, True, False), (H, True, True)):
        for a in range(D):
            for b in range(D):
                tmp[a, b] = M[order[a] if rows else a, order[b] if cols else b]
        M[:] = tmp
    return True


@kernel
def refine(aw):
    """One first-order step of the stored X, Y, L towards this point's pencil (needs ``pencil_balls``).

    Returns the largest entry of the correction P (X <- X (I + P)): the step is quadratically convergent, so a
    small one leaves the decomposition accurate to about its square.  -1 if the stored decomposition is too far
    from this pencil (a pair turned real, or Y is no longer a near inverse).
    """
    mats, An, Mp, yk, yb, lam, size, group, state = aw.mats, aw.An, aw.Mp, aw.yk, aw.yb, aw.lam, aw.size, aw.group, aw.state
    X, Y, Z, AX, H, T, P = mats[0], mats[1], mats[2], mats[3], mats[4], mats[5], mats[7]
    n, D = An.shape[1], X.shape[0]
    _products(X, AX, Z, An, Mp, yk, yb, n, D)
    # (``group`` is scratch here: 1 at a pair whose coupling to its conjugate is removed to first order)
    # Y ~ (B X)^-1 again: Newton-Schulz steps Y <- Y (2 I - Z Y) while they converge fast, else LAPACK's inverse.
    # (every step: the update (I + P)^-1 Y ~ (I - P) Y of the step before errs by P^2, which would stay in L)
    for _ in range(SCHULZ_STEPS):
        np.dot(Z, Y, T)
        worst = 0.0
        for i in range(D):
            s = 0.0
            for j in range(D):
                T[i, j] = (2.0 if i == j else 0.0) - T[i, j]
                s += abs(T[i, j] - (1.0 if i == j else 0.0))
            worst = max(worst, s)
        if not worst < SCHULZ:
            try:
                Y[:] = np.linalg.inv(Z)
            except Exception:  # numba catches no narrower class; a singular B X
                return -1.0
            break
        if worst < 2.0**-30:  # an error of Y this small only widens the discs by its square
            break
        np.dot(Y, T, H)
        Y[:] = H
        if worst < 2.0**-15:  # the step squares the error: no need to check again
            break
    np.dot(Y, AX, H)  # ~ X^-1 B^-1 A X
    # where two real eigenvalues met and left the axis, or a pair met it, the blocks change with them
    regrouped = _regroup(X, Y, H, size, mats[8], D)
    if regrouped:
        state[layout.AAO_MOVED] = 1
    # the 2 x 2 diagonal blocks back to normal form [[a, b], [-b, a]] (S: H_bb S = S N), 1 x 1 ones read off
    j = 0
    while j < D:
        if size[j] == 1:
            lam[j, 0], lam[j, 1] = H[j, j], 0.0
            j += 1
            continue
        p, q, r, s = H[j, j], H[j, j + 1], H[j + 1, j], H[j + 1, j + 1]
        a = 0.5 * (p + s)
        group[j] = 0
        # The block is [[a, b], [-b, a]] (a + i b) plus a part of modulus conj that couples a + i b with a - i b.
        # Solved exactly (below) only where the pair may be meeting the axis (b or conj small against |a + i b|, conj
        # near b) or was just formed by ``_regroup``; elsewhere conj is removed to first order like every other
        # coupling (``_sylvester`` with i = j: conj / 2 b), as Newton's method in complex arithmetic does.  A conj
        # far above b is the step seen through ill-conditioned eigenvectors (identical bodies on ideal joints,
        # condition numbers ~ 1e5): the block's own eigenvalues are then far off, real, and solving it exactly split
        # the pair and made the refinement diverge at any grid spacing (docs/certification.md, 4b).
        b, conj = 0.5 * (q - r), math.hypot(0.5 * (p - s), 0.5 * (q + r))
        size_ab = SPLIT * (abs(a) + abs(b))
        if not regrouped and abs(b) > size_ab and (conj < 0.5 * abs(b) or conj > size_ab):
            # made b > 0 (columns j + 1 of X, rows j + 1 of Y negated)
            if b < 0.0:
                for i in range(D):
                    X[i, j + 1], H[i, j + 1] = -X[i, j + 1], -H[i, j + 1]
                for c in range(D):
                    Y[j + 1, c], H[j + 1, c] = -Y[j + 1, c], -H[j + 1, c]
                b = -b
            lam[j, 0], lam[j, 1], lam[j + 1, 0], lam[j + 1, 1] = a, b, a, b
            group[j] = 1
            j += 2
            continue
        disc2 = 0.25 * (p - s) * (p - s) + q * r
        if not disc2 < 0.0:
            # the pair met the axis: two real eigenvalues, each with its real eigenvector of the block
            e = math.sqrt(disc2)
            m1, m2 = a + e, a - e
            if abs(q) >= abs(r):
                s11, s21, s12, s22 = q, m1 - p, q, m2 - p
            else:
                s11, s21, s12, s22 = m1 - s, r, m2 - s, r
            if not _transform(X, Y, H, j, s11, s12, s21, s22, D):
                return -1.0
            size[j], size[j + 1] = 1, 1
            state[layout.AAO_MOVED] = 1
            lam[j, 0], lam[j, 1], lam[j + 1, 0], lam[j + 1, 1] = H[j, j], 0.0, H[j + 1, j + 1], 0.0
            j += 2
            continue
        b = math.sqrt(-disc2)
        # eigenvector of a + i b: (q, a - p + i b) (q != 0: a non-real pair has q r < 0)
        if not _transform(X, Y, H, j, q, 0.0, a - p, b, D):
            return -1.0
        for c in (j, j + 1):
            lam[c, 0], lam[c, 1] = a, b
        j += 2
    # off-diagonal blocks: L_i P_ij - P_ij L_j = -H_ij, so that (I + P)^-1 H (I + P) is block diagonal to first
    # order.  A 2 x 2 normal form [[a, b], [-b, a]] acts as the complex number a + i b; a 2 x 2 P splits into a part
    # that commutes with it and one that conjugates it (``_sylvester``), so every block has a closed form.
    P[:] = 0.0
    big = 0.0
    radius = 0.0
    for i in range(D):
        radius = max(radius, abs(lam[i, 0]) + abs(lam[i, 1]))
    i = 0
    while i < D:
        j = 0
        li = abs(lam[i, 0]) + abs(lam[i, 1]) + radius
        while j < D:
            if size[i] == 1 and size[j] == 1:  # the common case, inline: real eigenvalues
                da = lam[i, 0] - lam[j, 0]
                if i != j and abs(da) > CLUSTER * (li + abs(lam[j, 0])):
                    P[i, j] = -H[i, j] / da
                    big = max(big, abs(P[i, j]))
            elif i != j or (size[i] == 2 and group[i] == 1):
                _sylvester(H, P, lam, size, i, j, radius)
                for r in range(i, i + size[i]):
                    for c in range(j, j + size[j]):
                        big = max(big, abs(P[r, c]))
            j += size[j]
        i += size[i]
    if not big < math.inf:  # a NaN that max() passed over only makes verify fail: it checks every bound
        return -1.0
    np.dot(X, P, H)
    X += H
    np.dot(P, Y, H)
    Y -= H
    return big


@kernel
def extrapolate(aw):
    """X, Y linearly extrapolated from the last two points where they continue each other (else the last
    point's kept); the last point's saved for the next."""
    mats, state = aw.mats, aw.state
    X, Y, Xp, Yp = mats[0], mats[1], mats[9], mats[10]
    D = X.shape[0]
    for i in range(D):
        for j in range(D):
            x, y = X[i, j], Y[i, j]
            if state[layout.AAO_CONTINUES] == 1:
                X[i, j], Y[i, j] = 2.0 * x - Xp[i, j], 2.0 * y - Yp[i, j]
            Xp[i, j], Yp[i, j] = x, y
    state[layout.AAO_MOVED] = 0


@kernel
def last_step(step, moved, last):
    """True if the refinement stops after ``step`` steps, the last of size ``moved``, the one before ``last``.

    Quadratic convergence until rounding: stop there, or when the steps no longer shrink after the first few (a
    cluster, or a neighbour too far for Newton's method), or grow wild, or after REFINE_STEPS.
    """
    return step >= REFINE_STEPS or not (moved > REFINE_TOL and (step < 4 or moved < 0.5 * last) and moved < DIVERGED)


@kernel
def proof_due(moved, tried, stop):
    """True if the discs are to be tried after a step of size ``moved`` (the last try was after one of ``tried``).

    A step of size s leaves an error of about s^2: from VERIFY_AT on, the discs may already separate, and a proof
    costs less than a step, so it is tried before refining further (again only once the steps have shrunk a lot
    since the last try); the last step's decomposition is tried unless it already was.
    """
    return 0.0 <= moved < tried and (stop or (moved <= VERIFY_AT and moved <= tried * VERIFY_AT))


@kernel
def certify(body, E, nmodes, parent, m, pws, C, Mo, aw, warm):
    """(N_c, warm used) of one point whose pencil workspace ``pws`` is prepared, or (-1, ...) if unproved.

    ``warm``: first refine the decomposition left by the previous point; cold (the eigenvectors of
    the float linearisation, into C with scratch Mo) if that fails or there is none.
    """
    state = aw.state
    pencil_balls(body, E, nmodes, pws, aw)
    if warm and state[layout.AAO_HELD] == 1:
        extrapolate(aw)
        moved = refine(aw)
        last = np.inf
        tried = np.inf  # the step size at the last proof attempt
        for step in range(1, REFINE_STEPS + 1):
            stop = last_step(step, moved, last)
            if proof_due(moved, tried, stop):
                tried = moved
                nonreal = verify(m, aw)
                if nonreal >= 0:
                    state[layout.AAO_WARM] += 1
                    state[layout.AAO_CONTINUES] = 1 - state[layout.AAO_MOVED]
                    return nonreal // 2, True
            if stop:
                break
            last = moved
            moved = refine(aw)
    state[layout.AAO_HELD] = 0
    state[layout.AAO_CONTINUES] = 0
    if not pencil.linearisation(body, E, nmodes, parent, pws, C, Mo):
        return -1, False
    state[layout.AAO_COLD] += 1
    if not decompose(C, aw):
        return -1, False
    state[layout.AAO_HELD] = 1
    nonreal = verify(m, aw)
    if nonreal < 0:
        return -1, False
    return nonreal // 2, False
