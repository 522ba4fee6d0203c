"""Characteristic polynomial of one parameter point, in rigorous interval arithmetic.

docs/model.md: p(lambda) = det Phi(lambda) * prod_k Q_k(lambda) with
Phi = lambda^2 M + lambda G - K - diag(liquid_k) and Q_k = prod_l (lambda + beta_kl),
beta_kl = omega_k - lambda_kl = omega_k (kappa_kl - 2) / kappa_kl.

We expand det(diag(Q) Phi T) instead, with T the path matrix of the tree of
bodies: T[k, j] = 1 if body j lies on the path from the base to body k (j = k
included), else 0, so theta = T phi with phi_j = theta_j - theta_parent(j) the
tilt of body j relative to its parent (docs/trees.md: T is the transpose of
Wittenburg's path matrix with every arc pointing at the base; for a chain it is
the lower-triangular matrix of ones).  det T = 1, so the polynomial is the
same, but K T is exact and sparse: the elastic Laplacian maps column j of T to
K_j (e_j - e_parent(j)).  Hence every zero that the physics puts into the
constant terms (the rigid tilt of a free system, ideal joints, g = 0) is an
exact zero, and the matching lambda = 0 roots are factored out exactly instead
of being smeared into tiny nonzero coefficients.

Every number is an interval (hi, lo, rad) of ``dd.py`` stored along a last axis
of length 3.  Per-point parameter layout (all float64):
  body[k]   = (m, A, C, c, s, omega) of body k (0-based), columns named in ``layout``
              (M, A, C, CM, S, OMEGA); s is not read here
  joint[k]  = stiffness of the joint of body k with its parent (joint[0]: the
              base joint, fixed support only; in a chain joint[k] = K_k)
  at[k]     = position of that joint on the parent's axis, measured from the
              parent's own joint (at[0] is not read; in a chain at[k] = s_{k-1})
  g         = gravity (fixed support only)
  E[k, l], kappa[k, l] for l < nmodes[k]
Per block: parent (int64[n]), the tree in a regular numbering (Wittenburg):
parent[0] = -1 (body 0, the scene's body 1, is on the base or is the free
system's reference body) and 0 <= parent[k] < k.  A chain has parent[k] = k - 1.
"""

from __future__ import annotations

import numpy as np

from . import dd, layout
from .options import kernel


@kernel
def _set(X, i, v):
    X[i, 0], X[i, 1], X[i, 2] = v


@kernel
def check_parent(parent, n):
    """Raise ValueError unless parent (int64[n]) is a tree in a regular numbering (module docstring)."""
    if parent.shape[0] != n or (n > 0 and parent[0] != -1):
        raise ValueError("parent must have one entry per body and parent[0] == -1")
    for k in range(1, n):
        if parent[k] < 0 or parent[k] >= k:
            raise ValueError("parent must be a regular numbering: 0 <= parent[k] < k for k >= 1")


@kernel
def path_matrix(parent, T):
    """Write T[k, j] = True if body j is on the path from the base to body k (j == k included)."""
    T[:] = False
    for k in range(parent.shape[0]):
        j = k
        while j >= 0:
            T[k, j] = True
            j = parent[j]


@kernel
def _lever_arms(body, rb, at, ra, parent, free, J):
    """Write the lever-arm matrix J (docs/model.md, docs/trees.md) into J (n, n, 3).

    J[k, k] = c_k; for every body i on the path below body k, J[k, i] is the
    position on the axis of i of the joint through which the path leaves i.
    """
    n = body.shape[0]
    J[:] = 0.0
    for k in range(n):
        J[k, k, 0], J[k, k, 2] = body[k, layout.CM], rb[k, layout.CM]
        child = k
        i = parent[k]
        while i >= 0:
            J[k, i, 0], J[k, i, 2] = at[child], ra[child]
            child = i
            i = parent[i]
    if not free:
        return
    mt = (0.0, 0.0, 0.0)
    for k in range(n):
        mt = dd.add(*mt, body[k, layout.M], 0.0, rb[k, layout.M])
    if not dd.certain_nonzero(*mt):  # a box whose total mass may be 0: no enclosure, so nothing is proved
        J[:] = np.nan
        return
    for i in range(n):
        s = (0.0, 0.0, 0.0)
        for j in range(n):
            s = dd.fma(*s, body[j, layout.M], 0.0, rb[j, layout.M], J[j, i, 0], J[j, i, 1], J[j, i, 2])
        mh, ml, mr = dd.div(*s, *mt)
        for k in range(n):
            J[k, i, 0], J[k, i, 1], J[k, i, 2] = dd.add(J[k, i, 0], J[k, i, 1], J[k, i, 2], -mh, -ml, mr)


