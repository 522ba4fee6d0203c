"""Check the exact reference (tests/reference.py) against the paper's closed forms.

The paper is Kononov 1999 (docs/model.md, References), equations (22)-(34); the physics
is docs/model.md, which wins where the two disagree. Every comparison is exact
(rational arithmetic, ``Poly`` equality), with random rational parameters from
seeded generators, so a wrong sign, a missing factor or a wrong lever arm
shows up as a hard failure.

The paper's side is always built by hand from the *printed* formulas (its
``A'_k``, ``a_k``, ``mu``'s, ``F_k``), never from the reference's own ``M``,
and its determinant is taken with a different routine (sympy ``Matrix``
Berkowitz on expression entries) from the one in ``char_poly``
(``DomainMatrix`` over ``QQ[lam]``).

Discrepancies found between the paper as printed and docs/model.md / the
mechanics, and how they are resolved here (each has a test that pins it):

1. (29), fixed n = 3: ``A'_1 = A_1 + m_2 s_1^2`` is printed; the mechanics (and
   the reference) give ``A_1 + m_23 s_1^2`` (both upper bodies ride on O_2).
   The n = 2 formula seems to have been copied. Corrected form used; the
   printed one is shown to be different.
2. (28), identical free bodies: ``mu_ij = mu (2i-1) a_i`` is printed; it must
   be ``mu (2i-1) a_j`` (i < j), as docs/model.md says and as (27) itself uses.
   Corrected form used; the printed one is shown to be different.
3. Split (23)/(24): the text says "a_2 = a_3 = ... = a_n", and docs/model.md repeats
   it, but the split F_1 ... F_n = 0 needs a_2 = ... = a_n = 0 (each upper
   joint at the centre of mass of its "enlarged" body, as the paper's own
   words say; then every off-diagonal s_i a_j vanishes). Merely equal nonzero
   a_k do NOT split the determinant; a test shows that.
4. Free case: the paper's c_1 is the distance C_1 O_2 = s_1 - c_1 in docs/model.md
   terms (as docs/model.md notes); its A_k there are central moments, while in the
   fixed case its A_k are about the joint, A_k + m_k c_k^2.
5. (27), last equation: the printed ``mu sum_{i=2}^n a_i u_i''`` for body n
   should read ``mu a_n sum_{i=1}^{n-1} (2i-1) u_i''``; only (28) is used.

Constants found (all asserted exactly): fixed (29)/(31), free (30)/(32) and
(28): ``p = lam^(2n) det(paper) prod Q_k`` with constant 1. (33)/(34):
``p = lam^n prod_r P_r`` with ``P_r = m c^2 lam Q (F~ - r)`` and constant 1.
Split: ``p = prod_k lam^2 F_k Q_k``, constant 1. Reversed free chain: p
identical. omega -> -omega: ``p_(-w)(lam) = (-1)^L p_w(-lam)``, L = total
number of liquid modes. Scaling: ``p_s(lam/T) = (M L^2/T^2)^n T^(-L) p(lam)``.
"""

from __future__ import annotations

import os
import random
import sys
from fractions import Fraction as Fr

import pytest
import sympy
from hypothesis import given, settings, strategies as st

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import reference as ref  # noqa: E402
from reference import lam  # noqa: E402

R = sympy.Rational


# ---------------------------------------------------------------- helpers ---

def rq(rng, lo, hi, den=7):
    """Random rational in [lo, hi] with a small denominator, never 0."""
    while True:
        d = rng.randint(1, den)
        x = Fr(rng.randint(int(lo * d), int(hi * d)), d)
        if x != 0:
            return x


def rand_liquid(rng, modes):
    return dict(E=[rq(rng, 0.05, 0.6, 13) for _ in range(modes)],
                kappa=[rq(rng, -3, 3, 5) for _ in range(modes)])


