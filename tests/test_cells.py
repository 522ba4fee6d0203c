"""Cells of an atlas (stabmap.run.cells): what ``cell`` claims about the grid cell around each node, checked in
exact rational arithmetic (python-flint) at points inside the cells, and against the exact boundaries of
narrow windows and bands (the roots of the discriminant in omega, tests/test_boxes.py)."""

from __future__ import annotations

import dataclasses
import random

import numpy as np
import pytest
import xarray as xr
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import stabmap
from stabmap.run import cells
from stabmap.run.critical import critical
from stabmap.scene.grid import Axis, resample
from stabmap.store.dataset import edges
from stabmap.store.variables import CELL
from stabmap.systems.gyroscopes import exact
from stabmap.systems.gyroscopes.outputs import BY_BOX
from stabmap.systems.gyroscopes.points import point_arrays
from stabmap.systems.gyroscopes.scene import from_dict
from cellspare import spare as larger_spare
from systems import EXACT_BOUNDARIES, WINDOW, random_system

WHOLE, CHANGE, NODE = (CELL.value(m) for m in ("whole_cell", "contains_change", "node_only"))



def _exact(scene, values: dict[str, np.ndarray]) -> np.ndarray:
    pts = point_arrays(scene, {k: np.asarray(v, dtype=float) for k, v in values.items()})
    return exact.decide_points(*pts.kernel_args(), np.arange(pts.body.shape[0]))


def _atlas(scene, spare: float | None = None, **kwargs):
    """The atlas of ``scene``; ``spare``: the tiles' spare for proofs (cells.SPARE) for this atlas, so that a test of what
    cells claim sees boxes tried on a coarse grid, where the default spare tries few."""
    with larger_spare(cells.SPARE if spare is None else spare):
        return stabmap.compute_atlas(scene, threads=1, progress=False, **kwargs)


def _cell_points(scene, index: tuple[int, ...], rng, k: int) -> dict[str, np.ndarray]:
    """k random points of the cell of the node ``index`` (uniform in its box)."""
    out = {}
    for axis, i in zip(scene.grid, index):
        e = edges(axis.array)
        out[axis.name] = rng.uniform(min(e[i], e[i + 1]), max(e[i], e[i + 1]), k)
    return out


def _cells_containing(scene, x: float) -> list[int]:
    """The cells of a 1-D scan that hold the value x (two where x is an edge)."""
    e = edges(scene.grid[0].array)
    return [i for i in range(len(e) - 1) if min(e[i], e[i + 1]) <= x <= max(e[i], e[i + 1])]


# ---------------------------------------------------------------------------------------------- bounds
def test_cells_tile_the_scan_and_are_written_as_cf_bounds(tmp_path):
    scene = resample(stabmap.example("paper-n1-fixed"), omega=7, c_1=5)
    ds = _atlas(scene)
    for axis in scene.grid:
        b = ds[f"{axis.name}_bounds"].values
        assert ds[axis.name].attrs["bounds"] == f"{axis.name}_bounds"
        assert b[0, 0] == axis.values[0] and b[-1, 1] == axis.values[-1]
        assert np.array_equal(b[1:, 0], b[:-1, 1])  # no gap, no overlap
        assert np.all((b[:, 0] <= axis.array) & (axis.array <= b[:, 1]))
        assert np.allclose(b[1:, 0], 0.5 * (axis.array[1:] + axis.array[:-1]), rtol=0, atol=1e-15)
    path = tmp_path / "a.nc"
    stabmap.write_atlas(ds, path)
    back = xr.load_dataset(path)
    assert back["omega"].attrs["bounds"] == "omega_bounds" and back["omega_bounds"].shape == (7, 2)
    assert back["cell"].attrs["flag_meanings"] == " ".join(CELL.meanings)


# ---------------------------------------------------------------------------------- narrow windows and bands
def test_the_narrow_window_never_lies_in_a_whole_cell():
    scene = from_dict(WINDOW)
    ds = _atlas(scene, spare=1.0)
    cell = ds["cell"].values
    # the window lies between two nodes that agree (N_c = 1 at omega = 11.5 and 12.5): their label is not claimed
    # for the window's cell, which is node_only (its sub-boxes straddle the window), and the boundary at 13.84
    # between nodes that differ lies in a cell proved to hold the change
    assert ds["n_complex_pairs"].sel(omega=[11.5, 12.5]).values.tolist() == [1, 1]
    for x in EXACT_BOUNDARIES:
        for i in _cells_containing(scene, x):
            assert cell[i] != WHOLE, (x, i)
    assert [CELL.meaning(int(cell[i])) for i in _cells_containing(scene, EXACT_BOUNDARIES[2])] == ["contains_change"]
    assert (cell == WHOLE).sum() >= 75  # the rest mostly proved (a spare of one node proof a cell affords 19 box proofs)


