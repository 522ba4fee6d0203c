"""The source paper's printed equations, in exact rational arithmetic (python-flint).

Kononov's paper (docs/model.md, References; equations 22-34) writes the characteristic equation of a chain
through the functions F_k on the diagonal of a determinant, and for a few cases factors it into
single-body equations whose stability has a closed form.  This module restates those printed
formulas independently of the kernels and of docs/model.md's matrices (M, G, K), so that the engine can
be checked against the paper:

- ``paper_polynomial``: p(lambda) from the printed determinants (22)/(29)/(31) (fixed support, any n)
  and (30)/(32) (free support, n = 2, 3) or (28) (free identical bodies, any n; with docs/model.md's
  correction mu_ij = mu (2i-1) a_j).  Rows are multiplied by lambda^2 Q_k, which gives docs/model.md's p.
- ``factors``: the single-body factors of the cases the paper solves in closed form: one top (23),
  one free body (24), identical free bodies (34) and (33) without joint stiffness, and the split of
  a fixed chain into (23) and (24) when a_2 = ... = a_n = 0.  Each factor has degree <= 3 in
  lambda (after exact lambda = 0 roots), so "all roots real" is exactly "discriminant >= 0": the
  closed-form stability condition (Maievskii's condition for the top without liquid).
- ``closed_form_boundaries``: where that condition changes along one parameter, as the real roots
  of the discriminant (a polynomial in that parameter) at which the exact count changes.

Parameters enter as exact binary values of the floats (as the engine sees them).  Any parameter
may instead be the polynomial ``T`` (a ``flint.fmpq_poly`` in the scanned variable t): factors then
have coefficients in Q[t] and their discriminants are polynomials in t.  Coefficients are in
ascending powers of lambda.
"""

from __future__ import annotations

from dataclasses import dataclass

import flint

from ...errors import StabmapError

T = flint.fmpq_poly([0, 1])  # the scanned variable t
ZERO = flint.fmpq(0)


def q(x) -> flint.fmpq:
    """The exact rational value of a float (or int, or fmpq)."""
    if isinstance(x, (flint.fmpq, flint.fmpq_poly)):
        return x
    num, den = float(x).as_integer_ratio()
    return flint.fmpq(num, den)


@dataclass
class Chain:
    """One parameter point of a chain, as the paper's symbols; lists run over bodies 1..n (0-based).

    Values are ``fmpq`` or, for the scanned parameter, ``T``-polynomials.  ``A`` is the equatorial
    inertia about the body's own centre of mass and ``c`` the distance from the lower joint to it
    (docs/model.md's convention; the paper's fixed-support A_k about the joint is A + m c^2).
    """

    m: list
    A: list
    C: list
    c: list
    s: list
    omega: list
    E: list  # per body, list of E_l
    kappa: list  # per body, list of kappa_l
    K: list  # K_1..K_{n-1}
    K_0: object = ZERO
    g: object = ZERO
    free: bool = False

    @property
    def n(self) -> int:
        return len(self.m)


def chain_from_arrays(body, joint, g, E, kappa, nmodes, free: bool) -> Chain:
    """A ``Chain`` of exact values from one point of the kernels' per-point layout (``points``)."""
    n = len(body)
    col = [[q(body[k][j]) for k in range(n)] for j in range(6)]
    return Chain(
        m=col[0], A=col[1], C=col[2], c=col[3], s=col[4], omega=col[5],
        E=[[q(E[k][l]) for l in range(int(nmodes[k]))] for k in range(n)],
        kappa=[[q(kappa[k][l]) for l in range(int(nmodes[k]))] for k in range(n)],
        K=[q(joint[j]) for j in range(1, n)], K_0=q(joint[0]), g=q(g), free=bool(free),
    )


# ---------------------------------------------------------------- polynomials in lambda over Q or Q[t]

def _mul(a: list, b: list) -> list:
    out = [ZERO] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            out[i + j] = out[i + j] + x * y
    return out


def _add(a: list, b: list) -> list:
    size = max(len(a), len(b))
    return [(a[i] if i < len(a) else ZERO) + (b[i] if i < len(b) else ZERO) for i in range(size)]


