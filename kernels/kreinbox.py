"""Krein boxes: N_c proved on a whole box of the spin-scaled model from a few definite compressions.

A box moves the one spin rate omega of every body (not through 0) and at most one mechanical axis t whose kernel
inputs are copies of its value and enter M, C and K affinely (a mass, an inertia A or C, a joint's stiffness, g;
not a length, whose entries are quadratic).  In mu = lambda / omega (docs/certification.md, section 6)

    Phi_1(mu; u, t) = mu^2 M(t) + mu diag(C(t)) - u K(t) - liquid_1(mu),      u = 1 / omega^2,

the poles mu = -beta_kl (unit spin) are fixed and Phi_1 is bilinear in (u, t): on the rectangle
[u_lo, u_hi] x [t_lo, t_hi] it is a convex combination of its four corner values.

**Real roots, sign-aware (docs/certification.md, section 4).**  Border the polynomial part of Phi_1 with one row per liquid mode with
E != 0 and beta != 0: H(mu) = [[A(mu), C], [C^T, diag(c (mu + beta))]], c = E beta^2 (1 - beta), whose Schur
complement is Phi_1.  H is a real symmetric matrix polynomial, det H = prod c * p_1 / (the exact factors below),
and by Haynsworth nu_H(mu) = nu(Phi_1(mu)) + #{c (mu + beta) < 0} off the poles, with sign(c) = sign(E kappa)
(1 - beta = 2 / kappa at unit spin).  Its eigenvalues are analytic in mu (Rellich) and their product is det H, so
nu_H changes only at real roots of p_1, by at most their multiplicity: real roots in (a, b) >= |nu_H(b) - nu_H(a)|,
poles not subtracted.  With M' = M - diag(sum E) positive definite, nu_H(+inf) = #{c < 0}, nu_H(-inf) = #{c > 0}.
Modes with E = 0 (beta != 0) give the exact real root -beta of p_1, modes with beta = 0 (kappa = 2) the exact
root 0: p_1 has those besides the roots of det H.

**Constant inertia over the box.**  Separators mu_s are floats fixed over the box, placed (by float approximations
at the box's centre, which prove nothing) between runs of real roots of one Krein type.  At mu_s, V- and V+ are
float eigenvectors of Phi_1(mu_s; centre) for its negative and positive eigenvalues.  If V-^T Phi_1 V- < 0 and
V+^T Phi_1 V+ > 0 at the four corners (balls: ``pencil.real_matrix`` from the corners' exact inputs, the compression
in balls, ``elimination.inertia``), they hold on the whole box (convex combinations), and by Courant-Fischer
Phi_1(mu_s; .) has exactly dim V- negative and dim V+ positive eigenvalues everywhere on it (dim V- + dim V+ = n).
The pole terms of nu_H(mu_s) are fixed (mu_s + beta excludes 0).  M' > 0 at the two t corners holds on the box
(M' is affine in t), so deg p_1 = D = sum (2 + L_k) on it.  So every point of the box has at least
R = sum |delta nu_H| + (exact roots) real roots.  R = D: N_c = 0 on the whole box.

**Complex pairs.**  For k = (D - R) / 2 upper approximations, an eigenpair Krawczyk test over the box: with
a, s in [-1, 1] the box's u and t, Phi_1 = P0 + a Pa + s Ps + a s Pas exactly (bilinear), P0 the centre's
matrix, Pa = -ru K0, Ps = mu^2 M1 + mu diag(C1) - uc K1, Pas = -ru K1 (M0, M1 the mean and half difference of
M at t_lo, t_hi, and so on).  F(v, mu) = [Phi_1(mu) v; v_k - 1].  With x~ = (v~, mu~) and R ~ J(x~)^-1 floats,
K = x~ - R F(x~) + (I - R J(X)) (X - x~) over X = x~ + discs(rho) and the box; R F and R J are expanded in the four
parts and each product R * part is formed in balls before its absolute value (the centred form: the plain ball
form loses the cancellation in w^T K v: Neumaier 1990, centred forms).  |K - x~| < rho componentwise proves a unique zero in X for
every point of the box (Krawczyk, complex discs are convex), so an eigenvalue of Phi_1, not a pole since the disc
lies in the upper half plane: a non-real root of p_1.  k discs pairwise disjoint, clear of the real axis: 2k
distinct non-real roots at every point, R + 2k = D, and N_c = k on the whole box.  Where the test fails over the
whole box it is made over each of its 2 x 2 quarters (``SPLIT_PAIRS``): R holds on the whole box, so k pairs on
every quarter are k pairs on the box.

Approximations come from the box before it in the block (a sweep's neighbour: its separators and polished pairs),
else from the eigenvalues of the float linearisation at the box's centre (dgeev).

Everything that decides is balls with outward rounding (``ball.py``); floats only choose separators, the
vectors V-, V+, the approximations and R.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from . import approximations, ball, elimination, layout, pencil
from .options import kernel
from .status import DECIDED_DISKS, DECIDED_INERTIA, UNDECIDED

NEAR_REAL = 1e-6  # approximations within this of the axis (relative to 1 + |mu|) are taken as real roots
KRAWCZYK_STEPS = 16  # epsilon-inflation steps of the Krawczyk test
INFLATE = 1.125  # each step starts from the last bound times this
SPLIT_PAIRS = 1  # Krawczyk over the whole box, then over its 2 x 2 quarters (1), its 4 x 4 sixteenths (2) ...
NEWTON_STEPS = 4  # float Newton steps on the bordered eigenpair system at the centre
TINY = 2.0**-60  # the smallest radius the Krawczyk test starts from (relative to 1 + |x|)

# info columns written by ``krein_box_block`` per box
INFO_SEPARATORS = 0
INFO_PAIRS = 1
INFO_REAL = 2  # real roots proved (inertia count plus exact roots), -1 if the separators failed
INFO_NEWTON = 4  # float Newton steps of the Krawczyk tests
INFO_ITERATIONS = 5  # Krawczyk iterations (each: two ball evaluations of Phi_1 and Phi_1' over the disc)
INFO_STAGE = 3  # where it stopped: 0 inputs, 1 lc, 2 approximations, 3 separators, 4 count, 5 krawczyk, 6 proved cold, 7 proved warm
NINFO = 6

KreinWork = namedtuple("KreinWork", "T jmk sub tmat tvec cmat cvec beta krein cm cr C Mo F dF Sm Sr Wm Wr V P wr wi z "
                                    "feat ftype seps bord "
                                    "pm pr qm qr cr0 cr1 Jm Jr Xm Xr Rm bm br Bm Bv bv prev pz pv "
                                    "lbody ljoint lg lat lE lkappa stats")


@kernel
def allocate(n, nmodes, parent):
    """Scratch for one block of boxes of n bodies with nmodes[k] modes each (ValueError for a bad ``parent``)."""
    lmax = max(1, nmodes.max())
    pw = pencil.allocate(n, lmax, parent)
    L = lmax
    D = 2 * n + nmodes.sum()
    N = n + 1
    tmat = np.zeros((2, layout.PENCIL_MAT, n, n))  # the two t corners at u = 1
    tvec = np.zeros((2, layout.PENCIL_VEC, n))
    cmat = np.zeros((5, layout.PENCIL_MAT, n, n))  # corners (u_i, t_j) at 2 i + j; 4: the centre (floats)
    cvec = np.zeros((5, layout.PENCIL_VEC, n))
    return KreinWork(pw.T, pw.jmk, pw.sub, tmat, tvec, cmat, cvec, pw.beta, pw.krein, pw.cm, pw.cr,
                     np.zeros((D, D)), np.zeros((n, n)), np.zeros((n, n), np.complex128), np.zeros((n, n), np.complex128),
                     np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)),
                     np.zeros(D), np.zeros(D), np.zeros(D, np.complex128),
                     np.zeros(D + 1), np.zeros(D + 1, np.int64), np.zeros(D + 1), np.zeros((3, n * L + 1)),
                     # Krawczyk: centred parts as real balls (mid, rad): 0 M0, 1 M1, 2 K0 uc, 3 K1 uc, 4 K0 ru, 5 K1 ru
                     np.zeros((6, n, n)), np.zeros((6, n, n)), np.zeros((2, n)), np.zeros((2, n)),  # qm, qr: G0, G1
                     np.zeros(N), np.zeros(N),
                     np.zeros((N, N), np.complex128), np.zeros((N, N)), np.zeros((N, N), np.complex128), np.zeros((N, N)),
                     np.zeros((N, N), np.complex128), np.zeros(N, np.complex128), np.zeros(N), np.zeros((N, N)), np.zeros(N),
                     np.zeros(N), np.zeros(4, np.int64), np.zeros(D, np.complex128), np.zeros((D, n), np.complex128),
                     np.zeros((2, n, layout.NBODY)), np.zeros((2, n)), np.zeros(2), np.zeros((2, n)), np.zeros((n, L)), np.zeros((n, L)),
                     np.zeros(2, np.int64))


@kernel
def _ws(kw, c):
    """A ``pencil`` workspace whose matrices are those of slot c of ``kw.cmat`` (a corner, or 4 the centre)."""
    return layout.PencilWork(kw.T, kw.jmk, kw.sub, kw.cmat[c], kw.cvec[c], kw.beta, kw.krein, kw.cm, kw.cr)


@kernel
def _twork(kw, j):
    return layout.PencilWork(kw.T, kw.jmk, kw.sub, kw.tmat[j], kw.tvec[j], kw.beta, kw.krein, kw.cm, kw.cr)


@kernel
def _corners(kw, u_lo, u_hi, n):
    """kw.cmat[2 i + j]: the t corner j with the stiffness times u_i (u_0 = u_lo, u_1 = u_hi), in balls;
    kw.cmat[4]: the centre in floats (means; radii 0), which only steers."""
    for i in range(2):
        u = u_lo if i == 0 else u_hi
        for j in range(2):
            c = 2 * i + j
            kw.cmat[c, :, :, :] = kw.tmat[j]
            kw.cvec[c, :, :] = kw.tvec[j]
            for a in range(n):
                for b in range(n):
                    kw.cmat[c, layout.K_MID, a, b], kw.cmat[c, layout.K_RAD, a, b] = ball.rmul(
                        u, 0.0, kw.tmat[j, layout.K_MID, a, b], kw.tmat[j, layout.K_RAD, a, b])
    uc = 0.5 * u_lo + 0.5 * u_hi
    kw.cmat[4] = 0.0
    kw.cvec[4] = 0.0
    for a in range(n):
        for b in range(n):
            kw.cmat[4, layout.M_MID, a, b] = 0.5 * (kw.tmat[0, layout.M_MID, a, b] + kw.tmat[1, layout.M_MID, a, b])
            kw.cmat[4, layout.K_MID, a, b] = uc * 0.5 * (kw.tmat[0, layout.K_MID, a, b] + kw.tmat[1, layout.K_MID, a, b])
        for r in (layout.G_MID, layout.ESUM_MID):
            kw.cvec[4, r, a] = 0.5 * (kw.tvec[0, r, a] + kw.tvec[1, r, a])


@kernel
def _lc_positive(kw, n):
    """M' = M - diag(sum_l E_kl) proved positive definite at both t corners (so on the box: affine in t)."""
    for j in range(2):
        for a in range(n):
            for b in range(a + 1):
                kw.Sm[a, b], kw.Sr[a, b] = kw.tmat[j, layout.M_MID, a, b], kw.tmat[j, layout.M_RAD, a, b]
            kw.Sm[a, a], kw.Sr[a, a] = ball.radd(kw.Sm[a, a], kw.Sr[a, a], -kw.tvec[j, layout.ESUM_MID, a], kw.tvec[j, layout.ESUM_RAD, a])
        if elimination.inertia(kw.Sm, kw.Sr, n) != 0:
            return False
    return True


