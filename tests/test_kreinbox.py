"""Krein boxes (kernels/kreinbox.py; docs/certification.md, section 6): N_c on a whole omega x t box, every proved box checked in
exact rational arithmetic (python-flint, ``exact.decide_points``) at its four corners and at random interior points."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from systems import WINDOW, window_straddling_boxes

import stabmap
from stabmap.kernels import layout
from stabmap.run.critical import critical
from stabmap.systems.gyroscopes import exact
from stabmap.systems.gyroscopes.kreinboxes import krein_arrays, krein_box, prove_krein_boxes
from stabmap.systems.gyroscopes.points import point_arrays
from stabmap.systems.gyroscopes.scene import from_dict

SQUARE = np.array([(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)])


def _exact(scene, values: dict[str, np.ndarray]) -> np.ndarray:
    pts = point_arrays(scene, values)
    return exact.decide_points(*pts.kernel_args(), np.arange(pts.body.shape[0]))


def _samples(lower, upper, i: int, rng, inside: int = 3) -> dict[str, np.ndarray]:
    """The four corners of box i and ``inside`` random interior points (two axes, in the order of ``lower``)."""
    t = np.concatenate([SQUARE, rng.random((inside, 2))])
    return {a: lower[a][i] + t[:, d] * (upper[a][i] - lower[a][i]) for d, a in enumerate(lower)}


def _check(scene, lower, upper, nc, rng, inside: int = 3) -> int:
    """Every proved box has its N_c at its corners and inside, exactly; returns how many were checked."""
    proved = np.flatnonzero(nc >= 0)
    for i in proved:
        got = _exact(scene, _samples(lower, upper, i, rng, inside))
        assert np.all(got == nc[i]), (i, {a: (lower[a][i], upper[a][i]) for a in lower}, nc[i], got)
    return proved.size


def _log_boxes(rng, count, w, m, width):
    """Random boxes with omega in w, m in m (log-uniform), each side a share 10^width of its lower corner."""
    lo_w = np.exp(rng.uniform(*np.log(w), count))
    lo_m = np.exp(rng.uniform(*np.log(m), count))
    fw, fm = 10.0 ** rng.uniform(*width, count), 10.0 ** rng.uniform(*width, count)
    return lo_w, lo_w * (1 + fw), lo_m, lo_m * (1 + fm)


@pytest.mark.parametrize("spin, width, share", [((1.0, 10.0), (-4, -1.5), 0.85), ((10.0, 200.0), (-4, -0.7), 0.85)])
def test_paper_n3_fixed_spin_by_mass_boxes_hold_their_label_in_exact_arithmetic(spin, width, share):
    # low spin: the liquid clusters 1e-5 apart (one type each: no separator between them); high spin: wide boxes
    scene = stabmap.example("paper-n3-fixed")
    rng = np.random.default_rng(11 if spin[0] < 5 else 12)
    a, b, c, d = _log_boxes(rng, 40, spin, (0.1, 10.0), width)
    lower, upper = {"omega": a, "m_2": c}, {"omega": b, "m_2": d}
    nc, proved, info = prove_krein_boxes(scene, lower, upper)
    assert proved.mean() >= share, (proved.mean(), info[~proved])
    assert _check(scene, lower, upper, nc, rng) >= 30
    # low spin: one complex pair everywhere (Krawczyk); high spin: stable boxes (the real count alone) and pairs
    assert set(nc[proved].tolist()) == ({1} if spin[0] < 5 else {0, 1})


def test_paper_n3_fixed_boxes_with_complex_pairs_and_stable_ones_are_both_proved():
    # omega 60, m_2 0.1 is stable (N_c = 0: the real count alone); omega 5 has one pair (Krawczyk)
    scene = stabmap.example("paper-n3-fixed")
    assert krein_box(scene, {"omega": (60.0, 60.5), "m_2": (0.1, 0.101)}) == 0
    assert krein_box(scene, {"omega": (5.0, 5.05), "m_2": (1.0, 1.01)}) == 1
    assert _exact(scene, {"omega": np.array([60.0, 60.5]), "m_2": np.array([0.1, 0.101])}).tolist() == [0, 0]
    assert _exact(scene, {"omega": np.array([5.0, 5.05]), "m_2": np.array([1.0, 1.01])}).tolist() == [1, 1]


def test_boxes_whose_samples_differ_are_never_proved_and_proved_ones_agree_with_every_sample():
    # a strip of paper-n3-fixed tiled by boxes across omega at a few masses: where exact samples of one box differ
    # (a boundary runs through it), the box must be left unproved
    scene = stabmap.example("paper-n3-fixed")
    rng = np.random.default_rng(5)
    edges_w = np.exp(np.linspace(np.log(1.0), np.log(200.0), 61))
    lower, upper = {"omega": [], "m_2": []}, {"omega": [], "m_2": []}
    for m in (0.15, 0.6, 2.5, 8.0):
        lower["omega"] += list(edges_w[:-1])
        upper["omega"] += list(edges_w[1:])
        lower["m_2"] += [m] * 60
        upper["m_2"] += [m * 1.3] * 60
    lower = {k: np.array(v) for k, v in lower.items()}
    upper = {k: np.array(v) for k, v in upper.items()}
    nc, proved, _ = prove_krein_boxes(scene, lower, upper)
    mixed = 0
    for i in range(nc.size):
        got = _exact(scene, _samples(lower, upper, i, rng, inside=4))
        if len(set(got.tolist())) > 1:
            mixed += 1
            assert not proved[i], (i, got, nc[i])
        elif proved[i]:
            assert np.all(got == nc[i]), (i, got, nc[i])
    assert mixed >= 4 and proved.sum() >= 120, (mixed, proved.sum())


def test_boxes_straddling_a_boundary_of_the_narrow_window_are_never_proved():
    # WINDOW's stable window (0.108 rad/s wide at K_1 = 10) and narrower liquid bands (E = 1e-6): omega x K_1 and
    # omega x m_2 boxes holding points on both sides of a boundary, 1e-9 to 1 rad/s wider than the bracket
    for scene, other, value, lower, upper, x in window_straddling_boxes():
        left = _exact(scene, {"omega": x[:, 0], other: np.full(len(x), value)})
        right = _exact(scene, {"omega": x[:, 1], other: np.full(len(x), value)})
        assert np.all(left != right)
        rows, part = krein_arrays(scene, lower, upper)
        assert rows.size == len(x)  # every one is a Krein box: the kernel is what refuses them
        nc, proved, _ = prove_krein_boxes(scene, lower, upper)
        assert not proved.any(), ([b.E for b in scene.bodies], other, np.flatnonzero(proved))


def test_paper_n2_fixed_spin_by_joint_stiffness_boxes_hold_their_label_in_exact_arithmetic():
    scene = stabmap.example("paper-n2-fixed")
    axes = [a.name for a in scene.grid]
    assert axes == ["omega", "K_1"], axes
    w, k = scene.grid[0].array, scene.grid[1].array
    rng = np.random.default_rng(3)
    count = 40
    lo_w = rng.uniform(w.min(), w.max(), count)
    lo_k = rng.uniform(k.min(), k.max(), count)
    lower = {"omega": lo_w, "K_1": lo_k}
    upper = {"omega": lo_w + (w.max() - w.min()) * 10.0 ** rng.uniform(-3.5, -1.5, count),
             "K_1": lo_k + (k.max() - k.min()) * 10.0 ** rng.uniform(-3.5, -1.5, count)}
    nc, proved, info = prove_krein_boxes(scene, lower, upper)
    assert proved.mean() >= 0.75, (proved.mean(), info[~proved])
    assert _check(scene, lower, upper, nc, rng) >= 30


def test_the_corner_inputs_are_the_models_at_unit_spin_and_lengths_are_refused():
    scene = stabmap.example("paper-n3-fixed")
    lower, upper = {"omega": np.array([3.0, 50.0]), "m_2": np.array([0.5, 2.0])}, {"omega": np.array([4.0, 40.0]), "m_2": np.array([0.7, 1.5])}
    rows, part = krein_arrays(scene, lower, upper)
    assert rows.tolist() == [0, 1]
    for j, pick in enumerate((np.minimum, np.maximum)):
        pts = point_arrays(scene, {"omega": np.ones(2), "m_2": pick(lower["m_2"], upper["m_2"])})
        assert np.array_equal(part.body[:, j], pts.body) and np.array_equal(part.joint[:, j], pts.joint)
        assert np.array_equal(part.g[:, j], pts.g) and np.array_equal(part.at[:, j], pts.at)
    assert np.all(part.body[..., layout.OMEGA] == 1.0)
    # 1 / omega^2 of every omega of the box lies in [u_lo, u_hi]
    for i, (a, b) in enumerate(zip(lower["omega"], upper["omega"], strict=True)):
        w = np.linspace(min(a, b), max(a, b), 101)
        assert np.all((part.u_lo[i] <= 1.0 / w**2) & (1.0 / w**2 <= part.u_hi[i]))
    # a length enters M quadratically: no Krein box (its Phi_1 is not bilinear)
    two = from_dict(dict(WINDOW, grid={"omega": {"values": [20.0]}, "c_1": {"values": [0.1]}}))
    rows, part = krein_arrays(two, {"omega": np.array([20.0]), "c_1": np.array([0.1])}, {"omega": np.array([21.0]), "c_1": np.array([0.11])})
    assert rows.size == 0 and part is None


@st.composite
def _chains(draw):
    """Small chains with the structural corners of the count: kappa = 2 (beta = 0, an exact root at 0), E = 0 (an
    exact root at -beta, no pole term), negative kappa (c < 0), identical bodies, free chains, negative spins."""
    n = draw(st.integers(1, 3))
    free = draw(st.booleans())
    identical = draw(st.booleans())
    seed = draw(st.integers(0, 2**32 - 1))
    axis = draw(st.sampled_from(["none", "m", "A", "C", "K", "g"] if not free else ["none", "A", "C", "K"]))
    e_exp = draw(st.sampled_from([-6.0, -4.0, -3.0, -2.0]))
    return n, free, identical, seed, axis, e_exp


def _chain_scene(n, free, identical, seed, axis, e_exp):
    rng = np.random.default_rng(seed)
    bodies = []
    for k in range(n):
        if identical and k:
            bodies.append(dict(bodies[0]))
            continue
        b = {"m": float(rng.uniform(0.5, 2)), "A": float(rng.uniform(0.01, 0.05)), "C": float(rng.uniform(0.02, 0.08)),
             "c": float(rng.uniform(-0.05, 0.15)), "s": float(rng.uniform(0.1, 0.3))}
        L = int(rng.integers(0, 3))
        if L:
            E = [float(x) for x in 10.0**e_exp * rng.uniform(0.5, 2.0, L)]
            if rng.random() < 0.2:
                E[0] = 0.0
            b["fluid"] = {"E": E, "kappa": [float(x) for x in rng.choice([-2.5, 1.31, 2.0, 2.7, 4.5], L, replace=False)]}
        bodies.append(b)
    system = {"support": "fixed" if not free else "free", "bodies": bodies, "joints": [float(x) for x in rng.uniform(1, 40, n - 1)]}
    if not free:
        system["g"] = 9.81
    names = {"m": "m_1", "A": f"A_{n}", "C": "C_1", "K": "K_1" if n > 1 else None, "g": "g", "none": None}
    other = names[axis] if not (free and axis == "K" and n == 1) else None
    grid = {"omega": {"values": [10.0]}}
    if other:
        grid[other] = {"values": [1.0]}
    return from_dict(dict(system, grid=grid)), other, rng


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_chains())
def test_property_proved_krein_boxes_of_random_chains_hold_their_label_exactly(case):
    scene, other, rng = _chain_scene(*case)
    count = 6
    w = rng.uniform(1.0, 80.0, count) * rng.choice([-1.0, 1.0], count)
    lower, upper = {"omega": w}, {"omega": w * (1.0 + 10.0 ** rng.uniform(-4, -1, count))}
    if other:
        base = {"m_1": 1.0, "C_1": 0.05, "K_1": 10.0, "g": 9.81}.get(other, 0.03)
        t = base * rng.uniform(0.5, 2.0, count)
        lower[other], upper[other] = t, t * (1.0 + 10.0 ** rng.uniform(-4, -1, count))
    nc, proved, _ = prove_krein_boxes(scene, lower, upper)
    for i in np.flatnonzero(proved):
        t = np.concatenate([SQUARE, rng.random((2, 2))])
        values = {a: lower[a][i] + t[:, d] * (upper[a][i] - lower[a][i]) for d, a in enumerate(lower)}
        got = _exact(scene, values)
        assert np.all(got == nc[i]), (case, i, {a: (lower[a][i], upper[a][i]) for a in lower}, nc[i], got)


@pytest.mark.slow
def test_paper_n3_fixed_one_cell_tiles_swept_warm_hold_their_label_in_exact_arithmetic():
    # the atlas's use: one-cell boxes of the 300 x 300 grid swept along omega, each warm from its predecessor's
    # separators and pairs; two 30 x 30 patches (low spin, where the pair moves fast, and high spin), every proved
    # box exact at its corners and one interior point
    from stabmap.scene.grid import resample
    from stabmap.store.dataset import edges

    scene = resample(stabmap.example("paper-n3-fixed"), omega=300, m_2=300)
    ew, em = (edges(a.array) for a in scene.grid)
    rng = np.random.default_rng(9)
    checked = 0
    for i0, j0 in ((0, 40), (200, 150)):
        j, i = (x.ravel() for x in np.meshgrid(np.arange(j0, j0 + 30), np.arange(i0, i0 + 30), indexing="ij"))
        lower, upper = {"omega": ew[i], "m_2": em[j]}, {"omega": ew[i + 1], "m_2": em[j + 1]}
        nc, proved, info = prove_krein_boxes(scene, lower, upper)
        assert proved.mean() >= 0.9, proved.mean()
        assert np.mean(info[proved, 3] == 7) >= 0.5  # most warm
        checked += _check(scene, lower, upper, nc, rng, inside=1)
    assert checked >= 1600


def test_the_kernel_refuses_inputs_outside_its_model():
    # every spin must be 1 (the spin-scaled model) and 0 < u_lo <= u_hi: anything else is left undecided
    from stabmap.kernels import UNDECIDED
    from stabmap.kernels.kreinbox import NINFO, krein_box_block

    scene = stabmap.example("paper-n3-fixed")
    rows, part = krein_arrays(scene, {"omega": np.array([60.0] * 4), "m_2": np.array([0.1] * 4)},
                              {"omega": np.array([60.5] * 4), "m_2": np.array([0.101] * 4)})
    body, joint, g, at, E, kappa, nmodes, free, parent, u_lo, u_hi = part.kernel_args()
    body[1, 0, 0, layout.OMEGA] = 2.0
    u_lo[2] = 0.0
    u_lo[3], u_hi[3] = u_hi[3], u_lo[3]
    nc = np.empty(4, np.int16)
    status = np.empty(4, np.int8)
    info = np.zeros((4, NINFO), np.int64)
    krein_box_block(body, joint, g, at, E, kappa, nmodes, free, parent, u_lo, u_hi, True, nc, status, info)
    assert nc.tolist() == [0, -1, -1, -1] and status[1:].tolist() == [UNDECIDED] * 3