@pytest.mark.parametrize("E", [1e-4, 1e-6, 1e-8])
def test_narrow_liquid_bands_never_hide_in_a_whole_cell(E):
    # Smaller E narrows the liquid resonances to bands far below the scan step; the boundaries come from critical
    # values (checked against the exact discriminant in tests/test_boxes.py), each located to 1e-10.
    system = dict(WINDOW, bodies=[dict(b, fluid=dict(b["fluid"], E=[E])) for b in WINDOW["bodies"]])
    scene = from_dict(system)
    ds = _atlas(scene, spare=1.0)
    crit = critical(scene, "omega", rtol=1e-10, progress=False, threads=1)
    keep = np.isfinite(crit["boundary_lower"].values)
    cell = ds["cell"].values
    for a, b in zip(crit["boundary_lower"].values[keep], crit["boundary_upper"].values[keep]):
        for i in set(_cells_containing(scene, a)) | set(_cells_containing(scene, b)):
            assert cell[i] != WHOLE, (E, a, i)
    # and every whole cell holds its label at random interior points, exactly
    rng = np.random.default_rng(int(-np.log10(E)))
    whole = np.flatnonzero(cell == WHOLE)
    pick = rng.choice(whole, min(40, whole.size), replace=False)
    x = np.concatenate([_cell_points(scene, (i,), rng, 3)["omega"] for i in pick])
    assert np.array_equal(_exact(scene, {"omega": x}), np.repeat(ds["n_complex_pairs"].values[pick], 3))


# --------------------------------------------------------------------------------------- random scenes (2-D)
def _random_scene(seed: int):
    """A random fixed chain (tests/systems.py, every body at the common spin) over omega x another parameter."""
    rng = random.Random(seed)
    n = rng.randint(1, 3)
    system = random_system(rng, n, rng.randint(0, 2), "fixed")
    for body in system["bodies"]:
        body.pop("omega", None)
    other, start, stop = rng.choice([("K_1", 0.0, 40.0), ("m_1", 0.5, 3.0), ("c_1", -0.05, 0.2), ("g", 0.0, 20.0)][n == 1:])
    system["grid"] = {"omega": {"start": rng.uniform(1, 10), "stop": rng.uniform(30, 120), "num": rng.randint(5, 12)},
                      other: {"start": start, "stop": stop, "num": rng.randint(4, 8)}}
    return from_dict(system)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1))
def test_a_whole_cell_has_its_label_at_random_interior_points_in_exact_arithmetic(seed):
    scene = _random_scene(seed)
    ds = _atlas(scene, spare=1.0)
    cell, label = ds["cell"].values, ds["n_complex_pairs"].values
    rng = np.random.default_rng(seed)
    whole = np.argwhere(cell == WHOLE)
    for index in whole[rng.permutation(len(whole))[:6]]:
        pts = _cell_points(scene, tuple(index), rng, 4)
        assert np.all(_exact(scene, pts) == label[tuple(index)]), (seed, tuple(index))
    # a claimed change: two labels inside the cell (node, face-centre or corner labels, else random points find the other)
    change = np.argwhere(cell == CHANGE)
    for index in change[rng.permutation(len(change))[:2]]:
        corners = {a.name: edges(a.array)[[i, i + 1]] for a, i in zip(scene.grid, index)}
        grid = np.meshgrid(*corners.values(), indexing="ij")
        faces = {a.name: np.array([a.array[i]] * (2 * len(scene.grid))) for a, i in zip(scene.grid, index)}
        for d, a in enumerate(scene.grid):
            faces[a.name][2 * d : 2 * d + 2] = corners[a.name]
        seen = set(_exact(scene, {k: g.ravel() for k, g in zip(corners, grid)}).tolist()) | {int(label[tuple(index)])}
        seen |= set(_exact(scene, faces).tolist())
        if len(seen) == 1:
            seen |= set(_exact(scene, _cell_points(scene, tuple(index), rng, 300)).tolist())
        assert len(seen) > 1, (seed, tuple(index))


