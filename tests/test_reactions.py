"""stabmap.reactions against independent references (tests/reactions_reference.py): the least-norm solution by a
50-digit SVD, an exact rational KKT solve and equal springs by the stiffness method; the paper's square plate;
collinear and two-node layouts; releases; bad input."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
import scipy.linalg
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from reactions_reference import exact_kkt, mpmath_least_norm, springs
from stabmap import StabmapError
from stabmap.reactions import closed_form, solve, solve_batch

PLATE = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]


def constraint_matrix(nodes, releases=()):
    """The full constraint system (balance rows, release rows) about the given origin, in floats."""
    nodes = np.asarray(nodes, float)
    n = len(nodes)
    A = np.zeros((6 + len(releases), 3 * n))
    for i, x in enumerate(nodes):
        A[:3, 3 * i : 3 * i + 3] = np.eye(3)
        A[3:6, 3 * i : 3 * i + 3] = [[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]]
    for r, (k, e) in enumerate(releases):
        A[6 + r, 3 * k : 3 * k + 3] = e
    return A


def load_scale(nodes, F, M, R=None):
    """|F| + |M_c| / ell (M_c about the centroid, ell the nodes' RMS radius), and max |R_i| when given."""
    nodes = np.asarray(nodes, float)
    c = nodes.mean(axis=0)
    ell = np.sqrt(np.mean(np.sum((nodes - c) ** 2, axis=1))) or 1.0
    scale = np.linalg.norm(F) + np.linalg.norm(np.asarray(M) - np.cross(c, F)) / ell
    return max(scale, 0.0 if R is None else float(np.abs(R).max())), ell


def check_solution(nodes, F, M, releases, R):
    """Balance to 1e-12 of the load scale, no force along a release, R orthogonal to the null space of A."""
    nodes, F, M = (np.asarray(v, float) for v in (nodes, F, M))
    scale, ell = load_scale(nodes, F, M, R)
    assert np.linalg.norm(R.sum(axis=0) + F) <= 1e-12 * scale
    assert np.linalg.norm(np.cross(nodes, R).sum(axis=0) + M) <= 1e-12 * scale * max(ell, np.abs(nodes).max())
    for k, e in releases:
        assert abs(np.dot(R[k], e)) <= 1e-12 * scale * np.linalg.norm(e)
    null = scipy.linalg.null_space(constraint_matrix(nodes, releases))
    if null.size:
        assert np.abs(null.T @ R.ravel()).max() <= 1e-12 * scale


# ---------------------------------------------------------------------------------------------------- the paper
def test_square_plate_a_quarter_of_the_weight_each():
    G = 981.0
    exact, rank = exact_kkt(PLATE, [0, 0, -G], [0, 0, 0])
    assert rank == 6 and exact == [[0, 0, Fraction(G) / 4]] * 4  # exactly G/4, in exact arithmetic
    r = solve(PLATE, [0.0, 0.0, -G], [0.0, 0.0, 0.0])
    assert r.compatible and r.rank == 6 and r.free_motions == 0
    assert np.array_equal(r.R, [[0, 0, G / 4]] * 4)  # an exact tie, so solved exactly: G/4 rounded, which is G/4
    assert r.n_critical == 4 and r.critical_node == 0 and r.decided_by == "exact_rational"
    assert np.array_equal(closed_form(PLATE, [0.0, 0.0, -G], [0.0, 0.0, 0.0]), np.tile([0.0, 0.0, G / 4], (4, 1)))


def test_square_plate_moved_centre_of_mass_matches_the_linear_distribution():
    """Weight G at (cx, cy) on corners (+-a, +-a): R_i = G/4 (1 + cx x_i / a^2 + cy y_i / a^2), hand-derived."""
    G, a = 100.0, 0.5
    for cx, cy in [(0.1, 0.0), (0.2, -0.3), (0.45, 0.45)]:
        F = np.array([0.0, 0.0, -G])
        r = solve(PLATE, F, np.cross([cx, cy, 0.0], F))
        want = G / 4 * (1 + cx * np.array(PLATE)[:, 0] / a**2 + cy * np.array(PLATE)[:, 1] / a**2)
        np.testing.assert_allclose(r.R[:, 2], want, rtol=0, atol=1e-12 * G)
        assert r.critical_node == int(np.argmax(want))


# ---------------------------------------------------------------------------------------------------- references
def layouts():
    coordinate = st.floats(-3, 3, allow_nan=False).map(lambda v: round(v, 3))
    node = st.tuples(coordinate, coordinate, coordinate)
    return st.lists(node, min_size=3, max_size=7, unique=True)


def vectors(bound=100.0):
    return st.tuples(*[st.floats(-bound, bound, allow_nan=False)] * 3)


@st.composite
def problems(draw, releases=True):
    nodes = draw(layouts())
    n = len(nodes)
    rel = []
    if releases:
        for _ in range(draw(st.integers(0, 3))):
            e = draw(vectors(1.0))
            assume(np.linalg.norm(e) > 0.1)
            rel.append((draw(st.integers(0, n - 1)), e))
    F, M = draw(vectors()), draw(vectors())
    # Accuracy is claimed for well-conditioned layouts; near-degenerate ones are the subject of other tests.
    A = constraint_matrix(np.asarray(nodes) - np.mean(nodes, axis=0), rel)
    s = np.linalg.svd(A, compute_uv=False)
    assume(s[-1] > 1e-3 * s[0] and np.linalg.norm(F) + np.linalg.norm(M) > 1e-3)
    return nodes, F, M, tuple(rel)


@settings(max_examples=60, deadline=None)
@given(problems())
def test_matches_the_50_digit_svd_and_balances(problem):
    nodes, F, M, releases = problem
    r = solve(nodes, F, M, releases=releases)
    ref, rank = mpmath_least_norm(nodes, F, M, releases)
    assert r.rank == rank == 6 + len(releases)
    assert r.compatible and ref is not None
    scale, _ = load_scale(nodes, F, M, ref)
    assert np.abs(r.R - ref).max() <= 1e-10 * scale
    check_solution(nodes, F, M, releases, r.R)
    assert r.residual <= 1e-12
    assert r.max_norm == pytest.approx(np.linalg.norm(ref, axis=1).max(), rel=1e-10)


@settings(max_examples=40, deadline=None)
@given(problems())
def test_matches_equal_springs(problem):
    nodes, F, M, releases = problem
    r = solve(nodes, F, M, releases=releases)
    ref = springs(nodes, np.array(F), np.array(M), releases)
    scale, _ = load_scale(nodes, F, M, ref)
    assert np.abs(r.R - ref).max() <= 1e-10 * scale


@settings(max_examples=40, deadline=None)
@given(problems(releases=False), vectors(10.0))
def test_does_not_depend_on_the_origin(problem, shift):
    """Moving the origin to s moves the nodes by -s and the moment to M - s x F (about s): the same reactions."""
    nodes, F, M, _ = problem
    s = np.array(shift)
    moved = solve(np.asarray(nodes) - s, F, np.asarray(M) - np.cross(s, F))
    r = solve(nodes, F, M)
    scale, _ = load_scale(nodes, F, M, r.R)
    assert np.abs(moved.R - r.R).max() <= 1e-10 * scale
    np.testing.assert_allclose(closed_form(nodes, F, M), r.R, rtol=0, atol=1e-10 * scale)


def small_integers(rng, n, collinear=False):
    if collinear:
        d, p = np.zeros(3, dtype=int), rng.integers(-5, 6, 3)
        while not d.any():
            d = rng.integers(-3, 4, 3)
        t = rng.choice(np.arange(-6, 7), size=n, replace=False)
        return [tuple(int(v) for v in p + k * d) for k in t]
    pts = set()
    while len(pts) < n:
        pts.add(tuple(int(v) for v in rng.integers(-4, 5, 3)))
    return sorted(pts)


@pytest.mark.parametrize("seed", range(18))
def test_matches_the_exact_kkt_solve(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 7))
    collinear = seed % 3 == 0 or n == 2
    nodes = small_integers(rng, n, collinear)
    releases = [(int(rng.integers(0, n)), tuple(int(v) for v in rng.integers(-2, 3, 3))) for _ in range(seed // 3 % 3)]
    releases = [(k, e) for k, e in releases if any(e)]
    F = rng.integers(-50, 51, 3).astype(float)
    M = rng.integers(-50, 51, 3).astype(float)
    if collinear:  # no moment about the line, exactly, so that reactions exist: F through a node, and a torque normal to d
        d = np.subtract(nodes[1], nodes[0])
        M = np.cross(nodes[0], F) + np.cross(d, rng.integers(-5, 6, 3))
    exact, rank = exact_kkt(nodes, F, M, releases)
    r = solve(nodes, F, M, releases=releases)
    assert r.rank == rank
    assert r.compatible == (exact is not None)
    if exact is not None:
        ref = np.array([[float(v) for v in row] for row in exact])
        scale, _ = load_scale(nodes, F, M, ref)
        assert np.abs(r.R - ref).max() <= 1e-10 * scale
        check_solution(nodes, F, M, releases, r.R)
        mp, mp_rank = mpmath_least_norm(nodes, F, M, releases)
        assert mp_rank == rank and np.abs(mp - ref).max() <= 1e-10 * scale


# ---------------------------------------------------------------------------------------------------- degenerate
SHAFT = [[0.0, 0.0, 0.0], [1.0, 2.0, 2.0], [3.0, 6.0, 6.0]]  # on the line through 0 along (1, 2, 2)


def test_collinear_nodes_carry_a_load_without_moment_about_their_line():
    F = np.array([10.0, -20.0, 5.0])
    M = np.cross([0.5, 1.0, 3.0], F)  # F acting at a point off the line: a moment about the line in general ...
    d = np.array([1.0, 2.0, 2.0]) / 3
    M_ok = M - np.dot(M, d) * d  # ... here taken away (the nodes' centroid lies on the line through 0)
    r = solve(SHAFT, F, M_ok)
    assert r.compatible and r.rank == 5 and r.free_motions == 1
    check_solution(SHAFT, F, M_ok, (), r.R)
    ref, rank = mpmath_least_norm(SHAFT, F, M_ok)
    assert rank == 5 and np.abs(r.R - ref).max() <= 1e-10 * load_scale(SHAFT, F, M_ok, ref)[0]
    np.testing.assert_allclose(r.R, springs(SHAFT, F, M_ok), rtol=0, atol=1e-9 * np.abs(ref).max())
    with pytest.raises(StabmapError, match="collinear"):
        closed_form(SHAFT, F, M_ok)  # the paper's formula has no answer here; the least-norm rule has


def test_collinear_nodes_with_a_moment_about_their_line_are_incompatible():
    F = np.array([10.0, -20.0, 5.0])
    r = solve(SHAFT, F, np.cross([0.5, 1.0, 3.0], F))
    assert not r.compatible and r.R is None and r.rank == 5 and r.critical_node is None
    assert np.isnan(r.max_norm) and r.n_critical == 0
    assert mpmath_least_norm(SHAFT, F, np.cross([0.5, 1.0, 3.0], F))[0] is None
    assert exact_kkt(SHAFT, F, np.cross([0.5, 1.0, 3.0], F))[0] is None


def test_two_nodes_are_collinear():
    nodes = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
    r = solve(nodes, [0.0, 0.0, -10.0], [0.0, 5.0, 0.0])  # weight 10 at x = 0.5
    assert r.compatible and r.rank == 5
    np.testing.assert_allclose(r.R, [[0, 0, 7.5], [0, 0, 2.5]], atol=1e-13)
    r = solve(nodes, [4.0, 0.0, 0.0], [0.0, 0.0, 0.0])  # along the line: shared equally, the indeterminate part
    np.testing.assert_allclose(r.R, [[-2, 0, 0], [-2, 0, 0]], atol=1e-13)
    assert r.n_critical == 2
    assert not solve(nodes, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]).compatible  # a torque about the line


def test_one_node_carries_the_force_and_no_moment():
    r = solve([[1.0, 2.0, 3.0]], [1.0, 2.0, 3.0], np.cross([1.0, 2.0, 3.0], [1.0, 2.0, 3.0]))
    assert r.compatible and r.rank == 3 and r.free_motions == 3
    np.testing.assert_allclose(r.R, [[-1.0, -2.0, -3.0]])
    assert not solve([[1.0, 2.0, 3.0]], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]).compatible


