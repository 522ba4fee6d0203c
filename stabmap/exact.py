"""Exact decision of a point: the polynomial in rational arithmetic, its real roots certified (python-flint).

Used for every point the interval kernel cannot prove.  The parameters are
taken at their exact binary values, so the exact path decides the very point
the float path was asked about.  Same per-point layout as ``kernels.charpoly``.
"""

from __future__ import annotations

import flint
import numpy as np


def _q(x: float) -> flint.fmpq:
    num, den = float(x).as_integer_ratio()
    return flint.fmpq(num, den)


def char_poly(body, joint, g, E, kappa, nmodes, free: bool) -> flint.fmpq_poly:
    """p(lambda) of MODEL.md for one point, exactly (ascending coefficients via ``.coeffs()``)."""
    n = len(body)
    m = [_q(body[k][0]) for k in range(n)]
    A = [_q(body[k][1]) for k in range(n)]
    C = [_q(body[k][2]) for k in range(n)]
    c = [_q(body[k][3]) for k in range(n)]
    s = [_q(body[k][4]) for k in range(n)]
    w = [_q(body[k][5]) for k in range(n)]
    K = [_q(joint[k]) for k in range(n)]
    zero = flint.fmpq(0)
    J = [[s[i] if i < k else (c[k] if i == k else zero) for i in range(n)] for k in range(n)]
    if free:
        mt = sum(m, zero)
        for i in range(n):
            mean = sum((m[j] * J[j][i] for j in range(n)), zero) / mt
            for k in range(n):
                J[k][i] -= mean
    M = [[(A[i] if i == j else zero) + sum((m[k] * J[k][i] * J[k][j] for k in range(n)), zero) for j in range(n)] for i in range(n)]
    Kmat = [[zero] * n for _ in range(n)]
    for j in range(1, n):  # joint j joins bodies j-1 and j (0-based)
        Kmat[j - 1][j - 1] += K[j]
        Kmat[j][j] += K[j]
        Kmat[j - 1][j] -= K[j]
        Kmat[j][j - 1] -= K[j]
    if not free:
        Kmat[0][0] += K[0]
        gq = _q(g)
        for k in range(n):
            a_k = m[k] * c[k] + s[k] * sum(m[k + 1 :], zero)
            Kmat[k][k] -= gq * a_k
    rows = []
    for k in range(n):
        betas = [w[k] - 2 * w[k] / _q(kappa[k][l]) for l in range(int(nmodes[k]))]
        rows.append((betas, [_q(E[k][l]) for l in range(int(nmodes[k]))]))
    degree = sum(2 + len(b) for b, _ in rows)

    def P(x: flint.fmpq) -> flint.fmpq_mat:
        """diag(Q) Phi at lambda = x, a rational matrix."""
        out = flint.fmpq_mat(n, n)
        for k, (betas, Es) in enumerate(rows):
            Q = flint.fmpq(1)
            R = zero
            for beta, e in zip(betas, Es):
                R = R * (x + beta) + e * Q
                Q = Q * (x + beta)
            for j in range(n):
                v = x * x * M[k][j] - Kmat[k][j]
                if j == k:
                    v = (v + x * C[k] * w[k]) * Q - x * x * (x + w[k]) * R
                else:
                    v *= Q
                out[k, j] = v
        return out

    # p has degree <= sum(2 + L_k): interpolate it from that many + 1 exact determinants.
    xs = [flint.fmpq(i) for i in range(degree + 1)]
    return _interpolate(xs, [P(x).det() for x in xs])


def _interpolate(xs: list, ys: list) -> flint.fmpq_poly:
    """The polynomial through (xs, ys), exactly (Newton divided differences)."""
    coef = list(ys)
    m = len(xs)
    for j in range(1, m):
        for i in range(m - 1, j - 1, -1):
            coef[i] = (coef[i] - coef[i - 1]) / (xs[i] - xs[i - j])
    poly = flint.fmpq_poly([coef[-1]])
    for i in range(m - 2, -1, -1):
        poly = poly * flint.fmpq_poly([-xs[i], 1]) + coef[i]
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


def decide_points(body, joint, g, E, kappa, nmodes, free, index) -> np.ndarray:
    """Exact N_c for the points ``index`` of a block (arrays as for the kernels)."""
    out = np.empty(len(index), dtype=np.int16)
    for i, p in enumerate(index):
        out[i] = complex_pairs(char_poly(body[p], joint[p], g[p], E[p], kappa[p], nmodes, free))
    return out


__all__ = ["char_poly", "complex_pairs", "count_real_roots", "decide_points"]