def rand_body(rng, modes=1):
    b = dict(m=rq(rng, 0.5, 5), A=rq(rng, 0.2, 3), C=rq(rng, 0.2, 4),
             c=rq(rng, -2, 2), s=rq(rng, 0.5, 3), omega=rq(rng, -6, 6, 3))
    b.update(rand_liquid(rng, modes))
    return b


def rat(b):
    """Body dict with exact sympy rationals (for hand-built paper formulas)."""
    out = {k: R(v) for k, v in b.items() if k not in ("E", "kappa")}
    out["E"] = [R(e) for e in b.get("E", ())]
    out["kappa"] = [R(k) for k in b.get("kappa", ())]
    return out


def Q(b):
    return ref.liquid_Q(b["omega"], b.get("kappa", ()))


def scaled_det(P, row_factors):
    """det(diag(row_factors) * P) as an exact Poly, via Berkowitz.

    Multiplying row k by ``lam^2 Q_k`` turns every paper entry into a
    polynomial; ``cancel`` must leave no denominator, which is itself checked.
    """
    n = len(P)
    rows = []
    for k in range(n):
        row = []
        for j in range(n):
            e = sympy.cancel(sympy.together(P[k][j] * row_factors[k]))
            _, den = sympy.fraction(e)
            assert den.free_symbols == set(), f"entry ({k},{j}) not polynomial"
            row.append(sympy.expand(e))
        rows.append(row)
    return sympy.Poly(sympy.Matrix(rows).det(method="berkowitz"), lam)


def poly(expr):
    return sympy.Poly(sympy.expand(expr), lam)


def total_modes(bodies):
    return sum(len(b.get("kappa", ())) for b in bodies)


# ------------------------------------------------------ count_complex_pairs ---

def test_count_complex_pairs_on_constructed_polynomials():
    rng = random.Random(11)
    for _ in range(40):
        expr, pairs, real = R(rq(rng, -5, 5)), 0, 0
        for _ in range(rng.randint(0, 4)):          # real roots, repeated
            mult = rng.randint(1, 3)
            expr *= (lam - R(rq(rng, -4, 4)))**mult
            real += mult
        for _ in range(rng.randint(0, 3)):          # conjugate pairs, repeated
            mult = rng.randint(1, 2)
            a, b = R(rq(rng, -3, 3)), R(rq(rng, 0.1, 2))
            expr *= ((lam - a)**2 + b**2)**mult
            pairs += mult
        p = poly(expr)
        assert p.degree() == real + 2 * pairs
        assert ref.count_real_roots(p) == real
        assert ref.count_complex_pairs(p) == pairs
        assert ref.count_complex_pairs(sympy.expand(expr)) == pairs


def test_count_complex_pairs_edge_cases():
    with pytest.raises(ValueError):
        ref.count_complex_pairs(sympy.Poly(0, lam))
    with pytest.raises(ValueError):
        ref.count_complex_pairs(sympy.Poly(lam**2 + 0.5, lam))   # float domain
    assert ref.count_complex_pairs(sympy.Poly(3, lam)) == 0
    # Degree is the actual one: a vanishing would-be leading term is gone.
    assert ref.count_complex_pairs(poly(0 * lam**5 + lam**2 + 1)) == 1
    # Double and triple real roots count with multiplicity.
    assert ref.count_complex_pairs(poly((lam - 1)**2 * (lam + 2)**3)) == 0
    assert ref.count_complex_pairs(poly((lam**2 + 1)**2 * lam**3)) == 2


def test_floats_are_converted_exactly():
    body = dict(m=1, A=1, C=1, c=0.1, s=1, omega=0.3)
    p = ref.char_poly([body], "fixed", g=0.7)
    c, w, g = R(0.1), R(0.3), R(0.7)
    assert c != R(1, 10)            # the exact binary value, not the decimal
    assert p == poly((1 + c**2) * lam**2 + w * lam + c * g)
    assert p != ref.char_poly([dict(body, c=Fr(1, 10), omega=Fr(3, 10))],
                              "fixed", g=Fr(7, 10))