def _scale(a: list, x) -> list:
    return [x * y for y in a]


def _is_zero(x) -> bool:
    return x == 0 if isinstance(x, flint.fmpq) else x.is_zero()


def _trim(a: list) -> list:
    while len(a) > 1 and _is_zero(a[-1]):
        a = a[:-1]
    return a


def _Q(omega, kappa: list) -> list:
    """Q(lambda) = prod_l (lambda + omega - lambda_l), lambda_l = 2 omega / kappa_l."""
    out = [flint.fmpq(1)]
    for k in kappa:
        out = _mul(out, [omega - 2 * omega / k, flint.fmpq(1)])
    return out


def F_polynomial(A_prime, C, omega, restoring, E: list, kappa: list) -> list:
    """lambda^2 Q(lambda) F(lambda) for the paper's F = A' + C w/lambda + restoring/lambda^2 - (lambda + w) sum E_l/(lambda + w - lambda_l)."""
    out = _mul([restoring, C * omega, A_prime], _Q(omega, kappa))
    for l, e in enumerate(E):
        others = _Q(omega, kappa[:l] + kappa[l + 1 :])
        out = _add(out, _scale(_mul([ZERO, ZERO, omega, flint.fmpq(1)], others), -e))
    return _trim(out)


def _about_joint_and_a(ch: Chain):
    """The fixed support's A'_k (about O_k, plus the upper masses at s_k) and a_k = m_k c_k + s_k sum_{j>k} m_j."""
    n = ch.n
    upper = [sum(ch.m[k + 1 :], ZERO) for k in range(n)]
    A_prime = [ch.A[k] + ch.m[k] * ch.c[k] ** 2 + ch.s[k] ** 2 * upper[k] for k in range(n)]
    a = [ch.m[k] * ch.c[k] + ch.s[k] * upper[k] for k in range(n)]
    return A_prime, a


def _free_inertia_and_mu(ch: Chain):
    """A'_k and the couplings mu of the free chain: printed (32) for n = 2, (30) for n = 3, (27)/(28) for identical bodies."""
    n, m = ch.n, ch.m
    mt = sum(m, ZERO)
    if n == 2:
        c1, c2 = ch.s[0] - ch.c[0], ch.c[1]  # the paper's c_1 is C_1 O_2 (docs/model.md)
        return [ch.A[0] + m[0] * m[1] / mt * c1**2, ch.A[1] + m[1] * m[0] / mt * c2**2], {(0, 1): m[0] * c1 / mt * m[1] * c2}
    if n == 3:
        c1, c2, c3, s2 = ch.s[0] - ch.c[0], ch.c[1], ch.c[2], ch.s[1]
        A_prime = [
            ch.A[0] + m[0] * (m[1] + m[2]) / mt * c1**2,
            ch.A[1] + (m[1] * (m[0] + m[2]) * c2**2 - 2 * m[1] * m[2] * c2 * s2 + m[2] * (m[0] + m[1]) * s2**2) / mt,
            ch.A[2] + m[2] * (m[0] + m[1]) / mt * c3**2,
        ]
        mu = {(0, 1): m[0] * c1 / mt * (m[1] * c2 + m[2] * s2), (0, 2): m[0] * m[2] / mt * c1 * c3,
              (1, 2): m[2] * c3 / mt * (m[0] * s2 + (s2 - c2) * m[1])}
        return A_prime, mu
    if _identical(ch):
        c, mass = ch.c[0], ch.m[0]
        mu = c / n
        a = [(2 * n - 2 * k + 1) * mass * c for k in range(1, n + 1)]
        A_prime = [ch.A[0] + mu * mass * c * ((2 * n - 2 * k + 1) * (2 * k - 1) - n) for k in range(1, n + 1)]
        return A_prime, {(i - 1, j - 1): mu * (2 * i - 1) * a[j - 1] for i in range(1, n + 1) for j in range(i + 1, n + 1)}
    raise StabmapError(f"the paper prints the free chain's determinant for n = 2, 3 and for identical bodies only (got n = {n})")


