"""Every reactions label is proved: rank, compatibility, critical_node and n_critical equal those of the exact
rational KKT solve (tests/reactions_reference.py, independent of stabmap's solver) on random, collinear, released,
mirror-symmetric (exact ties) and near-tied layouts; the float error bound holds against the exact reactions;
the near-ties need the proof; atlases say per point how it was decided (decided_by)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import assume, event, given, settings
from hypothesis import strategies as st
from reactions_reference import exact_kkt, mpmath_least_norm

import stabmap
from stabmap.cli import main
from stabmap.reactions import ERROR_RTOL, solve, solve_batch
from stabmap.scene.grid import resample
from stabmap.systems.reactions import exact, floats
from stabmap.systems.reactions.solver import check_releases, prepare_releases

PLATE = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]


def exact_labels(nodes, F, M, releases=()):
    """(rank, compatible, critical_node, n_critical) of the exact KKT solution: the lowest-numbered node with the
    largest exact |R_i|^2, and how many nodes share that value exactly."""
    R, rank = exact_kkt(nodes, F, M, releases)
    if R is None:
        return rank, False, None, 0
    squares = [sum(v * v for v in row) for row in R]
    tied = [i for i, s in enumerate(squares) if s == max(squares)]
    return rank, True, tied[0], len(tied)


def labels(r):
    return r.rank, r.compatible, r.critical_node, r.n_critical


def exact_R(nodes, F, M, releases=()) -> np.ndarray:
    R, _ = exact_kkt(nodes, F, M, releases)
    return np.array([[float(v) for v in row] for row in R])


# ---------------------------------------------------------------------------------------------------- strategies
def coordinates(scale=3.0):
    return st.floats(-scale, scale, allow_nan=False).map(lambda v: round(v, 3))


def vectors(bound=100.0):
    return st.tuples(*[st.floats(-bound, bound, allow_nan=False, allow_subnormal=False)] * 3)


@st.composite
def problems(draw, max_releases=3):
    nodes = draw(st.lists(st.tuples(coordinates(), coordinates(), coordinates()), min_size=1, max_size=6, unique=True))
    n = len(nodes)
    releases = []
    for _ in range(draw(st.integers(0, max_releases))):
        e = draw(st.tuples(*[st.integers(-2, 2).map(float)] * 3))
        assume(any(e))
        releases.append((draw(st.integers(0, n - 1)), e))
    return nodes, draw(vectors()), draw(vectors()), tuple(releases)


@st.composite
def mirrored(draw):
    """A layout symmetric under x -> -x (every node has a twin), releases mirrored, and a load the reflection
    keeps (F_x = 0, M_y = M_z = 0): twins carry exactly equal |R_i|."""
    positive = st.integers(1, 3000).map(lambda k: k / 1000)
    half = draw(st.lists(st.tuples(positive, coordinates(), coordinates()), min_size=2, max_size=3, unique=True))
    nodes = [p for x, y, z in half for p in ((x, y, z), (-x, y, z))]
    releases = []
    if draw(st.booleans()):
        k = draw(st.integers(0, len(half) - 1))
        e = draw(st.tuples(*[st.integers(-2, 2).map(float)] * 3).filter(any))
        releases = [(2 * k, e), (2 * k + 1, (-e[0], e[1], e[2]))]
    F = (0.0, draw(st.floats(-100, 100)), draw(st.floats(-100, 100)))
    M = (draw(st.floats(-100, 100)), 0.0, 0.0)
    return nodes, F, M, tuple(releases)


# ---------------------------------------------------------------------------------------------------- labels
@settings(max_examples=60, deadline=None)
@given(problems())
def test_labels_equal_the_exact_ones_on_random_layouts(problem):
    nodes, F, M, releases = problem
    r = solve(nodes, F, M, releases=releases)
    assert labels(r) == exact_labels(nodes, F, M, releases)
    event(r.decided_by)
    if r.compatible:
        ref = exact_R(nodes, F, M, releases)
        error = np.linalg.norm(r.R - ref)
        if r.decided_by == "exact_rational":
            assert np.array_equal(r.R, ref)  # the exact reactions, rounded
        else:
            assert error <= ERROR_RTOL * r.max_norm


@pytest.mark.parametrize("seed", range(12))
def test_labels_on_collinear_layouts(seed):
    """Nodes exactly on a line (integers): rank 5 (plus releases), a load compatible iff it has no moment about
    the line, in exact arithmetic."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 6))
    d = rng.integers(1, 4, 3) * rng.choice([-1, 1], 3)
    p = rng.integers(-4, 5, 3)
    nodes = [tuple(float(v) for v in p + k * d) for k in rng.choice(np.arange(-5, 6), n, replace=False)]
    F = rng.integers(-50, 51, 3).astype(float)
    M = np.cross(nodes[0], F) + (np.cross(d, rng.integers(-5, 6, 3)) if seed % 2 else rng.integers(-5, 6, 3))
    releases = [(int(rng.integers(0, n)), tuple(rng.integers(-2, 3, 3).astype(float)))] if seed % 3 == 0 else []
    releases = [(k, e) for k, e in releases if any(e)]
    r = solve(nodes, F, M, releases=releases)
    assert labels(r) == exact_labels(nodes, F, M, releases)
    assert r.decided_by == "exact_rational"  # a rank-deficient layout: no float bound can prove its rank
    assert r.rank == mpmath_least_norm(nodes, F, M, releases)[1]