@kernel
def _compress(Sm, Sr, V, cols, ncols, n, Wm, Wr):
    """Balls of W = V[:, cols]^T S V[:, cols] (lower triangle) for the symmetric ball matrix S (lower triangle read)
    and the float V."""
    for a in range(ncols):
        for b in range(a + 1):
            wm, wr = 0.0, 0.0
            for i in range(n):
                # (S V_b)_i
                sm, sr = 0.0, 0.0
                for j in range(n):
                    em, er = (Sm[i, j], Sr[i, j]) if j <= i else (Sm[j, i], Sr[j, i])
                    t = ball.rmul(em, er, V[j, cols[b]], 0.0)
                    sm, sr = ball.radd(sm, sr, t[0], t[1])
                t = ball.rmul(V[i, cols[a]], 0.0, sm, sr)
                wm, wr = ball.radd(wm, wr, t[0], t[1])
            Wm[a, b], Wr[a, b] = wm, wr


@kernel
def _jacobi(A, n, w, V):
    """Eigenvalues w and eigenvectors (columns of V) of the symmetric float A (n x n, destroyed): cyclic Jacobi,
    no allocation (LAPACK's call costs more than the work at these sizes).  Only steers."""
    for i in range(n):
        for j in range(n):
            V[i, j] = 1.0 if i == j else 0.0
    for _ in range(30):
        off = 0.0
        diag = 0.0
        for i in range(n):
            diag += A[i, i] * A[i, i]
            for j in range(i + 1, n):
                off += A[i, j] * A[i, j]
        if off <= 1e-32 * diag or off == 0.0:
            break
        for p in range(n - 1):
            for q in range(p + 1, n):
                apq = A[p, q]
                if apq == 0.0:
                    continue
                theta = (A[q, q] - A[p, p]) / (2.0 * apq)
                t = (1.0 if theta >= 0.0 else -1.0) / (abs(theta) + math.sqrt(theta * theta + 1.0))
                c = 1.0 / math.sqrt(t * t + 1.0)
                sn = t * c
                for k in range(n):
                    akp, akq = A[k, p], A[k, q]
                    A[k, p], A[k, q] = c * akp - sn * akq, sn * akp + c * akq
                for k in range(n):
                    apk, aqk = A[p, k], A[q, k]
                    A[p, k], A[q, k] = c * apk - sn * aqk, sn * apk + c * aqk
                for k in range(n):
                    vkp, vkq = V[k, p], V[k, q]
                    V[k, p], V[k, q] = c * vkp - sn * vkq, sn * vkp + c * vkq
    for i in range(n):
        w[i] = A[i, i]


