"""The reactions of one layout in exact rational arithmetic (python-flint): rank, compatibility, the least-norm R.

Node positions, loads and release directions are binary floats, so each is an exact rational, and so is the
least-norm solution. This module works with those exact values. It is the fallback for every point that the
floating-point bound (``floats``) cannot decide, and it decides those points exactly.

The constraint system stays rational. It has one unknown per node and component (3n), six balance rows
(sum R_i = -F, sum x_i x R_i = -M, about the origin of the x_i) and one row e . R_k = 0 per independent
release (``release_rows``). The releases are rows, not an orthonormal basis of what a node carries, because such
a basis is irrational. The least norm over all 3n unknowns under these rows is the same solution. Write C for the
matrix and d for the right-hand side. Take a set s of independent rows of C. Then

    R = C_s^T (C_s C_s^T)^-1 d_s = H d_s,

and the load is compatible iff the other rows' right-hand sides are the same combinations of d_s as the rows
themselves are of C_s: d_o = T d_s, T = C_o C_s^T (C_s C_s^T)^-1. H and T depend on the layout only
(``Layout``, factored once per distinct layout); a point costs one product (``Layout.solve``).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import flint
import numpy as np

BALANCE_ROWS = 6


def q(x: float) -> flint.fmpq:
    """The exact value of a binary float."""
    return flint.fmpq(*float(x).as_integer_ratio())


def _to_float(v: flint.fmpq) -> float:
    """The float nearest to v (Python's int / int is correctly rounded)."""
    return float(Fraction(int(v.p), int(v.q)))


def _rank(vectors: list[list[flint.fmpq]]) -> int:
    return flint.fmpq_mat(len(vectors), 3, [c for v in vectors for c in v]).rank() if vectors else 0


def release_rows(n: int, releases) -> tuple[tuple[int, np.ndarray], ...]:
    """The independent release rows: per node, the directions in the order given, each kept only when it is not
    a combination of the node's directions kept before it (exactly: parallel or dependent releases count once).

    ``releases`` are (node, direction) pairs with float directions as given (not normalised: a normalised
    direction is a rounded one). Each kept direction is scaled by a power of two to a largest component in
    [1, 2) where that is exact, so that the rows of the float bound (``floats``) have entries of order one.
    """
    kept: dict[int, list[list[flint.fmpq]]] = {}
    out = []
    for node, e in releases:
        e = np.asarray(e, dtype=np.float64)
        exact = [q(v) for v in e]
        here = kept.setdefault(int(node), [])
        if _rank(here + [exact]) > len(here):
            here.append(exact)
            shift = 1 - int(np.frexp(np.abs(e).max())[1])
            scaled = np.ldexp(e, shift)
            out.append((int(node), scaled if np.array_equal(np.ldexp(scaled, -shift), e) else e))  # exact or as given
    return tuple(out)


def constraint_rows(x: np.ndarray, releases) -> flint.fmpq_mat:
    """C of the module docstring, exactly: 6 balance rows and one row per release, 3n columns."""
    n = len(x)
    m = BALANCE_ROWS + len(releases)
    zero, one = flint.fmpq(0), flint.fmpq(1)
    A = [[zero] * (3 * n) for _ in range(m)]
    for i, p in enumerate(x):
        a, b, c = (q(v) for v in p)
        for d in range(3):
            A[d][3 * i + d] = one
        # x_i x R_i = (y R_z - z R_y, z R_x - x R_z, x R_y - y R_x)
        A[3][3 * i + 1], A[3][3 * i + 2] = -c, b
        A[4][3 * i + 0], A[4][3 * i + 2] = c, -a
        A[5][3 * i + 0], A[5][3 * i + 1] = -b, a
    for r, (k, e) in enumerate(releases):
        for d in range(3):
            A[BALANCE_ROWS + r][3 * k + d] = q(e[d])
    return flint.fmpq_mat(m, 3 * n, [v for row in A for v in row])


@dataclass(frozen=True)
class Point:
    """One point decided exactly: ``R`` and ``norms`` are the exact values rounded to floats (NaN when
    incompatible); ``critical_node`` is the lowest-numbered node whose |R_i|^2 equals the largest exactly,
    ``n_critical`` how many do (-1 and 0 when incompatible)."""

    compatible: bool
    R: np.ndarray
    norms: np.ndarray
    critical_node: int
    n_critical: int


class Layout:
    """One layout (node positions and independent release rows), factored exactly (module docstring).

    Attributes
    ----------
    rank : int
        Rank of C: the balance rows and the release rows.
    balance_rows : list of int
        Which of the six balance rows are in the independent set s (release rows always are: their right-hand
        side is zero, and they are independent of each other; a balance row that depends on them is left out).
    """

    def __init__(self, x: np.ndarray, releases) -> None:
        self.n = len(x)
        C = constraint_rows(np.asarray(x, dtype=np.float64), releases)
        m = C.nrows()
        # Independent rows of C, releases first: the pivot columns of the reduced echelon form of C^T with the
        # release rows ordered first (they are independent, so all of them are pivots).
        order = list(range(BALANCE_ROWS, m)) + list(range(BALANCE_ROWS))
        Ct = flint.fmpq_mat(C.ncols(), m, [C[i, j] for j in range(C.ncols()) for i in order])
        reduced, rank = Ct.rref()
        pivots = []
        col = 0
        for r in range(rank):
            while reduced[r, col] == 0:
                col += 1
            pivots.append(order[col])
            col += 1
        self.rank = int(rank)
        self.rows = pivots
        self.others = [i for i in range(BALANCE_ROWS) if i not in pivots]
        Cs = flint.fmpq_mat(len(pivots), C.ncols(), [C[i, j] for i in pivots for j in range(C.ncols())])
        if pivots:
            W = Cs.transpose() * (Cs * Cs.transpose()).inv()  # C_s^T (C_s C_s^T)^-1
        else:
            W = flint.fmpq_mat(C.ncols(), 0)
        # Only the balance rows have a nonzero right-hand side: keep the columns of H and T that multiply them.
        self.balance_rows = [i for i in pivots if i < BALANCE_ROWS]
        cols = [pivots.index(i) for i in self.balance_rows]
        self.H = flint.fmpq_mat(C.ncols(), len(cols), [W[j, c] for j in range(C.ncols()) for c in cols])
        if self.others:
            Co = flint.fmpq_mat(len(self.others), C.ncols(), [C[i, j] for i in self.others for j in range(C.ncols())])
            CW = Co * W
            self.T = flint.fmpq_mat(len(self.others), len(cols), [CW[i, c] for i in range(len(self.others)) for c in cols])
        else:
            self.T = None

    def solve(self, F, M) -> Point:
        """The exact least-norm reactions of the load (F, M) on this layout, and its labels."""
        d = [-q(v) for v in F] + [-q(v) for v in M]
        ds = flint.fmpq_mat(len(self.balance_rows), 1, [d[i] for i in self.balance_rows])
        if self.T is not None:
            want = self.T * ds
            if any(want[r, 0] != d[i] for r, i in enumerate(self.others)):
                nan = np.full(self.n, np.nan)
                return Point(False, np.full((self.n, 3), np.nan), nan, -1, 0)
        R = self.H * ds
        R = [[R[3 * i + c, 0] for c in range(3)] for i in range(self.n)]
        squares = [a * a + b * b + c * c for a, b, c in R]
        top = max(squares)
        tied = [i for i, s in enumerate(squares) if s == top]
        return Point(
            True,
            np.array([[_to_float(v) for v in row] for row in R]),
            np.sqrt([_to_float(s) for s in squares]),  # equal squares give equal norms: exact ties stay ties
            tied[0],
            len(tied),
        )
