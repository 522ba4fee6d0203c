"""stabmap.systems.gyroscopes.halfplane against references it does not compute itself.

- Arb's certified complex roots (flint.acb_poly.roots on the Gaussian-rational coefficients, at 256 bits or more):
  a root's side of the real axis is trusted only when its ball's imaginary part excludes 0 (``arb`` comparisons are
  true only when certain).  Used for random complex polynomials, near-axis clusters and thresholds.
- The construction: p = c * prod (x - r)^m with exact Gaussian-rational roots r, so the count of each side is read off
  the roots themselves (repeated roots, shared conjugate pairs, real roots, lambda = 0 twice; Arb cannot isolate
  repeated roots).
- The worked example of /work/shared/FINITE_RE.md section 3: lambda (lambda - 1 - 0.1i)(lambda + 2 + 0.3i)
  (lambda - 0.5 - 0.2i) has 1 growing, 1 real and 2 decaying roots (solutions ~ exp(i lambda t)).
- The ideal limit: for a real polynomial the growing roots are stabmap.systems.gyroscopes.exact.complex_pairs (and,
  for a free chain, tests/reference.py's sympy polynomial with its structural double zero).

Conventions: growing means Im lambda < 0; faster_than(sigma0) counts -Im lambda > sigma0, strictly.
"""

from __future__ import annotations

import random
from fractions import Fraction

import flint
import pytest
from flint import acb, acb_poly, fmpq, fmpq_poly

from stabmap.errors import StabmapError
from stabmap.systems.gyroscopes import exact, halfplane

X = fmpq_poly([0, 1])
ZERO = fmpq_poly([])


@pytest.fixture(autouse=True)
def precision():
    """Arb at 256 bits for the reference roots; the caller's precision back afterwards."""
    old = flint.ctx.prec
    flint.ctx.prec = 256
    yield
    flint.ctx.prec = old


# --- helpers: Gaussian-rational polynomials as (re, im) pairs ----------------------------------------------------


def mul(p, q):
    (a, b), (c, d) = p, q
    return a * c - b * d, a * d + b * c


def from_roots(roots, lead=(1, 0)):
    """(re, im) of lead * prod (x - r)^m for roots [(re_r, im_r, m)] with exact rational parts."""
    p = (fmpq_poly([lead[0]]), fmpq_poly([lead[1]]))
    for a, b, m in roots:
        for _ in range(m):
            p = mul(p, (X - fmpq(a), fmpq_poly([-fmpq(b)])))
    return p


def sides(roots, sigma0=0):
    """(faster than sigma0, exactly sigma0, slower) from the construction: growth rate -Im r against sigma0."""
    sigma0 = q(sigma0)
    out = [0, 0, 0]
    for _, b, m in roots:
        rate = -fmpq(b)
        out[0 if rate > sigma0 else 1 if rate == sigma0 else 2] += m
    return tuple(out)


def arb_roots(re, im):
    """Arb's certified roots of re + i*im (squarefree), refined to radius 1e-40."""
    n = max(re.degree(), im.degree())
    coeffs = [acb(re[k], im[k]) for k in range(n + 1)]
    return acb_poly(coeffs).roots(tol=1e-40, maxprec=4096)


def arb_sides(re, im, sigma0=0):
    """(faster, undecided, slower) by Arb: -Im r - sigma0 certified > 0, not certified either way, certified < 0."""
    out = [0, 0, 0]
    for r in arb_roots(re, im):
        t = -r.imag - q(sigma0)
        out[0 if t > 0 else 2 if t < 0 else 1] += 1
    return tuple(out)


def q(x):
    """An exact rational: a float at its binary value, a Fraction as it is."""
    if isinstance(x, float):
        return fmpq(*x.as_integer_ratio())
    if isinstance(x, Fraction):
        return fmpq(x.numerator, x.denominator)
    return fmpq(x)


def rand_q(rng, top=9, dens=(1, 2, 3, 4)):
    return fmpq(rng.randint(-top, top), rng.choice(dens))


# --- the worked example and the sign convention --------------------------------------------------------------------