@kernel
def _csolve(A, B, N, m, X):
    """X = A^-1 B for the complex N x N A and N x m B by Gaussian elimination with partial pivoting, A and B
    destroyed; False if a pivot is 0 or the result not finite.  Floats: only steers."""
    for c in range(N):
        p, best = c, -1.0
        for i in range(c, N):
            if abs(A[i, c]) > best:
                p, best = i, abs(A[i, c])
        if not best > 0.0:
            return False
        if p != c:
            for j in range(N):
                A[c, j], A[p, j] = A[p, j], A[c, j]
            for j in range(m):
                B[c, j], B[p, j] = B[p, j], B[c, j]
        inv = 1.0 / A[c, c]
        for i in range(c + 1, N):
            f = A[i, c] * inv
            if f == 0.0:
                continue
            for j in range(c, N):
                A[i, j] -= f * A[c, j]
            for j in range(m):
                B[i, j] -= f * B[c, j]
    for j in range(m):
        for i in range(N - 1, -1, -1):
            t = B[i, j]
            for q in range(i + 1, N):
                t -= A[i, q] * X[q, j]
            X[i, j] = t / A[i, i]
            if not (math.isfinite(X[i, j].real) and math.isfinite(X[i, j].imag)):
                return False
    return True


@kernel
def _separator_inertia(s, body2, E, nmodes, parent, kw, n):
    """nu(Phi_1(s; .)) proved constant over the box (four corners, two compressions): that count, or -1."""
    ws = _ws(kw, 4)
    pencil.float_matrices(s + 0.0j, body2[0], E, nmodes, ws, kw.F, kw.dF)
    for a in range(n):
        for b in range(n):
            kw.Wm[a, b] = kw.F[a, b].real
    w, V = kw.bv[:n], kw.V
    _jacobi(kw.Wm, n, w, V)
    neg = np.empty(n, np.int64)
    pos = np.empty(n, np.int64)
    nn, npos = 0, 0
    for i in range(n):
        if w[i] < 0.0:
            neg[nn] = i
            nn += 1
        else:
            pos[npos] = i
            npos += 1
    for c in range(4):
        if not pencil.real_matrix(s, body2[c % 2], E, nmodes, parent, _ws(kw, c), kw.Sm, kw.Sr):
            return -1
        if nn > 0:
            _compress(kw.Sm, kw.Sr, V, neg, nn, n, kw.Wm, kw.Wr)
            if elimination.inertia(kw.Wm, kw.Wr, nn) != nn:
                return -1
        if npos > 0:
            _compress(kw.Sm, kw.Sr, V, pos, npos, n, kw.Wm, kw.Wr)
            if elimination.inertia(kw.Wm, kw.Wr, npos) != 0:
                return -1
    return nn


@kernel
def _pole_terms(s, kw, nb):
    """#{bordered modes: c (s + beta) < 0}, or -1 if some s + beta is not proved nonzero."""
    count = 0
    for i in range(nb):
        dm, dr = ball.radd(s, 0.0, kw.bord[0, i], kw.bord[1, i])
        if not ball.excludes_zero(dm, dr):
            return -1
        if (dm > 0.0) != (kw.bord[2, i] > 0.0):
            count += 1
    return count


@kernel
def _place_separators(kw, nreal, npole):
    """Separators between neighbouring real approximations (sorted in kw.feat[:nreal]) of different types, each at
    the middle of the widest gap between the two roots and the poles between them (kw.bord[0, :npole]: minus the
    poles).  Returns how many (kw.seps)."""
    ns = 0
    for i in range(nreal - 1):
        if kw.ftype[i] == kw.ftype[i + 1]:
            continue
        a, b = kw.feat[i], kw.feat[i + 1]
        if not a < b:
            continue
        # widest gap among a, the poles in (a, b) (every pole: bordered or not), b
        best, where = -1.0, 0.5 * (a + b)
        left = a
        while True:
            nxt = b
            for q in range(npole):
                x = -kw.bord[0, q]
                if left < x < nxt:
                    nxt = x
            if nxt - left > best:
                best, where = nxt - left, 0.5 * (left + nxt)
            if nxt >= b:
                break
            left = nxt
        kw.seps[ns] = where
        ns += 1
    return ns


@kernel
def _null_vector(A, n, x):
    """A float null vector of the nearly singular A (n x n, destroyed): one step of inverse iteration from ones,
    by Gaussian elimination with partial pivoting (a zero pivot replaced by a tiny one).  Only steers."""
    for i in range(n):
        x[i] = 1.0
    for c in range(n):
        p, best = c, -1.0
        for i in range(c, n):
            if abs(A[i, c]) > best:
                p, best = i, abs(A[i, c])
        if p != c:
            for j in range(n):
                A[c, j], A[p, j] = A[p, j], A[c, j]
            x[c], x[p] = x[p], x[c]
        if A[c, c] == 0.0:
            A[c, c] = 2.0**-60 * (1.0 + best)
        for i in range(c + 1, n):
            f = A[i, c] / A[c, c]
            for j in range(c, n):
                A[i, j] -= f * A[c, j]
            x[i] -= f * x[c]
    for i in range(n - 1, -1, -1):
        t = x[i]
        for j in range(i + 1, n):
            t -= A[i, j] * x[j]
        x[i] = t / A[i, i]
    big = 0.0
    for i in range(n):
        big = max(big, abs(x[i]))
    if not (big > 0.0 and math.isfinite(big)):
        return False
    for i in range(n):
        x[i] /= big
    return True


