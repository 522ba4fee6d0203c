"""Proofs of the closed-chain labels (docs/closed.md, section 5): every stability class is proved, or the
point is flagged ``undecided``.

A label says whether a family's equilibrium exists at the given lengths and, if it does, the index and nullity of
the Hessian of U - sum R . closure on the closures' tangent space with the rotation taken out (``equations``).
The parameters are taken at their exact binary values; a family's labels depend on its length ratio h2/h1 only
(h1, c1^2 and h scale the forces and the energy), so one proof serves every point of a ratio.

- **Existence** is decided in exact rational arithmetic (python-flint ``fmpq``): figure-eight-4 exists iff
  h2 <= h1, figure-eight-6 iff (2 h1 + h2)^2 < 2 h2^2 (that is h1/h2 < (sqrt 2 - 1)/2; equality is irrational),
  the hinges iff h2 <= 2 h1, the ring of winding j iff sum h_k w^k = 0 for w = exp(2 pi i j/n), i.e. iff the
  cyclotomic polynomial of w's order n/gcd(n, j) divides sum h_k x^k.  At equality a two-length family is folded onto
  a line (every axis parallel): an exact point whose closed form is rational.
- **Index and nullity** of an unfolded family member come from the bordered (KKT) matrix
  K = [[H, A^T], [A, 0]], H the Hessian (units of c1^2/h), A the m = 2L + 1 rows of the closures and the
  rotation.  If K is nonsingular, A has full row rank (a null vector y of A^T gives K (0, y) = 0) and, by
  Haynsworth's inertia theorem, inertia(K) = inertia(Z^T H Z) + (m, m, 0) for any basis Z of null(A): the index
  is K's negative eigenvalues minus m and the nullity is 0.  K's inertia is proved in ball arithmetic
  (python-flint ``arb``): K in balls from the closed form evaluated in balls (square roots only, no trigonometry),
  V the floating-point eigenvectors of K's midpoint (any fixed matrix of doubles), M = V^T K V in balls, and the
  pivots of M's LDL^T factorisation in balls, largest eigenvalues first.  When every pivot ball excludes 0, M is
  nonsingular, so are V and K, and by Sylvester's law of inertia K has as many negative eigenvalues as M has
  negative pivots.  A pivot ball that holds 0 is retried at a higher precision (``PRECISIONS``); after the last
  the point is ``undecided``.  The ratio is a double, a change of index sits at an irrational ratio (sqrt 2,
  5.986...), so in practice the ladder decides every point.
- **Folded end points** (h2 = h1 for figure-eight-4, h2 = 2 h1 for the hinges) have rational closed forms
  (every sine and cosine is 0 or +-1): the rank of A, a basis of its null space and the characteristic polynomial
  of the reduced Hessian are computed exactly; its roots are real, so Descartes' rule of signs counts them
  exactly.  The closure rows lost are added to the nullity (docs/closed.md), so such a point is degenerate.
- **Rings** have R = 0 and H = cos(2 pi j/n) times the cycle's Laplacian, which is positive definite off the
  rotation; the closures keep full rank (a closed polygon that is not folded).  So the index is n - 3 when
  4j > n, the nullity n - 3 when 4j = n (decided in integers), and both are 0 otherwise.
- **Equilibria without a closed form** (``search``, and lengths that follow a family's pattern only to rounding):
  the Krawczyk operator on the general equations (22), (24) in balls proves a unique equilibrium in a box around
  the floating-point solution, and the inertia is then proved as above with that box's sines and cosines.

Floating point decides nothing here: it only supplies the starting guesses and the congruence V.  python-flint's
working precision is global, so every proof holds ``_LOCK`` while it sets it.
"""

from __future__ import annotations

import itertools
import math
import threading
from contextlib import contextmanager
from dataclasses import dataclass

import flint
import numpy as np
from flint import arb, arb_mat, fmpq, fmpq_mat, fmpq_poly, fmpz_poly

from . import space

