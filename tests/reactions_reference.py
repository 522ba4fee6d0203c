"""Independent references for the reactions of point nodes (tests/test_reactions*.py), none using stabmap's solver.

Each sets up the constraint system its own way, about the nodes' given origin (no centroid, no scaling):

- ``mpmath_least_norm``: the full system (six balance rows, one row per release) and its least-norm solution by
  an SVD in 50-digit arithmetic;
- ``exact_kkt``: the same system in exact rationals (python-flint), its independent rows found by an exact
  row reduction, and the KKT system [[I, A^T], [A, 0]] of min |R|^2 subject to A R = b solved exactly;
- ``springs``: the stiffness method: every node an equal spring (stiffness k, none along its released
  directions), the body's small translation and rotation from K q = (F, M), the spring forces from them.
"""

from __future__ import annotations

from fractions import Fraction

import flint
import mpmath
import numpy as np


def _rows(nodes, releases, number):
    """The constraint matrix A (6 + r rows, 3n columns) as nested lists of ``number(x)`` entries.

    Rows 0-2: sum R_i; rows 3-5: sum x_i x R_i; then e . R_k = 0 for each release (k, e).
    """
    n = len(nodes)
    zero = number(0)
    A = [[zero] * (3 * n) for _ in range(6 + len(releases))]
    for i, p in enumerate(nodes):
        x, y, z = (number(v) for v in p)
        for d in range(3):
            A[d][3 * i + d] = number(1)
        # x_i x R_i = (y Rz - z Ry, z Rx - x Rz, x Ry - y Rx)
        A[3][3 * i + 1], A[3][3 * i + 2] = -z, y
        A[4][3 * i + 0], A[4][3 * i + 2] = z, -x
        A[5][3 * i + 0], A[5][3 * i + 1] = -y, x
    for r, (k, e) in enumerate(releases):
        for d in range(3):
            A[6 + r][3 * k + d] = number(e[d])
    return A


def mpmath_least_norm(nodes, F, M, releases=(), dps: int = 50):
    """(R or None, rank) by the SVD of the full system in ``dps`` digits; singular values below 1e-30 of the
    largest count as zero (the inputs are exact binary numbers, so a rank deficiency leaves ~1e-50)."""
    with mpmath.workdps(dps):
        A = mpmath.matrix(_rows(nodes, releases, mpmath.mpf))
        b = mpmath.matrix([-mpmath.mpf(v) for v in F] + [-mpmath.mpf(v) for v in M] + [0] * len(releases))
        U, S, V = mpmath.svd_r(A, full_matrices=False)
        smax = max(S)
        rank = sum(1 for s in S if s > mpmath.mpf("1e-30") * smax)
        coef = U.T * b
        y = mpmath.matrix(len(S), 1)
        for k in range(len(S)):
            y[k] = coef[k] / S[k] if S[k] > mpmath.mpf("1e-30") * smax else 0
        R = V.T * y
        residual = mpmath.norm(A * R - b)
        if residual > mpmath.mpf("1e-30") * max(mpmath.norm(b), 1):
            return None, rank
        return np.array([float(v) for v in R]).reshape(-1, 3), rank


def _fmpq(v) -> flint.fmpq:
    """The exact rational value of a float or integer (a float's binary value, digit for digit)."""
    return flint.fmpq(*Fraction(v).as_integer_ratio())


def exact_kkt(nodes, F, M, releases=()):
    """(R as Fractions or None, rank) from the exact KKT system of the independent constraint rows."""
    A = _rows(nodes, releases, _fmpq)
    b = [-_fmpq(v) for v in F] + [-_fmpq(v) for v in M] + [_fmpq(0)] * len(releases)
    m, ncol = len(A), len(A[0])
    At = flint.fmpq_mat(ncol, m, [A[i][j] for j in range(ncol) for i in range(m)])
    reduced, rank = At.rref()
    pivots = []  # the pivot columns of rref(A^T) are independent rows of A
    for r in range(rank):
        pivots.append(next(c for c in range(m) if reduced[r, c] != 0))
    augmented = flint.fmpq_mat(m, ncol + 1, [v for i in range(m) for v in A[i] + [b[i]]])
    if augmented.rank() > rank:
        return None, rank
    size = ncol + rank
    K = [[_fmpq(0)] * size for _ in range(size)]
    for j in range(ncol):
        K[j][j] = _fmpq(1)
    for r, i in enumerate(pivots):
        for j in range(ncol):
            K[ncol + r][j] = A[i][j]
            K[j][ncol + r] = A[i][j]
    rhs = [_fmpq(0)] * ncol + [b[i] for i in pivots]
    sol = flint.fmpq_mat(size, size, [v for row in K for v in row]).solve(flint.fmpq_mat(size, 1, rhs))
    R = [Fraction(int(sol[j, 0].p), int(sol[j, 0].q)) for j in range(ncol)]
    return [R[3 * i : 3 * i + 3] for i in range(len(nodes))], rank


def _skew(v):
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def springs(nodes, F, M, releases=(), k: float = 1.0e6):
    """Reactions of equal springs of stiffness ``k`` (none along a node's released directions), stiffness method.

    The body moves by q = (u, theta); node i's spring stretches by P_i (u + theta x x_i) and pushes back with
    R_i = -k P_i (u + theta x x_i); balance gives K q = (F, M), K = k sum G_i P_i G_i^T, G_i = [E; [x_i]x].
    K is singular when the nodes leave a motion free; the load must not drive it, and least squares picks q.
    """
    nodes = np.asarray(nodes, dtype=float)
    P = []
    for i in range(len(nodes)):
        E = np.array([np.asarray(e, float) for j, e in releases if j == i]).reshape(-1, 3)
        P.append(np.eye(3) - (E.T @ np.linalg.pinv(E.T) if len(E) else 0.0))
    G = [np.vstack([np.eye(3), _skew(x)]) for x in nodes]
    K = k * sum(g @ p @ g.T for g, p in zip(G, P))
    q = np.linalg.lstsq(K, np.concatenate([F, M]), rcond=1e-12)[0]
    return np.array([-k * p @ g.T @ q for g, p in zip(G, P)])
