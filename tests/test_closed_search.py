"""Closed chains: ``search`` against independent references (tests/closed_reference.py).

Every equilibrium it reports satisfies the general equations to 1e-12 (the test's own residual at 30 digits),
is a regular root (Newton from perturbed starts returns to it), has the index of the energy probe, and is
distinct from the others modulo rotation, relabelling and reflection; the closed-form families are among them.
"""

from __future__ import annotations

import functools
import math

import closed_reference as ref
import mpmath as mp
import numpy as np
import pytest
from test_closed_families import joint_angles, scaled_residual

from stabmap import closed
from stabmap.errors import StabmapError

# The paper's planar model (the chain confined to its plane): these tests check the planar results;
# tests/test_closed_space.py checks stability in space.
planar_solve = functools.partial(closed.solve, model="planar")
planar_search = functools.partial(closed.search, model="planar")


def same_shape(a, b) -> bool:
    """The test's own equivalence: a cyclic relabelling, the reversed numbering or a mirror image maps b onto a."""
    ha, hb = np.asarray(a.lengths), np.asarray(b.lengths)
    target = joint_angles(a.theta)
    for th, h in ((b.theta, hb), (math.pi + b.theta[::-1], hb[::-1])):
        for sign in (1, -1):
            for m in range(h.size):
                if np.allclose(np.roll(h, m), ha, rtol=1e-12) and np.allclose(
                    np.angle(np.exp(1j * (joint_angles(sign * np.roll(th, m)) - target))), 0, atol=1e-7
                ):
                    return True
    return False


@pytest.fixture(scope="module", params=[[1.0] * 5, [1.0, 2.0, 1.5, 1.2, 0.7], [1.0, 6.0, 1.0, 1.0, 6.0, 1.0], [1.0, 1.0, 1.5, 1.0, 1.0, 1.5]],
                ids=["equal-5", "uneven-5", "figure-eight-6", "hinge-lengths"])
def found(request):
    return request.param, planar_search(request.param, starts=240)


def test_every_found_equilibrium_satisfies_the_general_equations_and_is_distinct(found):
    lengths, eqs = found
    assert eqs, "the search found nothing"
    for i, eq in enumerate(eqs):
        assert eq.exists and eq.shape == "found" and eq.lengths == tuple(lengths)
        assert eq.residual <= 1e-12 and scaled_residual(eq) <= 1e-12
        assert not any(same_shape(eq, other) for other in eqs[:i])
    assert [e.energy for e in eqs] == sorted(e.energy for e in eqs)


def test_every_found_equilibrium_is_a_regular_root_with_the_probes_index(found):
    lengths, eqs = found
    L = [mp.mpf(x) for x in lengths]
    loops = [list(range(len(L)))]
    rng = np.random.default_rng(3)
    # Small kicks: the six-body eight at h2/h1 = 6 sits 0.25 % above its bifurcation (5.986), where an asymmetric
    # equilibrium lies 0.05 rad away from the symmetric one.
    for eq in eqs:
        theta = [mp.mpf(float(t)) for t in eq.theta]
        start = [t + mp.mpf(float(d)) for t, d in zip(theta, rng.normal(0, 1e-4, len(theta)))]
        th, _ = ref.newton(start, [tuple(mp.mpf(float(c)) * mp.mpf("1.03") for c in eq.forces[0])], L, loops)
        assert np.abs(np.angle(np.exp(1j * (joint_angles([float(t) for t in th]) - joint_angles(eq.theta))))).max() < 1e-10
        with mp.workdps(40):
            exact, _ = ref.newton(theta, [tuple(mp.mpf(float(c)) for c in eq.forces[0])], L, loops)
        assert (eq.index, eq.nullity) == ref.inertia(ref.probe(exact, L, loops))


def test_the_closed_form_families_are_found(found):
    lengths, eqs = found
    expected = {
        (1.0, 6.0, 1.0, 1.0, 6.0, 1.0): [("figure-eight-6", 1), ("ring", 1)],
        (1.0, 1.0, 1.5, 1.0, 1.0, 1.5): [("hinge-straight", 1), ("ring", 1)],
        (1.0,) * 5: [("ring", 1), ("ring", 2)],
    }.get(tuple(lengths), [])
    for shape, j in expected:
        eq = planar_solve(shape, lengths, j=j)
        assert any(same_shape(eq, other) and other.energy == pytest.approx(eq.energy, rel=1e-12) for other in eqs), shape


def test_equal_pentagon_has_the_rings_and_one_figure_eight():
    eqs = planar_search([1.0] * 5)
    by_turns = sorted((abs(e.rotation_index), e.index, e.stability) for e in eqs)
    assert by_turns == [(0, 1, "unstable"), (1, 0, "stable"), (2, 2, "unstable")]


def test_search_is_repeatable_and_checks_its_input():
    a = planar_search([1.0, 0.5, 1.0, 0.5], seed=4)
    b = planar_search([1.0, 0.5, 1.0, 0.5], seed=4)
    assert [(e.energy, tuple(e.theta)) for e in a] == [(e.energy, tuple(e.theta)) for e in b]
    assert planar_search([1.0] * 4) == []  # four equal bodies: rhombi and folds only, nothing isolated
    with pytest.raises(StabmapError, match="cannot close"):
        planar_search([1.0, 1.0, 3.0])
    with pytest.raises(StabmapError, match=r"lengths\[2\] must be > 0"):
        planar_search([1.0, 0.0, 1.0])


@pytest.mark.slow
def test_more_starts_find_no_fewer_shapes_and_the_same_ones():
    lengths = [1.0, 1.3, 0.8, 1.1, 0.9, 1.2, 1.0]
    few, many = planar_search(lengths, starts=150), planar_search(lengths, starts=1500, seed=1)
    assert len(many) >= len(few)
    for eq in few:
        assert any(same_shape(eq, other) for other in many)
    for eq in many:
        assert scaled_residual(eq) <= 1e-12