# Values of the provenance flag ``decided_by`` (outputs.DECIDED_BY gives their meanings).
BY_BALLS = 0  # existence exactly, index and nullity in ball arithmetic from the closed form
BY_EXACT = 1  # everything in exact rational arithmetic: absent points, folded end points
BY_STRUCTURE = 2  # rings: existence exactly, inertia from H = cos(2 pi j/n) x Laplacian
BY_INTERVAL_NEWTON = 3  # no closed form: the equilibrium by the Krawczyk operator, the inertia in balls
UNDECIDED = 4  # not proved: the point's label is the class "undecided"

# Precisions [bits] of the ball arithmetic, tried in turn until every pivot (and Krawczyk box) is decided.
PRECISIONS = (64, 128, 256, 512)
NEWTON_STEPS = 4  # Newton steps on the midpoints before each Krawczyk test
_LOCK = threading.RLock()


@dataclass(frozen=True)
class Verdict:
    """What is proved about one point: existence (1, 0, or -1 undecided), index and nullity (-1: not known).

    The functions of this module prove the planar block (index and nullity in the plane); ``space_proofs`` adds
    the out-of-plane block and keeps the planar counts in ``planar_index`` and ``planar_nullity``.
    """

    exists: int
    index: int
    nullity: int
    decided_by: int
    planar_index: int = -1
    planar_nullity: int = -1

    @property
    def proved(self) -> bool:
        return self.decided_by != UNDECIDED


ABSENT_VERDICT = Verdict(0, -1, -1, BY_EXACT)
UNDECIDED_VERDICT = Verdict(-1, -1, -1, UNDECIDED)


@contextmanager
def precision(bits: int):
    """python-flint's working precision set to ``bits`` (and the lock held) inside the block."""
    with _LOCK:
        old = flint.ctx.prec
        flint.ctx.prec = bits
        try:
            yield
        finally:
            flint.ctx.prec = old


def exact(x: float) -> fmpq:
    """The exact rational value of a double."""
    num, den = float(x).as_integer_ratio()
    return fmpq(num, den)


# ---------------------------------------------------------------------------------------------------- existence
def pattern_existence(family: str, r: fmpq) -> str:
    """``"present"``, ``"folded"`` (the end point of the range: exists, on a line) or ``"absent"`` at ratio r = h2/h1."""
    if family == "figure-eight-6":  # h1/h2 < (sqrt 2 - 1)/2  <=>  (2 + r)^2 < 2 r^2 (r > 0); never equal
        return "present" if (2 + r) ** 2 < 2 * r * r else "absent"
    end = {"figure-eight-4": fmpq(1), "hinge": fmpq(2), "hinge-straight": fmpq(2)}[family]
    return "present" if r < end else "folded" if r == end else "absent"


def ring_closes(lengths: list[fmpq], j: int) -> bool:
    """Whether sum_k h_k w^k = 0, w = exp(2 pi i j/n): the cyclotomic polynomial of w's order divides sum h_k x^k."""
    n = len(lengths)
    order = n // math.gcd(n, j)
    poly = fmpq_poly([fmpq(0)] + list(lengths))
    return poly % fmpq_poly(fmpz_poly.cyclotomic(order)) == 0


def ring_inertia(n: int, j: int) -> tuple[int, int]:
    """Index and nullity of a closed ring: H = cos(2 pi j/n) L on n - 3 directions (L positive definite there)."""
    d = n - 3
    if d == 0 or 4 * j < n:
        return 0, 0
    return (0, d) if 4 * j == n else (d, 0)


# -------------------------------------------------------------------------------------------------- closed forms
def _pattern_lengths(pattern, r):
    return [1 if p == 1 else r for p in pattern]