def test_worked_example_of_finite_re_section_3():
    # lambda (lambda - 1 - 0.1i)(lambda + 2 + 0.3i)(lambda - 0.5 - 0.2i): roots 0, 1 + 0.1i, -2 - 0.3i, 0.5 + 0.2i
    roots = [(0, 0, 1), (1, fmpq(1, 10), 1), (-2, fmpq(-3, 10), 1), (fmpq(1, 2), fmpq(2, 10), 1)]
    re, im = from_roots(roots)
    assert halfplane.counts(re, im) == (1, 1, 2)
    assert (halfplane.growing_roots(re, im), halfplane.real_roots(re, im), halfplane.decaying_roots(re, im)) == (1, 1, 2)
    # the single growing root is -2 - 0.3i (Im < 0, so exp(i lambda t) grows like exp(0.3 t))
    assert halfplane.faster_than(re, im, fmpq(29, 100)) == 1
    assert halfplane.faster_than(re, im, fmpq(3, 10)) == 0


def test_first_degree_signs():
    # x - i: root +i decays (exp(i*i*t) = exp(-t)); x + i: root -i grows
    assert halfplane.counts(X, fmpq_poly([-1])) == (0, 0, 1)
    assert halfplane.counts(X, fmpq_poly([1])) == (1, 0, 0)
    # a purely imaginary leading coefficient: i x + 1 has root i, decaying; 2i x has root 0
    assert halfplane.counts(fmpq_poly([1]), fmpq_poly([0, 1])) == (0, 0, 1)
    assert halfplane.counts(ZERO, fmpq_poly([0, 2])) == (0, 1, 0)
    # a nonzero constant has no roots
    assert halfplane.counts(fmpq_poly([3]), fmpq_poly([-1])) == (0, 0, 0)


# --- random complex polynomials against Arb ------------------------------------------------------------------------


def test_random_complex_polynomials_against_arb():
    rng = random.Random(20261129)
    checked = undecided = 0
    for _ in range(400):
        n = rng.randint(1, 12)
        re = fmpq_poly([rand_q(rng) for _ in range(n + 1)])
        im = fmpq_poly([rand_q(rng) for _ in range(n + 1)])
        if re[n] == 0 and im[n] == 0:
            continue
        try:
            ref = arb_sides(re, im)
        except ValueError:  # a repeated root: Arb cannot isolate it (the constructions below cover that case)
            undecided += 1
            continue
        got = halfplane.counts(re, im)
        assert sum(got) == n
        if ref[1]:  # a root whose side Arb cannot certify: the certified ones must still agree
            undecided += 1
            assert got[0] >= ref[0] and got[2] >= ref[2] and got[0] + got[2] <= ref[0] + ref[2] + ref[1], (re, im, got, ref)
            continue
        checked += 1
        assert got == (ref[0], 0, ref[2]), (re, im, got, ref)
    assert checked >= 360 and undecided <= 20


def test_complex_leading_coefficient_is_normalised_exactly():
    # the same roots under leading coefficients 1, i, -3 + 2i, 1/7 - 5i: the counts are the roots'
    rng = random.Random(7)
    for _ in range(60):
        roots = [(rand_q(rng, 5), rand_q(rng, 5), 1) for _ in range(rng.randint(1, 8))]
        want = sides(roots)
        for lead in [(1, 0), (0, 1), (-3, 2), (fmpq(1, 7), -5), (0, fmpq(-2, 3))]:
            assert halfplane.counts(*from_roots(roots, lead)) == want


# --- repeated, clustered and shared roots, against the construction ------------------------------------------------


def test_repeated_roots_and_shared_conjugate_pairs():
    i10 = fmpq(1, 10)
    cases = [
        [(0, 0, 2)],  # a free chain's structural double zero alone
        [(0, 0, 2), (1, i10, 1), (-2, -3 * i10, 1)],
        [(1, 2, 3)],  # a triple decaying root
        [(1, -2, 2), (1, 2, 2)],  # a shared conjugate pair, twice: gcd(P, Q) = p
        [(1, -2, 2), (1, 2, 1)],  # the pair shared once, the growing member once more
        [(1, -2, 1), (1, 2, 3), (0, 0, 2), (5, 0, 1)],
        [(fmpq(1, 3), 0, 4), (fmpq(-1, 3), 1, 2), (fmpq(-1, 3), -1, 1)],
        [(2, 1, 1), (2, -1, 1), (3, 4, 1), (3, -4, 1), (0, 0, 2)],  # real polynomial: 2 growing = N_c
        [(0, 0, 2), (0, 1, 2), (0, -1, 2), (1, 1, 1)],
        [(1, fmpq(1, 2), 6), (1, fmpq(-1, 2), 6)],  # degree 12, one pair of multiplicity 6
    ]
    for roots in cases:
        for lead in [(1, 0), (2, -3)]:
            assert halfplane.counts(*from_roots(roots, lead)) == sides(roots), roots


