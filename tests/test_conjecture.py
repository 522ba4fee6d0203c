"""The paper's conjecture for identical free chains (docs/conjecture.md), against exact references.

Everything exact here comes from ``tests/reference.py`` (sympy, a literal restatement of
docs/model.md), not from ``scripts/conjecture.py``; the script's own exact builder is itself
checked against the reference, and its quick mode is run once.
"""

from __future__ import annotations

import math
import pathlib
import runpy
from fractions import Fraction

import numpy as np
import pytest
import sympy

import reference as R

import stabmap

SCRIPT = pathlib.Path(__file__).resolve().parents[1] / "scripts" / "conjecture.py"

# Short-decimal parameters of one body (exact rationals); c_k = c, s_k = 2c for every body.
BODY = {"m": Fraction("1.3"), "A": Fraction("0.7"), "C": Fraction("0.45"), "c": Fraction("0.4"), "omega": Fraction("3.1")}
MODES = {1: ([Fraction("0.21")], [Fraction("3.5")]), 2: ([Fraction("0.12"), Fraction("0.05")], [Fraction("2.6"), Fraction("-1.7")])}

# The counterexample family of docs/conjecture.md, dyadic so that the engine sees exactly these values.
FAMILY = {"m": 2, "A": 4, "C": 1, "c": 1, "s": 2, "omega": 1, "E": [Fraction(1, 2)], "kappa": [4]}
K_STABLE = 1024


def chain(n, body, E, kappa, A=None):
    """n identical bodies as reference.py wants them."""
    b = dict(body, s=2 * body["c"], E=E, kappa=kappa)
    if A is not None:
        b["A"] = A
    return [dict(b) for _ in range(n)]


def gram(n, m=1, c=1):
    """S = J^T diag(m) J of n identical free bodies, from the reference's lever arms."""
    J = R.lever_arms(chain(n, {"m": m, "A": 1, "C": 1, "c": c, "omega": 1}, [], []), "free")
    return J.T * sympy.diag(*([sympy.Rational(m)] * n)) * J


@pytest.mark.parametrize("n", range(2, 11))
def test_gram_eigenvalues_are_cot_squared(n):
    """nu_j = m c^2 cot^2(j pi / 2n): exact characteristic polynomial, and numerically."""
    x = sympy.Symbol("x")
    S = gram(n)
    closed = x * sum((-1) ** k * math.comb(2 * n, 2 * k + 1) * x ** (n - 1 - k) for k in range(n)) / (2 * n)
    assert sympy.expand(S.charpoly(x).as_expr() - closed) == 0
    numeric = np.sort(np.linalg.eigvalsh(np.array(S.tolist(), dtype=float)))
    cot2 = np.sort([0.0] + [1 / math.tan(j * math.pi / (2 * n)) ** 2 for j in range(1, n)])
    np.testing.assert_allclose(numeric, cot2, rtol=1e-12, atol=1e-12)
    # The paper's F~ convention, (33) and (34): roots (n-1)/n - nu_j / (m c^2).
    if n in (2, 3):
        paper = sorted((n - 1) / n - v for v in cot2)
        np.testing.assert_allclose(paper, [-0.5, 0.5] if n == 2 else [-7 / 3, 1 / 3, 2 / 3], atol=1e-12)


@pytest.mark.parametrize("n", range(2, 11))
def test_ideal_joints_factorisation_exact(n):
    """K = 0: p = sum_k e_k(S) (lam^2 Q)^k p_1^(n-k) = prod_j p_1(A + nu_j), so p_1 divides p."""
    L = 2 if n in (3, 6, 10) else 1  # two modes where the degree stays cheap enough, n = 10 included
    E, kappa = MODES[L]
    p = R.char_poly(chain(n, BODY, E, kappa), "free")
    p1 = R.char_poly(chain(1, BODY, E, kappa), "free")
    assert p.degree() == n * (2 + L) and p1.degree() == 2 + L
    assert p.rem(p1).is_zero

    lam = R.lam
    Q = sympy.Poly(R.liquid_Q(BODY["omega"], kappa), lam)
    S = gram(n, BODY["m"], BODY["c"])
    cp = S.charpoly(sympy.Symbol("x")).all_coeffs()  # [1, -e_1, e_2, ...]
    total = sympy.Poly(0, lam, domain=sympy.QQ)
    for k in range(n + 1):
        total += (-1) ** k * cp[k] * (sympy.Poly(lam**2, lam) * Q) ** k * p1 ** (n - k)
    assert (p - total).is_zero


def test_factorisation_needs_ideal_joints_and_identical_bodies():
    """The same division fails with a joint stiffness or with one body changed (the check can fail)."""
    E, kappa = MODES[1]
    p1 = R.char_poly(chain(1, BODY, E, kappa), "free")
    stiff = R.char_poly(chain(3, BODY, E, kappa), "free", joints=[Fraction("0.5"), Fraction("0.5")])
    assert not stiff.rem(p1).is_zero
    bodies = chain(3, BODY, E, kappa)
    bodies[1]["A"] = Fraction("0.8")
    assert not R.char_poly(bodies, "free").rem(p1).is_zero


def test_ideal_joints_any_masses_and_lengths():
    """The proof needs equal A, C, omega and liquid only: free chains with any m_k, c_k, s_k keep p_1 as a factor."""
    E, kappa = MODES[1]
    same = {k: BODY[k] for k in ("A", "C", "omega")}
    geometry = [("1.3", "0.4", "0.9"), ("0.6", "-0.2", "1.1"), ("2.2", "0.7", "0.5"), ("0.9", "0.3", "0.3")]
    bodies = [dict(same, m=Fraction(m), c=Fraction(c), s=Fraction(s), E=E, kappa=kappa) for m, c, s in geometry]
    p1 = R.char_poly(chain(1, BODY, E, kappa), "free")
    assert R.char_poly(bodies, "free").rem(p1).is_zero
    # On a fixed point J is invertible (c_1 != 0): no zero eigenvalue, no common factor.
    assert not R.char_poly(bodies, "fixed", g=Fraction("9.8")).rem(p1).is_zero


