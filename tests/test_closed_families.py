"""Closed chains: the families' equilibria against independent references (tests/closed_reference.py).

Closed forms at 40 digits (mpmath) and exactly (sympy), Newton on the general equations from perturbed starts,
and the energy probe on the closed configurations for every index and nullity; the degenerate cases; points
1e-7 (relative) either side of every existence and stability boundary; critical values to 1e-10.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import closed_reference as ref
import mpmath as mp
import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import stabmap
from stabmap import closed
from stabmap.errors import StabmapError

# The paper's planar model (the chain confined to its plane): these tests check the planar results;
# tests/test_closed_space.py checks stability in space.
planar_solve = functools.partial(closed.solve, model="planar")
planar_search = functools.partial(closed.search, model="planar")

FAMILY_N = {"figure-eight-4": 4, "figure-eight-6": 6, "hinge": 6, "hinge-straight": 6}
# Ratios h2/h1 at which each family exists, spread over its range (both sides of the stability boundaries).
INSIDE = {
    "figure-eight-4": (0.05, 0.3, 0.7, 0.99),
    "figure-eight-6": (4.9, 5.5, 6.0, 7.0, 15.0, 80.0),
    "hinge": (0.1, 0.8, 1.3, 1.5, 1.99),
    "hinge-straight": (0.1, 1.0, 1.9),
}


def scaled_residual(eq) -> float:
    """The test's own residual of the general equations at the code's float solution, scaled as documented:
    each torque equation by 2 + a_k |R|, each closure by its length sum (evaluated at 30 digits)."""
    with mp.workdps(30):
        theta = [mp.mpf(float(t)) for t in eq.theta]
        L = [mp.mpf(x) for x in eq.lengths]
        n = len(theta)
        loops = [[k - 1 for k in loop] for loop in eq.loops]
        loop_of = {k: i for i, loop in enumerate(loops) for k in loop}
        worst = mp.mpf(0)
        for k in range(n):
            Ry, Rz = (mp.mpf(float(f)) for f in eq.forces[loop_of[k]])
            a = L[k] * mp.mpf(eq.h) / mp.mpf(eq.c1sq)
            r = mp.sin(theta[(k + 1) % n] - theta[k]) - mp.sin(theta[k] - theta[k - 1]) - a * (Rz * mp.sin(theta[k]) + Ry * mp.cos(theta[k]))
            worst = max(worst, abs(r) / (2 + a * mp.sqrt(Ry**2 + Rz**2)))
        for loop in loops:
            gap = mp.sqrt(mp.fsum(L[k] * mp.sin(theta[k]) for k in loop) ** 2 + mp.fsum(L[k] * mp.cos(theta[k]) for k in loop) ** 2)
            worst = max(worst, gap / mp.fsum(L[k] for k in loop))
        return float(worst)


def probe_inertia(family, ratio, n=None, j=1):
    L = ref.lengths_of(family, ratio, n)
    theta, _ = ref.closed_form(family, L, j=j)
    return ref.inertia(ref.probe(theta, L, ref.loops_of(family, len(L))))


def joint_angles(theta) -> np.ndarray:
    d = np.asarray(theta, dtype=float) - np.roll(np.asarray(theta, dtype=float), 1)
    return np.angle(np.exp(1j * d))


# ------------------------------------------------------------------------------------------------ closed forms
@pytest.mark.parametrize("family", list(INSIDE))
def test_the_closed_forms_of_closed_md_solve_the_general_equations_at_40_digits(family):
    for r in INSIDE[family]:
        L = ref.lengths_of(family, r)
        theta, forces = ref.closed_form(family, L, c1sq=mp.mpf("2.5"), h=mp.mpf("0.7"))
        assert ref.residual(theta, L, forces, ref.loops_of(family, len(L)), c1sq=mp.mpf("2.5"), h=mp.mpf("0.7")) < mp.mpf(10) ** -35


def test_exact_closed_forms_with_sympy():
    r = sp.symbols("r", positive=True)
    c, s = sp.sqrt(1 - r**2), r  # figure-eight-4: sin t = h2/h1 = r, h1 = 1, c1^2 = h = 1
    th = [(-s, c), (1, 0), (-s, -c), (1, 0)]  # (sin, cos) of -t, pi/2, pi + t, pi/2
    L = [1, r, 1, r]
    Ry = 2  # 2/a_1
    for k in range(4):
        sn, cn = th[(k + 1) % 4], th[k - 1]
        sin_next = sn[0] * th[k][1] - sn[1] * th[k][0]  # sin(theta_{k+1} - theta_k)
        sin_prev = th[k][0] * cn[1] - th[k][1] * cn[0]
        assert sp.simplify(sin_next - sin_prev - L[k] * Ry * th[k][1]) == 0
    assert sp.simplify(sum(L[k] * th[k][0] for k in range(4))) == 0
    # figure-eight-6 exists up to a = h1/h2 where p = 1 - 2a + sqrt(1 - 4a) reaches 1: a = (sqrt 2 - 1)/2.
    a = sp.symbols("a", positive=True)
    (root,) = sp.solve(sp.Eq(1 - 2 * a + sp.sqrt(1 - 4 * a), 1), a)
    assert sp.simplify(root - (sp.sqrt(2) - 1) / 2) == 0
    # p is the larger root of (41), p^2 + 2p(2a - 1) + 4a^2 = 0 (docs/closed.md), real up to a = 1/4.
    p = 1 - 2 * a + sp.sqrt(1 - 4 * a)
    assert sp.simplify(sp.expand(p**2 + 2 * p * (2 * a - 1) + 4 * a**2)) == 0
    # the ring closes for alternating lengths and even n: sum of h_k w^k = 0 for w = exp(2 pi i j / n), j < n/2
    for n, j in ((4, 1), (6, 1), (6, 2), (8, 3)):
        w = sp.exp(2 * sp.pi * sp.I * j / n)
        assert sp.simplify(sp.expand(sum((1 if k % 2 == 0 else r) * w ** (k + 1) for k in range(n)), complex=True)) == 0


@pytest.mark.parametrize("family", list(INSIDE))
def test_solve_matches_the_closed_forms_and_satisfies_the_equations_to_1e_12(family):
    for r in INSIDE[family]:
        L = [float(x) for x in ref.lengths_of(family, r)]
        eq = planar_solve(family, L, c1sq=3.0, h=0.8)
        theta, forces = ref.closed_form(family, L, c1sq=3, h=mp.mpf("0.8"))
        assert eq.exists and eq.theta.shape == (len(L),)
        np.testing.assert_allclose(eq.theta, [float(x) for x in theta], rtol=0, atol=1e-12)
        np.testing.assert_allclose(eq.forces, [[float(f) for f in F] for F in forces], rtol=1e-12, atol=1e-12)
        assert eq.energy == pytest.approx(float(ref.energy(theta, 3, mp.mpf("0.8"))), rel=1e-12)
        assert eq.residual <= 1e-12 and scaled_residual(eq) <= 1e-12


@settings(max_examples=60, deadline=None)
@given(family=st.sampled_from(list(INSIDE)), r=st.floats(0.01, 30.0), h1=st.floats(0.01, 100.0), c1sq=st.floats(1e-3, 1e3))
def test_every_reported_equilibrium_satisfies_the_general_equations(family, r, h1, c1sq):
    L = [float(x) for x in ref.lengths_of(family, r, h1=h1)]
    eq = planar_solve(family, L, c1sq=c1sq)
    # docs/closed.md's ranges are open; at the closing end the family folds onto a line and is reported (degenerate).
    end = {"figure-eight-4": L[1] == L[0], "hinge": L[2] == 2 * L[0], "hinge-straight": L[2] == 2 * L[0]}.get(family, False)
    assert eq.exists == (ref.closed_form(family, L) is not None or end)
    assert not end or eq.stability == "degenerate"
    if eq.exists:
        assert scaled_residual(eq) <= 1e-12
    else:
        assert np.isnan(eq.theta).all() and eq.index == eq.nullity == -1 and eq.stability == "absent"


@pytest.mark.parametrize("family,r", [("figure-eight-4", 0.6), ("figure-eight-6", 5.5), ("figure-eight-6", 9.0), ("hinge", 0.7), ("hinge", 1.7), ("hinge-straight", 1.2)])
def test_newton_on_the_general_equations_from_perturbed_starts_returns_to_the_closed_form(family, r):
    L = ref.lengths_of(family, r)
    loops = ref.loops_of(family, len(L))
    theta, forces = ref.closed_form(family, L)
    rng = np.random.default_rng(7)
    eq = planar_solve(family, [float(x) for x in L])
    for _ in range(3):
        start = [x + mp.mpf(float(d)) for x, d in zip(theta, rng.normal(0, 0.02, len(theta)))]
        kick = [(f[0] * mp.mpf(1.05), f[1] + mp.mpf(0.02)) for f in forces]
        th, F = ref.newton(start, kick, L, loops)
        assert ref.residual(th, L, F, loops) < mp.mpf(10) ** -28
        np.testing.assert_allclose(joint_angles([float(x) for x in th]), joint_angles(eq.theta), atol=1e-12)
        # Newton's shape is turned by phi (theta_1 was perturbed and held): its force turns with it.
        phi = float(th[0]) - eq.theta[0]
        turn = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
        np.testing.assert_allclose([turn.T @ [float(c) for c in f] for f in F], eq.forces, atol=1e-12)


# ---------------------------------------------------------------------------------------------------- inertia
@pytest.mark.parametrize("family", list(INSIDE))
def test_index_and_nullity_match_the_energy_probe_on_the_closed_shapes(family):
    for r in INSIDE[family]:
        eq = planar_solve(family, [float(x) for x in ref.lengths_of(family, r)], h=1.0)
        assert (eq.index, eq.nullity) == probe_inertia(family, r), (family, r)
        assert eq.stability == ("stable" if eq.index == 0 else "unstable")
        # Both reduce on orthonormal bases of the same space (tangent to the closures, orthogonal to the
        # rotation), so the spectra agree too; with c1^2 = h = 1 the units agree as well.
        L = ref.lengths_of(family, r)
        Q = ref.probe(ref.closed_form(family, L)[0], L, ref.loops_of(family, len(L)))
        np.testing.assert_allclose(np.sort(eq.eigenvalues), sorted(float(e) for e in mp.eigsy(Q, eigvals_only=True)), atol=1e-9)


@pytest.mark.parametrize("n,j,r", [(5, 1, 1), (5, 2, 1), (6, 1, 0.4), (6, 2, 2.5), (7, 1, 1), (7, 3, 1), (8, 1, 0.5), (8, 3, 1.7), (9, 2, 1), (10, 3, 1.3)])
def test_rings_match_the_probe_and_the_rule_cos_2_pi_j_over_n(n, j, r):
    L = [float(x) for x in ref.lengths_of("ring", r, n)]
    eq = planar_solve("ring", L, j=j)
    assert eq.exists and eq.rotation_index == j and np.allclose(eq.forces, 0)
    assert (eq.index, eq.nullity) == probe_inertia("ring", r, n, j)
    assert eq.stable == (math.cos(2 * math.pi * j / n) > 0)
    assert scaled_residual(eq) <= 1e-12


def test_degenerate_rings_n_4_and_n_8_j_2_are_families_of_equal_energy():
    for n, j, r, null in ((4, 1, 1.0, 1), (4, 1, 0.3, 1), (8, 2, 1.0, 5), (8, 2, 2.0, 5)):
        eq = planar_solve("ring", [float(x) for x in ref.lengths_of("ring", r, n)], j=j)
        assert (eq.index, eq.nullity, eq.stability) == (0, null, "degenerate")
        assert probe_inertia("ring", r, n, j) == (0, null)  # U is constant along the rhombi (and their like)
    tri = planar_solve("ring", [2.0, 2.0, 2.0])  # three bodies: rigid, nothing to move
    assert (tri.index, tri.nullity, tri.stability, tri.eigenvalues.size) == (0, 0, "stable", 0)


@pytest.mark.parametrize("family,r", [("figure-eight-4", 1.0), ("hinge", 2.0), ("hinge-straight", 2.0)])
def test_folded_end_points_exist_and_are_degenerate(family, r):
    """At the end of its range a family folds onto a line: an equilibrium, but the closures lose rank there."""
    eq = planar_solve(family, [float(x) for x in ref.lengths_of(family, r)])
    assert eq.exists and eq.stability == "degenerate" and eq.nullity >= 1 and eq.rotation_index is None
    assert eq.residual <= 1e-12 and scaled_residual(eq) <= 1e-12
    axes = np.stack([-np.sin(eq.theta), np.cos(eq.theta)], axis=-1)
    assert np.abs(axes[:, 0] * axes[0, 1] - axes[:, 1] * axes[0, 0]).max() < 1e-12  # every axis on one line
    # ... which is the limit of the family from inside its range:
    inside = planar_solve(family, [float(x) for x in ref.lengths_of(family, r * (1 - 1e-12))])
    assert np.abs(np.angle(np.exp(1j * (joint_angles(inside.theta) - joint_angles(eq.theta))))).max() < 1e-5


# ---------------------------------------------------------------------------------------------------- boundaries
def _stability_boundary(family, guess):
    """The ratio where the probe's smallest eigenvalue (its determinant) crosses zero, to ~20 digits."""

    def det(r):
        L = ref.lengths_of(family, r)
        theta, _ = ref.closed_form(family, L)
        return mp.det(ref.probe(theta, L, ref.loops_of(family, len(L))))

    return mp.findroot(det, mp.mpf(guess))