def _identical(ch: Chain) -> bool:
    same = all(getattr(ch, key)[k] == getattr(ch, key)[0] for key in ("m", "A", "c") for k in range(ch.n))
    return same and all(ch.s[k] == 2 * ch.c[0] for k in range(ch.n - 1))


def paper_polynomial(ch: Chain) -> flint.fmpq_poly:
    """p(lambda) from the paper's printed determinant, rows multiplied by lambda^2 Q_k (exact; numbers only, not T)."""
    n = ch.n
    K = [ch.K_0 if not ch.free else ZERO] + list(ch.K) + [ZERO]  # K[k] joins bodies k and k+1 (1-based); K[0] the base
    if ch.free:
        A_prime, mu = _free_inertia_and_mu(ch)
        restoring = [-K[k] - K[k + 1] for k in range(n)]
    else:
        A_prime, a = _about_joint_and_a(ch)
        mu = {(i, j): ch.s[i] * a[j] for i in range(n) for j in range(i + 1, n)}
        restoring = [a[k] * ch.g - K[k] - K[k + 1] for k in range(n)]
    rows = []
    for i in range(n):
        Qi = _Q(ch.omega[i], ch.kappa[i])
        row = []
        for j in range(n):
            if i == j:
                row.append(F_polynomial(A_prime[i], ch.C[i], ch.omega[i], restoring[i], ch.E[i], ch.kappa[i]))
            else:
                off = [K[min(i, j) + 1] if abs(i - j) == 1 else ZERO, ZERO, mu[min(i, j), max(i, j)]]
                row.append(_mul(off, Qi))
        rows.append([flint.fmpq_poly(e) for e in row])
    return det(rows)


def det(rows: list) -> flint.fmpq_poly:
    """Determinant of a matrix of polynomials by Bareiss' fraction-free elimination (every division is exact)."""
    a = [list(r) for r in rows]
    n, sign, prev = len(a), 1, flint.fmpq_poly(1)
    for k in range(n - 1):
        pivot = next((i for i in range(k, n) if not a[i][k].is_zero()), None)
        if pivot is None:
            return flint.fmpq_poly(0)
        if pivot != k:
            a[k], a[pivot], sign = a[pivot], a[k], -sign
        for i in range(k + 1, n):
            for j in range(k + 1, n):
                a[i][j] = (a[i][j] * a[k][k] - a[i][k] * a[k][j]) // prev
        prev = a[k][k]
    return sign * a[n - 1][n - 1]


# ---------------------------------------------------------------- the closed-form cases

def factors(ch: Chain, case: str) -> list[list]:
    """The single-body factors of p(lambda) that the paper derives for ``case``; their product is p up to lambda^k and a constant.

    case: "top" (23: one body, fixed), "free-body" (24: one free body about its centre of mass),
    "identical-free" (34 for n = 2, 33 for n = 3: identical free bodies, one spin, no joint
    stiffness), "split" (23 times (24)s: fixed chain, a_2 = ... = a_n = 0, no joint stiffness).
    """
    if case == "top":
        A_prime, a = _about_joint_and_a(ch)
        return [F_polynomial(A_prime[0], ch.C[0], ch.omega[0], a[0] * ch.g - ch.K_0, ch.E[0], ch.kappa[0])]
    if case == "free-body":
        return [F_polynomial(ch.A[0], ch.C[0], ch.omega[0], ZERO, ch.E[0], ch.kappa[0])]
    if case == "identical-free":
        # (34): F~ = 1/2, -1/2 with F~ = (A + mc^2/2 + ...)/(mc^2); (33): F~ = 2/3, 1/3, -7/3 with A + 2mc^2/3.
        shift, roots = {2: (flint.fmpq(1, 2), (flint.fmpq(1, 2), flint.fmpq(-1, 2))),
                        3: (flint.fmpq(2, 3), (flint.fmpq(2, 3), flint.fmpq(1, 3), flint.fmpq(-7, 3)))}[ch.n]
        mc2 = ch.m[0] * ch.c[0] ** 2
        return [F_polynomial(ch.A[0] + (shift - r) * mc2, ch.C[0], ch.omega[0], ZERO, ch.E[0], ch.kappa[0]) for r in roots]
    if case == "split":
        A_prime, a = _about_joint_and_a(ch)
        return [F_polynomial(A_prime[k], ch.C[k], ch.omega[k], a[k] * ch.g - (ch.K_0 if k == 0 else ZERO), ch.E[k], ch.kappa[k]) for k in range(ch.n)]
    raise ValueError(f"unknown closed-form case {case!r}")