def closed_form(family: str, r, sqrt):
    """cos theta_k, sin theta_k, the scaled loop forces rho = R h / c1^2 as (rho_y, rho_z) per loop, and the lengths,
    of a family at ratio r = h2/h1 with h1 = 1 (the labels are scale-free), in the arithmetic of r (balls or exact
    rationals; ``sqrt`` its square root).  The closed forms of docs/closed.md written with square roots only."""
    one, zero = r * 0 + 1, r * 0
    if family == "figure-eight-4":  # theta = (-t, pi/2, pi + t, pi/2), sin t = r, R_y = 2/a_1
        st = r
        ct = sqrt(1 - st * st)
        c = [ct, zero, -ct, zero]
        s = [-st, one, -st, one]
        rho = [(2 * one, zero)]
    elif family == "figure-eight-6":  # theta = (t, -s, t, pi - t, pi + s, pi - t)
        a = 1 / r
        p = 1 - 2 * a + sqrt(1 - 4 * a)
        sin2 = (p * p - 1) / (p * p - 4 * a * a)
        st, ct = sqrt(sin2), sqrt(1 - sin2)
        ss, cs = 2 * a * st, p * ct
        c = [ct, cs, ct, -ct, -cs, -ct]
        s = [st, -ss, st, st, -ss, st]
        rho = [((2 - p - 2 * a) * st, zero)]
    elif family in ("hinge", "hinge-straight"):  # sin t = r/2
        st = r / 2
        ct = sqrt(1 - st * st)
        c = [ct, ct, zero, -ct, -ct, zero]
        if family == "hinge":  # theta = (-t, t, -pi/2, pi - t, pi + t, pi/2); loops {S1, S5, S6}, {S2, S3, S4}
            s = [-st, st, -one, st, -st, one]
            force = 2 * st + 1
            rho = [(force, zero), (-force, zero)]
        else:  # theta = (-t, -t, pi/2, pi + t, pi + t, pi/2)
            s = [-st, -st, one, -st, -st, one]
            rho = [(one, zero)]
    else:
        raise KeyError(family)
    return c, s, rho


def _exact_sqrt(x: fmpq) -> fmpq:
    """The square root of a rational square (the folded end points need sqrt(0) only)."""
    num, den = int(x.p), int(x.q)
    rn, rd = math.isqrt(num), math.isqrt(den)
    if num < 0 or rn * rn != num or rd * rd != den:
        raise ArithmeticError(f"{x} is not the square of a rational")
    return fmpq(rn, rd)


def hessian_and_rows(c, s, rho, lengths, loop_of):
    """H (n x n, units of c1^2/h) and the rows of every loop's closure, as lists, in the arithmetic of ``c``.

    H = cyclic Laplacian with weights w_k = cos(theta_k - theta_(k-1)) + diag(h_k (rho_z cos theta_k - rho_y sin
    theta_k)); the rows of loop l are (h_k cos theta_k) and (-h_k sin theta_k) over its bodies, 0 elsewhere.
    """
    n = len(c)
    zero = c[0] * 0
    w = [c[k] * c[k - 1] + s[k] * s[k - 1] for k in range(n)]  # joint k joins bodies k - 1 and k
    H = [[zero] * n for _ in range(n)]
    for k in range(n):
        ry, rz = rho[loop_of[k]]
        H[k][k] = w[k] + w[(k + 1) % n] + lengths[k] * (rz * c[k] - ry * s[k])
        H[k][k - 1] = H[k][k - 1] - w[k]
        H[k - 1][k] = H[k - 1][k] - w[k]
    rows = []
    for loop in range(len(rho)):
        rows.append([lengths[k] * c[k] if loop_of[k] == loop else zero for k in range(n)])
        rows.append([-lengths[k] * s[k] if loop_of[k] == loop else zero for k in range(n)])
    return H, rows


# ------------------------------------------------------------------------------------------------------- inertia
def ball_inertia(H, rows) -> tuple[int, int] | None:
    """Index and nullity (0) of H on null(rows) with the rotation taken out, proved in balls; None: not decided.

    ``H`` and ``rows`` (the closures) hold arbs at the current precision; each closure row is scaled by a double
    near 1 / its size (any nonzero scale keeps null(A) and conditions K) and the rotation row is added.
    """
    return bordered_inertia(H, scaled_rows(rows) + [[arb(1.0 / math.sqrt(len(H)))] * len(H)])