BOUNDARIES = {
    # (family, boundary, class just below, class just above)
    "figure-eight-4 exists": ("figure-eight-4", lambda: mp.mpf(1), "unstable", "absent"),
    "figure-eight-6 exists": ("figure-eight-6", lambda: 2 / (mp.sqrt(2) - 1), "absent", "unstable"),
    "figure-eight-6 stable": ("figure-eight-6", lambda: _stability_boundary("figure-eight-6", "5.98"), "unstable", "stable"),
    "hinge stable": ("hinge", lambda: _stability_boundary("hinge", "1.41"), "stable", "unstable"),
    "hinge exists": ("hinge", lambda: mp.mpf(2), "unstable", "absent"),
    "hinge-straight exists": ("hinge-straight", lambda: mp.mpf(2), "unstable", "absent"),
}


@pytest.mark.parametrize("name", list(BOUNDARIES))
def test_points_1e_7_either_side_of_every_boundary(name):
    family, where, below, above = BOUNDARIES[name]
    b = where()
    for side, expected in ((-1, below), (1, above)):
        r = b * (1 + side * mp.mpf("1e-7"))
        eq = planar_solve(family, [float(x) for x in ref.lengths_of(family, r)])
        assert eq.stability == expected, (name, side)
        if eq.exists:
            assert (eq.index, eq.nullity) == probe_inertia(family, r)
            assert scaled_residual(eq) <= 1e-12
        else:
            assert ref.closed_form(family, ref.lengths_of(family, r)) is None