def _strip_zero_roots(f: list) -> list:
    while len(f) > 1 and _is_zero(f[0]):
        f = f[1:]
    return f


def discriminant(f: list):
    """Discriminant of a polynomial of degree 2 or 3 (ascending coefficients over Q or Q[t])."""
    if len(f) == 3:
        c, b, a = f
        return b * b - 4 * a * c
    if len(f) == 4:
        d, c, b, a = f
        return b * b * c * c - 4 * a * c**3 - 4 * b**3 * d - 27 * a * a * d * d + 18 * a * b * c * d
    raise StabmapError(f"no closed form: a factor of degree {len(f) - 1} (the closed forms cover degree <= 3)")


def closed_form_pairs(fs: list[list]) -> int:
    """Complex-conjugate root pairs of the product of numeric factors, from the closed-form criterion of each.

    A real polynomial of degree 2 or 3 has only real roots exactly when its discriminant is >= 0,
    and otherwise one complex pair; lambda = 0 roots (the free body's) are real and stripped first.
    """
    pairs = 0
    for f in fs:
        f = _strip_zero_roots(_trim(list(f)))
        if len(f) > 2:
            pairs += int(discriminant(f) < 0)
    return pairs


def at(f: list, t) -> list:
    """Substitute t = value (exact) into a factor whose coefficients may be T-polynomials."""
    t = q(t)
    return [x(t) if isinstance(x, flint.fmpq_poly) else x for x in f]


def closed_form_boundaries(fs: list[list], lo: float, hi: float) -> list[tuple[float, int, int]]:
    """Values of t in (lo, hi) where the closed-form count changes: (t, pairs below, pairs above).

    Candidates are the real roots of each factor's discriminant and leading coefficient (polynomials
    in t, isolated by Arb to about 1e-15 relative); the count is evaluated exactly between them.
    """
    candidates = set()
    for f in fs:
        f = _trim(list(f))
        for poly in (discriminant(_strip_zero_roots(f)), f[-1]):
            if isinstance(poly, flint.fmpq_poly) and poly.degree() > 0:
                for root, _mult in poly.complex_roots():
                    if root.imag == 0:
                        x = float(root.real.mid())
                        if lo < x < hi:
                            candidates.add(x)
    edges = [lo] + sorted(candidates) + [hi]
    mids = [(a + b) / 2 for a, b in zip(edges[:-1], edges[1:], strict=True)]
    counts = [closed_form_pairs([at(f, x) for f in fs]) for x in mids]
    return [(x, counts[i], counts[i + 1]) for i, x in enumerate(edges[1:-1]) if counts[i] != counts[i + 1]]


def maievskii_omega(A: float, m: float, c: float, C: float, g: float) -> float:
    """Maievskii's critical spin rate of one top on a fixed point [rad/s]: C^2 w^2 = 4 (A + m c^2) m c g (A about the centre of mass)."""
    return 2.0 * ((A + m * c * c) * m * c * g) ** 0.5 / abs(C)


# ---------------------------------------------------------------- exact counting

def complex_pairs(p: flint.fmpq_poly) -> int:
    """Complex-conjugate root pairs of an exact polynomial, multiplicity counted.

    Arb's isolation of the roots of the integer numerator is certified and returns real roots with
    an exactly zero imaginary part (a Sturm sequence over Q gives the same counts but its
    coefficients grow to thousands of digits from binary parameters: 60x slower at degree 12).
    """
    if p.is_zero():
        raise StabmapError("the characteristic polynomial vanishes identically")
    real = sum(mult for root, mult in p.numer().complex_roots() if root.imag == 0)
    return (p.degree() - real) // 2
