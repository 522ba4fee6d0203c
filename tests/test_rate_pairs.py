"""Growth rates from the non-real roots only (kernels/rates.py, docs/rates.md) against independent references.

- the Newton disk d |q(z)| / |q'(z)| (Henrici 1974, section 6.4) holds a root of q: checked against mpmath's roots
  at 60 digits of the same float polynomial, from polished and from deliberately poor approximations;
- growth rates of chains with liquid and of identical bodies (repeated real roots) against the roots of the exact
  rational polynomial (FLINT/Arb through ``rates.exact_roots``, and mpmath), proved by the pairs' disks, not by
  exact arithmetic;
- the warm start (a neighbour's pairs) changes no stored value: the same points in any order give the same
  float32 rates and bounds.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
from test_rates import CHAINS

from stabmap.kernels import rates as kernel_rates
from stabmap.systems import loads_scene, of
from stabmap.systems.gyroscopes import rates
from stabmap.systems.gyroscopes.points import point_arrays

mpmath.mp.dps = 60

CHAIN = CHAINS[3].replace("frequencies = true\n", "")  # three tops with liquid, growth rate only

# Identical bodies on equal elastic joints: the liquid roots of the three cavities coincide to about 1e-6 (relative),
# the real roots cluster, the pairs stay simple.
IDENTICAL = """
title = "three identical tops with liquid, equal joints"
g = 9.81
joints = [120.0, 120.0]
""" + """
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25
fluid = { E = [1e-4, 2e-5], kappa = [1.31, 2.7] }
""" * 3 + """
[grid]
omega = { start = 1.0, stop = 200.0, num = 3 }
K_1 = { start = 20.0, stop = 200.0, num = 3 }
"""


def exact_rate(points, p: int, D: int) -> tuple[float, float]:
    """(lower, upper) of max |Im lambda| from FLINT/Arb on the exact rational polynomial."""
    _, _, _, rate = rates.exact_roots(points, p, D)
    return rate[1], rate[2]


def _poly_from_roots(roots) -> np.ndarray:
    """Float coefficients (ascending) of prod (x - r), as an exact interval polynomial (radius 0) in the kernel's form."""
    coeffs = np.real(np.poly(roots))[::-1].copy()
    X = np.zeros((coeffs.size, 3))
    X[:, 0] = coeffs
    return X


@pytest.mark.parametrize("seed", range(6))
def test_a_newton_disk_holds_a_root_of_the_polynomial(seed):
    rng = np.random.default_rng(seed)
    pairs = rng.uniform(-2, 2, 3) + 1j * rng.uniform(0.05, 1.5, 3)
    real = rng.uniform(-2, 2, 4)
    X = _poly_from_roots(np.concatenate([pairs, pairs.conj(), real]))
    d = X.shape[0] - 1
    exact = mpmath.polyroots([mpmath.mpf(float(x)) for x in X[::-1, 0]], maxsteps=500, extraprec=500)
    for z0 in pairs:
        for z in (z0, z0 * (1 + 1e-3), z0 + 0.05j, z0 * (1 + 1e-12)):
            r = kernel_rates.newton_radius(X, d, complex(z))
            assert np.isfinite(r)
            gap = min(abs(mpmath.mpc(z) - w) for w in exact)
            assert gap <= r, (seed, z, float(gap), r)
            if abs(z - z0) < 1e-9 * abs(z0):
                assert r < 1e-8 * abs(z0)  # from a good approximation the disk is small


def test_a_newton_radius_is_infinite_where_the_derivative_may_vanish():
    X = _poly_from_roots(np.array([1.0 + 1j, 1.0 - 1j, 1.0 + 1j, 1.0 - 1j]))  # a double pair: p'(1 + i) = 0
    assert kernel_rates.newton_radius(X, 4, 1.0 + 1.0j) == np.inf


def _rates_at(text: str, **axes):
    scene = loads_scene(text)
    values = {k: np.asarray(v, dtype=np.float64) for k, v in axes.items()}
    out = of(scene).evaluate(scene, values)
    return scene, point_arrays(scene, values), out


@pytest.mark.parametrize("text, axes", [
    (CHAIN, {"omega": np.linspace(0.5, 120.0, 40)}),
    (IDENTICAL, {"omega": np.repeat(np.linspace(1.0, 200.0, 20), 2), "K_1": np.tile([30.0, 150.0], 20)}),
])
def test_growth_rates_from_the_pairs_hold_the_exact_rate(text, axes):
    scene, points, out = _rates_at(text, **axes)
    unstable = np.flatnonzero(out["n_complex_pairs"] > 0)
    assert unstable.size >= 5
    method = out["growth_rate_method"][unstable]
    assert np.all(method == rates.PAIRS), np.unique(method, return_counts=True)  # never exact arithmetic here
    for p in unstable:
        lo, hi = exact_rate(points, p, scene.degree)
        got_lo, got_hi = float(out["growth_rate_lower"][p]), float(out["growth_rate_upper"][p])
        assert got_lo <= lo and hi <= got_hi, (p, got_lo, lo, hi, got_hi)
        assert got_hi - got_lo <= 1e-6 * got_hi
        assert got_lo <= out["growth_rate"][p] <= got_hi


