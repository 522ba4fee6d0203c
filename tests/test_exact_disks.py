"""The exact path's fast count (``exact_disks``, integer matrices of ``exact.int_matrix``) against independent
references: polynomials built from chosen roots (the count is known by construction), integer matrices whose
determinant is known (unimodular transforms of a diagonal), and tests/reference.py's sympy model for chains.

``exact_disks.count`` may return None (not proved, the caller falls back to the exact polynomial), never a wrong
count: every case checks that, and the well-separated cases also check that it does prove.
"""

from __future__ import annotations

import random
from fractions import Fraction

import flint
import numpy as np
import pytest

from stabmap.systems.gyroscopes import exact, exact_disks
from stabmap.systems.gyroscopes.points import point_arrays
from stabmap.systems.gyroscopes.scene import from_dict

import reference as ref
from systems import random_system, reference_args

X = flint.fmpq_poly([0, 1])


def _poly(real, pairs, scale=1) -> flint.fmpz_poly:
    """Integer polynomial with the real roots ``real`` (Fractions, repeats allowed) and the complex pairs
    a +- i b for (a, b) in ``pairs`` (Fractions, b != 0), times ``scale``."""
    p = flint.fmpq_poly([scale])
    for r in real:
        p *= X - flint.fmpq(r.numerator, r.denominator)
    for a, b in pairs:
        a, b = flint.fmpq(a.numerator, a.denominator), flint.fmpq(b.numerator, b.denominator)
        p *= X * X - 2 * a * X + a * a + b * b
    return (p * p.denom()).numer()


def _one_by_one(p: flint.fmpz_poly):
    """p as a 1 x 1 matrix polynomial: (coefs, degrees) for ``exact_disks.count``."""
    return [flint.fmpz_mat([[c]]) for c in p.coeffs()], [p.degree()]


def _count(p: flint.fmpz_poly):
    return exact_disks.count(*_one_by_one(p))


def _frac(rng, lo, hi, den=2**20):
    return Fraction(rng.randrange(int(lo * den), int(hi * den)), den)


@pytest.mark.parametrize("seed", range(12))
def test_chosen_roots_are_counted(seed):
    rng = random.Random(seed)
    nreal, npairs = rng.randrange(0, 14), rng.randrange(0, 10)
    real = {_frac(rng, -50, 50) for _ in range(nreal)}
    pairs = {(_frac(rng, -50, 50), _frac(rng, 0.01, 40)) for _ in range(npairs)}
    p = _poly(sorted(real), sorted(pairs), scale=rng.choice([1, -3, 2**70 + 1]))
    if p.degree() < 1:
        return
    # Distinct roots at least 2^-20 apart in a box of 100: float approximations separate them.
    assert _count(p) == len(real)


@pytest.mark.parametrize("seed", range(8))
def test_roots_over_many_decades(seed):
    rng = random.Random(100 + seed)
    real = {Fraction(rng.choice([-1, 1]) * rng.randrange(1, 1000), 1) * Fraction(10) ** rng.randrange(-8, 8) for _ in range(10)}
    pairs = {(Fraction(rng.randrange(-100, 100), 7) * Fraction(10) ** (e := rng.randrange(-6, 6)), Fraction(rng.randrange(1, 100), 3) * Fraction(10) ** e)
             for _ in range(6)}
    got = _count(_poly(sorted(real), sorted(pairs)))
    assert got is None or got == len(real)


@pytest.mark.parametrize("gap_exp", [-10, -20, -30, -45, -60, -80])
def test_near_double_roots_are_never_miscounted(gap_exp):
    """Two real roots 2^gap_exp apart, and a complex pair as close to the axis: never a wrong count."""
    a, eps = Fraction(3, 7), Fraction(2) ** gap_exp
    near_real = _poly([a, a + eps, Fraction(-5)], [(Fraction(1), Fraction(1, 2))])
    near_pair = _poly([a, Fraction(-5)], [(a, eps), (Fraction(1), Fraction(1, 2))])
    assert _count(near_real) in (None, 3)
    assert _count(near_pair) in (None, 2)
    if gap_exp >= -10:  # far above the float approximations' error: proved
        assert _count(near_real) == 3 and _count(near_pair) == 2
    if gap_exp >= -20:  # two real roots 1e-6 apart: the Weierstrass steps in balls separate them
        assert _count(near_real) == 3