@kernel
def _scaled(x, r, u):
    """Enclosure of (x +- r) u for floats x, r >= 0 and u > 0.  x u is exact in double-double (``two_prod``), so a
    point x stays a point: only r u, rounded up, is a radius (and ``ETA`` where the product is so small that its
    rounding error may underflow).  An exact zero stays exact."""
    if x == 0.0 and r == 0.0:
        return 0.0, 0.0, 0.0
    h, l = dd.two_prod(x, u)
    rad = r * u * dd.INFL
    if abs(h) < 2.0**-900:
        rad += dd.ETA
    return h, l, rad


@kernel
def _stiffness_T(body, rb, joint, rj, at, ra, parent, g, rg, free, sub, K, u):
    """Write K T (see module docstring) into K (n, n, 3), the stiffness (joints and g) times the float u > 0 (the
    spin-scaled model; u = 1: K T itself, operation for operation); sub (n, 3) is scratch."""
    n = body.shape[0]
    K[:] = 0.0
    for j in range(1, n):
        if u == 1.0:
            K[j, j, 0], K[j, j, 2] = joint[j], rj[j]
            K[parent[j], j, 0], K[parent[j], j, 2] = -joint[j], rj[j]
        else:
            _set(K[j], j, _scaled(joint[j], rj[j], u))
            _set(K[parent[j]], j, dd.neg(*_scaled(joint[j], rj[j], u)))
    if free:
        return
    if u == 1.0:
        K[0, 0, 0], K[0, 0, 2] = joint[0], rj[0]
        gu = (g, 0.0, rg)
    else:
        _set(K[0], 0, _scaled(joint[0], rj[0], u))
        gu = _scaled(g, rg, u)
    # sub[k]: mass of the subtree of body k; children come after their parent, so go backwards.
    for k in range(n - 1, -1, -1):
        outboard = (0.0, 0.0, 0.0)  # mass of the bodies beyond body k
        leaf = True
        a = dd.mul(body[k, layout.M], 0.0, rb[k, layout.M], body[k, layout.CM], 0.0, rb[k, layout.CM])
        for j in range(k + 1, n):
            if parent[j] != k:
                continue
            # a_k = m_k c_k + sum over the children j of k of at_j (mass of the subtree of j)
            a = dd.fma(*a, at[j], 0.0, ra[j], sub[j, 0], sub[j, 1], sub[j, 2])
            outboard = (sub[j, 0], sub[j, 1], sub[j, 2]) if leaf else dd.add(*outboard, sub[j, 0], sub[j, 1], sub[j, 2])
            leaf = False
        if leaf:
            a = dd.add(*a, 0.0, 0.0, 0.0)  # as m_k c_k + s_k * 0: the same rounding bound as a chain's top body
        ga = dd.mul(*gu, *a)
        j = k
        while j >= 0:  # row k of -g diag(a) T: the bodies on the path to k
            K[k, j, 0], K[k, j, 1], K[k, j, 2] = dd.add(K[k, j, 0], K[k, j, 1], K[k, j, 2], *dd.neg(*ga))
            j = parent[j]
        _set(sub, k, dd.add(*outboard, body[k, layout.M], 0.0, rb[k, layout.M]))