def test_random_constructions_with_multiplicity():
    # hundreds of p = c prod (x - r)^m, roots drawn from a small pool so that repeats, conjugates and reals are common
    rng = random.Random(51)
    pool = [(fmpq(a, 2), fmpq(b, 2)) for a in range(-3, 4) for b in (-2, -1, 0, 1, 2)]
    for _ in range(300):
        roots, degree, target = [], 0, rng.randint(1, 12)
        while degree < target:
            a, b = rng.choice(pool)
            m = rng.randint(1, 3)
            roots.append((a, b, m))
            if rng.random() < 0.3:  # and its conjugate: a pair shared by p and its conjugate polynomial
                roots.append((a, -b, rng.randint(1, 2)))
            degree = sum(m for *_, m in roots)
        lead = (rand_q(rng, 4), rand_q(rng, 4))
        if lead == (0, 0):
            lead = (1, 0)
        got = halfplane.counts(*from_roots(roots, lead))
        assert got == sides(roots), roots
        assert sum(got) == degree


def test_roots_within_1e_12_of_the_axis():
    e = fmpq(1, 10**12)
    cases = [
        [(1, e, 1)],
        [(1, -e, 1)],
        [(1, e, 1), (1, -e, 1), (1, 0, 1)],  # a cluster of three, within 1e-12 of each other, one on each side
        [(fmpq(1, 3), e / 3, 1), (fmpq(1, 3) + e, -e / 7, 1), (fmpq(1, 3) - e, 2 * e, 1), (0, 0, 2)],
        [(-2, -e, 1), (-2 + e, -e, 1), (5, e / 1000, 1), (5, -e / 1000, 1), (7, 3, 1)],
    ]
    for roots in cases:
        want = sides(roots)
        re, im = from_roots(roots, (3, -1))
        assert halfplane.counts(re, im) == want, roots
        if all(m == 1 for *_, m in roots) and not any(b == 0 for _, b, _ in roots):
            assert arb_sides(re, im) == want  # Arb resolves 1e-15 at these precisions; confirms the construction
    # repeated near-axis roots (Arb cannot isolate them): the construction alone
    roots = [(1, e, 3), (1, -e, 2), (1, 0, 2)]
    assert halfplane.counts(*from_roots(roots)) == sides(roots) == (2, 2, 3)


# --- the ideal limit -----------------------------------------------------------------------------------------------


def test_ideal_limit_is_complex_pairs_on_real_polynomials():
    rng = random.Random(3)
    for trial in range(200):
        if trial % 2:  # random real coefficients
            n = rng.randint(1, 12)
            P = fmpq_poly([rand_q(rng) for _ in range(n)] + [rand_q(rng) or 1])
        else:  # real roots and conjugate pairs with multiplicity, a structural double zero now and then
            P = fmpq_poly([rand_q(rng) or 1])
            for _ in range(rng.randint(1, 5)):
                a, b, m = rand_q(rng, 3), rand_q(rng, 3), rng.randint(1, 2)
                P *= (X * X - 2 * a * X + a * a + b * b) ** m if b else (X - a) ** m
            if rng.random() < 0.3:
                P *= X * X
        want = exact.complex_pairs(P)
        for im in (ZERO, fmpq_poly([0])):
            got = halfplane.counts(P, im)
            assert got[0] == got[2] == want
            assert got[1] == exact.count_real_roots(P)
        # a real polynomial times a complex constant is still real up to that constant: the same count
        assert halfplane.counts(2 * P, -5 * P) == (want, P.degree() - 2 * want, want)


def test_free_chain_char_poly_with_its_structural_zeros():
    import sympy
    from reference import char_poly

    R = sympy.Rational
    bodies = [{"m": 1, "A": R(1, 50), "C": R(3, 100), "c": R(1, 10), "s": R(1, 5), "omega": 30},
              {"m": 2, "A": R(1, 20), "C": R(1, 100), "c": R(1, 10), "s": 0, "omega": -10, "E": [R(1, 100)], "kappa": [R(3, 2)]}]
    # a stiff joint: the rigid tilt, lambda = 0 once; an ideal joint (K_1 = 0): lambda = 0 twice
    for joints, zeros in (([5], 1), ([0], 2)):
        poly = char_poly(bodies, "free", joints=joints)
        P = fmpq_poly([fmpq(int(c.p), int(c.q)) for c in reversed(poly.all_coeffs())])
        assert all(P[k] == 0 for k in range(zeros)) and P[zeros] != 0
        want = exact.complex_pairs(P)
        assert halfplane.counts(P, ZERO) == (want, P.degree() - 2 * want, want)
        assert halfplane.real_roots(P, ZERO) == exact.count_real_roots(P) >= zeros


