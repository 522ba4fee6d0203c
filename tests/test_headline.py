"""The headline (stabmap/read/headline.py): its numbers are the atlas's own, counted here again with numpy from
hand-made Datasets; and cell sizes from the bounds variables, a discrete axis (a list of cases) weighing 1 per case.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import xarray as xr

from stabmap.read.headline import Headline, region_word
from stabmap.read.info import describe
from stabmap.read.summary import cell_sizes, summary
from stabmap.store.dataset import bounds
from stabmap.store.variables import CELL
from stabmap.systems import closed, gyroscopes
from stabmap.systems.gyroscopes.outputs import DECIDED_BY, N_COMPLEX_PAIRS

NODE_ONLY, WHOLE, CHANGE, NOT_PROVED = (CELL.value(m) for m in ("node_only", "whole_cell", "contains_change", "not_proved"))


def atlas(nc: np.ndarray, cell: np.ndarray | None, omega=None, k=None, k_bounds=None) -> xr.Dataset:
    """A gyroscope atlas over (K_1, omega) made by hand, with each axis's CF bounds (``k_bounds``: others for K_1)."""
    ny, nx = nc.shape
    omega = np.geomspace(1.0, 100.0, nx) if omega is None else np.asarray(omega, dtype=float)
    k = np.linspace(0.0, 10.0, ny) if k is None else np.asarray(k, dtype=float)
    coords = {
        "K_1": ("K_1", k, {"units": "N m rad-1", "scale": "linear", "bounds": "K_1_bounds"}),
        "omega": ("omega", omega, {"units": "rad s-1", "scale": "log", "bounds": "omega_bounds"}),
        "K_1_bounds": (("K_1", "bnds"), bounds(k) if k_bounds is None else k_bounds),
        "omega_bounds": (("omega", "bnds"), bounds(omega)),
    }
    dims = ("K_1", "omega")
    data = {"n_complex_pairs": (dims, nc.astype(np.int16), N_COMPLEX_PAIRS.attrs()),
            "decided_by": (dims, np.zeros(nc.shape, np.int8), DECIDED_BY.attrs())}
    if cell is not None:
        data["cell"] = (dims, cell.astype(np.int8), CELL.attrs())
    return xr.Dataset(data, coords=coords, attrs={"title": "hand-made", "stabmap_format_version": 5})


def numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"(\d+(?:\.\d+)?) %", text)]


def area_share(ds: xr.Dataset, mask: np.ndarray) -> float:
    """The share of the scanned area where ``mask`` holds, from the bounds variables (cells weighted by size)."""
    w = np.outer(*(np.abs(np.diff(ds[f"{d}_bounds"].values, axis=1))[:, 0] for d in ds.n_complex_pairs.dims))
    return float(w[mask].sum() / w.sum())


@pytest.fixture
def labels():
    rng = np.random.default_rng(5)
    return rng.integers(0, 3, size=(7, 11))


def test_node_by_node_atlas_counts_grid_points_and_says_no_cell_is_proved(labels):
    ds = atlas(labels, np.full(labels.shape, NODE_ONLY))
    head = summary(ds)["headline"]
    stable = 100 * np.count_nonzero(labels == 0) / labels.size
    assert head == f"{stable:.1f} % of 77 grid points stable (every point proved); cells: nothing proved between grid points"


def test_cell_proved_atlas_gives_the_area_weighted_shares(labels):
    rng = np.random.default_rng(6)
    cell = rng.choice([NODE_ONLY, WHOLE, CHANGE], size=labels.shape, p=[0.2, 0.7, 0.1])
    ds = atlas(labels, cell)
    head = summary(ds)["headline"]
    assert head.startswith(f"{100 * np.mean(labels == 0):.1f} % of 77 grid points stable (every point proved); label proved over ")
    points, whole, change = numbers(head)
    assert whole == pytest.approx(100 * area_share(ds, cell == WHOLE), abs=0.051)
    assert change == pytest.approx(100 * area_share(ds, cell == CHANGE), abs=0.051)
    assert "of the scanned area, a change proved in" in head
    # the log axis crowds grid points at its low end: the area's share is not the points' share
    assert abs(100 * np.mean(cell == WHOLE) - whole) > 0.1


def test_inferred_points_are_named_and_counted(labels):
    cell = np.full(labels.shape, WHOLE)
    cell[::2, ::3] = NOT_PROVED
    cell[1, 1] = CHANGE
    ds = atlas(labels, cell)
    head = summary(ds)["headline"]
    n = int(np.count_nonzero(cell == NOT_PROVED))
    assert f"grid points stable ({n} points inferred, not proved); label proved over " in head
    assert numbers(head)[1] == pytest.approx(100 * area_share(ds, cell == WHOLE), abs=0.051)
    # stabmap info prints the same sentence, before the axes
    text = describe(ds, "a.nc")
    assert " ".join(text.split("  axes:")[0].split()).endswith(head)