def test_invalid_input_is_rejected():
    b = dict(m=1, A=1, C=1, c=1, s=1, omega=1)
    with pytest.raises(ValueError):
        ref.char_poly([b], "hinged")
    with pytest.raises(ValueError):
        ref.char_poly([b, b], "fixed", joints=[1, 2])
    with pytest.raises(ValueError):
        ref.char_poly([b], "free", K0=1)
    with pytest.raises(ValueError):
        ref.char_poly([dict(b, E=[1], kappa=[])], "fixed")
    with pytest.raises(TypeError):
        ref.char_poly([dict(b, m=sympy.sqrt(2))], "fixed")


# --------------------------------------------------------------- n = 1 -------

def test_single_fixed_top_closed_form():
    rng = random.Random(1)
    for _ in range(20):
        b = rand_body(rng, 0)
        g = rq(rng, -10, 10)
        m, A, C, c, w = (R(b[k]) for k in ("m", "A", "C", "c", "omega"))
        p = ref.char_poly([b], "fixed", g=g)
        assert p == poly((A + m * c**2) * lam**2 + C * w * lam + m * c * R(g))


def _maievskii_point(A, m, c, C, w, g):
    body = dict(m=m, A=A, C=C, c=c, s=1, omega=w)
    p = ref.char_poly([body], "fixed", g=g)
    lhs = R(C)**2 * R(w)**2
    rhs = 4 * (R(A) + R(m) * R(c)**2) * R(m) * R(c) * R(g)
    return p, lhs, rhs


def test_maievskii_on_and_off_the_boundary():
    rng = random.Random(2)
    for _ in range(30):
        A, m, c, C = (rq(rng, 0.2, 4) for _ in range(4))
        w = rq(rng, -8, 8, 3)
        # Exactly on the boundary C^2 w^2 = 4 (A + m c^2) m c g.
        g_b = Fr(C)**2 * Fr(w)**2 / (4 * (A + m * c**2) * m * c)
        p, lhs, rhs = _maievskii_point(A, m, c, C, w, g_b)
        assert lhs == rhs
        assert sympy.discriminant(p.as_expr(), lam) == 0     # a double root
        assert ref.count_complex_pairs(p) == 0               # ... is stable
        for eps in (Fr(1, 10**9), Fr(1, 10**3)):
            p_hi, _, _ = _maievskii_point(A, m, c, C, w, g_b * (1 + eps))
            p_lo, _, _ = _maievskii_point(A, m, c, C, w, g_b * (1 - eps))
            assert ref.count_complex_pairs(p_hi) == 1
            assert ref.count_complex_pairs(p_lo) == 0


@settings(max_examples=40, deadline=None, derandomize=True, database=None)
@given(A=st.fractions(Fr(1, 10), 5), m=st.fractions(Fr(1, 10), 5),
       c=st.fractions(-3, 3), C=st.fractions(0, 5), w=st.fractions(-10, 10),
       g=st.fractions(-20, 20))
def test_maievskii_condition_hypothesis(A, m, c, C, w, g):
    p, lhs, rhs = _maievskii_point(A, m, c, C, w, g)
    assert p.degree() == 2                   # A + m c^2 > 0
    assert (ref.count_complex_pairs(p) == 0) == (lhs >= rhs)


# ------------------------------------------------------ fixed support -------