def test_releases_are_respected_and_can_free_the_body():
    sliding = [(k, [1.0, 0.0, 0.0]) for k in range(4)]  # every corner slides along x
    r = solve(PLATE, [0.0, 3.0, -100.0], [0.0, 0.0, 0.0], releases=sliding)
    assert r.compatible and r.rank == 6 - 1 + 4 and r.free_motions == 1
    assert np.abs(r.R[:, 0]).max() <= 1e-13 * 100
    r = solve(PLATE, [3.0, 0.0, -100.0], [0.0, 0.0, 0.0], releases=sliding)  # a force along the free motion
    assert not r.compatible and r.R is None and r.free_motions == 1
    assert exact_kkt(PLATE, [3.0, 0.0, -100.0], [0.0, 0.0, 0.0], sliding)[0] is None
    # A hinge axis (release along y at node 1) gives node 1 no y force, the others share it.
    r = solve(PLATE, [0.0, 8.0, -100.0], [0.0, 0.0, 0.0], releases=[(1, [0.0, 2.0, 0.0])])
    assert r.rank == 7 and abs(r.R[1, 1]) <= 1e-13 and r.R[:, 1].sum() == pytest.approx(-8.0)
    # Released in three directions: the node carries nothing; parallel releases count once.
    releases = [(2, [1, 0, 0]), (2, [0, 1, 0]), (2, [0, 0, 1]), (3, [1, 0, 0]), (3, [-2, 0, 0])]
    r = solve(PLATE, [1.0, 2.0, -100.0], [0.0, 0.0, 0.0], releases=releases)
    assert r.compatible and np.abs(r.R[2]).max() <= 1e-13 and abs(r.R[3, 0]) <= 1e-13
    assert r.rank == 6 + 3 + 1  # the dependent release row of node 3 does not count
    assert exact_kkt(PLATE, [1.0, 2.0, -100.0], [0.0, 0.0, 0.0], releases)[1] == r.rank
    check_solution(PLATE, [1.0, 2.0, -100.0], [0.0, 0.0, 0.0], releases, r.R)
    # Nodes 0 and 1 alone carry vertical force: on one line, they cannot hold a weight at the plate's centre.
    releases[3:] = [(3, [0, 0, 1]), (3, [0, 0, -2])]
    assert not solve(PLATE, [1.0, 2.0, -100.0], [0.0, 0.0, 0.0], releases=releases).compatible