@settings(max_examples=40, deadline=None)
@given(mirrored())
def test_mirror_symmetric_layouts_tie_exactly(problem):
    nodes, F, M, releases = problem
    r = solve(nodes, F, M, releases=releases)
    want = exact_labels(nodes, F, M, releases)
    assert labels(r) == want
    event(f"n_critical {r.n_critical}")
    if r.compatible and r.max_norm > 0:
        assert r.n_critical % 2 == 0 and r.n_critical >= 2  # every node has a twin carrying as much
        assert r.norms[r.critical_node] == r.norms[r.critical_node ^ 1]  # twins: 2k and 2k + 1


def test_the_plate_ties_where_it_is_symmetric():
    G = 98.1
    F = np.array([0.0, 0.0, -G])
    centre = solve(PLATE, F, [0.0, 0.0, 0.0])
    assert (centre.critical_node, centre.n_critical, centre.decided_by) == (0, 4, "exact_rational")
    assert np.array_equal(centre.R[:, 2], [G / 4] * 4)
    for c, tied in [((0.0, 0.1), 2), ((0.0, -0.3), 0), ((0.2, 0.0), 1), ((-0.45, 0.0), 0)]:
        r = solve(PLATE, F, np.cross([*c, 0.0], F))
        assert (r.critical_node, r.n_critical) == (tied, 2) == exact_labels(PLATE, F, np.cross([*c, 0.0], F))[2:]


# ---------------------------------------------------------------------------------------------------- near-ties
NEAR = [1e-10, 1e-12, -1e-13, 1e-14, 1e-15, -1e-15, 1e-16, -1e-17, -1e-18, 1e-300, -5e-324]


@pytest.mark.parametrize("eps", NEAR)
def test_near_ties_are_told_apart(eps):
    """The plate's weight at (eps, 0.1): nodes 2 and 3 differ by G eps. The exact label is node 2 for eps > 0 and
    node 3 for eps < 0, never a tie. The old tolerance (1e-9) called all of these ties; floats cannot tell
    below about 1e-16, where the reported |R_2| and |R_3| are equal floats."""
    F = np.array([0.0, 0.0, -98.1])
    M = np.cross([eps, 0.1, 0.0], F)
    r = solve(PLATE, F, M)
    assert labels(r) == exact_labels(PLATE, F, M) == (6, True, 2 if eps > 0 else 3, 1)
    if abs(eps) <= 1e-17:
        assert r.norms[2] == r.norms[3] and r.critical_node == 3 - (eps > 0)
    assert r.decided_by == ("float_with_bound" if abs(eps) >= 1e-14 else "exact_rational")