def fixed_paper_matrix(bs, g, joints, A_prime):
    """Paper (22)/(29)/(31): F_k on the diagonal, s_i a_j + kappa_i^2/lam^2."""
    n = len(bs)
    m = [b["m"] for b in bs]
    a = [bs[k]["m"] * bs[k]["c"] + bs[k]["s"] * sum(m[k + 1:], 0)
         for k in range(n)]
    Kj = [0] + list(joints) + [0] * (n - len(joints))       # kappa_0 = kappa_n = 0
    P = [[None] * n for _ in range(n)]
    for i in range(n):
        P[i][i] = ref.paper_F(A_prime[i], bs[i]["C"], bs[i]["omega"],
                              bs[i]["E"], bs[i]["kappa"],
                              restoring=a[i] * g - Kj[i] - Kj[i + 1])
        for j in range(i + 1, n):
            P[i][j] = P[j][i] = (bs[i]["s"] * a[j]
                                 + (Kj[i + 1] / lam**2 if j == i + 1 else 0))
    return P


def _fixed_check(n, seed, A_prime_rule):
    rng = random.Random(seed)
    bodies = [rand_body(rng, rng.randint(0, 2)) for _ in range(n)]
    g = rq(rng, -10, 10)
    joints = [rq(rng, 0, 5) for _ in range(n - 1)]
    bs = [rat(b) for b in bodies]
    A_prime = A_prime_rule(bs)
    P = fixed_paper_matrix(bs, R(g), [R(k) for k in joints], A_prime)
    factors = [lam**2 * Q(b) for b in bodies]
    return ref.char_poly(bodies, "fixed", g=g, joints=joints), scaled_det(P, factors)


def _about_joint(b):
    # The paper's fixed-support A_k is about the joint O_k, not about C_k.
    return b["A"] + b["m"] * b["c"]**2


@pytest.mark.parametrize("seed", range(4))
def test_fixed_two_bodies_eq31(seed):
    def A_prime(bs):
        b1, b2 = bs
        return [_about_joint(b1) + b2["m"] * b1["s"]**2, _about_joint(b2)]
    p, paper = _fixed_check(2, 100 + seed, A_prime)
    assert p == paper                      # p = lam^4 det(31) Q_1 Q_2, const 1


@pytest.mark.parametrize("seed", range(3))
def test_fixed_three_bodies_eq29(seed):
    def A_prime(bs, printed=False):
        b1, b2, b3 = bs
        upper = b2["m"] if printed else b2["m"] + b3["m"]
        return [_about_joint(b1) + upper * b1["s"]**2,
                _about_joint(b2) + b3["m"] * b2["s"]**2,
                _about_joint(b3)]
    p, paper = _fixed_check(3, 200 + seed, A_prime)
    assert p == paper                      # p = lam^6 det(29) Q_1 Q_2 Q_3
    # Discrepancy 1: the printed A'_1 = A_1 + m_2 s_1^2 does not match.
    _, printed = _fixed_check(3, 200 + seed,
                              lambda bs: A_prime(bs, printed=True))
    assert printed != p


@pytest.mark.parametrize("n", [4, 5])
def test_fixed_general_n_eq22_with_joints(n):
    # (22) generalised with joints the way (29) does it, for n beyond the
    # paper's explicit examples; liquid on every body.
    def A_prime(bs):
        return [_about_joint(b) + b["s"]**2 * sum(x["m"] for x in bs[k + 1:])
                for k, b in enumerate(bs)]
    rng = random.Random(300 + n)
    bodies = [rand_body(rng, 1) for _ in range(n)]
    g, joints = rq(rng, -10, 10), [rq(rng, 0, 5) for _ in range(n - 1)]
    bs = [rat(b) for b in bodies]
    P = fixed_paper_matrix(bs, R(g), [R(k) for k in joints], A_prime(bs))
    paper = scaled_det(P, [lam**2 * Q(b) for b in bodies])
    assert ref.char_poly(bodies, "fixed", g=g, joints=joints) == paper


def _split_bodies(rng, n, equal_value=0):
    """Fixed chain with a_2 = ... = a_n = equal_value (c_k solved for)."""
    bodies = [rand_body(rng, rng.randint(0, 2)) for _ in range(n)]
    for k in range(n - 1, 0, -1):
        above = sum((b["m"] for b in bodies[k + 1:]), Fr(0))
        bodies[k]["c"] = (Fr(equal_value) - bodies[k]["s"] * above) / bodies[k]["m"]
    return bodies