def bordered_inertia(H, A) -> tuple[int, int] | None:
    """Index and nullity (0) of H on null(A), proved in balls from the bordered matrix K = [[H, A^T], [A, 0]];
    None: not decided (module docstring).

    K is brought by the congruence M = V^T K V (V: eigenvectors of K's midpoint, largest |eigenvalue| first) to
    nearly diagonal form.  When every Gershgorin interval of M excludes 0, the intervals left and right of 0 are
    disjoint and each holds as many eigenvalues as it has centres (shrink M's off-diagonal part to 0: no
    eigenvalue crosses 0), so K has as many negative eigenvalues as M has negative diagonal entries.  Otherwise
    the pivots of M's LDL^T in balls decide when none holds 0 (Sylvester's law of inertia).
    """
    n = len(H)
    m = len(A)
    N = n + m
    zero = arb(0)
    K = [[zero] * N for _ in range(N)]
    for i in range(n):
        for k in range(n):
            K[i][k] = H[i][k]
    for r in range(m):
        for k in range(n):
            K[n + r][k] = K[k][n + r] = A[r][k]
    mid = np.array([[float(x) for x in row] for row in K])
    if not np.isfinite(mid).all():
        return None
    lam, V = np.linalg.eigh(0.5 * (mid + mid.T))
    V = V[:, np.argsort(-np.abs(lam), kind="stable")]
    Vb = arb_mat(V.tolist())
    a = (Vb.transpose() * arb_mat(K) * Vb).tolist()
    negative = _gershgorin_negatives(a)
    if negative is None:
        negative = _ldl_negatives(a)
    if negative is None:
        return None
    index = negative - m
    if index < 0 or N - negative - m < 0:  # Haynsworth: K has at least m eigenvalues of each sign
        raise ArithmeticError(f"inertia of the bordered matrix ({N - negative}, {negative}) has fewer than m = {m} of one sign")
    return index, 0


def _gershgorin_negatives(a) -> int | None:
    """The number of negative eigenvalues of the symmetric ball matrix ``a`` when its Gershgorin intervals all
    exclude 0; None otherwise."""
    negative = 0
    N = len(a)
    for i in range(N):
        radius = sum((abs(a[i][j]) for j in range(N) if j != i), arb(0))
        if a[i][i] - radius > 0:
            continue
        if a[i][i] + radius < 0:
            negative += 1
            continue
        return None
    return negative


def _ldl_negatives(a) -> int | None:
    """The negative pivots of the LDL^T of the ball matrix ``a`` (no pivoting, lower triangle, in place); None when
    a pivot ball holds 0."""
    N = len(a)
    negative = 0
    for k in range(N):  # a[i][k] keeps L_ik d_k
        d = a[k][k]
        if d < 0:
            negative += 1
        elif not d > 0:
            return None
        for i in range(k + 1, N):
            f = a[i][k] / d
            if not f.is_finite():
                return None
            for j in range(k + 1, i + 1):
                a[i][j] = a[i][j] - f * a[j][k]
    return negative


def exact_inertia(H, rows, symmetries=None) -> tuple[int, int]:
    """Index and nullity, in exact rational arithmetic, of H on null(rows) with the symmetries taken out (default:
    the plane's rotation, a row of ones); the closure rows lost to dependence (a folded loop) are added to the
    nullity."""
    n = len(H)
    symmetries = [[fmpq(1)] * n] if symmetries is None else [list(r) for r in symmetries]
    A = fmpq_mat([list(r) for r in rows] + symmetries)
    lost = len(rows) - fmpq_mat([list(r) for r in rows]).rank()  # symmetries lie in null(rows): ranks add
    numer, _ = A.numer_denom()
    X, dim = numer.nullspace()
    if dim != n - A.rank():
        raise ArithmeticError("null space of the closure rows has the wrong dimension")
    if dim == 0:
        return 0, lost
    Z = fmpq_mat([[X[i, k] for k in range(dim)] for i in range(n)])
    R = Z.transpose() * fmpq_mat(H) * Z
    coeffs = [fmpq(x) for x in R.charpoly().coeffs()]  # ascending; the roots are R's eigenvalues, all real
    zeros = next(k for k, x in enumerate(coeffs) if x != 0)
    negative = _sign_changes([x * (-1) ** k for k, x in enumerate(coeffs)])
    positive = _sign_changes(coeffs)
    if zeros + negative + positive != dim:
        raise ArithmeticError("Descartes' count does not add up: the characteristic polynomial is not real-rooted")
    return negative, zeros + lost