def test_cells_keep_every_node_label_and_compute_fewer_nodes():
    for name in ("paper-n1-fixed", "paper-n2-fixed", "paper-n2-free", "paper-n3-fixed-split", "tree-two-rotors-free"):
        scene = resample(stabmap.example(name), **{a.name: 24 for a in stabmap.example(name).grid})
        nodes, cells = _atlas(scene, prove_cells=False), _atlas(scene)
        assert np.array_equal(nodes["n_complex_pairs"].values, cells["n_complex_pairs"].values), name
        assert np.all(nodes["cell"].values == NODE)
        computed = cells["decided_by"].values != BY_BOX
        assert np.array_equal(nodes["decided_by"].values[computed], cells["decided_by"].values[computed]), name
        # a node a box proved lies in a whole cell
        assert np.all(cells["cell"].values[~computed] == WHOLE), name


def test_systems_without_box_proofs_answer_node_only():
    for name in ("closed-hinge", "reactions-square-plate"):
        scene = stabmap.example(name)
        scene = resample(scene, **{a.name: min(6, len(a.values)) for a in scene.grid})
        ds = _atlas(scene)
        assert np.all(ds["cell"].values == NODE), name


def test_a_cavity_axis_leaves_cells_node_only():
    # The liquid modes depend on the cavity's half height: no box encloses them (boxes.box_axes), so no cell is proved.
    scene = stabmap.example("top-cylinder-cavity")
    scene = resample(scene, omega=6, half_height_1=5)
    ds = _atlas(scene)
    assert np.all(ds["cell"].values == NODE)
    assert np.array_equal(ds["n_complex_pairs"].values, _atlas(scene, prove_cells=False)["n_complex_pairs"].values)


def test_query_says_whether_the_cell_is_proved(tmp_path):
    scene = dataclasses.replace(from_dict(WINDOW), grid=(Axis("omega", tuple(np.linspace(0.5, 99.5, 100))),))
    ds = _atlas(scene, spare=1.0)
    from stabmap.read.query import label_at

    assert label_at(ds, omega=12.0).cell == "node_only"  # the window's cell: N_c = 1 at its node, not claimed in it
    assert label_at(ds, omega=13.9).cell == "contains_change"
    assert label_at(ds, omega=60.0).cell == "whole_cell"


# ------------------------------------------------------------------------- located answers (query --locate)
def test_located_boundaries_and_smallest_stable_find_the_window_the_grid_misses(tmp_path, capsys):
    from stabmap.cli import main
    from stabmap.read import query
    from stabmap.read.located import located_boundaries, located_smallest_stable

    ds = _atlas(from_dict(WINDOW))
    grid = query.boundaries(ds, "omega")
    assert grid.sizes["boundary"] == 1  # the window lies between two grid values with N_c = 1
    b = located_boundaries(ds, "omega", progress=False)
    assert b.attrs["located"] == 1 and b.attrs["n_undecided"] == 0
    assert b.sizes["boundary"] == 3
    for lo, hi, x in zip(b["boundary_lower"].values, b["boundary_upper"].values, EXACT_BOUNDARIES):
        assert hi - lo <= 1e-10 * hi and abs(0.5 * (lo + hi) - x) < 1e-6
    assert b["n_complex_pairs_below"].values.tolist() == [1, 0, 1] and b["n_complex_pairs_above"].values.tolist() == [0, 1, 0]
    s = located_smallest_stable(ds, "omega", progress=False)
    assert float(s["smallest_stable"]) == pytest.approx(EXACT_BOUNDARIES[0], abs=1e-6)
    assert not bool(s["stable_to_scan_end"]) and not bool(s["undecided_below"])
    assert float(query.smallest_stable(ds, "omega")["smallest_stable"]) > 13.8  # the grid's answer: 14 % too high
    path = tmp_path / "w.nc"
    stabmap.write_atlas(ds, path)
    assert main(["query", str(path), "--boundaries", "omega", "--locate"]) == 0
    out = capsys.readouterr().out
    assert "3 changes of N_c on 1 of 1 line, each located to 1e-10 relative" in out and "the list is complete" in out
    assert main(["query", str(path), "omega=12", "--locate"]) == 2
    assert "--locate applies to --boundaries and --smallest-stable" in capsys.readouterr().err


def test_a_box_is_halved_across_the_axis_its_proof_names_alone():
    from stabmap.run.cells import _halves

    lo, hi = np.array([[0, 0], [0, 0], [0, 0]]), np.array([[4, 4], [4, 4], [1, 4]])
    along = np.array([[True, False], [False, False], [True, False]])  # omega alone; none; an axis one cell wide
    got = sorted(map(tuple, np.hstack(_halves(lo, hi, along))))
    assert got == sorted([(0, 0, 2, 4), (2, 0, 4, 4),  # across the first axis alone
                          (0, 0, 2, 2), (0, 2, 2, 4), (2, 0, 4, 2), (2, 2, 4, 4),  # no axis named: both
                          (0, 0, 1, 2), (0, 2, 1, 4)])  # the named axis cannot be cut: the other