def test_atlas_without_cells_gives_only_its_grid_points(labels):
    head = summary(atlas(labels, None))["headline"]
    assert head == f"{100 * np.mean(labels == 0):.1f} % of 77 grid points stable (every point proved)"


def test_other_systems_read_in_their_own_words():
    h = Headline(points=10, stable=None, whole=0.0)
    assert h.text(gyroscopes.SYSTEM) == "10 grid points (every point proved); cells: nothing proved between grid points"
    h = Headline(points=10, stable=3, undecided=1, inferred=2, whole=0.5, change=0.25, axes=3, shown=False)
    assert h.text(closed.SYSTEM) == ("30.0 % of 10 grid points stable (2 points inferred and 1 undecided, not proved); "
                                     "label proved over 50.0 % of the scanned volume, a change proved in 25.0 %")
    h = Headline(points=10, stable=3, undecided=1, whole=0.5, axes=2, shown=True)
    assert h.text(closed.SYSTEM) == ("30.0 % of the 10 grid points shown stable (1 point undecided, not proved); "
                                     "label proved over 50.0 % of the area shown")
    assert [region_word(n) for n in (1, 2, 3, 4)] == ["range", "area", "volume", "volume"]


# ------------------------------------------------------------------------------------------------- cell sizes
def test_cell_sizes_come_from_the_bounds_variable():
    ds = atlas(np.zeros((3, 4), int), None, k=[0.0, 1.0, 3.0], k_bounds=np.array([[0.0, 0.5], [0.5, 2.5], [2.5, 7.0]]))
    np.testing.assert_array_equal(cell_sizes(ds, "K_1"), [0.5, 2.0, 4.5])  # not the midpoints' [0.5, 1.5, 1.0]
    np.testing.assert_allclose(cell_sizes(ds.drop_vars("K_1_bounds"), "K_1"), [0.5, 1.5, 1.0])


def test_a_discrete_axis_weighs_each_of_its_cases_alike():
    # a list of cases: CF bounds with both edges at the value (cells of width 0)
    k = np.array([1.0, 2.0, 50.0])
    nc = np.array([[0, 0, 0, 0], [0, 0, 1, 1], [1, 1, 1, 1]])
    cell = np.array([[WHOLE] * 4, [WHOLE, NODE_ONLY, NODE_ONLY, WHOLE], [NODE_ONLY] * 4])
    ds = atlas(nc, cell, omega=[1.0, 2.0, 3.0, 4.0], k=k, k_bounds=np.column_stack([k, k]))
    np.testing.assert_array_equal(cell_sizes(ds, "K_1"), [1.0, 1.0, 1.0])
    s = summary(ds)
    w = np.abs(np.diff(ds.omega_bounds.values, axis=1))[:, 0]  # the cases are averaged, each over its omega cells
    whole = np.mean([w[row == WHOLE].sum() / w.sum() for row in cell])
    assert s["cell_volume"]["whole_cell"] == pytest.approx(whole)
    # only omega spans the region: the shares are of a range, not of an area
    assert s["headline"].endswith(f"label proved over {100 * whole:.1f} % of the scanned range")


# ------------------------------------------------------------------------------------------------ figure titles
def test_the_figure_title_is_the_headline_of_what_it_shows(labels):
    from stabmap.read.plot import atlas_figure

    cell = np.full(labels.shape, WHOLE)
    cell[::2, ::3] = NOT_PROVED
    ds = atlas(labels, cell)
    title = " ".join(atlas_figure(ds).axes[0].get_title().split())
    assert summary(ds)["headline"] in title  # the whole atlas drawn: the same sentence as stabmap info
    row = 2  # holds inferred points (every other row)
    strip = " ".join(atlas_figure(ds, sel={"K_1": float(ds.K_1[row])}).axes[0].get_title().split())
    w = np.abs(np.diff(ds.omega_bounds.values, axis=1))[:, 0]
    n = int(np.count_nonzero(cell[row] == NOT_PROVED))
    assert (f"{100 * np.mean(labels[row] == 0):.1f} % of the 11 grid points shown stable "
            f"({n} points inferred, not proved); label proved over {100 * w[cell[row] == WHOLE].sum() / w.sum():.1f} % "
            "of the range shown") in strip