@kernel
def _inertia_T(body, rb, parent, J, M):
    """Write M T, M = diag(A) + J^T diag(m) J, into M (n, n, 3)."""
    n = body.shape[0]
    for i in range(n):
        for j in range(n):
            acc = (body[i, layout.A], 0.0, rb[i, layout.A]) if i == j else (0.0, 0.0, 0.0)
            for k in range(n):
                t = dd.mul(body[k, layout.M], 0.0, rb[k, layout.M], J[k, i, 0], J[k, i, 1], J[k, i, 2])
                acc = dd.fma(*acc, *t, J[k, j, 0], J[k, j, 1], J[k, j, 2])
            _set(M[i], j, acc)
    # Column j of M T collects the columns of M of the subtree of j: add each column into its
    # parent's, children first (backwards in a regular numbering).  A chain: columns i >= j.
    for k in range(n):
        for j in range(n - 1, 0, -1):
            i = parent[j]
            _set(M[k], i, dd.add(M[k, i, 0], M[k, i, 1], M[k, i, 2], M[k, j, 0], M[k, j, 1], M[k, j, 2]))


@kernel
def structure(body, joint, at, g, parent, free, sub, J, M, K):
    """M T and K T of one point (double-double intervals) into M, K (n, n, 3); J, sub are scratch."""
    zero, zero1 = np.zeros_like(body), np.zeros(body.shape[0])
    _lever_arms(body, zero, at, zero1, parent, free, J)
    _inertia_T(body, zero, parent, J, M)
    _stiffness_T(body, zero, joint, zero1, at, zero1, parent, g, 0.0, free, sub, K, 1.0)


@kernel
def _liquid_polys(omega, romega, E, kappa, L, q, w):
    """Q = prod_l (lambda + beta_l) into q and R = sum_l E_l prod_{l' != l} (lambda + beta_l') into w."""
    q[: L + 1] = 0.0
    w[: L + 1] = 0.0
    q[0, 0] = 1.0
    for l in range(L):
        kap = kappa[l]
        # two_sum makes kappa - 2 exact, so beta is an exact zero when kappa == 2.
        h, lo = dd.two_sum(kap, -2.0)
        beta = dd.mul(omega, 0.0, romega, h, lo, 0.0)
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
def _matrix(body, rb, joint, rj, at, ra, g, rg, E, kappa, nmodes, parent, free, T, sub, J, M, K, q, w, P, reuse, u=1.0):
    """Write P = diag(Q) Phi T as interval polynomials into P (n, n, 3 + Lmax, 3).

    Row k has degree 2 + nmodes[k]; unused trailing coefficients are exact zeros.
    ``reuse``: M T and K T in M, K are those of this point already (only omega
    or the liquid changed since the previous point).  T from ``path_matrix``.
    rb, rj, ra, rg: radii of body, joint, at and g (zeros for one point): the
    enclosures then hold for every parameter value within them (a box).  u: the stiffness (joints and g) is
    taken times u (``_stiffness_T``).
    """
    n = body.shape[0]
    if not reuse:
        _lever_arms(body, rb, at, ra, parent, free, J)
        _inertia_T(body, rb, parent, J, M)
        _stiffness_T(body, rb, joint, rj, at, ra, parent, g, rg, free, sub, K, u)
    P[:] = 0.0
    for k in range(n):
        L = nmodes[k]
        omega, romega = body[k, layout.OMEGA], rb[k, layout.OMEGA]
        _liquid_polys(omega, romega, E[k], kappa[k], L, q, w)
        G = dd.mul(body[k, layout.C], 0.0, rb[k, layout.C], omega, 0.0, romega)  # C_k omega_k
        for j in range(n):
            e = P[k, j]
            # P_kj = Q (lambda^2 MT_kj + lambda GT_kj - KT_kj) - T_kj lambda^2 (lambda + omega) R
            mk = (M[k, j, 0], M[k, j, 1], M[k, j, 2])
            kk = (-K[k, j, 0], -K[k, j, 1], K[k, j, 2])
            on_path = T[k, j]
            for a in range(L + 1):
                qa = (q[a, 0], q[a, 1], q[a, 2])
                if dd.is_zero(*qa):
                    continue
                _set(e, a, dd.fma(e[a, 0], e[a, 1], e[a, 2], *qa, *kk))
                if on_path:
                    _set(e, a + 1, dd.fma(e[a + 1, 0], e[a + 1, 1], e[a + 1, 2], *qa, *G))
                _set(e, a + 2, dd.fma(e[a + 2, 0], e[a + 2, 1], e[a + 2, 2], *qa, *mk))
            if on_path:
                for a in range(L):
                    wa = (w[a, 0], w[a, 1], w[a, 2])
                    _set(e, a + 3, dd.add(e[a + 3, 0], e[a + 3, 1], e[a + 3, 2], *dd.neg(*wa)))
                    _set(e, a + 2, dd.fma(e[a + 2, 0], e[a + 2, 1], e[a + 2, 2], -omega, 0.0, romega, *wa))


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
    bodies have a_k = 0 and ideal joints splits into n blocks (docs/model.md).
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
def allocate(n, lmax, degree, parent):
    """Scratch arrays for one block: allocated once per block, reused for every point.

    Checks ``parent`` (ValueError unless a regular numbering) and stores its path matrix.
    """
    check_parent(parent, n)
    J = np.empty((n, n, 3))
    M = np.empty((n, n, 3))
    K = np.empty((n, n, 3))
    q = np.empty((lmax + 1, 3))
    w = np.empty((lmax + 1, 3))
    P = np.empty((n, n, lmax + 3, 3))
    D = np.empty((1 << n, degree + 1, 3))
    T = np.empty((n, n), np.bool_)
    path_matrix(parent, T)
    sub = np.empty((n, 3))
    zero, zero1 = np.zeros((n, 6)), np.zeros(n)  # the parameters' radii at a single point
    return layout.CharpolyWork(J, M, K, q, w, P, D, T, sub, zero, zero1)