@kernel
def _count(kw, ns, body2, E, nmodes, parent, n, nb, cpos):
    """Real roots of det H proved at every point of the box: sum |delta nu_H| over -inf, kw.seps[:ns], +inf; or -1."""
    last = cpos  # nu_H(-inf) = nu(M') + #{c > 0}, nu(M') = 0
    real = 0
    for i in range(ns):
        s = kw.seps[i]
        if i > 0 and not s > kw.seps[i - 1]:
            return -1
        poles = _pole_terms(s, kw, nb)
        if poles < 0:
            return -1
        nu = _separator_inertia(s, body2, E, nmodes, parent, kw, n)
        if nu < 0:
            return -1
        nu += poles
        real += abs(nu - last)
        last = nu
    return real + abs((nb - cpos) - last)  # nu_H(+inf) = #{c < 0}


@kernel
def _pairs_once(kw, k, warm, E, nmodes, n):
    """k pairs proved by Krawczyk tests over the (sub-)box of kw.pm (``_krawczyk_parts``) from kw.pz[:k] (with
    ``warm`` also the eigenvectors kw.pv[:k]), the discs pairwise disjoint and in the upper half plane; the polished
    approximations back into kw.pz, kw.pv."""
    cz = np.empty(k, np.complex128)
    cr = np.empty(k)
    for q in range(k):
        ok, z, r = _krawczyk(kw.pz[q], kw.pv[q], warm, E, nmodes, kw, n, kw.pv[q])
        if not ok:
            return False
        cz[q], cr[q] = z, r
        kw.pz[q] = z
    for a in range(k):
        for b in range(a):
            if not abs(cz[a] - cz[b]) * ball.LOW > (cr[a] + cr[b]) * ball.INFL:
                return False
    return True


@kernel
def _pairs(kw, k, warm, E, nmodes, n, u_lo, u_hi):
    """k non-real pairs at every point of the box: Krawczyk over the whole box, else over each of its 2 x 2
    quarters (``SPLIT_PAIRS``; their union is the box: u at u_lo, the float midpoint, u_hi; s at -1, 0, 1).  The
    real count holds on the whole box already, so k pairs on each quarter give N_c = k on the box."""
    for depth in range(SPLIT_PAIRS + 1):
        m = 1 << depth
        ok = True
        for iu in range(m):
            a = u_lo if iu == 0 else u_lo + (u_hi - u_lo) * (iu / m)
            b = u_hi if iu == m - 1 else u_lo + (u_hi - u_lo) * ((iu + 1) / m)
            if not (u_lo <= a <= b <= u_hi):
                return False
            for js in range(m):
                _krawczyk_parts(kw, a, b, n, -1.0 + (2.0 * js + 1.0) / m, 1.0 / m)
                if not _pairs_once(kw, k, warm or depth > 0 or iu + js > 0, E, nmodes, n):
                    ok = False
                    break
            if not ok:
                break
        if ok:
            return True
    return False


@kernel
def _same_inputs(kw, body2, joint2, g2, at2, E, kappa, nmodes, n):
    """Whether the last box prepared exactly these inputs (kw.prev[3] = 1: kw.lbody ... hold them)."""
    if kw.prev[3] != 1:
        return False
    for j in range(2):
        if g2[j] != kw.lg[j]:
            return False
        for k in range(n):
            if joint2[j, k] != kw.ljoint[j, k] or at2[j, k] != kw.lat[j, k]:
                return False
            for c in range(layout.NBODY):
                if body2[j, k, c] != kw.lbody[j, k, c]:
                    return False
    for k in range(n):
        for l in range(nmodes[k]):
            if E[k, l] != kw.lE[k, l] or kappa[k, l] != kw.lkappa[k, l]:
                return False
    return True


@kernel
def krein_box(body2, joint2, g2, at2, E, kappa, nmodes, free, parent, u_lo, u_hi, kw, info):
    """N_c proved on the box (module docstring), or -1.  body2[j], joint2[j], g2[j], at2[j]: the kernel inputs at the
    t corner j (every spin 1, the stiffness at u = 1); u in [u_lo, u_hi], 0 < u_lo <= u_hi.

    kw.prev holds what the last box proved with (kw.prev[0] = 1: its separators kw.seps[:prev[1]] and its prev[2]
    pairs' approximations kw.pz, kw.pv): a neighbour's, tried first with no eigenvalue problem.  Approximations
    only steer: any of them, from anywhere, leaves the proof as rigorous."""
    n = body2.shape[1]
    info[:] = 0
    info[INFO_REAL] = -1
    kw.stats[:] = 0
    warm = kw.prev[0] == 1
    kw.prev[0] = 0
    if not (u_lo > 0.0 and u_lo <= u_hi and u_hi < math.inf):
        return -1
    for j in range(2):
        for k in range(n):
            if body2[j, k, layout.OMEGA] != 1.0:
                return -1
    # M, K of the two t corners: as the last box's if its inputs were these (a sweep along omega)
    if not _same_inputs(kw, body2, joint2, g2, at2, E, kappa, nmodes, n):
        for j in range(2):
            pencil.prepare(body2[j], joint2[j], at2[j], g2[j], E, kappa, nmodes, parent, free, _twork(kw, j), False)
        kw.lbody[:] = body2
        kw.ljoint[:] = joint2
        kw.lg[:] = g2
        kw.lat[:] = at2
        for k in range(n):
            for l in range(nmodes[k]):
                kw.lE[k, l], kw.lkappa[k, l] = E[k, l], kappa[k, l]
        kw.prev[3] = 1
    # the modes: exact roots (beta = 0: at 0; E = 0: at -beta) and the bordered ones with the sign of c
    D, exact, nb = 0, 0, 0
    for k in range(n):
        D += 2 + nmodes[k]
        for l in range(nmodes[k]):
            bm, br = kw.beta[0, k, l], kw.beta[1, k, l]
            if bm == 0.0 and br == 0.0:
                exact += 1
            elif E[k, l] == 0.0:
                exact += 1
            else:
                kw.bord[0, nb], kw.bord[1, nb] = bm, br
                kw.bord[2, nb] = 1.0 if (E[k, l] > 0.0) == (kappa[k, l] > 0.0) else -1.0  # sign(c) = sign(E kappa)
                nb += 1
    npole = nb  # then the poles of the modes with E = 0: no term of Phi_1, but real_matrix avoids them too
    for k in range(n):
        for l in range(nmodes[k]):
            bm, br = kw.beta[0, k, l], kw.beta[1, k, l]
            if E[k, l] == 0.0 and not (bm == 0.0 and br == 0.0):
                kw.bord[0, npole], kw.bord[1, npole], kw.bord[2, npole] = bm, br, 0.0
                npole += 1
    cpos = 0
    for i in range(nb):
        if kw.bord[2, i] > 0.0:
            cpos += 1
    info[INFO_STAGE] = 1
    if not _lc_positive(kw, n):
        return -1
    _corners(kw, u_lo, u_hi, n)
    # a neighbour's separators and pairs first
    if warm:
        ns, k = kw.prev[1], kw.prev[2]
        real = _count(kw, ns, body2, E, nmodes, parent, n, nb, cpos)
        if real >= 0 and real + exact + 2 * k == D and (k == 0 or _pairs(kw, k, True, E, nmodes, n, u_lo, u_hi)):
            kw.prev[0] = 1
            info[INFO_SEPARATORS], info[INFO_PAIRS], info[INFO_REAL], info[INFO_STAGE] = ns, k, real + exact, 7
            return k
    info[INFO_STAGE] = 2
    # approximations at the centre (floats: they only steer)
    Dl = D
    cws = _ws(kw, 4)
    if not pencil.linearisation(body2[0], E, nmodes, parent, cws, kw.C, kw.Mo):
        return -1
    for i in range(Dl):
        for j in range(Dl):
            if not math.isfinite(kw.C[i, j]):
                return -1
    if not approximations.eigenvalues(kw.C, kw.wr, kw.wi, kw.V, kw.z, Dl, 0):
        return -1
    w = kw.z
    nreal = 0
    order = np.argsort(w.real)
    x = kw.bv[:n]
    for idx in order:
        z = w[idx]
        if abs(z.imag) > NEAR_REAL * (1.0 + abs(z)):
            continue
        # Krein type: sign of theta^T Phi_1'(z) theta, theta a null vector of Phi_1(z)
        pencil.float_matrices(z.real + 0.0j, body2[0], E, nmodes, cws, kw.F, kw.dF)
        for i in range(n):
            for j in range(n):
                kw.Wm[i, j] = kw.F[i, j].real
        if not _null_vector(kw.Wm, n, x):
            continue
        tau = 0.0
        for i in range(n):
            for j in range(n):
                tau += x[i] * kw.dF[i, j].real * x[j]
        kw.feat[nreal] = z.real
        kw.ftype[nreal] = 1 if tau >= 0.0 else -1
        nreal += 1
    info[INFO_STAGE] = 3
    ns = _place_separators(kw, nreal, npole)
    info[INFO_SEPARATORS] = ns
    real = _count(kw, ns, body2, E, nmodes, parent, n, nb, cpos)
    if real < 0:
        return -1
    real += exact
    info[INFO_REAL] = real
    info[INFO_STAGE] = 4
    if real > D or (D - real) % 2 != 0:
        return -1
    k = (D - real) // 2
    if k > 0:
        # the k upper approximations farthest from the axis
        info[INFO_STAGE] = 5
        up = np.empty(Dl, np.int64)
        nup = 0
        for i in range(Dl):
            if w[i].imag > NEAR_REAL * (1.0 + abs(w[i])):
                up[nup] = i
                nup += 1
        if nup < k:
            return -1
        ims = np.empty(nup)
        for i in range(nup):
            ims[i] = -w[up[i]].imag
        pick = np.argsort(ims)[:k]
        for q in range(k):
            kw.pz[q] = w[up[pick[q]]]
        if not _pairs(kw, k, False, E, nmodes, n, u_lo, u_hi):
            return -1
    kw.prev[0], kw.prev[1], kw.prev[2] = 1, ns, k
    info[INFO_PAIRS] = k
    info[INFO_STAGE] = 6
    return k


