"""Exact decision of a point: the polynomial in rational arithmetic, its real roots certified (python-flint).

Used for every point the interval kernel cannot prove.  The parameters are
taken at their exact binary values, so the exact path decides the very point
the float path was asked about.  Same per-point layout as ``kernels.charpoly``.
"""

from __future__ import annotations

import functools

import flint
import numpy as np

from ...kernels import layout
from . import exact_disks, topology


def _q(x: float) -> flint.fmpq:
    num, den = float(x).as_integer_ratio()
    return flint.fmpq(num, den)


def char_poly(body, joint, g, E, kappa, nmodes, free: bool, parent=None, at=None) -> flint.fmpq_poly:
    """p(lambda) of docs/model.md for one point, exactly (ascending coefficients via ``.coeffs()``).

    ``parent`` and ``at`` as for the kernels (a regular numbering, parent[0] = -1); None: a chain.
    The matrices come from Wittenburg's S and T (``topology``, docs/trees.md), not from
    the kernels' walk along each path.
    """
    return _poly(*int_matrix(body, joint, g, E, kappa, nmodes, free, parent, at))


def _poly(coefs: list, den, degrees: list) -> flint.fmpq_poly:
    """det(sum_t coefs[t] x^t) / den: p has degree <= sum(degrees), so that many + 1 integer determinants."""
    return _interpolate([flint.fmpq(_horner(coefs, x).det()) for x in range(sum(degrees) + 1)]) / den


def _horner(coefs: list, x: int) -> flint.fmpz_mat:
    """sum_t coefs[t] x^t, an integer matrix."""
    out = coefs[-1]
    for c in coefs[-2::-1]:
        out = out * x + c
    return out


def int_matrix(body, joint, g, E, kappa, nmodes, free: bool, parent=None, at=None):
    """(coefs, den, degrees): diag(Q) Phi = (sum_t coefs[t] lambda^t) / diag(den_k), den = prod den_k > 0.

    Each row k is cleared of its denominators (den_k, the least common multiple over the row), so
    p = det(sum_t coefs[t] lambda^t) / den, and the determinants at integer points are integer
    determinants (``fmpz_mat.det``, FLINT's), 2.4x faster than the rational ones at degree 48.
    Arguments as for ``char_poly``; degrees[k] = 2 + L_k bounds the degree of row k.
    """
    rows, Mm, Km, spin, w, degree = _parts(body, joint, g, E, kappa, nmodes, free, parent, at)
    n = len(rows)
    x = flint.fmpq_poly([0, 1])
    ints, den = [], flint.fmpz(1)
    for k, (betas, Es) in enumerate(rows):
        Q, R = _liquid(betas, Es, x)
        row = [Q * (Mm[k, j] * x * x - Km[k, j]) for j in range(n)]
        row[k] += x * spin[k] * Q - x * x * (x + w[k]) * R
        dk = flint.fmpz(1)
        for a in row:
            dk = dk.lcm(a.denom())
        ints.append([(a * dk).numer() for a in row])
        den *= dk
    top = max(a.degree() for r in ints for a in r)
    coefs = [flint.fmpz_mat([[a[t] for a in r] for r in ints]) for t in range(top + 1)]
    return coefs, den, [2 + len(b) for b, _ in rows]


def _liquid(betas: list, Es: list, x):
    """(Q, R) = (prod_l (x + beta_l), sum_l E_l prod_{m != l} (x + beta_m)) for x an fmpq or an fmpq_poly."""
    Q, R = 1 + 0 * x, 0 * x
    for beta, e in zip(betas, Es, strict=True):
        R = R * (x + beta) + e * Q
        Q = Q * (x + beta)
    return Q, R