def test_multiple_roots_are_not_proved_by_disks_but_zero_rows_are():
    double = _poly([Fraction(1), Fraction(1), Fraction(2)], [(Fraction(0), Fraction(1))])
    assert _count(double) is None  # two approximations under one root: left to the exact polynomial
    assert exact.count_real_roots(flint.fmpq_poly(double)) == 3
    # x^3 (x - 2)(x^2 + 1): the factor x^3 comes off the row exactly, the rest is proved by disks.
    assert _count(_poly([Fraction(0)] * 3 + [Fraction(2)], [(Fraction(0), Fraction(1))])) == 4


def test_a_zero_leading_coefficient_is_not_proved():
    coefs = [flint.fmpz_mat([[1, 2], [3, 4]]), flint.fmpz_mat([[1, 1], [1, 1]])]  # det has no x^2 term
    assert exact_disks.count(coefs, [1, 1]) is None


def _unimodular(rng, n):
    """A random integer matrix of determinant 1 (product of elementary operations)."""
    U = flint.fmpz_mat([[int(i == j) for j in range(n)] for i in range(n)])
    for _ in range(3 * n):
        i, j = rng.sample(range(n), 2)
        E = flint.fmpz_mat([[int(r == c) for c in range(n)] for r in range(n)])
        E[i, j] = rng.randrange(-3, 4)
        U = U * E
    return U


@pytest.mark.parametrize("seed", range(6))
def test_matrix_polynomials_with_a_known_determinant(seed):
    """diag(p_1 .. p_n) V with V unimodular, then rows of no larger degree added to others: det = p_1 ... p_n,
    whose roots are chosen, and row i still has degree deg p_i with the x^d coefficient intact."""
    rng = random.Random(200 + seed)
    n = rng.randrange(2, 5)
    polys, real = [], 0
    for _ in range(n):
        r = {_frac(rng, -20, 20) for _ in range(rng.randrange(1, 4))}
        c = {(_frac(rng, -20, 20), _frac(rng, 0.1, 10)) for _ in range(rng.randrange(0, 3))}
        polys.append(_poly(sorted(r), sorted(c)))
        real += len(r)
    top = max(p.degree() for p in polys)
    V = _unimodular(rng, n)
    coefs = [flint.fmpz_mat([[polys[i][t] if i == j else 0 for j in range(n)] for i in range(n)]) * V for t in range(top + 1)]
    for _ in range(n):
        i, j = rng.sample(range(n), 2)
        if polys[j].degree() <= polys[i].degree():
            c = rng.randrange(-5, 6)
            for t in range(top + 1):
                for k in range(n):
                    coefs[t][i, k] += c * coefs[t][j, k]
    assert exact_disks.count(coefs, [p.degree() for p in polys]) == real


def _points(system):
    pts = point_arrays(from_dict(system), {})
    return pts.kernel_args()


def _special_systems():
    rng = random.Random(31)
    out = [random_system(rng, n, modes, support) for n in (1, 2, 3, 4) for modes in (0, 1, 2) for support in ("fixed", "free")]
    kappa2 = random_system(rng, 3, 2, "fixed")
    kappa2["bodies"][1]["fluid"]["kappa"][0] = 2.0
    still = random_system(rng, 3, 2, "fixed")
    still["omega"] = 0.0
    for b in still["bodies"]:
        b.pop("omega", None)
    double = {"support": "fixed", "g": 4.0, "omega": 1.0, "bodies": [{"m": 1.0, "A": 0.1875, "C": 1.0, "c": 0.25}]}
    return out + [kappa2, still, double]