def _sign_changes(coeffs) -> int:
    signs = [1 if x > 0 else -1 for x in coeffs if x != 0]
    return sum(1 for a, b in itertools.pairwise(signs) if a != b)


# ------------------------------------------------------------------------------------------------------- families
def prove_pattern(family: str, r: fmpq, pattern, loop_of) -> Verdict:
    """The verdict of a two-length family at the exact ratio r = h2/h1."""
    where = pattern_existence(family, r)
    if where == "absent":
        return ABSENT_VERDICT
    if where == "folded":
        c, s, rho = closed_form(family, r, _exact_sqrt)
        index, nullity = exact_inertia(*hessian_and_rows(c, s, rho, _pattern_lengths(pattern, r), loop_of))
        return Verdict(1, index, nullity, BY_EXACT)
    for bits in PRECISIONS:
        with precision(bits):
            rb = arb(r)
            c, s, rho = closed_form(family, rb, lambda x: x.sqrt())
            found = ball_inertia(*hessian_and_rows(c, s, rho, _pattern_lengths(pattern, rb), loop_of))
        if found is not None:
            return Verdict(1, found[0], found[1], BY_BALLS)
    return Verdict(1, -1, -1, UNDECIDED)


def prove_ring(lengths: list[fmpq], j: int) -> Verdict:
    """The verdict of the ring of winding j with exact lengths."""
    if not ring_closes(lengths, j):
        return ABSENT_VERDICT
    index, nullity = ring_inertia(len(lengths), j)
    return Verdict(1, index, nullity, BY_STRUCTURE)


def pattern_ratio(lengths: list[fmpq], pattern) -> fmpq | None:
    """h2/h1 when the lengths follow the pattern exactly (every h1 body equal, every h2 body equal); else None."""
    first = {kind: lengths[pattern.index(kind)] for kind in (1, 2)}
    if any(x != first[kind] for x, kind in zip(lengths, pattern, strict=True)):
        return None
    return first[2] / first[1]


def ratio_hull_absent(family: str, lengths: list[fmpq], pattern) -> bool:
    """Lengths off the pattern by rounding: whether every ratio between the smallest and the largest h2/h1 they
    allow lies where the family is absent (its existence is monotone in the ratio)."""
    h1 = [x for x, k in zip(lengths, pattern, strict=True) if k == 1]
    h2 = [x for x, k in zip(lengths, pattern, strict=True) if k == 2]
    return all(pattern_existence(family, r) == "absent" for r in (min(h2) / max(h1), max(h2) / min(h1)))