# ---------------------------------------------------------------------------------------------------------------
# The Krawczyk test of one complex pair over the box


@kernel
def _half(am, ar, bm, br, sign):
    """(a + sign b) / 2 as a ball (the halving is exact but for underflow, covered by ETA in radd)."""
    m, r = ball.radd(am, ar, sign * bm, br)
    return 0.5 * m, 0.5 * r + ball.ETA


@kernel
def _centred(am, ar, bm, br, sc, hs):
    """For X(s) = A + s B (balls A, B), s = sc + hs sigma: the balls of A + sc B and hs B (sc, hs dyadic floats)."""
    t = ball.rmul(sc, 0.0, bm, br)
    c = ball.radd(am, ar, t[0], t[1])
    return c[0], c[1], hs * bm, hs * br + ball.ETA


@kernel
def _krawczyk_parts(kw, u_lo, u_hi, n, sc, hs):
    """The centred parts over the sub-box u in [u_lo, u_hi], s in [sc - hs, sc + hs] (s in [-1, 1] the box's t):
    kw.pm, kw.pr: 0 M0, 1 M1, 2 uc K0, 3 uc K1, 4 ru K0, 5 ru K1 (real balls; M0 and M1 the middle and half change of
    M over the sub-box's t, from M(s) = (M(t_lo) + M(t_hi)) / 2 + s (M(t_hi) - M(t_lo)) / 2; K at u = 1); kw.qm,
    kw.qr: G0, G1.  [u_lo, u_hi] lies in [uc - ru, uc + ru]."""
    uc = 0.5 * u_lo + 0.5 * u_hi
    ru = np.nextafter(max(u_hi - uc, uc - u_lo), np.inf)
    t = kw.tmat
    for a in range(n):
        for b in range(n):
            m0, r0 = _half(t[1, layout.M_MID, a, b], t[1, layout.M_RAD, a, b], t[0, layout.M_MID, a, b], t[0, layout.M_RAD, a, b], 1.0)
            m1, r1 = _half(t[1, layout.M_MID, a, b], t[1, layout.M_RAD, a, b], t[0, layout.M_MID, a, b], t[0, layout.M_RAD, a, b], -1.0)
            kw.pm[0, a, b], kw.pr[0, a, b], kw.pm[1, a, b], kw.pr[1, a, b] = _centred(m0, r0, m1, r1, sc, hs)
            m0, r0 = _half(t[1, layout.K_MID, a, b], t[1, layout.K_RAD, a, b], t[0, layout.K_MID, a, b], t[0, layout.K_RAD, a, b], 1.0)
            m1, r1 = _half(t[1, layout.K_MID, a, b], t[1, layout.K_RAD, a, b], t[0, layout.K_MID, a, b], t[0, layout.K_RAD, a, b], -1.0)
            k0m, k0r, k1m, k1r = _centred(m0, r0, m1, r1, sc, hs)
            kw.pm[2, a, b], kw.pr[2, a, b] = ball.rmul(uc, 0.0, k0m, k0r)
            kw.pm[3, a, b], kw.pr[3, a, b] = ball.rmul(uc, 0.0, k1m, k1r)
            kw.pm[4, a, b], kw.pr[4, a, b] = ball.rmul(ru, 0.0, k0m, k0r)
            kw.pm[5, a, b], kw.pr[5, a, b] = ball.rmul(ru, 0.0, k1m, k1r)
        g0, gr0 = _half(kw.tvec[1, layout.G_MID, a], kw.tvec[1, layout.G_RAD, a], kw.tvec[0, layout.G_MID, a], kw.tvec[0, layout.G_RAD, a], 1.0)
        g1, gr1 = _half(kw.tvec[1, layout.G_MID, a], kw.tvec[1, layout.G_RAD, a], kw.tvec[0, layout.G_MID, a], kw.tvec[0, layout.G_RAD, a], -1.0)
        kw.qm[0, a], kw.qr[0, a], kw.qm[1, a], kw.qr[1, a] = _centred(g0, gr0, g1, gr1, sc, hs)