@kernel
def same_structure(body, joint, at, g, p):
    """True if point p has the inertia and stiffness of point p - 1 (only omega or the liquid differ)."""
    if p == 0 or g[p] != g[p - 1]:
        return False
    for k in range(body.shape[1]):
        if joint[p, k] != joint[p - 1, k] or at[p, k] != at[p - 1, k]:
            return False
        for col in layout.STRUCTURE:  # omega may differ
            if body[p, k, col] != body[p - 1, k, col]:
                return False
    return True


@kernel
def matrix_point(body, joint, at, g, E, kappa, nmodes, parent, free, ws, reuse):
    """Build P = diag(Q) Phi T of one point into ws.P; ws from ``allocate`` (with this parent)."""
    J, M, K, q, w, P, T, sub, zero, zero1 = ws.J, ws.M, ws.K, ws.q, ws.w, ws.P, ws.T, ws.sub, ws.zero, ws.zero1
    _matrix(body, zero, joint, zero1, at, zero1, g, 0.0, E, kappa, nmodes, parent, free, T, sub, J, M, K, q, w, P, reuse)


@kernel
def matrix_box(body, rb, joint, rj, at, ra, g, rg, E, kappa, nmodes, parent, free, ws, u=1.0):
    """Build P of a box of parameters into ws.P: every parameter x within its radius r (x +- r) of the
    midpoint given (rb, rj, ra, rg: radii shaped as body, joint, at and g).  The intervals of P then hold
    P at every point of the box.  E and kappa are points (they are never scanned).

    u (a float > 0): the joints and g are taken times u, the product exact in double-double.  The spin-scaled
    model's node u_i (docs/certification.md, section 6): formed here, its inputs need no rounding radius."""
    J, M, K, q, w, P, T, sub = ws.J, ws.M, ws.K, ws.q, ws.w, ws.P, ws.T, ws.sub
    _matrix(body, rb, joint, rj, at, ra, g, rg, E, kappa, nmodes, parent, free, T, sub, J, M, K, q, w, P, False, u)


@kernel
def block_det(ws, rowdeg, i0, i1, out):
    """Enclosure of det P[i0:i1, i0:i1] (after ``matrix_point``) into out; returns its degree bound."""
    P, D = ws.P, ws.D
    _laplace_det(P[i0:i1, i0:i1], rowdeg[i0:i1], D, out)
    return int(rowdeg[i0:i1].sum())


@kernel
def charpoly_point(body, joint, at, g, E, kappa, nmodes, parent, rowdeg, free, ws, out, reuse=False):
    """Enclosure of p(lambda) for one point into out (deg + 1, 3); ws from ``allocate``, rowdeg = nmodes + 2."""
    matrix_point(body, joint, at, g, E, kappa, nmodes, parent, free, ws, reuse)
    block_det(ws, rowdeg, 0, body.shape[0], out)