@pytest.mark.parametrize("n", [2, 3, 4])
def test_fixed_split_eq23_eq24(n):
    rng = random.Random(400 + n)
    bodies = _split_bodies(rng, n)
    g, K0 = rq(rng, -10, 10), rq(rng, 0, 3)
    bs = [rat(b) for b in bodies]
    m = [b["m"] for b in bs]
    a = [bs[k]["m"] * bs[k]["c"] + bs[k]["s"] * sum(m[k + 1:], 0)
         for k in range(n)]
    assert all(x == 0 for x in a[1:])
    expected = sympy.Integer(1)
    for k, b in enumerate(bs):
        # A'_k = diagonal of M: about-joint inertia plus the upper masses at s_k.
        A_prime = _about_joint(b) + b["s"]**2 * sum(m[k + 1:], 0)
        # (23) for k = 1 (gravity; K0 is this module's generalisation, the
        # paper has K0 = 0); (24) for k >= 2 (no gravity term since a_k = 0).
        restoring = a[0] * R(g) - R(K0) if k == 0 else 0
        F = ref.paper_F(A_prime, b["C"], b["omega"], b["E"], b["kappa"],
                        restoring=restoring)
        expected *= sympy.cancel(lam**2 * F * Q(bodies[k]))
    p = ref.char_poly(bodies, "fixed", g=g, K0=K0)
    assert p == poly(expected)             # constant 1
    # The total count then splits too.
    singles = sum(ref.count_complex_pairs(poly(sympy.cancel(
        lam**2 * ref.paper_F(_about_joint(b) + b["s"]**2 * sum(m[k + 1:], 0),
                             b["C"], b["omega"], b["E"], b["kappa"],
                             restoring=(a[0] * R(g) - R(K0)) if k == 0 else 0)
        * Q(bodies[k])))) for k, b in enumerate(bs))
    assert ref.count_complex_pairs(p) == singles


def test_fixed_equal_but_nonzero_a_does_not_split():
    # Discrepancy 3: with a_2 = a_3 = 1 (equal, not zero) the coupling s_i a_j
    # stays, so p is not the product of the diagonal F_k.
    rng = random.Random(450)
    bodies = _split_bodies(rng, 3, equal_value=1)
    bs = [rat(b) for b in bodies]
    m = [b["m"] for b in bs]
    expected = sympy.Integer(1)
    for k, b in enumerate(bs):
        a_k = b["m"] * b["c"] + b["s"] * sum(m[k + 1:], 0)
        A_prime = _about_joint(b) + b["s"]**2 * sum(m[k + 1:], 0)
        F = ref.paper_F(A_prime, b["C"], b["omega"], b["E"], b["kappa"],
                        restoring=a_k * 9)
        expected *= sympy.cancel(lam**2 * F * Q(bodies[k]))
    assert ref.char_poly(bodies, "fixed", g=9) != poly(expected)


# -------------------------------------------------------- free support -------

def free_paper_matrix(bs, joints, A_prime, mus):
    """Paper (30)/(32): F_k on the diagonal, mu's plus kappa^2/lam^2."""
    n = len(bs)
    Kj = [0] + list(joints) + [0] * (n - len(joints))
    P = [[None] * n for _ in range(n)]
    for i in range(n):
        P[i][i] = ref.paper_F(A_prime[i], bs[i]["C"], bs[i]["omega"],
                              bs[i]["E"], bs[i]["kappa"],
                              restoring=-Kj[i] - Kj[i + 1])
        for j in range(i + 1, n):
            P[i][j] = P[j][i] = (mus[i, j]
                                 + (Kj[i + 1] / lam**2 if j == i + 1 else 0))
    return P


