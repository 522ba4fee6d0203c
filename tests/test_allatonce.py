"""The all-at-once certificate (docs/certification.md, section 4b) against exact arithmetic.

``kernels.allatonce_block`` runs that certificate alone (no other proof behind it), so every label it gives is
its own; each is compared with the exact N_c of python-flint (``exact.char_poly``: rational determinants and
Arb root isolation), an independent path.  Lines of omega in grid order exercise the refinement from a
neighbour's decomposition as well as cold starts.
"""

from __future__ import annotations

import numpy as np
import pytest

from stabmap import kernels
from stabmap.kernels import certify
from stabmap.systems.gyroscopes.points import PointArrays

from test_certify import (OFFSETS, _bisect_boundary, _with_omega, chain_with_boundary, exact_nc, make_points,
                          random_chain, run_decide, seed_of)


def run_allatonce(pts: PointArrays):
    """(N_c, status, cold starts) of ``allatonce_block`` on the points in order."""
    npts = pts.body.shape[0]
    nc = np.empty(npts, np.int16)
    st = np.empty(npts, np.int8)
    cold = kernels.allatonce_block(*pts.kernel_args(), nc, st)
    assert set(st.tolist()) <= {kernels.DECIDED_ALLATONCE, kernels.UNDECIDED}
    return nc, st, int(cold)


def check_line(pts: PointArrays, sample=None):
    """Every label the certificate gives equals the exact one (on ``sample`` of the points, all by default);
    returns the share of points it decided and its cold starts."""
    nc, st, cold = run_allatonce(pts)
    idx = range(pts.body.shape[0]) if sample is None else sample
    wrong = [(p, float(pts.body[p, 0, 5]), int(nc[p]), exact_nc(pts, p)) for p in idx
             if st[p] == kernels.DECIDED_ALLATONCE and nc[p] != exact_nc(pts, p)]
    assert not wrong, f"wrong labels (point, omega, N_c, exact): {wrong}"
    return float(np.mean(st == kernels.DECIDED_ALLATONCE)), cold


@pytest.mark.parametrize("n,modes", [(2, 0), (2, 3), (3, 1), (4, 2), (6, 0), (6, 4), (8, 1)])
@pytest.mark.parametrize("kind", ["mixed", "identical"])
def test_fixed_lines_against_exact(n, modes, kind):
    rng = np.random.default_rng(seed_of("fixed", n, modes, kind))
    shares, colds, points = [], 0, 0
    for _ in range(3):
        pts = random_chain(rng, n, modes, False, kind, omegas=np.linspace(-100.0, 100.0, 40))
        share, cold = check_line(pts)
        shares.append(share)
        colds += cold
        points += 40
    # the certificate decides most of these points, and most of them without an eigenvector problem of their own
    assert np.mean(shares) >= 0.8, shares
    assert colds < 0.6 * points, colds


@pytest.mark.parametrize("n,modes", [(2, 1), (3, 2), (5, 0)])
def test_free_and_ideal_chains_never_wrong(n, modes):
    """Free chains (structural zero roots, often defective: the certificate may fail, never mislabel) and
    ideal joints."""
    rng = np.random.default_rng(seed_of("free", n, modes))
    for free, kind in ((True, "mixed"), (False, "zerok")):
        pts = random_chain(rng, n, modes, free, kind, omegas=np.linspace(-80.0, 80.0, 15))
        check_line(pts)


@pytest.mark.slow
@pytest.mark.parametrize("n,modes,kind", [(12, 2, "mixed"), (12, 0, "identical"), (16, 1, "mixed"), (24, 0, "mixed"),
                                          (32, 0, "mixed"), (16, 4, "identical"), (32, 1, "identical")])
def test_many_bodies_against_exact(n, modes, kind):
    """Long chains: the certificate decides nearly all points of a line; a sample is checked exactly."""
    rng = np.random.default_rng(seed_of("many", n, modes, kind))
    pts = random_chain(rng, n, modes, False, kind, omegas=np.linspace(-100.0, 100.0, 40))
    share, cold = check_line(pts, sample=[0, 7, 19, 20, 33, 39])
    assert share >= 0.8, share


def ideal_identical_chain(omegas) -> PointArrays:
    """32 identical bodies on ideal joints (the chain of ``bench_kernel.py``'s identical kind, seed 1007, line 2):
    eigenvectors so ill-conditioned (condition numbers ~ 1e5) that each pair's coupling to its own conjugate
    dwarfs its imaginary part after a grid step."""
    n = 32
    body1 = np.tile([0.7663498589263649, 0.0836889627734496, 0.05532120030682841, -0.004015611722115786,
                     0.5973167918033255, 0.0], (n, 1))
    body = np.repeat(body1[None], len(omegas), 0)
    body[:, :, 5] = np.asarray(omegas)[:, None]
    joint = np.zeros(n)
    joint[0] = 21.68954737401416
    return make_points(body, joint, 9.81, np.full((n, 1), 0.00121048), np.full((n, 1), 3.98670178),
                       np.zeros(n, np.int64), False)


