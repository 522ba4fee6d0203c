"""Exact decision of a point: the polynomial in rational arithmetic, its real roots certified (python-flint).

Used for every point the interval kernel cannot prove.  The parameters are
taken at their exact binary values, so the exact path decides the very point
the float path was asked about.  Same per-point layout as ``kernels.charpoly``.
"""

from __future__ import annotations

import flint
import numpy as np

from . import topology


def _q(x: float) -> flint.fmpq:
    num, den = float(x).as_integer_ratio()
    return flint.fmpq(num, den)


def char_poly(body, joint, g, E, kappa, nmodes, free: bool, parent=None, at=None) -> flint.fmpq_poly:
    """p(lambda) of docs/model.md for one point, exactly (ascending coefficients via ``.coeffs()``).

    ``parent`` and ``at`` as for the kernels (a regular numbering, parent[0] = -1); None: a chain.
    The matrices come from Wittenburg's S and T (``topology``, docs/trees.md), not from
    the kernels' walk along each path.
    """
    P, degree = char_matrix(body, joint, g, E, kappa, nmodes, free, parent, at)
    # p has degree <= sum(2 + L_k): interpolate it from that many + 1 exact determinants.
    return _interpolate([P(flint.fmpq(i)).det() for i in range(degree + 1)])


def char_matrix(body, joint, g, E, kappa, nmodes, free: bool, parent=None, at=None):
    """(P, degree): P(x) = diag(Q) Phi at lambda = x as a rational matrix (Phi itself, symmetric, without liquid
    modes), and the degree bound of its determinant; arguments as for ``char_poly``."""
    n = len(body)
    parent = [k - 1 for k in range(n)] if parent is None else [int(p) for p in parent]
    at = [0.0] + [body[parent[k]][4] for k in range(1, n)] if at is None else at
    m = [_q(body[k][0]) for k in range(n)]
    A = [_q(body[k][1]) for k in range(n)]
    C = [_q(body[k][2]) for k in range(n)]
    c = [_q(body[k][3]) for k in range(n)]
    w = [_q(body[k][5]) for k in range(n)]
    Kj = [_q(joint[k]) for k in range(n)]  # the joint of body k with its parent (k = 0: the base joint)
    arm = [_q(at[k]) for k in range(n)]
    zero = flint.fmpq(0)
    tree = [p + 1 for p in parent]  # 1-based, 0 = the base
    S = topology.incidence(*topology.arcs(tree))[1:].tolist()  # arcs away from the base; no base row
    T = topology.path_matrix(*topology.arcs(tree)).tolist()
    J = [[zero + x for x in row] for row in topology.lever_arms(tree, arm, c).tolist()]
    if free:
        mt = sum(m, zero)
        for i in range(n):
            mean = sum((m[j] * J[j][i] for j in range(n)), zero) / mt
            for k in range(n):
                J[k][i] -= mean
    M = [[(A[i] if i == j else zero) + sum((m[k] * J[k][i] * J[k][j] for k in range(n)), zero) for j in range(n)] for i in range(n)]
    if free:
        Kj[0] = zero  # no base joint
    # Elastic: sum_a K_a phi_a^2 / 2 with phi = -S^T theta, so K = S diag(K_a) S^T.
    Kmat = [[sum((S[i][a] * S[j][a] * Kj[a] for a in range(n)), zero) for j in range(n)] for i in range(n)]
    if not free:
        gq = _q(g)
        # a = m c - S+ diag(at) T m: each body's own first moment plus, for every joint a on it,
        # at_a times the mass beyond a (-T m).
        beyond = [-sum((T[a][j] * m[j] for j in range(n)), zero) for a in range(n)]
        for k in range(n):
            a_k = m[k] * c[k] + sum((arm[a] * beyond[a] for a in range(n) if S[k][a] > 0), zero)
            Kmat[k][k] -= gq * a_k
    rows = []
    for k in range(n):
        betas = [w[k] - 2 * w[k] / _q(kappa[k][l]) for l in range(int(nmodes[k]))]
        rows.append((betas, [_q(E[k][l]) for l in range(int(nmodes[k]))]))
    degree = sum(2 + len(b) for b, _ in rows)

    Mm, Km = flint.fmpq_mat(M), flint.fmpq_mat(Kmat)
    spin = [C[k] * w[k] for k in range(n)]

    def P(x: flint.fmpq) -> flint.fmpq_mat:
        """diag(Q) Phi at lambda = x, a rational matrix: diag(Q) (x^2 M - K) + diag(x C w Q - x^2 (x + w) R), the
        matrix products in FLINT (a Python loop over the n^2 entries cost most of the exact path)."""
        scale = flint.fmpq_mat(n, n)
        extra = []
        for k, (betas, Es) in enumerate(rows):
            Q = flint.fmpq(1)
            R = zero
            for beta, e in zip(betas, Es):
                R = R * (x + beta) + e * Q
                Q = Q * (x + beta)
            scale[k, k] = Q
            extra.append(x * spin[k] * Q - x * x * (x + w[k]) * R)
        out = scale * (Mm * (x * x) - Km)
        for k in range(n):
            out[k, k] += extra[k]
        return out

    return P, degree


def _interpolate(ys: list) -> flint.fmpq_poly:
    """The polynomial through (i, ys[i]), i = 0..len(ys) - 1, exactly.

    At equally spaced integers the divided differences are forward differences
    over j!: on a common denominator they are integer subtractions, 7x faster
    than rational divided differences at degree 48 (the exact path's largest cost).
    """
    den = flint.fmpz(1)
    for y in ys:
        q = y.denom()
        den = den * q // den.gcd(q)
    diffs = [y.numer() * (den // y.denom()) for y in ys]
    lead = [diffs[0]]
    while len(diffs) > 1:
        diffs = [b - a for a, b in zip(diffs, diffs[1:])]
        lead.append(diffs[0])
    coef, fact = [], flint.fmpz(1)
    for j, d in enumerate(lead):
        fact *= max(j, 1)
        coef.append(flint.fmpq(d, fact * den))
    poly = flint.fmpq_poly([coef[-1]])
    for i in range(len(coef) - 2, -1, -1):
        poly = poly * flint.fmpq_poly([-i, 1]) + coef[i]
    return poly


def count_real_roots(p: flint.fmpq_poly) -> int:
    """Real roots of the nonzero polynomial p, counted with multiplicity.

    FLINT/Arb isolates every root of the exact polynomial (after an exact
    square-free factorisation) and certifies which are real: those come back
    with an imaginary part that is exactly zero.
    """
    return sum(mult for root, mult in p.numer().complex_roots() if root.imag.is_zero())


def complex_pairs(p: flint.fmpq_poly) -> int:
    """N_c = (deg p - real roots with multiplicity) / 2, or -1 if p is identically zero."""
    if p == 0:
        return -1
    return (p.degree() - count_real_roots(p)) // 2


def decide_points(body, joint, g, E, kappa, nmodes, free, parent, at, index) -> np.ndarray:
    """Exact N_c for the points ``index`` of a block (arrays as for the kernels)."""
    out = np.empty(len(index), dtype=np.int16)
    for i, p in enumerate(index):
        out[i] = complex_pairs(char_poly(body[p], joint[p], g[p], E[p], kappa[p], nmodes, free, parent, at[p]))
    return out


__all__ = ["char_poly", "complex_pairs", "count_real_roots", "decide_points"]