@settings(max_examples=30, deadline=None)
@given(mirrored(), st.sampled_from([1e-15, -1e-15, 3e-16, 1e-13, -1e-300]))
def test_near_ties_on_random_symmetric_layouts(problem, eps):
    """A mirror-symmetric problem (exact ties) pushed off symmetry by a relative eps along x."""
    nodes, F, M, releases = problem
    scale = max(abs(v) for v in F + M)
    assume(scale > 1e-3)
    F = (eps * scale, F[1], F[2])
    r = solve(nodes, F, M, releases=releases)
    assert labels(r) == exact_labels(nodes, F, M, releases)
    event(f"{r.decided_by}, n_critical {r.n_critical}")


def test_the_near_ties_need_the_proof(monkeypatch):
    """Skip the proof (trust the floats' largest |R_i|) and the labels go wrong: these cases test the proof."""
    F = np.array([0.0, 0.0, -98.1])
    monkeypatch.setattr(floats, "separated", lambda norms, delta: np.isfinite(delta))
    r = solve(PLATE, F, np.cross([-1e-17, 0.1, 0.0], F))
    assert r.decided_by == "float_with_bound" and r.critical_node == 2  # the exact label is 3
    r = solve(PLATE, F, np.cross([0.0, 0.0, 0.0], F))
    assert r.n_critical == 1  # the exact tie of four goes unseen