def _free_setup(n, seed):
    rng = random.Random(seed)
    bodies = [rand_body(rng, rng.randint(0, 2)) for _ in range(n)]
    joints = [rq(rng, 0, 5) for _ in range(n - 1)]
    return bodies, joints, [rat(b) for b in bodies]


@pytest.mark.parametrize("seed", range(4))
def test_free_two_bodies_eq32(seed):
    bodies, joints, bs = _free_setup(2, 500 + seed)
    b1, b2 = bs
    m = b1["m"] + b2["m"]
    c1 = b1["s"] - b1["c"]           # paper's c_1 = C_1 O_2 (docs/model.md)
    c2 = b2["c"]
    A_prime = [b1["A"] + b1["m"] * b2["m"] / m * c1**2,
               b2["A"] + b2["m"] * b1["m"] / m * c2**2]
    mus = {(0, 1): b1["m"] * c1 / m * b2["m"] * c2}
    P = free_paper_matrix(bs, [R(k) for k in joints], A_prime, mus)
    paper = scaled_det(P, [lam**2 * Q(b) for b in bodies])
    assert ref.char_poly(bodies, "free", joints=joints) == paper


@pytest.mark.parametrize("seed", range(3))
def test_free_three_bodies_eq30(seed):
    bodies, joints, bs = _free_setup(3, 600 + seed)
    b1, b2, b3 = bs
    m1, m2, m3 = b1["m"], b2["m"], b3["m"]
    m = m1 + m2 + m3
    c1, c2, c3, s2 = b1["s"] - b1["c"], b2["c"], b3["c"], b2["s"]
    A_prime = [b1["A"] + m1 * (m2 + m3) / m * c1**2,
               b2["A"] + (m2 * (m1 + m3) * c2**2 - 2 * m2 * m3 * c2 * s2
                          + m3 * (m1 + m2) * s2**2) / m,
               b3["A"] + m3 * (m1 + m2) / m * c3**2]
    mus = {(0, 1): m1 * c1 / m * (m2 * c2 + m3 * s2),
           (0, 2): m1 * m3 / m * c1 * c3,
           (1, 2): m3 * c3 / m * (m1 * s2 + (s2 - c2) * m2)}
    P = free_paper_matrix(bs, [R(k) for k in joints], A_prime, mus)
    paper = scaled_det(P, [lam**2 * Q(b) for b in bodies])
    assert ref.char_poly(bodies, "free", joints=joints) == paper


def _identical_free(rng, n, same_spin_and_liquid=True):
    base = rand_body(rng, 2)
    base["c"] = abs(base["c"]) or Fr(1)
    base["s"] = 2 * base["c"]
    bodies = []
    for _ in range(n):
        b = dict(base)
        if not same_spin_and_liquid:
            b["omega"] = rq(rng, -6, 6, 3)
            b.update(rand_liquid(rng, rng.randint(0, 2)))
        bodies.append(b)
    return bodies


@pytest.mark.parametrize("n, roots, shift", [
    (2, [R(1, 2), R(-1, 2)], R(1, 2)),                 # (34)
    (3, [R(2, 3), R(1, 3), R(-7, 3)], R(2, 3)),        # (33)
])
@pytest.mark.parametrize("seed", range(2))
def test_identical_free_factorisation_eq33_eq34(n, roots, shift, seed):
    rng = random.Random(700 + 10 * n + seed)
    bodies = _identical_free(rng, n)
    b = rat(bodies[0])
    mc2 = b["m"] * b["c"]**2
    # F~ = F / (m c^2) with F = A + shift m c^2 + C w / lam - liquid.
    F = ref.paper_F(b["A"] + shift * mc2, b["C"], b["omega"], b["E"], b["kappa"])
    Qb = Q(bodies[0])
    # P_r = m c^2 lam Q (F~ - r): the polynomial form of each factor.
    factors = [poly(sympy.cancel(lam * Qb * (F - r * mc2))) for r in roots]
    expected = poly(lam**n) * sympy.prod(factors)
    p = ref.char_poly(bodies, "free")
    assert p == expected                       # constant 1, power lam^n
    # The paper's conclusion: the single free body about its centre of mass
    # (the factor with r = shift, i.e. F = A + C w/lam - liquid) divides p,
    # so an unstable single body makes the whole chain unstable.
    single = ref.char_poly([bodies[0]], "free")
    assert single.degree() == 2 + len(b["kappa"])
    assert sympy.rem(p, single) == 0
    assert ref.count_complex_pairs(p) >= ref.count_complex_pairs(single)