def test_the_batch_is_the_points_one_by_one():
    rng = np.random.default_rng(5)
    nodes = rng.normal(size=(7, 5, 3))  # seven layouts of five nodes
    F, M = rng.normal(size=(4, 1, 3)) * 50, rng.normal(size=(4, 7, 3)) * 20
    out = solve_batch(nodes, F, M, releases=[(0, [0.0, 0.0, 1.0])])
    assert out.R.shape == (4, 7, 5, 3) and out.rank.shape == (4, 7)
    for i in range(4):
        for j in range(7):
            one = solve(nodes[j], F[i, 0], M[i, j], releases=[(0, [0.0, 0.0, 1.0])])
            np.testing.assert_allclose(out.R[i, j], one.R, rtol=0, atol=1e-12 * np.abs(one.R).max())
            assert out.critical_node[i, j] == one.critical_node and out.rank[i, j] == one.rank


def test_zero_load_gives_zero_reactions():
    r = solve(PLATE, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    assert r.compatible and not r.R.any() and r.max_norm == 0.0 and r.n_critical == 4


# ---------------------------------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "nodes,F,M,releases,message",
    [
        ([[0, 0, np.nan], [1, 0, 0]], [0, 0, 1], [0, 0, 0], (), "nodes: node 0 has a non-finite coordinate"),
        ([[0, 0], [1, 0]], [0, 0, 1], [0, 0, 0], (), r"nodes must be an \(n, 3\) array"),
        ([[0, 0, 0], [1, 0]], [0, 0, 1], [0, 0, 0], (), r"nodes must be an \(n, 3\) array of node positions \[x, y, z\], got \[\[0, 0, 0\], \[1, 0\]\]"),
        (PLATE, "up", [0, 0, 0], (), r"F must be a 3-vector"),
        (PLATE, [0, 1], [0, 0, 0], (), r"F must be a 3-vector"),
        (PLATE, [0, 0, 1], [0, np.inf, 0], (), "M must be finite"),
        (PLATE, [0, 0, 1], [0, 0, 0], [(1, [0.0, 0.0, 0.0])], r"releases\[0\] direction is zero"),
        (PLATE, [0, 0, 1], [0, 0, 0], [(4, [1.0, 0.0, 0.0])], "node 4 does not exist; the nodes are numbered 0..3"),
        (PLATE, [0, 0, 1], [0, 0, 0], [(0, [1.0, 0.0])], r"releases\[0\] direction must be a 3-vector"),
        (PLATE, [0, 0, 1], [0, 0, 0], [0], r"releases\[0\] must be a pair"),
        ([[0, 0, 0], [1, 1, 1], [0, 0, 0]], [0, 0, 1], [0, 0, 0], (), "nodes 0 and 2 are at the same point"),
        ([[[0, 0, 0]]], [0, 0, 1], [0, 0, 0], (), "solve_batch takes stacks"),
    ],
)
def test_bad_input_names_the_parameter(nodes, F, M, releases, message):
    with pytest.raises(StabmapError, match=message):
        solve(nodes, F, M, releases=releases)


@pytest.mark.slow
@settings(max_examples=600, deadline=None)
@given(problems())
def test_many_layouts_match_the_50_digit_svd(problem):
    """The fast test's comparison on ten times as many layouts, loads and releases."""
    nodes, F, M, releases = problem
    r = solve(nodes, F, M, releases=releases)
    ref, rank = mpmath_least_norm(nodes, F, M, releases)
    assert r.rank == rank and r.compatible and ref is not None
    assert np.abs(r.R - ref).max() <= 1e-10 * load_scale(nodes, F, M, ref)[0]
    check_solution(nodes, F, M, releases, r.R)