# ---------------------------------------------------------------------------------------------------- the bound
@st.composite
def hard_problems(draw):
    """Layouts and loads over many scales: far from the origin, nearly collinear, nearly dependent releases."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n = draw(st.integers(3, 6))
    x = rng.normal(size=(n, 3)) * 10.0 ** draw(st.floats(-4, 4))
    kind = draw(st.sampled_from(["plain", "far", "thin", "releases"]))
    if kind == "far":
        x = x + rng.normal(size=3) * 10.0 ** draw(st.floats(0, 7))
    if kind == "thin":
        x = np.outer(rng.normal(size=n), rng.normal(size=3)) + rng.normal(size=(n, 3)) * 10.0 ** draw(st.floats(-14, -1))
    releases = [(int(rng.integers(0, n)), rng.normal(size=3)) for _ in range(draw(st.integers(0, 3)))]
    if kind == "releases" and releases:
        k, e = releases[0]
        releases.append((k, 3 * e + rng.normal(size=3) * 10.0 ** draw(st.floats(-15, -2))))
    F = rng.normal(size=3) * 10.0 ** draw(st.floats(-8, 8))
    M = rng.normal(size=3) * 10.0 ** draw(st.floats(-8, 8))
    return x, F, M, releases


@settings(max_examples=80, deadline=None)
@given(hard_problems())
def test_the_float_bound_holds(problem):
    """|R - R*| <= delta wherever the bound claims one; R* by the exact KKT reference, not by stabmap."""
    x, F, M, releases = problem
    rows = prepare_releases(len(x), check_releases(releases, len(x)))
    R, delta = floats.Layouts(x, rows).solve(F, M)
    event("bound proved" if np.isfinite(delta) else "no bound")
    if np.isfinite(delta):
        ref, rank = exact_kkt(x.tolist(), F, M, releases)
        assert rank == 6 + len(rows) and ref is not None  # the proved full row rank
        err2 = sum((Fraction(float(a)) - b) ** 2 for a, b in zip(R.ravel(), (v for row in ref for v in row)))
        assert float(err2) <= float(delta) ** 2
    r = solve(x, F, M, releases=releases)
    assert labels(r) == exact_labels(x.tolist(), F, M, releases)


def test_the_bound_proves_well_conditioned_layouts_and_is_tight():
    rng = np.random.default_rng(7)
    x, F, M = rng.normal(size=(20, 5, 3)), rng.normal(size=(20, 3)), rng.normal(size=(20, 3))
    R, delta = floats.Layouts(x, ()).solve(F, M)
    assert np.isfinite(delta).all()
    assert (delta <= 1e-13 * np.abs(R).max(axis=(-2, -1))).all()


def test_releases_are_exact_rows():
    """Dependent releases count once, exactly: parallel ones do, a direction 2^-60 off parallel does not."""
    assert len(exact.release_rows(4, [(3, np.array([1.0, 0, 0])), (3, np.array([-2.0, 0, 0]))])) == 1
    off = [(3, (1.0, 0.0, 0.0)), (3, (1.0, 2.0**-60, 0.0))]
    assert len(exact.release_rows(4, [(k, np.array(e)) for k, e in off])) == 2
    F, M = [1.0, 2.0, -100.0], [0.5, 0.0, 0.0]
    r = solve(PLATE, F, M, releases=off)
    assert labels(r) == exact_labels(PLATE, F, M, off) and r.rank == 8


def test_the_batch_decides_each_point_like_solve():
    rng = np.random.default_rng(2)
    nodes = np.round(rng.normal(size=(3, 4, 3)), 2)
    nodes[1] = PLATE
    F = np.zeros((5, 3, 3))
    F[..., 2] = -98.1
    c = np.zeros((5, 3, 3))
    c[:, :, :2] = np.round(rng.uniform(-0.5, 0.5, (5, 3, 2)), 1)
    c[0] = 0.0  # ties on the plate
    out = solve_batch(nodes, F, np.cross(c, F))
    for i in range(5):
        for j in range(3):
            one = solve(nodes[j], F[i, j], np.cross(c[i, j], F[i, j]))
            assert (out.critical_node[i, j], out.n_critical[i, j], out.rank[i, j]) == (one.critical_node, one.n_critical, one.rank)
            assert ("float_with_bound", "exact_rational")[out.decided_by[i, j]] == one.decided_by
            assert labels(one) == exact_labels(nodes[j].tolist(), F[i, j], np.cross(c[i, j], F[i, j]))


# ---------------------------------------------------------------------------------------------------- atlases
def test_atlas_flags_how_each_point_was_decided(tmp_path, capsys, monkeypatch):
    """The plate over its centre of mass on a grid through 0: exact ties on the axes, floats elsewhere; each
    distinct layout (one here) is factored exactly once per block."""
    made = []

    class Counting(exact.Layout):
        def __init__(self, *args):
            made.append(1)
            super().__init__(*args)

    monkeypatch.setattr(exact, "Layout", Counting)
    scene = resample(stabmap.example("reactions-square-plate"), c_x=5, c_y=5)
    ds = stabmap.compute_atlas(scene, threads=1, chunk_points=25)  # one task
    assert len(made) == 1  # nine exact points, one layout
    by = ds["decided_by"]
    assert by.attrs["flag_meanings"] == "float_with_bound exact_rational" and list(by.attrs["flag_values"]) == [0, 1]
    on_axis = (ds["c_x"] == 0) | (ds["c_y"] == 0)
    centre = (ds["c_x"] == 0) & (ds["c_y"] == 0)
    assert ((by == 1) == on_axis).all()
    assert (ds["n_critical"] == 1 + on_axis + 2 * centre).all()  # 4 at the centre, 2 on the axes, 1 off them
    path = stabmap.write_atlas(ds, tmp_path / "plate.nc")
    assert main(["info", str(path)]) == 0
    assert "decided by: float with bound 16, exact rational 9" in capsys.readouterr().out
    assert main(["query", str(path), "c_x=0", "c_y=0.3"]) == 0
    text = capsys.readouterr().out
    assert "n_critical = 2" in text and "(decided by exact rational)" in text