@pytest.mark.parametrize("seed", range(2))
def test_identical_free_four_bodies_eq28(seed):
    n = 4
    rng = random.Random(800 + seed)
    bodies = _identical_free(rng, n, same_spin_and_liquid=False)
    joints = [rq(rng, 0, 5) for _ in range(n - 1)]
    bs = [rat(b) for b in bodies]
    m, A, c = bs[0]["m"], bs[0]["A"], bs[0]["c"]
    mu = c / n
    a = [(2 * n - 2 * k + 1) * m * c for k in range(1, n + 1)]
    A_prime = [A + mu * m * c * ((2 * n - 2 * k + 1) * (2 * k - 1) - n)
               for k in range(1, n + 1)]
    assert A_prime[0] == A_prime[-1]                   # printed (A'_1 = A'_n)

    def mus(printed):
        # i < j (1-based); discrepancy 2: printed a_i, correct a_j.
        return {(i - 1, j - 1): mu * (2 * i - 1) * (a[i - 1] if printed else a[j - 1])
                for i in range(1, n + 1) for j in range(i + 1, n + 1)}

    factors = [lam**2 * Q(b) for b in bodies]
    p = ref.char_poly(bodies, "free", joints=joints)
    Kj = [R(k) for k in joints]
    assert p == scaled_det(free_paper_matrix(bs, Kj, A_prime, mus(False)), factors)
    assert p != scaled_det(free_paper_matrix(bs, Kj, A_prime, mus(True)), factors)


def test_free_reference_point_is_arbitrary():
    # O_1 of a free chain is only a reference point: shifting it along the
    # axis (c_1 and s_1 by the same amount) must not change p.
    rng = random.Random(850)
    bodies = [rand_body(rng, 1) for _ in range(3)]
    joints = [rq(rng, 0, 3) for _ in range(2)]
    d = rq(rng, -2, 2)
    moved = [dict(bodies[0], c=bodies[0]["c"] + d, s=bodies[0]["s"] + d)] + bodies[1:]
    assert (ref.char_poly(bodies, "free", joints=joints)
            == ref.char_poly(moved, "free", joints=joints))


# ---------------------------------------------------------- symmetries -------

@pytest.mark.parametrize("n", [2, 3, 4])
def test_reversed_free_chain_has_the_same_polynomial(n):
    rng = random.Random(900 + n)
    bodies = [rand_body(rng, rng.randint(0, 2)) for _ in range(n)]
    joints = [rq(rng, 0, 5) for _ in range(n - 1)]
    # Body k -> n+1-k, c -> s - c (measured from the other joint, upward in
    # the flipped chain), s kept (same two joints), joints reversed.
    rev = [dict(b, c=b["s"] - b["c"]) for b in reversed(bodies)]
    p = ref.char_poly(bodies, "free", joints=joints)
    assert ref.char_poly(rev, "free", joints=joints[::-1]) == p    # exactly
    # Sanity that the test can fail: not reversing the joints changes p.
    if joints != joints[::-1]:
        assert ref.char_poly(rev, "free", joints=joints) != p