def char_matrix(body, joint, g, E, kappa, nmodes, free: bool, parent=None, at=None):
    """(P, degree): P(x) = diag(Q) Phi at lambda = x as a rational matrix (Phi itself, symmetric, without liquid
    modes), and the degree bound of its determinant; arguments as for ``char_poly``."""
    rows, Mm, Km, spin, w, degree = _parts(body, joint, g, E, kappa, nmodes, free, parent, at)
    n = len(rows)

    def P(x: flint.fmpq) -> flint.fmpq_mat:
        """diag(Q) Phi at lambda = x, a rational matrix: diag(Q) (x^2 M - K) + diag(x C w Q - x^2 (x + w) R), the
        matrix products in FLINT (a Python loop over the n^2 entries cost most of the exact path)."""
        scale = flint.fmpq_mat(n, n)
        extra = []
        for k, (betas, Es) in enumerate(rows):
            Q, R = _liquid(betas, Es, x)
            scale[k, k] = Q
            extra.append(x * spin[k] * Q - x * x * (x + w[k]) * R)
        out = scale * (Mm * (x * x) - Km)
        for k in range(n):
            out[k, k] += extra[k]
        return out

    return P, degree


def _parts(body, joint, g, E, kappa, nmodes, free: bool, parent=None, at=None):
    """(rows, M, K, spin, w, degree): each body's (betas, E) of its liquid modes, the rational M and K, C w, w."""
    n = len(body)
    parent = [k - 1 for k in range(n)] if parent is None else [int(p) for p in parent]
    at = [0.0] + [body[parent[k]][layout.S] for k in range(1, n)] if at is None else at
    m = [_q(body[k][layout.M]) for k in range(n)]
    A = [_q(body[k][layout.A]) for k in range(n)]
    C = [_q(body[k][layout.C]) for k in range(n)]
    c = [_q(body[k][layout.CM]) for k in range(n)]
    w = [_q(body[k][layout.OMEGA]) for k in range(n)]
    Kj = [_q(joint[k]) for k in range(n)]  # the joint of body k with its parent (k = 0: the base joint)
    arm = [_q(at[k]) for k in range(n)]
    zero = flint.fmpq(0)
    tree = [p + 1 for p in parent]  # 1-based, 0 = the base
    S, T = _incidence_and_paths(tuple(tree))
    J = [[zero + x for x in row] for row in topology.lever_arms(tree, arm, c).tolist()]
    if free:
        mt = sum(m, zero)
        for i in range(n):
            mean = sum((m[j] * J[j][i] for j in range(n)), zero) / mt
            for k in range(n):
                J[k][i] -= mean
    # M = diag(A) + J^T diag(m) J and K = S diag(K_a) S^T as FLINT products (Python sums cost most of a point).
    Jm = flint.fmpq_mat(J)
    M = (Jm.transpose() * _diag(m) * Jm + _diag(A)).tolist()
    if free:
        Kj[0] = zero  # no base joint
    # Elastic: sum_a K_a phi_a^2 / 2 with phi = -S^T theta, so K = S diag(K_a) S^T.
    Sm = flint.fmpq_mat(S)
    Kmat = (Sm * _diag(Kj) * Sm.transpose()).tolist()
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

    return rows, flint.fmpq_mat(M), flint.fmpq_mat(Kmat), [C[k] * w[k] for k in range(n)], w, degree


def _diag(v: list) -> flint.fmpq_mat:
    out = flint.fmpq_mat(len(v), len(v))
    for i, x in enumerate(v):
        out[i, i] = x
    return out


@functools.lru_cache(maxsize=64)
def _incidence_and_paths(tree: tuple) -> tuple[list, list]:
    """S (arcs away from the base, no base row) and T of ``topology`` as integer lists; one per tree shape."""
    return topology.incidence(*topology.arcs(tree))[1:].tolist(), topology.path_matrix(*topology.arcs(tree)).tolist()


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
        diffs = [b - a for a, b in zip(diffs, diffs[1:], strict=False)]  # neighbours: one fewer
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
        coefs, den, degrees = int_matrix(body[p], joint[p], g[p], E[p], kappa[p], nmodes, free, parent, at[p])
        real = exact_disks.count(coefs, degrees)
        out[i] = (sum(degrees) - real) // 2 if real is not None else complex_pairs(_poly(coefs, den, degrees))
    return out


__all__ = ["char_poly", "complex_pairs", "count_real_roots", "decide_points"]