@pytest.mark.parametrize("i", range(27))
def test_decide_points_matches_the_sympy_model(i):
    """The exact path (fast disks, else the exact polynomial) on chains against tests/reference.py."""
    system = _special_systems()[i]
    args = _points(system)
    got = int(exact.decide_points(*args, np.arange(1))[0])
    p = ref.char_poly(**reference_args(system))
    assert got == ref.count_complex_pairs(p), system
    a = args
    poly = exact.char_poly(a[0][0], a[1][0], a[2][0], a[3][0], a[4][0], a[5], a[6], a[7], a[8][0])
    want = [Fraction(int(c.p), int(c.q)) for c in reversed(p.all_coeffs())]
    have = [Fraction(int(c.p), int(c.q)) for c in poly.coeffs()]
    assert have == want  # the integer determinants give the model's polynomial exactly


def test_int_matrix_is_the_rational_matrix_row_scaled():
    """A(x) = diag(den_k) P(x) (char_matrix's rational matrix) at a few rational x, exactly, den = prod den_k."""
    rng = random.Random(5)
    system = random_system(rng, 4, 2, "fixed")
    a = _points(system)
    args = (a[0][0], a[1][0], a[2][0], a[3][0], a[4][0], a[5], a[6], a[7], a[8][0])
    coefs, den, degrees = exact.int_matrix(*args)
    P, degree = exact.char_matrix(*args)
    assert sum(degrees) == degree
    for x in (flint.fmpq(0), flint.fmpq(-3, 7), flint.fmpq(11, 2)):
        A = flint.fmpq_mat(coefs[-1])
        for c in coefs[-2::-1]:
            A = A * x + flint.fmpq_mat(c)
        Px = P(x)
        scales = flint.fmpz(1)
        for k in range(4):
            ratio = {A[k, j] / Px[k, j] for j in range(4) if Px[k, j] != 0}
            assert len(ratio) == 1 and all(r > 0 and r.q == 1 for r in ratio)
            scales *= ratio.pop().p
        assert scales == den


def test_disks_prove_the_random_chains_and_leave_the_double_root():
    """The fast path is what decides: every random chain above is proved by the disks (none by the fallback),
    and the exact double root (the last system) is left to the exact polynomial."""
    proved = []
    for system in _special_systems():
        a = _points(system)
        coefs, _, degrees = exact.int_matrix(a[0][0], a[1][0], a[2][0], a[3][0], a[4][0], a[5], a[6], a[7], a[8][0])
        proved.append(exact_disks.count(coefs, degrees) is not None)
    assert proved == [True] * 26 + [False]


def test_a_row_above_its_degree_bound_is_refused():
    coefs = [flint.fmpz_mat([[1, 0], [0, 1]]), flint.fmpz_mat([[0, 0], [1, 0]])]
    with pytest.raises(ValueError, match=r"row 1 .*degrees\[1\] = 0"):
        exact_disks.count(coefs, [1, 0])


@pytest.mark.parametrize("seed", range(6))
def test_tiny_liquid_and_near_boundaries_match_the_sympy_model(seed):
    """Where the kernels leave points to the exact path: E/A from 1e-12 to 1e-9 (roots within sqrt(E) of the poles
    -beta), and spin rates scanned across a boundary; decide_points against tests/reference.py at every point."""
    rng = random.Random(400 + seed)
    system = random_system(rng, 3, 2, rng.choice(["fixed", "free"]))
    for b in system["bodies"]:
        b["fluid"]["E"] = [b["A"] * 10.0 ** rng.uniform(-12, -9) for _ in b["fluid"]["E"]]
    proved = 0
    for omega in np.linspace(-60.0, 60.0, 7):
        system["omega"] = float(omega)
        a = _points(system)
        got = int(exact.decide_points(*a, np.arange(1))[0])
        want = ref.count_complex_pairs(ref.char_poly(**reference_args(system)))
        assert got == want, (system, omega)
        coefs, _, degrees = exact.int_matrix(a[0][0], a[1][0], a[2][0], a[3][0], a[4][0], a[5], a[6], a[7], a[8][0])
        proved += exact_disks.count(coefs, degrees) is not None
    assert proved >= 5  # most of them by the disks themselves, not by the fallback