@pytest.mark.parametrize("support", ["fixed", "free"])
def test_spin_reversal_maps_lam_to_minus_lam(support):
    rng = random.Random(1000 + len(support))
    for n in (1, 2, 3):
        bodies = [rand_body(rng, rng.randint(0, 2)) for _ in range(n)]
        kw = dict(joints=[rq(rng, 0, 5) for _ in range(n - 1)])
        if support == "fixed":
            kw.update(g=rq(rng, -10, 10), K0=rq(rng, 0, 3))
        flipped = [dict(b, omega=-b["omega"]) for b in bodies]
        p = ref.char_poly(bodies, support, **kw)
        q = ref.char_poly(flipped, support, **kw)
        sign = (-1) ** total_modes(bodies)
        assert q == sign * poly(p.as_expr().subs(lam, -lam))
        assert ref.count_complex_pairs(q) == ref.count_complex_pairs(p)


@pytest.mark.parametrize("support", ["fixed", "free"])
def test_unit_scaling_scales_roots_by_one_over_T(support):
    rng = random.Random(1100 + len(support))
    for n in (1, 2, 3):
        bodies = [rand_body(rng, rng.randint(0, 2)) for _ in range(n)]
        joints = [rq(rng, 0, 5) for _ in range(n - 1)]
        g, K0 = rq(rng, -10, 10), rq(rng, 0, 3)
        Lu, Mu, Tu = rq(rng, 0.2, 5), rq(rng, 0.2, 5), rq(rng, 0.2, 5)
        I, Kf = Mu * Lu**2, Mu * Lu**2 / Tu**2
        scaled = [dict(b, m=b["m"] * Mu, A=b["A"] * I, C=b["C"] * I,
                       c=b["c"] * Lu, s=b["s"] * Lu, omega=b["omega"] / Tu,
                       E=[e * I for e in b["E"]]) for b in bodies]
        kw = dict(joints=joints)
        kw_s = dict(joints=[k * Kf for k in joints])
        if support == "fixed":
            kw.update(g=g, K0=K0)
            kw_s.update(g=g * Lu / Tu**2, K0=K0 * Kf)
        p = ref.char_poly(bodies, support, **kw)
        ps = ref.char_poly(scaled, support, **kw_s)
        const = R(Kf)**n * R(Tu)**(-total_modes(bodies))
        assert poly(ps.as_expr().subs(lam, lam / R(Tu))) == const * p
        assert ref.count_complex_pairs(ps) == ref.count_complex_pairs(p)


# -------------------------------------------------- structure, n = 5 ---------

@pytest.mark.parametrize("support", ["fixed", "free"])
def test_five_bodies_two_modes_degree_leading_and_constant_terms(support):
    rng = random.Random(1200 + len(support))
    n = 5
    bodies = [rand_body(rng, 2) for _ in range(n)]
    joints = [rq(rng, 0, 5) for _ in range(n - 1)]
    kw = dict(joints=joints)
    if support == "fixed":
        kw.update(g=rq(rng, -10, 10), K0=rq(rng, 0, 3))
    p = ref.char_poly(bodies, support, **kw)
    M, G, K = ref.system_matrices(bodies, support, **kw)
    Esum = sympy.diag(*[sum(R(e) for e in b["E"]) for b in bodies])
    # Leading term lam^(2n+L): det(M - diag(sum_l E_kl)) (liquid "un-freezes").
    assert p.degree() == sum(2 + len(b["kappa"]) for b in bodies)
    assert p.LC() == (M - Esum).det()
    # lam = 0: the liquid term vanishes, Q_k(0) = prod (omega_k - lambda_kl).
    q0 = sympy.prod([Q(b).subs(lam, 0) for b in bodies])
    assert p.eval(0) == (-K).det() * q0
    if support == "free":
        assert p.eval(0) == 0          # the rigid tilt of the whole chain
    # Symmetric positive-definite inertia for a real mechanical system.
    assert M == M.T and all(M[:k, :k].det() > 0 for k in range(1, n + 1))
    assert ref.count_complex_pairs(p) >= 0