def test_the_boundaries_docs_closed_md_quotes_are_the_references():
    text = (Path(__file__).resolve().parents[1] / "docs" / "closed.md").read_text(encoding="utf-8")
    assert abs(_stability_boundary("hinge", "1.4") - mp.sqrt(2)) < mp.mpf(10) ** -18 and "stable below ratio √2" in text
    assert f"{float(_stability_boundary('figure-eight-6', '6')):.15g}" in text
    assert f"{float(2 / (mp.sqrt(2) - 1)):.10g}" in text


def test_odd_rings_with_unequal_lengths_do_not_close():
    for r, exists in ((1 - 1e-7, False), (1.0, True), (1 + 1e-7, False)):
        eq = planar_solve("ring", [1.0, r, 1.0, r, 1.0])
        assert eq.exists == exists and eq.stability == ("stable" if exists else "absent")


@pytest.mark.parametrize("name,family,guess,lo,hi", [
    ("figure-eight-6", "figure-eight-6", None, 3.0, 12.0),
    ("hinge", "hinge", None, 0.2, 2.6),
])
def test_critical_locates_existence_and_stability_boundaries_to_1e_10(name, family, guess, lo, hi):
    scene = stabmap.loads_scene(
        f'system = "closed"\nmodel = "planar"\nfamily = "{family}"\n[grid]\nratio = {{ start = {lo}, stop = {hi}, num = 25 }}\n'
    )
    ds = stabmap.critical(scene, "ratio", threads=1, progress=False)
    lower, upper = ds["boundary_lower"].values, ds["boundary_upper"].values
    ok = np.isfinite(lower)
    lower, upper = lower[ok], upper[ok]
    expected = [float(BOUNDARIES[k][1]()) for k in BOUNDARIES if BOUNDARIES[k][0] == family]
    assert len(expected) == 2
    for b in expected:
        # The brackets at one boundary: one (two if a point on it were degenerate or undecided).  Together they
        # hold the reference value and span at most 1e-10 of it.
        near = np.abs(lower - b) < 1e-6 * b
        assert near.any(), (b, lower, upper)
        lo, hi = lower[near].min(), upper[near].max()
        assert lo <= b <= hi and hi - lo <= 1e-10 * b, (b, lo, hi)
    # ... and nothing else changes along the scan
    assert (np.abs(lower[:, None] - np.array(expected)) < 1e-6 * np.array(expected)).any(axis=1).all()
    assert "is proved" in ds.attrs["comment"] and "proved" in ds["ratio_stable_lower"].attrs["comment"]
    assert "undecided: 0" in ds.attrs["critical_decided_by"]