@kernel
def _phi_disc(z, zr, which, E, nmodes, kw, n, Fm, Fr, dFm, dFr):
    """Complex balls of P(Z), P'(Z) over the disc Z = (z, zr): which 0 the centre's Phi_1 (M0, G0, uc K0, liquid),
    1 the t part Ps (M1, G1, uc K1, no liquid).  False if Z may hold a pole."""
    beta = kw.beta
    z2m, z2r = ball.cmul(z, zr, z, zr)
    a2 = abs(z2m) * ball.INFL  # upper bounds of |z^2|, |z| (hypot is within an ulp)
    az = abs(z) * ball.INFL
    im, kk = (0, 2) if which == 0 else (1, 3)
    for a in range(n):
        for b in range(n):
            # z^2 M - K for the complex ball z^2 and real balls M, K: the product of a complex float by a real one
            # rounds each part once (<= sqrt 2 u |z^2| |M|), the subtraction the real part once
            mm, mr, km, kr = kw.pm[im, a, b], kw.pr[im, a, b], kw.pm[kk, a, b], kw.pr[kk, a, b]
            am_ = abs(mm)
            Fm[a, b] = z2m * mm - km
            Fr[a, b] = (a2 * mr + z2r * (am_ + mr) + kr + 4.0 * ball.U * (a2 * am_ + abs(km)) + ball.ETA) * ball.INFL * ball.INFL
            dFm[a, b] = (2.0 * z) * mm  # 2 z exact
            dFr[a, b] = (2.0 * az * mr + 2.0 * zr * (am_ + mr) + 4.0 * ball.U * az * am_ + ball.ETA) * ball.INFL * ball.INFL
        gm, gr = ball.cmul(z, zr, kw.qm[which, a] + 0.0j, kw.qr[which, a])
        Fm[a, a], Fr[a, a] = ball.cadd(Fm[a, a], Fr[a, a], gm, gr)
        dFm[a, a], dFr[a, a] = ball.cadd(dFm[a, a], dFr[a, a], kw.qm[which, a] + 0.0j, kw.qr[which, a])
        if which != 0:
            continue
        # liquid: L = z^2 (z + 1) A + z (z + 1) e, L' = (3 z^2 + 2 z) A + z^2 (z + 1) A' + (2 z + 1) e,
        # A = sum E / (z + beta), A' = -sum E / (z + beta)^2 over beta != 0, e = sum E over beta = 0
        am, ar, pm_, pr_, em, er = 0.0j, 0.0, 0.0j, 0.0, 0.0j, 0.0
        for l in range(nmodes[a]):
            if beta[0, a, l] == 0.0 and beta[1, a, l] == 0.0:
                em, er = ball.cadd(em, er, E[a, l] + 0.0j, 0.0)
                continue
            dm, dr = ball.cadd(z, zr, beta[0, a, l] + 0.0j, beta[1, a, l])
            if not ball.excludes_zero(dm, dr):
                return False
            qm, qr = ball.cinv(dm, dr)
            tm, tr = ball.cmul(E[a, l] + 0.0j, 0.0, qm, qr)
            am, ar = ball.cadd(am, ar, tm, tr)
            tm, tr = ball.cmul(tm, tr, qm, qr)
            pm_, pr_ = ball.cadd(pm_, pr_, -tm, tr)
        w1m, w1r = ball.cadd(z, zr, 1.0 + 0.0j, 0.0)  # z + 1
        z3m, z3r = ball.cmul(z2m, z2r, w1m, w1r)  # z^2 (z + 1)
        Lm, Lr = ball.cmul(z3m, z3r, am, ar)
        zw = ball.cmul(z, zr, w1m, w1r)  # z (z + 1)
        t = ball.cmul(zw[0], zw[1], em, er)
        Lm, Lr = ball.cadd(Lm, Lr, t[0], t[1])
        Fm[a, a], Fr[a, a] = ball.cadd(Fm[a, a], Fr[a, a], -Lm, Lr)
        # L'
        # 3 z^2 + 2 z: 2 z is exact, 3 z2m rounds by at most 2u |3 z2m| (covered with 4u), 3 z2r rounded up
        c3 = ball.cadd(3.0 * z2m, (3.0 * z2r + 4.0 * ball.U * abs(3.0 * z2m)) * ball.INFL, 2.0 * z, 2.0 * zr)
        t1 = ball.cmul(c3[0], c3[1], am, ar)
        t2 = ball.cmul(z3m, z3r, pm_, pr_)
        t3 = ball.cmul(2.0 * z + 1.0, (2.0 * zr + 2.0 * ball.U * abs(2.0 * z + 1.0)) * ball.INFL, em, er)
        dl = ball.cadd(t1[0], t1[1], t2[0], t2[1])
        dl = ball.cadd(dl[0], dl[1], t3[0], t3[1])
        dFm[a, a], dFr[a, a] = ball.cadd(dFm[a, a], dFr[a, a], -dl[0], dl[1])
    return True


@kernel
def _float_phi(z, E, nmodes, kw, n, F, dF):
    """Floats of the centre's Phi_1(z) and Phi_1'(z) (midpoints of ``_phi_disc`` with which 0); only steers."""
    beta = kw.beta
    z2 = z * z
    for a in range(n):
        for b in range(n):
            F[a, b] = z2 * kw.pm[0, a, b] - kw.pm[2, a, b]
            dF[a, b] = (2.0 * z) * kw.pm[0, a, b]
        A, Ad, e = 0.0j, 0.0j, 0.0
        for l in range(nmodes[a]):
            if beta[0, a, l] == 0.0 and beta[1, a, l] == 0.0:
                e += E[a, l]
                continue
            q = ball.recip(z + beta[0, a, l])
            A += E[a, l] * q
            Ad -= E[a, l] * q * q
        F[a, a] += z * kw.qm[0, a] - z2 * (z + 1.0) * A - z * (z + 1.0) * e
        dF[a, a] += kw.qm[0, a] - (3.0 * z2 + 2.0 * z) * A - z2 * (z + 1.0) * Ad - (2.0 * z + 1.0) * e
    for a in range(n):
        for b in range(n):
            if not (math.isfinite(F[a, b].real) and math.isfinite(F[a, b].imag) and math.isfinite(dF[a, b].real) and math.isfinite(dF[a, b].imag)):
                return False
    return True


