"""Exact decision of a point in rational arithmetic (python-flint).

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
    lam = flint.fmpq_poly([0, 1])
    rows = []
    for k in range(n):
        Q = flint.fmpq_poly([1])
        R = flint.fmpq_poly([0])
        for l in range(int(nmodes[k])):
            beta = w[k] - 2 * w[k] / _q(kappa[k][l])
            R = R * (lam + beta) + _q(E[k][l]) * Q
            Q = Q * (lam + beta)
        row = []
        for j in range(n):
            entry = flint.fmpq_poly([-Kmat[k][j], C[k] * w[k] if j == k else 0, M[k][j]]) * Q
            if j == k:
                entry -= lam * lam * (lam + w[k]) * R
            row.append(entry)
        rows.append(row)
    return _bareiss_det(rows)


def _bareiss_det(a: list[list[flint.fmpq_poly]]) -> flint.fmpq_poly:
    """Fraction-free Gaussian elimination over Q[lambda]; every division is exact."""
    n = len(a)
    a = [row[:] for row in a]
    sign = 1
    prev = flint.fmpq_poly([1])
    for k in range(n - 1):
        if a[k][k] == 0:
            swap = next((i for i in range(k + 1, n) if a[i][k] != 0), None)
            if swap is None:
                return flint.fmpq_poly([0])
            a[k], a[swap] = a[swap], a[k]
            sign = -sign
        for i in range(k + 1, n):
            for j in range(k + 1, n):
                a[i][j] = (a[i][j] * a[k][k] - a[i][k] * a[k][j]) // prev
        prev = a[k][k]
    return sign * a[n - 1][n - 1]


def _distinct_real_roots(f: flint.fmpq_poly) -> int:
    """Sturm count of the distinct real roots of f (exact)."""
    seq = [f, f.derivative()]
    while seq[-1].degree() > 0:
        r = -(seq[-2] % seq[-1])
        if r == 0:
            break
        seq.append(r)
    plus = [1 if p.leading_coefficient() > 0 else -1 for p in seq]
    minus = [sp if p.degree() % 2 == 0 else -sp for sp, p in zip(plus, seq)]

    def variations(signs):
        return sum(1 for x, y in zip(signs, signs[1:]) if x != y)

    return variations(minus) - variations(plus)


def count_real_roots(p: flint.fmpq_poly) -> int:
    """Real roots of p counted with multiplicity (p nonzero)."""
    _, factors = p.factor_squarefree()
    return sum(e * _distinct_real_roots(f) for f, e in factors if f.degree() > 0)


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