def test_identical_chain_refines_warm():
    """On a fine line the ill-conditioned identical chain is decided warm (one cold start, not one per point: the
    refinement used to solve each pair's 2 x 2 block exactly, which split the pairs into real roots and diverged
    at any spacing), and every label agrees with exact arithmetic."""
    pts = ideal_identical_chain(np.linspace(60.0, 63.0, 60))
    share, cold = check_line(pts, sample=[0, 1, 2, 17, 30, 44, 59])
    assert share == 1.0
    assert cold <= 3, cold


def test_decide_block_uses_it_from_allatonce_bodies():
    """decide_block hands chains of ALLATONCE_BODIES bodies and more to the new certificate first."""
    n = certify.ALLATONCE_BODIES
    pts = random_chain(np.random.default_rng(7), n, 0, False, "mixed", omegas=np.linspace(-60.0, 60.0, 12))
    nc, st = run_decide(pts)
    assert np.mean(st == kernels.DECIDED_ALLATONCE) >= 0.5
    for p in (0, 5, 11):
        assert nc[p] == exact_nc(pts, p)


def test_decide_block_uses_it_for_few_modes_on_lines_and_backs_off_elsewhere():
    """From ALLATONCE_FEW bodies with at most ALLATONCE_WIDTH - 2 modes a body and no exact zero root,
    decide_block tries the certificate first along a line.  Scattered points (every point its own chain: each
    a cold start) make it pause after COLD_RUN cold starts, and a free chain (exact zero roots) never takes it
    first: the disks decide those.  Every label against exact arithmetic."""
    n = certify.ALLATONCE_FEW
    rng = np.random.default_rng(seed_of("few", n))
    line = random_chain(rng, n, 2, False, "mixed", omegas=np.linspace(-100.0, 100.0, 30))
    nc, st = run_decide(line)
    assert np.mean(st == kernels.DECIDED_ALLATONCE) >= 0.8
    assert nc.tolist() == [exact_nc(line, p) for p in range(30)]
    chains = [random_chain(rng, n, 2, False, "mixed", npts=1) for _ in range(30)]
    scattered = PointArrays(*(np.concatenate([getattr(c, f) for c in chains]) for f in ("body", "joint", "g", "E", "kappa")),
                            chains[0].nmodes, False)
    nc, st = run_decide(scattered)
    # COLD_RUN cold starts, a pause of PAUSE = 16 points, COLD_RUN more, then a pause of 32
    assert (st == kernels.DECIDED_ALLATONCE).sum() <= 2 * certify.COLD_RUN
    assert not np.any(st == kernels.UNDECIDED)
    assert nc.tolist() == [exact_nc(scattered, p) for p in range(30)]
    free = random_chain(rng, n, 2, True, "mixed", omegas=np.linspace(-100.0, 100.0, 12))
    nc, st = run_decide(free)
    assert not np.any(st == kernels.DECIDED_ALLATONCE)
    assert nc.tolist() == [exact_nc(free, p) for p in range(12)]


@pytest.mark.parametrize("n,modes,seed", [(1, 0, 1), (2, 1, 2), (3, 1, 3), (2, 2, 4)])
def test_near_boundaries_never_wrong(n, modes, seed):
    """Next to a change of N_c (a pair that meets the real axis: a near-double root, or a pair with a tiny
    imaginary part) the certificate either proves the right label or leaves the point undecided."""
    grid = np.linspace(1.0, 150.0, 12)
    pts, changes = chain_with_boundary(np.random.default_rng(seed), n, modes, grid, 30)
    decided = 0
    for i in changes[:2]:
        w_star = _bisect_boundary(pts, grid[i], grid[i + 1])
        # cold (every point alone) and along a line through the boundary (refined from the neighbour)
        offsets = sorted(OFFSETS + [s * r for r in (1e-2, 1e-3, 1e-6) for s in (-1, 1)])
        line = _with_omega(pts, [w_star * (1 + r) for r in offsets])
        _, st, _ = run_allatonce(line)
        share, _ = check_line(line)
        for p in range(line.body.shape[0]):
            one = _with_omega(pts, [float(line.body[p, 0, 5])])
            check_line(one)
        decided += int((st == kernels.DECIDED_ALLATONCE).sum())
    # far enough from the boundary it does decide (1e-2 and 1e-3 of omega away, on either side)
    assert decided >= 2


def test_atlas_layer_names_it_all_eigenvalues_at_once():
    """The labelled layer writes the new provenance as decided_by = all_eigenvalues_at_once (a proof)."""
    from stabmap.systems.gyroscopes.decide import decide
    from stabmap.systems.gyroscopes.outputs import BY_ALLATONCE, DECIDED_BY

    pts = random_chain(np.random.default_rng(11), 12, 1, False, "mixed", omegas=np.linspace(-50.0, 50.0, 8))
    nc, by = decide(pts)
    assert DECIDED_BY.value("all_eigenvalues_at_once") == BY_ALLATONCE == 7
    assert (by == BY_ALLATONCE).sum() >= 4
    assert [int(nc[p]) for p in (0, 7)] == [exact_nc(pts, p) for p in (0, 7)]