@pytest.mark.parametrize("A, unstable", [("0.9", False), ("1.1", True), ("4.9", True), ("5.1", False)])
def test_family_single_body_band(A, unstable):
    """One mode: the single body is unstable exactly for (C+E-2 sqrt(2EC/kappa))/b < A < (C+E+2 sqrt(2EC/kappa))/b,
    b = 1 - 2/kappa; for the family (C = 1, E = 1/2, kappa = 4) that is 1 < A < 5, whatever m, c, omega."""
    for omega in (Fraction(1), Fraction(37, 3)):
        single = R.char_poly([dict(FAMILY, A=Fraction(A), omega=omega)], "free")
        assert (R.count_complex_pairs(single) == 1) is unstable


@pytest.mark.parametrize("n", [2, 3, 10])
def test_counterexample_exact(n):
    """The family of docs/conjecture.md: single body unstable, chain with K = 1024 stable, K = 0 unstable."""
    single = R.char_poly([dict(FAMILY)], "free")
    assert single.degree() == 3 and R.count_complex_pairs(single) == 1
    count = R.sturm_complex_pairs if n <= 3 else R.arb_complex_pairs
    body = {k: v for k, v in FAMILY.items() if k not in ("E", "kappa")}
    stiff = R.char_poly(chain(n, body, FAMILY["E"], FAMILY["kappa"]), "free", joints=[K_STABLE] * (n - 1))
    ideal = R.char_poly(chain(n, body, FAMILY["E"], FAMILY["kappa"]), "free")
    assert stiff.degree() == 3 * n
    assert count(stiff) == 0
    assert count(ideal) >= 1
    if n <= 3:  # sympy's own root counting agrees where it is quick
        assert R.count_complex_pairs(stiff) == 0


def _family_scene(n):
    body = ("[[bodies]]\nm = 2.0\nA = 4.0\nC = 1.0\nc = 1.0\ns = 2.0\n"
            "fluid = { E = [0.5], kappa = [4.0] }\n")
    return (f'title = "counterexample n = {n}"\nsupport = "free"\nomega = 1.0\n\n' + "\n".join([body] * n)
            + f"\n[grid]\nK = {{ values = [0.0, {float(K_STABLE)}] }}\nomega = {{ values = [1.0, 64.0] }}\n")


@pytest.mark.parametrize("n", [2, 3, 10])
def test_counterexample_engine(n):
    """The engine's certified atlas: stable at K = 1024, omega = 1; unstable at K = 0 and at omega = 64."""
    ds = stabmap.compute_atlas(stabmap.loads_scene(_family_scene(n)))
    nc = ds["n_complex_pairs"].sel(K=float(K_STABLE), omega=1.0).item()
    assert nc == 0
    assert ds["n_complex_pairs"].sel(K=0.0, omega=1.0).item() >= 1
    # k = K / (m c^2 omega^2) = 1024 / (2 * 64^2) = 1/8: soft joints, the conjecture's regime again.
    assert ds["n_complex_pairs"].sel(K=float(K_STABLE), omega=64.0).item() >= 1
    single = stabmap.compute_atlas(stabmap.loads_scene(
        'support = "free"\nomega = 1.0\n[[bodies]]\nm = 2.0\nA = 4.0\nC = 1.0\nc = 1.0\n'
        "fluid = { E = [0.5], kappa = [4.0] }\n[grid]\nomega = { values = [1.0, 64.0] }\n"))
    assert (single["n_complex_pairs"].values == 1).all()


def test_script_exact_builder_matches_reference():
    """The script's engine-independent builder (used for its exact rechecks) is docs/model.md's p."""
    mod = runpy.run_path(str(SCRIPT))
    E, kappa = MODES[2]
    joints = [Fraction("0.3"), Fraction("1.7"), Fraction("0")]
    b = BODY
    ours = mod["chain_poly"](4, b["m"], b["c"], b["A"], b["C"], b["omega"], E, kappa, joints)
    ref = R.char_poly(chain(4, BODY, E, kappa), "free", joints=joints)
    assert [sympy.Rational(int(c.p), int(c.q)) for c in ours.coeffs()] == list(reversed(ref.all_coeffs()))
    single = mod["single_poly"](b["A"], b["C"], b["omega"], E, kappa)
    assert mod["complex_pairs"](single) == R.count_complex_pairs(R.char_poly(chain(1, BODY, E, kappa), "free"))


@pytest.mark.slow
def test_script_quick(capsys):
    out = runpy.run_path(str(SCRIPT))["main"](["--quick"])
    assert [r["n"] for r in out["gram"]] == list(range(2, 11)) and all(r["exact"] for r in out["gram"])
    assert all(r["factorised"] == r["divides"] == r["ge"] == r["trials"] for r in out["factorisation"])
    for r in out["family"]:
        assert (r["single"], r["K"], r["engine"]) == (1, 0, 0) and r["K0"] >= 1
    for n, res in out["search"].items():
        assert (res["nc0"] >= 1).all(), n  # ideal joints: never a counterexample (the theorem)
    text = capsys.readouterr().out
    assert "| n | chains (single unstable) |" in text and "## 5. Exact recheck" in text