@kernel
def _gamma(N):
    """A bound c with |fl(sum_q a_q b_q) - sum_q a_q b_q| <= c sum_q |a_q| |b_q| for N complex terms (BPZ: sqrt 5 u
    a product, sqrt 2 u an addition of partial sums; first order, with room for the rest at these sizes)."""
    return (4.0 * N + 8.0) * ball.U


@kernel
def _rvec_abs(R, aR, vm, vr, N, out):
    """out += |R v| (upper bounds) for the float R (aR = |R| rounded up) and the ball vector v."""
    g = _gamma(N)
    for i in range(N):
        m = 0.0j
        s1, s2 = 0.0, 0.0
        for q in range(N):
            m += R[i, q] * vm[q]
            av = abs(vm[q]) * ball.INFL
            s1 += aR[i, q] * vr[q]
            s2 += aR[i, q] * av
        r = (s1 + g * s2 + (4.0 * N + 4.0) * ball.ETA) * (1.0 + (2.0 * N + 8.0) * ball.U)
        out[i] = (out[i] + (abs(m) + r) * ball.INFL) * ball.INFL


@kernel
def _matvec_ball(Am, Ar, vm, vr, n, om, or_):
    """o = A v in complex balls (n x n times n)."""
    g = _gamma(n)
    for i in range(n):
        m = 0.0j
        s1, s2 = 0.0, 0.0
        for q in range(n):
            m += Am[i, q] * vm[q]
            aa, av = abs(Am[i, q]) * ball.INFL, abs(vm[q]) * ball.INFL
            s1 += aa * vr[q] + Ar[i, q] * (av + vr[q])
            s2 += aa * av
        om[i] = m
        or_[i] = (s1 + g * s2 + (4.0 * n + 4.0) * ball.ETA) * (1.0 + (2.0 * n + 8.0) * ball.U)


@kernel
def _bound_abs(R, aR, Am, Ar, N, B, identity, aA):
    """B += |I - R A| (``identity``) or |R A| (upper bounds) for the float R (aR = |R| rounded up) and the ball
    matrix A (N x N); aA is scratch."""
    g = _gamma(N + 1)
    for q in range(N):
        for j in range(N):
            aA[q, j] = abs(Am[q, j]) * ball.INFL
    for i in range(N):
        for j in range(N):
            m = 0.0j
            s1, s2 = 0.0, 0.0
            for q in range(N):
                m += R[i, q] * Am[q, j]
                s1 += aR[i, q] * Ar[q, j]
                s2 += aR[i, q] * aA[q, j]
            if identity:
                m = -m
                if i == j:
                    s2 += 1.0  # the rounding of 1 - m is within 2u (1 + |m|): inside g (s2 + 1)
                    m = m + 1.0
            r = (s1 + g * s2 + (4.0 * N + 4.0) * ball.ETA) * (1.0 + (2.0 * N + 8.0) * ball.U)
            B[i, j] = (B[i, j] + (abs(m) + r) * ball.INFL) * ball.INFL


@kernel
def _jacobian(z, zr, v, vr, k, which, E, nmodes, kw, n, F, Fr, dF, dFr, Jm, Jr, om, orr):
    """Balls of [[P(Z), P'(Z) V], [e_k^T or 0, 0]] (``which`` as ``_phi_disc``) into Jm, Jr; False at a pole."""
    if not _phi_disc(z, zr, which, E, nmodes, kw, n, F, Fr, dF, dFr):
        return False
    Jm[:, :] = 0.0
    Jr[:, :] = 0.0
    for a in range(n):
        for b in range(n):
            Jm[a, b], Jr[a, b] = F[a, b], Fr[a, b]
    _matvec_ball(dF, dFr, v, vr, n, om, orr)
    for a in range(n):
        Jm[a, n], Jr[a, n] = om[a], orr[a]
    if which == 0:
        Jm[n, k] = 1.0
    return True


@kernel
def _constant_part(q, kw, n, Jm, Jr):
    """[[-kw.pm[q], 0], [0, 0]] as balls (Pa = -ru K0 for q = 4, Pas = -ru K1 for q = 5)."""
    Jm[:, :] = 0.0
    Jr[:, :] = 0.0
    for a in range(n):
        for b in range(n):
            Jm[a, b], Jr[a, b] = -kw.pm[q, a, b] + 0.0j, kw.pr[q, a, b]