def test_low_spin_boxes_of_identical_cavities_fail_and_are_cut_across_the_spin_then_prove():
    # paper-n3-fixed below omega = 3 on a 4000 x 4000 grid: u = 1/omega^2 moves the clustered liquid roots fast and
    # m_2 barely, so 16 x 16-cell boxes fail and their corners say so; boxes one cell wide in omega then prove, and
    # their labels hold in exact arithmetic.
    scene = stabmap.example("paper-n3-fixed")
    system = stabmap.systems.of(scene)
    rng = np.random.default_rng(11)
    w, m = rng.uniform(1.0, 3.0, 24), np.exp(rng.uniform(np.log(0.1), np.log(10.0), 24))
    dw, dm = 199.0 / 4000, np.log(100.0) / 4000
    label, proved, cut = system.prove_and_cut_boxes(scene, {"omega": w, "m_2": m}, {"omega": w + 16 * dw, "m_2": m * np.exp(16 * dm)})
    assert not proved.any()
    across = cut["omega"] & ~cut["m_2"]
    assert across.mean() >= 0.75, across
    thin = {"omega": w + dw / 2, "m_2": m * np.exp(16 * dm)}
    label, proved, _ = system.prove_and_cut_boxes(scene, {"omega": w, "m_2": m}, thin)
    assert proved.mean() >= 0.75, proved
    for i in np.flatnonzero(proved)[:6]:
        t = rng.random(2)
        pts = point_arrays(scene, {"omega": np.array([w[i] + t[0] * dw / 2]), "m_2": np.array([m[i] * np.exp(t[1] * 16 * dm)])})
        assert exact.decide_points(*pts.kernel_args(), np.arange(1))[0] == label[i]


def test_the_probe_of_an_atlas_decided_cell_by_cell_times_whole_tiles():
    # Chunks are sized by the probe's pace: a point-by-point probe would price a cell-decided atlas at what its
    # nodes cost, and cut it into chunks too small (each a checkpoint write).  The probe times whole tiles instead.
    from stabmap.run.cells import tile_shape
    from stabmap.run.chunks import PROBE_RUNS, tile_locations
    from stabmap.run.tasks import probe_tiles

    scene = resample(stabmap.example("paper-n2-fixed"), omega=70, K_1=45)
    tile = tile_shape(scene)
    where = tile_locations(scene.shape, tile)
    assert where == tile_locations(scene.shape, tile) and len(where) == PROBE_RUNS
    for location in where:
        for (a, b), t, n in zip(location, tile, scene.shape):
            assert a % t == 0 and b == min(n, a + t)
    points, seconds = probe_tiles(scene, where)
    assert points > 0 and seconds > 0


# ------------------------------------------------------------------------ discrete axes and the proofs' spare
def test_a_listed_axis_is_discrete_and_each_slice_has_the_cells_of_its_own_2d_atlas(tmp_path):
    # K_1 = [0, 10, 120] are three cases, not a continuum: no cell spans two of them, so the slice at each listed
    # value holds the labels and cell flags of the 2-D atlas with that value fixed, and its bounds are the value.
    base = resample(stabmap.example("paper-n3-fixed"), omega=48, m_2=40)  # coarse: whole cells only with a larger spare
    values = (0.0, 10.0, 120.0)
    listed = dataclasses.replace(base, grid=(*base.grid, Axis("K_1", values, "values")))
    assert listed.grid[-1].discrete and cells.tile_shape(listed)[-1] == 1
    ds = _atlas(listed, spare=1.0)
    assert np.array_equal(ds["K_1_bounds"].values, np.column_stack([values, values]))
    for k, v in enumerate(values):
        fixed = dataclasses.replace(base, joints=(v, *base.joints[1:]))
        flat = _atlas(fixed, spare=1.0)
        assert np.array_equal(ds["n_complex_pairs"].values[..., k], flat["n_complex_pairs"].values), v
        assert np.array_equal(ds["cell"].values[..., k], flat["cell"].values), v
        assert (flat["cell"].values == WHOLE).any() and (flat["cell"].values == CHANGE).any(), v  # the test means something
    path = tmp_path / "listed.nc"
    stabmap.write_atlas(ds, path)
    assert np.array_equal(xr.load_dataset(path)["K_1_bounds"].values[:, 0], values)