# --- the threshold -------------------------------------------------------------------------------------------------


def test_faster_than_against_the_construction_including_equal_rates():
    roots = [(0, 0, 2), (1, fmpq(-3, 10), 1), (-1, fmpq(-3, 10), 2), (2, fmpq(-1, 2), 1), (0, fmpq(1, 4), 1), (3, fmpq(-1, 10**12), 1)]
    re, im = from_roots(roots, (1, 2))
    for s in [0, fmpq(1, 10**12), fmpq(1, 10**13), fmpq(1, 10), fmpq(3, 10), fmpq(3, 10) - fmpq(1, 10**15), fmpq(1, 2), 1,
              fmpq(-1, 4), fmpq(-1, 5), fmpq(-1, 3)]:
        want = sides(roots, s)
        assert halfplane.faster_than(re, im, s) == want[0], s
        assert halfplane.counts(*halfplane.shifted(re, im, s)) == want, s
    # strict: at sigma0 = 3/10 the three roots growing at exactly 3/10 are not counted (they sit on the shifted axis)
    assert halfplane.faster_than(re, im, fmpq(3, 10)) == 1
    assert halfplane.counts(*halfplane.shifted(re, im, fmpq(3, 10))) == (1, 3, 4)
    # sigma0 = 0 is growing_roots
    assert halfplane.faster_than(re, im, 0) == halfplane.growing_roots(re, im) == 5


def test_faster_than_random_polynomials_against_arb():
    rng = random.Random(11)
    done = 0
    for _ in range(60):
        n = rng.randint(1, 10)
        re = fmpq_poly([rand_q(rng) for _ in range(n)] + [rand_q(rng) or 1])
        im = fmpq_poly([rand_q(rng) for _ in range(n + 1)])
        for s in [fmpq(1, 3), fmpq(-1, 2), fmpq(3, 2), Fraction(1, 7), 0.25]:
            try:
                ref = arb_sides(re, im, s)
            except ValueError:
                continue
            if ref[1]:
                continue
            assert halfplane.faster_than(re, im, s) == ref[0], (re, im, s)
            done += 1
    assert done >= 250


def test_float_threshold_is_its_binary_value():
    # a root growing at exactly 1/10: the float 0.1 is slightly above 1/10, so that root is not faster than it
    re, im = from_roots([(1, fmpq(-1, 10), 1), (0, -1, 1)])
    assert halfplane.faster_than(re, im, 0.1) == 1
    assert halfplane.faster_than(re, im, fmpq(1, 10) - fmpq(1, 10**30)) == 2


def test_conjugate_mirror_keeps_the_counts():
    # omega -> -omega maps roots lambda -> -conj(lambda): q(x) = conj(p(-conj x)) has the same counts (construction)
    roots = [(1, fmpq(1, 10), 1), (-2, fmpq(-3, 10), 2), (0, 0, 2)]
    mirrored = [(-a, b, m) for a, b, m in roots]
    assert halfplane.counts(*from_roots(roots, (2, 1))) == halfplane.counts(*from_roots(mirrored, (2, -1))) == sides(roots)


# --- errors --------------------------------------------------------------------------------------------------------


def test_zero_polynomial_and_bad_inputs_are_refused():
    with pytest.raises(StabmapError, match="identically zero"):
        halfplane.counts(ZERO, ZERO)
    with pytest.raises(StabmapError, match="identically zero"):
        halfplane.growing_roots(fmpq_poly([0, 0]), fmpq_poly([0]))
    with pytest.raises(StabmapError, match="identically zero"):
        halfplane.faster_than(ZERO, ZERO, 1)
    with pytest.raises(StabmapError, match="sigma0"):
        halfplane.faster_than(X, ZERO, float("nan"))
    with pytest.raises(StabmapError, match="sigma0"):
        halfplane.faster_than(X, ZERO, "1/2")
    with pytest.raises(StabmapError, match="re must be"):
        halfplane.counts("x", ZERO)
    # plain lists of rationals are polynomials too
    assert halfplane.counts([0, 1], [1]) == (1, 0, 0)