# ----------------------------------------------------------------------------------------- Krawczyk (no closed form)
def _equations(x, theta1, lengths, loop_of, loops: int, point: bool):
    """F (the torque equations (22) of bodies 2..n, every loop's closure) and, unless ``point``, its Jacobian,
    at x = (theta_2..theta_n, rho_y, rho_z of each loop), in balls."""
    n = len(lengths)
    th = [theta1] + x[: n - 1]
    rho = [(x[n - 1 + 2 * l], x[n + 2 * l]) for l in range(loops)]
    sn = [t.sin() for t in th]
    cs = [t.cos() for t in th]
    nxt = [th[(k + 1) % n] - th[k] for k in range(n)]  # theta_(k+1) - theta_k
    F = []
    for k in range(1, n):
        ry, rz = rho[loop_of[k]]
        F.append(nxt[k].sin() - nxt[k - 1].sin() - lengths[k] * (rz * sn[k] + ry * cs[k]))
    for l in range(loops):
        F.append(sum((lengths[k] * sn[k] for k in range(n) if loop_of[k] == l), arb(0)))
        F.append(sum((lengths[k] * cs[k] for k in range(n) if loop_of[k] == l), arb(0)))
    if point:
        return F, None
    size = n - 1 + 2 * loops
    zero = arb(0)
    J = [[zero] * size for _ in range(size)]
    cn = [d.cos() for d in nxt]
    for k in range(1, n):
        row = k - 1
        ry, rz = rho[loop_of[k]]
        if (k + 1) % n:
            J[row][(k + 1) % n - 1] += cn[k]
        if k - 1:
            J[row][k - 2] += cn[k - 1]
        J[row][k - 1] += -cn[k] - cn[k - 1] - lengths[k] * (rz * cs[k] - ry * sn[k])
        J[row][n - 1 + 2 * loop_of[k]] = -lengths[k] * cs[k]
        J[row][n + 2 * loop_of[k]] = -lengths[k] * sn[k]
    for l in range(loops):
        for k in range(1, n):
            if loop_of[k] == l:
                J[n - 1 + 2 * l][k - 1] = lengths[k] * cs[k]
                J[n + 2 * l][k - 1] = -lengths[k] * sn[k]
    return F, J