# ---------------------------------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("args,kw,message", [
    (("figure-eight-4", [1, 0.5, 1]), {}, "even number of bodies"),
    (("figure-eight-6", [1, 6, 1, 1, 6]), {}, "even number of bodies"),
    (("ring", [1, -1, 1, 1]), {}, r"lengths\[2\] must be > 0"),
    (("ring", [1, 1, 3.5]), {}, "cannot close"),
    (("ring", [1, 1, 1, 1, 1]), {"j": 3}, r"j = 3 is out of range .* j <= 2"),
    (("ring", [1, 1, 1, 1]), {"j": 0}, "j must be >= 1"),
    (("hinge", [1, 1, 1, 1, 1, 1]), {"j": 2}, "applies to shape = 'ring' only"),
    (("figure-eight-4", [1, 0.5, 1, 0.6]), {}, r"does not follow the pattern \(h1, h2, h1, h2\) of family 'figure-eight-4'"),
    (("eight", [1, 1, 1, 1]), {}, "not a closed-chain family"),
    (("ring", [1, 1, 1, 1]), {"c1sq": 0}, "c1sq must be > 0"),
])
def test_bad_input_is_one_clear_error(args, kw, message):
    with pytest.raises(StabmapError, match=message):
        planar_solve(*args, **kw)