def test_identical_bodies_repeat_their_real_roots_but_not_their_pairs():
    """The reference the test above relies on: the identical chain's real roots nearly coincide."""
    scene, points, out = _rates_at(IDENTICAL, omega=np.linspace(1.0, 200.0, 20), K_1=np.full(20, 150.0))
    p = int(np.flatnonzero(out["n_complex_pairs"] > 0)[0])
    z, _, _, _ = rates.exact_roots(points, p, scene.degree)
    real = np.sort(z.real[np.abs(z.imag) == 0])
    assert np.min(np.diff(real) / np.abs(real[1:])) < 1e-4


def test_the_order_of_the_points_changes_no_stored_rate():
    scene = loads_scene(CHAIN)
    omega = np.linspace(0.5, 120.0, 60)
    points = point_arrays(scene, {"omega": omega})
    nc = of(scene).evaluate(scene, {"omega": omega})["n_complex_pairs"]
    at = np.flatnonzero(nc > 0)
    shuffled = np.random.default_rng(1).permutation(at)
    a = rates.growth_only(points, at, nc[at], scene.degree)
    b = rates.growth_only(points, shuffled, nc[shuffled], scene.degree)
    back = np.argsort(shuffled)[np.searchsorted(np.sort(shuffled), at)]
    for x, y in zip(a, b, strict=True):
        if x.dtype.kind == "f":
            np.testing.assert_array_equal(x.astype(np.float32), y[back].astype(np.float32))
        else:
            np.testing.assert_array_equal(x, y[back])


TOP4 = """
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25
fluid = { E = [1e-4, 5e-5, 2e-5, 1e-5], kappa = [1.31, 2.7, 4.8, 8.1] }
"""
SIX = 'g = 9.81\njoints = [120.0, 120.0, 120.0, 120.0, 120.0]\n' + TOP4 * 6 + '[grid]\nomega = { start = 1.0, stop = 200.0, num = 3 }\n'


def test_a_pair_beside_a_cluster_is_proved_by_phi_where_the_coefficients_cannot():
    """Six identical bodies, four modes each (degree 36): a pair beside the cluster of the six nutation roots.

    The coefficient enclosure, amplified by Horner's cancellation next to the cluster, gives that pair a disk as wide
    as half its distance to the axis; the disk from Phi(z) proves it to 1e-7.  The points are chosen by that test,
    made here against the exact roots, so the case is exercised whatever the grid.
    """
    scene = loads_scene(SIX)
    assert scene.degree == 36
    omega = np.linspace(1.0, 200.0, 40)
    values = {"omega": omega, "K_1": np.full(omega.size, 20.0)}
    out = of(scene).evaluate(scene, values)
    points = point_arrays(scene, values)
    coefficients = np.empty((omega.size, 37, 3))
    from stabmap.kernels import charpoly_block
    from stabmap.systems.gyroscopes.decide import kernel_args

    charpoly_block(*kernel_args(points), coefficients)
    beside = []
    for p in np.flatnonzero(out["n_complex_pairs"] > 0):
        z, _, kind, rate = rates.exact_roots(points, p, scene.degree)
        c = coefficients[p]
        top = int(np.max(np.flatnonzero(c[:, 0] != 0)))
        X = c[: top + 1].copy()
        pairs = z[(kind == 1) & (z.imag > 0)]
        wide = [kernel_rates.newton_radius(X, top, complex(w)) > kernel_rates.NARROW * w.imag for w in pairs]
        if any(wide):
            beside.append(p)
        got_lo, got_hi = float(out["growth_rate_lower"][p]), float(out["growth_rate_upper"][p])
        assert got_lo <= rate[1] and rate[2] <= got_hi and got_hi - got_lo <= 1e-6 * got_hi, p
    assert beside, "no pair beside the cluster on this line: the test no longer exercises the disks from Phi"
    # where Phi's disk is narrow enough the pair is proved without exact arithmetic (on this line: 4 of 5 points; the
    # fifth pair lies closer to the cluster than Phi's disk at its shifts, and goes to FLINT/Arb, enclosed as above)
    assert np.any(out["growth_rate_method"][beside] == rates.PAIRS), (beside, out["growth_rate_method"][beside])
