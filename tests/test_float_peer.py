"""The float peer (scripts/float_peer.py) builds stabmap's polynomial and, away from boundaries, its labels."""

from __future__ import annotations

import pathlib
import sys

import numpy as np
import pytest

import stabmap
from stabmap import kernels
from stabmap.scene.grid import resample
from stabmap.systems.gyroscopes.points import PointArrays

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "scripts"))

from float_peer import float_atlas, float_charpoly, float_count  # noqa: E402

CASES = [  # (free, parent, nmodes): chains of 1..3 bodies with 0..2 modes each, and a tree
    (False, [-1], [0]),
    (True, [-1], [2]),
    (False, [-1, 0], [1, 2]),
    (True, [-1, 0], [2, 0]),
    (False, [-1, 0, 1], [2, 2, 2]),
    (True, [-1, 0, 1], [0, 1, 2]),
    (False, [-1, 0, 0], [1, 0, 2]),
    (True, [-1, 0, 0], [2, 1, 1]),
]


def random_points(rng, free: bool, parent: list[int], nmodes: list[int], npts: int = 200) -> PointArrays:
    """Random physical points: positive masses and inertias, lengths and spins of either sign, liquid with |kappa| > 1."""
    n = len(parent)
    body = np.empty((npts, n, 6))
    body[..., 0] = rng.uniform(0.2, 5.0, (npts, n))
    body[..., 1] = rng.uniform(0.01, 0.5, (npts, n))
    body[..., 2] = rng.uniform(0.0, 0.5, (npts, n))
    body[..., 3] = rng.uniform(-0.5, 1.0, (npts, n))
    body[..., 4] = rng.uniform(0.1, 1.0, (npts, n))
    body[..., 5] = rng.choice([-1.0, 1.0], (npts, n)) * rng.uniform(0.5, 100.0, (npts, n))
    joint = rng.uniform(0.0, 50.0, (npts, n)) * (rng.random((npts, n)) < 0.7)
    lmax = max(1, max(nmodes))
    E = rng.uniform(0.001, 0.05, (npts, n, lmax))
    kappa = rng.choice([-1.0, 1.0], (npts, n, lmax)) * rng.uniform(1.1, 6.0, (npts, n, lmax))
    at = rng.uniform(-0.5, 1.0, (npts, n))
    at[:, 0] = 0.0
    g = rng.uniform(-10.0, 10.0, npts)
    return PointArrays(body, joint, g, E, kappa, np.array(nmodes, np.int64), free, np.array(parent, np.int64), at)


@pytest.mark.parametrize("free, parent, nmodes", CASES)
def test_coefficients_equal_stabmap_midpoints(free, parent, nmodes):
    rng = np.random.default_rng(sum(nmodes) + 10 * len(parent) + 100 * free)
    pts = random_points(rng, free, parent, nmodes)
    degree = int((pts.nmodes + 2).sum())
    ref = np.empty((pts.body.shape[0], degree + 1, 3))
    kernels.charpoly_block(*pts.kernel_args(), ref)
    mid = ref[..., 0] + ref[..., 1]
    peer = float_charpoly(pts)
    # Exact zeros (a free system's rigid tilt) are exact in both; every other coefficient to 1e-9 relative.
    np.testing.assert_array_equal(peer == 0.0, mid == 0.0)
    np.testing.assert_allclose(peer, mid, rtol=1e-9, atol=0.0)


def test_labels_equal_proved_atlas_on_a_small_grid():
    scene = stabmap.example("paper-n2-fixed")
    scene = resample(scene, **{a.name: 40 for a in scene.grid})
    proved = stabmap.compute_atlas(scene, progress=False)["n_complex_pairs"].values
    peer = float_atlas(scene)
    assert peer.shape == proved.shape == scene.shape
    differ = int((peer != proved).sum())
    print(f"paper-n2-fixed 40 x 40: the peer differs from the proved labels at {differ} of {peer.size} points")
    assert differ <= 0.01 * peer.size


def test_atlas_blocks_cover_the_grid_in_order(monkeypatch):
    """Rows split across several point_arrays blocks give the labels of one call over all points."""
    import float_peer

    scene = stabmap.example("tree-two-rotors-free")
    scene = resample(scene, **{a.name: 12 for a in scene.grid})
    whole = float_atlas(scene)
    monkeypatch.setattr(float_peer, "BLOCK_POINTS", 1)
    assert np.array_equal(float_atlas(scene), whole)


def test_sturm_on_known_polynomials():
    """Counts of a few polynomials whose roots are known, through the same kernel path (one body, no liquid)."""
    # One fixed top without liquid: p = A' lambda^2 + C omega lambda + m c g (docs/model.md, Maievskii).
    body = np.array([[[1.0, 0.5, 0.3, 0.0, 0.0, w]] for w in (0.0, 1.0, 10.0)])
    npts = body.shape[0]
    pts = PointArrays(body, np.zeros((npts, 1)), np.array([9.81, 9.81, 9.81]), np.zeros((npts, 1, 1)), np.ones((npts, 1, 1)),
                      np.array([0], np.int64), False)
    body[:, 0, 3] = 0.1  # m c g = 0.981, A' = 0.51: unstable until C omega >= 2 sqrt(0.51 * 0.981), about 1.41
    assert list(float_count(pts)) == [1, 1, 0]
    pts.g[:] = 0.0  # p = lambda (A' lambda + C omega): real roots, one an exact zero; omega = 0: a double root at 0
    assert list(float_count(pts)) == [0, 0, 0]


def test_sturm_is_bench_accuracys_float_sturm():
    """The same roundings as the accuracy table's "float Sturm, no tolerance": one method, even where it is wrong.

    paper-n3-fixed at low spin has near-triple root clusters (three identical cavities), where a float
    Sturm count depends on every rounding of the remainders.
    """
    from bench_accuracy import float_sturm
    from stabmap.systems.gyroscopes.points import point_arrays

    scene = stabmap.example("paper-n3-fixed")
    scene = resample(scene, **{a.name: 30 for a in scene.grid})
    omega, m2 = scene.grid[0].array, scene.grid[1].array
    pts = point_arrays(scene, {"omega": omega[:, None], "m_2": m2[None, :]})
    assert np.array_equal(float_count(pts), float_sturm(float_charpoly(pts), 0.0))