@kernel
def _krawczyk(z0, v0, warm, E, nmodes, kw, n, vout):
    """(ok, mu~, rho_mu): a disc about mu~ in the upper half plane holding, for every point of the box, exactly one
    eigenvalue of Phi_1 with its eigenvector in the box about v~ (module docstring).  Starts from z0 and, with
    ``warm``, the eigenvector v0 (else the least singular vector of Phi_1(z0)); v~ into vout."""
    N = n + 1
    F, dF, Fr, dFr = kw.F, kw.dF, kw.Sm, kw.Sr
    Jm, Jr, Xr, B = kw.Jm, kw.Jr, kw.Xr, kw.Bm
    om = kw.bm[:n]
    orr = kw.br[:n]
    z = z0
    v = np.empty(n, np.complex128)
    if warm:
        v[:] = v0
    else:
        if not _phi_disc(z, 0.0, 0, E, nmodes, kw, n, F, Fr, dF, dFr):
            return False, z, 0.0
        # one step of inverse iteration from ones (Phi_1(z0) is nearly singular), else the least singular vector
        A = F.copy()
        ones = np.ones((n, 1), np.complex128)
        col = np.empty((n, 1), np.complex128)
        if _csolve(A, ones, n, 1, col):
            for i in range(n):
                v[i] = col[i, 0]
        else:
            U, S, Vh = np.linalg.svd(F)
            for i in range(n):
                v[i] = np.conj(Vh[n - 1, i])
    k = 0
    for i in range(n):
        if abs(v[i]) > abs(v[k]):
            k = i
    if not abs(v[k]) > 0.0:
        return False, z, 0.0
    v = v / v[k]
    rhs = np.empty(N, np.complex128)
    dcol = np.empty((N, 1), np.complex128)
    J = kw.Rm
    vr0 = np.zeros(n)
    for step in range(NEWTON_STEPS):
        if not _float_phi(z, E, nmodes, kw, n, F, dF):
            return False, z, 0.0
        kw.stats[0] += 1
        J[:, :] = 0.0
        for a in range(n):
            for b in range(n):
                J[a, b] = F[a, b]
            t, w = 0.0j, 0.0j
            for b in range(n):
                t += dF[a, b] * v[b]
                w += F[a, b] * v[b]
            J[a, n] = t
            rhs[a] = w
        J[n, k] = 1.0
        rhs[n] = v[k] - 1.0
        if not _csolve(J, rhs.reshape((N, 1)), N, 1, dcol):
            return False, z, 0.0
        for a in range(n):
            v[a] -= dcol[a, 0]
        z = z - dcol[n, 0]
        v = v / v[k]
        if abs(dcol[n, 0]) <= 2.0**-45 * abs(z) and step >= 1:
            break
    # Phi_1(z~) in balls (the residual below) and Phi_1'(z~): their midpoints make J(x~) for R
    if not _phi_disc(z, 0.0, 0, E, nmodes, kw, n, F, Fr, dF, dFr):
        return False, z, 0.0
    v[k] = 1.0  # exactly: F's last entry v_k - 1 is then 0
    if not z.imag > 0.0:
        return False, z, 0.0
    vout[:] = v
    J[:, :] = 0.0
    for a in range(n):
        for b in range(n):
            J[a, b] = F[a, b]
        t = 0.0j
        for b in range(n):
            t += dF[a, b] * v[b]
        J[a, n] = t
    J[n, k] = 1.0
    R = np.empty((N, N), np.complex128)
    eye = np.zeros((N, N), np.complex128)
    for i in range(N):
        eye[i, i] = 1.0
    if not _csolve(J, eye, N, N, R):
        return False, z, 0.0
    aR = np.empty((N, N))
    for i in range(N):
        for j in range(N):
            aR[i, j] = abs(R[i, j]) * ball.INFL
    # R F(x~) over the box: F0 + a Fa + s Fs + a s Fas, each R * part in balls before |.|  (F is Phi_1(z~) in balls)
    bm = kw.cr0
    vm = np.zeros(N, np.complex128)
    base = np.zeros(N)
    _matvec_ball(F, Fr, v, vr0, n, om, orr)
    for a in range(n):
        vm[a], bm[a] = om[a], orr[a]
    vm[n], bm[n] = 0.0, 0.0
    _rvec_abs(R, aR, vm, bm, N, base)
    for part in range(3):  # Pa = -ru K0, Ps(z~), Pas = -ru K1
        if part == 1:
            _phi_disc(z, 0.0, 1, E, nmodes, kw, n, F, Fr, dF, dFr)
        else:
            q = 4 if part == 0 else 5
            for a in range(n):
                for b in range(n):
                    F[a, b], Fr[a, b] = -kw.pm[q, a, b] + 0.0j, kw.pr[q, a, b]
        _matvec_ball(F, Fr, v, vr0, n, om, orr)
        for a in range(n):
            vm[a], bm[a] = om[a], orr[a]
        _rvec_abs(R, aR, vm, bm, N, base)
    # |R Ja| + |R Jas|: the same for every X
    Bc = np.zeros((N, N))
    for q in (4, 5):
        _constant_part(q, kw, n, Jm, Jr)
        _bound_abs(R, aR, Jm, Jr, N, Bc, False, Xr)
    xa = np.empty(N)
    for i in range(n):
        xa[i] = abs(v[i])
    xa[n] = abs(z)
    rho = np.empty(N)
    for i in range(N):
        rho[i] = 2.0 * base[i] + TINY * (1.0 + xa[i])
    vb = np.empty(n)
    kr = np.empty(N)
    for it in range(KRAWCZYK_STEPS):
        kw.stats[1] += 1
        if not (rho[n] < z.imag * ball.LOW):
            return False, z, 0.0
        for i in range(n):
            vb[i] = rho[i]
        B[:, :] = Bc
        if not _jacobian(z, rho[n], v, vb, k, 0, E, nmodes, kw, n, F, Fr, dF, dFr, Jm, Jr, om, orr):
            return False, z, 0.0
        _bound_abs(R, aR, Jm, Jr, N, B, True, Xr)
        _jacobian(z, rho[n], v, vb, k, 1, E, nmodes, kw, n, F, Fr, dF, dFr, Jm, Jr, om, orr)
        _bound_abs(R, aR, Jm, Jr, N, B, False, Xr)
        # |K - x~| <= base + B rho (sums of nonnegative floats, each rounded up by INFL)
        ok = True
        for i in range(N):
            acc = base[i]
            for j in range(N):
                acc = (acc + B[i, j] * rho[j] * ball.INFL) * ball.INFL
            kr[i] = acc
            if not acc < rho[i]:
                ok = False
        if ok:
            return True, z, rho[n]
        if it == 0:
            # the next radii from the floats: rho = (I - B)^-1 base, inflated (they only choose where to test)
            IB = np.empty((N, N), np.complex128)
            bb = np.empty((N, 1), np.complex128)
            gg = np.empty((N, 1), np.complex128)
            for i in range(N):
                bb[i, 0] = base[i]
                for j in range(N):
                    IB[i, j] = (1.0 if i == j else 0.0) - B[i, j]
            good = _csolve(IB, bb, N, 1, gg)
            guess = np.empty(N)
            for i in range(N):
                guess[i] = gg[i, 0].real
                good = good and guess[i] > 0.0 and math.isfinite(guess[i])
            for i in range(N):
                rho[i] = (1.5 * guess[i] if good else INFLATE * kr[i]) + TINY * (1.0 + xa[i])
        else:
            for i in range(N):
                rho[i] = INFLATE * kr[i] + TINY * (1.0 + xa[i])
    return False, z, 0.0


@kernel
def krein_box_block(body, joint, g, at, E, kappa, nmodes, free, parent, u_lo, u_hi, warm, out_nc, out_status, out_info):
    """N_c of each of a block of Krein boxes (``krein_box``): body[p, j], joint[p, j], g[p, j], at[p, j] the inputs
    at box p's t corner j (j = 0, 1; every spin 1, stiffness at u = 1), E[p], kappa[p] its modes, u in
    [u_lo[p], u_hi[p]].  ``warm``: each box first tries the separators and pairs that proved the box before it
    (neighbours in a sweep; they only steer).  out_nc[p]: N_c or -1; out_status[p]: DECIDED_INERTIA (N_c = 0 by
    the real count alone), DECIDED_DISKS (with Krawczyk pairs) or UNDECIDED; out_info[p] (NINFO columns, ``INFO_*``)."""
    npts, n = body.shape[0], body.shape[2]
    kw = allocate(n, nmodes, parent)
    for p in range(npts):
        if not warm:
            kw.prev[0] = 0
        nc = krein_box(body[p], joint[p], g[p], at[p], E[p], kappa[p], nmodes, free, parent, u_lo[p], u_hi[p], kw, out_info[p])
        out_info[p, INFO_NEWTON], out_info[p, INFO_ITERATIONS] = kw.stats[0], kw.stats[1]
        out_nc[p] = nc
        out_status[p] = UNDECIDED if nc < 0 else (DECIDED_INERTIA if nc == 0 else DECIDED_DISKS)