def krawczyk(theta, rho, lengths, loop_of, bits: int):
    """Balls (theta, rho) holding the unique equilibrium near the guess, theta_1 held at its value; None: no proof.

    Newton steps on the midpoints refine the guess at the working precision, then the Krawczyk operator
    k(X) = x - C F(x) + (I - C J(X)) (X - x), C the midpoint inverse of J(x), is evaluated on the box X of
    radius 2^(-bits/2) (relative) around x: k(X) inside X's interior proves one and only one zero in X, and
    that zero lies in k(X).
    """
    n = len(lengths)
    loops = len(rho)
    theta1 = arb(float(theta[0]))
    h = [arb(float(v)) for v in lengths]
    x = [arb(float(t)) for t in theta[1:]] + [arb(float(v)) for f in rho for v in f]
    size = len(x)
    try:
        for _ in range(NEWTON_STEPS):
            F, J = _equations(x, theta1, h, loop_of, loops, point=False)
            step = arb_mat(J).solve(arb_mat([[f] for f in F]))
            x = [(x[i] - step[i, 0]).mid() for i in range(size)]
        F, J = _equations(x, theta1, h, loop_of, loops, point=False)
        C = arb_mat(J).inv().mid()
    except ZeroDivisionError:  # a singular Jacobian: no isolated equilibrium to prove
        return None
    if not all(v.is_finite() for row in C.tolist() for v in row):
        return None
    radius = 2.0 ** (-bits // 2)
    box = [x[i] + arb(0, radius * max(1.0, abs(float(x[i])))) for i in range(size)]
    Fx, _ = _equations(x, theta1, h, loop_of, loops, point=True)
    _, JX = _equations(box, theta1, h, loop_of, loops, point=False)
    eye = arb_mat([[int(i == k) for k in range(size)] for i in range(size)])
    k = arb_mat([[v] for v in x]) - C * arb_mat([[f] for f in Fx]) + (eye - C * arb_mat(JX)) * arb_mat(
        [[box[i] - x[i]] for i in range(size)])
    inner = [k[i, 0] for i in range(size)]
    if not all(box[i].contains_interior(inner[i]) for i in range(size)):
        return None
    theta_b = [theta1] + inner[: n - 1]
    rho_b = [(inner[n - 1 + 2 * l], inner[n + 2 * l]) for l in range(loops)]
    return theta_b, rho_b


def prove_equilibrium(theta, rho, lengths, loop_of, gamma=None) -> Verdict:
    """The verdict of an equilibrium known only approximately: ``theta`` (n,) [rad] and ``rho`` (L, 2) = R h / c1^2
    [1/m] at exact ``lengths`` (doubles); existence by Krawczyk, inertia in balls; undecided if either fails.
    With ``gamma`` (c2^2/c1^2, exact) the out-of-plane block is proved over the same box (``in_space``); without,
    the planar model's verdict (``planar_only``)."""
    found = False
    for bits in PRECISIONS:
        with precision(bits):
            box = krawczyk(theta, rho, lengths, loop_of, bits)
            if box is None:
                continue
            found = True
            th, rh = box
            c = [t.cos() for t in th]
            s = [t.sin() for t in th]
            hk = [arb(float(v)) for v in lengths]
            inertia = ball_inertia(*hessian_and_rows(c, s, rh, hk, loop_of))
            out = None if inertia is None or gamma is None else out_of_plane_inertia(c, s, rh, hk, loop_of, arb(gamma))
        if inertia is not None and (gamma is None or out is not None):
            planar = Verdict(1, inertia[0], inertia[1], BY_INTERVAL_NEWTON)
            return planar_only(planar) if gamma is None else in_space(planar, out)
    return Verdict(1 if found else -1, -1, -1, UNDECIDED)


# ------------------------------------------------------------------------------------------------------ in space
def scaled_rows(rows):
    """Each row times a double near 1 / its size: the same null space, a better conditioned bordered matrix."""
    return [[x * (1.0 / (max(abs(float(v)) for v in row) or 1.0)) for x in row] for row in rows]


def out_of_plane_inertia(c, s, rho, lengths, loop_of, gamma) -> tuple[int, int] | None:
    """Index and nullity (0) of the out-of-plane block (``space.out_of_plane``) on its closures with the two
    rotations and the spin taken out, proved in balls; None: not decided."""
    H, closures, symmetries = space.out_of_plane(c, s, rho, lengths, loop_of, gamma)
    return bordered_inertia(H, scaled_rows(closures + symmetries))


def planar_only(planar: Verdict) -> Verdict:
    """The planar model's verdict: the planar counts are the label's (the chain confined to its plane)."""
    return Verdict(planar.exists, planar.index, planar.nullity, planar.decided_by, planar.index, planar.nullity)


def in_space(planar: Verdict, out: tuple[int, int] | None) -> Verdict:
    """The verdict in space from the planar one and the out-of-plane (index, nullity): the counts add up (the
    reflection through the plane splits the Hessian).  ``out`` None: undecided.  A ring's planar proof by
    structure becomes a proof in balls (its out-of-plane block is proved in balls); a folded end's stays exact
    (its out-of-plane block is proved exactly)."""
    if planar.exists != 1 or planar.decided_by == UNDECIDED:
        return planar_only(planar)
    if out is None:
        return Verdict(1, -1, -1, UNDECIDED, planar.index, planar.nullity)
    by = BY_BALLS if planar.decided_by == BY_STRUCTURE else planar.decided_by
    return Verdict(1, planar.index + out[0], planar.nullity + out[1], by, planar.index, planar.nullity)


# ---------------------------------------------------------------------------------------------------------- batches
@dataclass(frozen=True)
class Verdicts:
    """The verdicts of P points as arrays: exists int8 (1, 0, -1 undecided), index and nullity int16 (-1: not
    known), decided_by int8."""

    exists: np.ndarray
    index: np.ndarray
    nullity: np.ndarray
    decided_by: np.ndarray
    planar_index: np.ndarray
    planar_nullity: np.ndarray

    @staticmethod
    def of(verdicts: list[Verdict]) -> Verdicts:
        def field(name, dtype):
            return np.array([getattr(v, name) for v in verdicts], dtype=dtype).reshape(-1)

        return Verdicts(field("exists", np.int8), field("index", np.int16), field("nullity", np.int16),
                        field("decided_by", np.int8), field("planar_index", np.int16), field("planar_nullity", np.int16))