def test_a_scanned_axis_marked_discrete_and_a_list_marked_continuous():
    from stabmap.errors import StabmapError
    from stabmap.scene.grid import parse_axes
    from stabmap.scene.values import Parameter

    any_number = lambda name: Parameter("", "", "")  # noqa: E731
    axes = parse_axes({"a": {"values": [1.0, 2.0]}, "b": {"start": 0.0, "stop": 1.0, "num": 5, "discrete": True},
                       "c": {"values": [1.0, 2.0, 4.0], "discrete": False}, "d": {"start": 0.0, "stop": 1.0, "num": 5}}, any_number)
    assert [a.discrete for a in axes] == [True, True, False, False]
    assert [a.continuous for a in axes] == [False, False, True, True]
    back = parse_axes({a.name: a.to_dict() for a in axes}, any_number)  # the scene stored in a file says the same
    assert back == axes
    with pytest.raises(StabmapError, match=r"grid\.a\.discrete must be true or false"):
        parse_axes({"a": {"values": [1.0, 2.0], "discrete": "yes"}}, any_number)


def test_proofs_beyond_the_nodes_cost_at_most_the_spare_and_what_boxes_saved(monkeypatch):
    # Counted from the calls the system gets, not from the tiles' own accounts: box proofs priced by box_cost, and
    # every label computed at a point that is not a node (the faces of cells beside a change), one node proof each.
    system = stabmap.systems.of(stabmap.example("paper-n3-fixed"))
    made = {"boxes": 0, "points": 0}
    prove, evaluate = type(system).prove_and_cut_boxes, type(system).evaluate

    def counted_prove(self, scene, lower, upper):
        made["boxes"] += len(next(iter(lower.values())))
        return prove(self, scene, lower, upper)

    def counted_evaluate(self, scene, values):
        made["points"] += len(next(iter(values.values())))
        return evaluate(self, scene, values)

    monkeypatch.setattr(type(system), "prove_and_cut_boxes", counted_prove)
    monkeypatch.setattr(type(system), "evaluate", counted_evaluate)
    for num in (20, 64):  # a coarse grid, where boxes fail for their size, and a finer one, where they prove
        scene = resample(stabmap.example("paper-n3-fixed"), omega=num, m_2=num)
        made.update(boxes=0, points=0)
        ds = _atlas(scene, chunk_points=num * num)  # one chunk, no probe
        by_box = int((ds["decided_by"].values == BY_BOX).sum())
        nodes = ds["cell"].size - by_box
        extra = made["boxes"] * system.box_cost(scene) + (made["points"] - nodes)
        assert made["boxes"] > 0 and extra <= cells.SPARE * ds["cell"].size + by_box, (num, made, by_box)


CHUNKED = """
title = "three tops with liquid, four modes each"
support = "fixed"
omega = 40.0
joints = [30.0, 20.0]
""" + "".join(f"""
[[bodies]]
m = {m}
A = {A}
C = {C}
c = {c}
s = {s}
fluid = {{ E = {E}, kappa = {kappa} }}
""" for m, A, C, c, s, E, kappa in (
    (2.0, 0.04, 0.05, 0.2, 0.5, [0.002, 0.0005, 0.0002, 0.0001], [1.6, 3.1, 5.2, 7.7]),
    (1.0, 0.02, 0.03, 0.15, 0.4, [0.001, 0.0002, 0.0001, 0.00005], [1.8, 2.9, 4.8, 8.1]),
    (0.5, 0.01, 0.012, 0.1, 0.3, [0.0005, 0.0001, 0.00005, 0.00002], [1.7, 3.3, 5.5, 7.9]))) + """
[grid]
omega = { start = 1.0, stop = 120.0, num = 240 }
m_2 = { start = 0.2, stop = 4.0, num = 640 }
"""


def test_cells_are_the_same_however_the_grid_is_cut_into_chunks():
    """A system's block of box proofs steers each box by the one before it (Krein boxes: a neighbour's separators
    and pairs), so boxes are proved one tile at a time: a tile's cells then do not depend on which other tiles share
    its chunk, and an atlas is the same cell for cell on one machine, a cluster, or after a resume."""
    scene = stabmap.loads_scene(CHUNKED)
    whole = stabmap.compute_atlas(scene, progress=False, chunk_points=20000)
    assert (whole.cell == cells.WHOLE_CELL).any() and (whole.cell != cells.WHOLE_CELL).any()
    for points in (1024, 60000):
        cut = stabmap.compute_atlas(scene, progress=False, chunk_points=points)
        for name in ("n_complex_pairs", "decided_by", "cell"):
            np.testing.assert_array_equal(whole[name].values, cut[name].values, err_msg=f"{name}, chunks of {points} points")
