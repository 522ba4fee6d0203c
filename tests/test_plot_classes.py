"""What a figure says about its classes: xarray's own plots in stabmap's colours, legends that name unstable classes,
and titles that give the grid points' share, then the share of the scanned area the cells prove (checked against
Maievskii's closed form).
"""

from __future__ import annotations

import re

import matplotlib
import numpy as np
import pytest
import xarray as xr
from matplotlib.colors import to_rgba
from scipy.integrate import quad

import stabmap
from cellspare import spare
from stabmap.errors import StabmapError
from stabmap.read.areas import area_shares
from stabmap.read.plot import atlas_figure, class_label, colour
from stabmap.read.summary import cell_sizes
from stabmap.systems import closed as closed_system
from stabmap.systems import gyroscopes
from stabmap.systems.gyroscopes.outputs import STABILITY, stability_from_pairs
from stabmap.systems.gyroscopes.paper import maievskii_omega

matplotlib.use("Agg")

A, C, M, G = 0.02, 0.03, 1.0, 9.81
W0, W1, C0, C1 = 1.0, 60.0, 0.02, 0.30
DRY_TOP = f"""
title = "one dry top"
support = "fixed"
g = {G}
omega = 20.0

[[bodies]]
m = {M}
A = {A}
C = {C}
c = 0.10

[grid]
omega = {{ start = {W0}, stop = {W1}, num = 150 }}
c_1 = {{ start = {C0}, stop = {C1}, num = 100, scale = "log" }}
"""


@pytest.fixture(scope="module")
def dry():
    """A dry top, spin rate x the height of its centre of mass on a log axis: cells proved by box proofs (a coarse
    grid: with a spare that lets boxes descend, so that the titles have proved shares to give)."""
    with spare(1.0):
        return stabmap.compute_atlas(stabmap.loads_scene(DRY_TOP), threads=1)


def exact_stable_share() -> float:
    """Maievskii: stable where omega >= omega_M(c); its share of the scanned rectangle, by quadrature."""
    above = lambda c: max(0.0, W1 - max(W0, maievskii_omega(A, M, c, C, G)))  # noqa: E731
    return quad(above, C0, C1, limit=200, epsabs=1e-12)[0] / ((W1 - W0) * (C1 - C0))


def numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"(\d+(?:\.\d+)?) %", text)]


# ----------------------------------------------------------------------------------------- xarray's own plots
def facecolours(mesh) -> np.ndarray:
    mesh.figure.canvas.draw()
    return np.asarray(mesh.get_facecolors())


@pytest.mark.parametrize("how", ["accessor", "style"])
def test_xarray_draws_stability_in_the_colours_of_the_maps(dry, how):
    import matplotlib.pyplot as plt

    da = dry.stability
    mesh = da.stabmap.plot() if how == "accessor" else da.plot(**dry.stabmap.style("stability"))
    try:
        got = facecolours(mesh)
        # each cell in the colour stabmap's map gives its N_c (0: stable, 1: one pair, the dry top's only classes)
        nc = dry.n_complex_pairs.transpose(*da.dims).values.ravel()
        assert set(np.unique(nc)) == {0, 1}
        want = np.array([to_rgba(colour(int(v))) for v in nc])
        np.testing.assert_allclose(got, want, atol=1e-6)
        assert [t.get_text() for t in mesh.colorbar.ax.get_yticklabels()] == list(STABILITY.meanings)
    finally:
        plt.close("all")


def test_plain_xarray_colours_differ_which_is_why_the_style_exists(dry):
    import matplotlib.pyplot as plt

    try:
        got = facecolours(dry.stability.plot())
        stable = (dry.stability.values == STABILITY.value("stable")).ravel()
        assert not np.allclose(got[stable], to_rgba(colour(0)), atol=1e-3)
    finally:
        plt.close("all")


def test_xarray_draws_the_label_and_flag_variables_with_named_classes(dry):
    import matplotlib.pyplot as plt

    try:
        mesh = dry.n_complex_pairs.stabmap.plot(x="omega")
        nc = dry.n_complex_pairs.transpose("c_1", "omega").values.ravel()
        np.testing.assert_allclose(facecolours(mesh), [to_rgba(colour(int(v))) for v in nc], atol=1e-6)
        assert [t.get_text() for t in mesh.colorbar.ax.get_yticklabels()] == [class_label(0, gyroscopes.SYSTEM), class_label(1, gyroscopes.SYSTEM)]
        style = dry.decided_by.stabmap.style()  # any flag variable: one colour a flag, its meaning on the colour bar
        assert style["cmap"].N == len(dry.decided_by.attrs["flag_values"])
        assert style["cbar_kwargs"]["format"](6.0) == "box proof"
    finally:
        plt.close("all")


def test_closed_chain_flags_take_the_colours_of_their_meanings():
    flags = closed_system.SYSTEM.variable("stability")
    da = xr.DataArray(np.array([[v for v, _ in flags.flags]] * 2, dtype=np.int8), dims=("y", "x"), name="stability", attrs=flags.attrs())
    style = da.stabmap.style()
    by_meaning = dict(zip(flags.meanings, style["cmap"].colors))
    s = closed_system.SYSTEM
    for meaning, value in (("stable", s.stable_label), ("unstable", 1), ("absent", s.absent_label), ("undecided", s.undecided_label)):
        assert by_meaning[meaning] == colour(value, s.stable_label, s.absent_label, s.undecided_label)
    # flags listed in another order draw the same: each cell in its meaning's colour
    import matplotlib.pyplot as plt

    backwards = da.assign_attrs(flag_values=flags.attrs()["flag_values"][::-1], flag_meanings=" ".join(flags.meanings[::-1]))
    try:
        got = facecolours(backwards.stabmap.plot())
        want = [to_rgba(by_meaning[flags.meaning(int(v))]) for v in da.values.ravel()]
        np.testing.assert_allclose(got, want, atol=1e-6)
    finally:
        plt.close("all")


def test_a_variable_without_classes_is_a_clear_error(dry):
    with pytest.raises(StabmapError, match=r"style\('stabilty'\): no such variable in this atlas; its class variables are: "
                                           r"n_complex_pairs, stability, decided_by, growth_rate_method, cell"):
        dry.stabmap.style("stabilty")
    with pytest.raises(StabmapError, match=r"omega_bounds: stabmap's colours are for class variables.*ds.omega_bounds.plot\(\)"):
        dry.omega_bounds.stabmap.style()
    with pytest.raises(StabmapError, match="stability has one axis; xarray's colour maps need two"):
        dry.stability.isel(c_1=0).stabmap.plot()
    three = xr.concat([dry.stability, dry.stability], dim="K_1")
    with pytest.raises(StabmapError, match=r"stability has 3 axes \(K_1, omega, c_1\).*col='c_1'"):
        three.stabmap.plot()
    grid = three.stabmap.plot(col="K_1")  # panels, as xarray makes them
    try:
        assert grid.axs.size == 2 and all(isinstance(m.norm, matplotlib.colors.BoundaryNorm) for m in grid._mappables)
    finally:
        import matplotlib.pyplot as plt

        plt.close("all")


# ------------------------------------------------------------------------------------------------------ legends
def test_every_unstable_class_says_unstable_in_the_legend():
    gyro = gyroscopes.SYSTEM
    for v in range(-1, 12):
        meaning = STABILITY.meaning(int(stability_from_pairs(np.array([v]))[0]))
        assert ("unstable" in class_label(v, gyro)) == (meaning == "unstable"), class_label(v, gyro)
    closed = closed_system.SYSTEM
    for v, meaning in closed.variable("stability").flags:
        assert ("unstable" in closed.class_name(v)) == (meaning == "unstable")


def test_the_drawn_legend_names_stable_and_unstable(dry):
    fig = atlas_figure(dry)
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert texts[:2] == ["stable (all roots real)", "unstable: 1 complex pair"]


# ------------------------------------------------------------------------------------------------------- titles
def test_title_gives_the_grid_points_then_the_proved_share_of_the_area(dry):
    title = atlas_figure(dry).axes[0].get_title().replace("\n", " ")
    points = 100 * float((dry.n_complex_pairs == 0).mean())
    assert f"{points:.1f} % of {dry.n_complex_pairs.size:,} grid points stable (every point proved);" in title
    assert "of the scanned area" in title and "undecided" not in title
    _, whole, change = numbers(title)
    # the cells' shares from the file's own bounds variables (the cells proved), each cell weighted by its size
    w = np.diff(dry.omega_bounds.values, axis=1)[:, 0]
    h = np.diff(dry.c_1_bounds.values, axis=1)[:, 0]
    area = np.outer(w, h) if dry.stability.dims == ("omega", "c_1") else np.outer(h, w)
    assert whole == pytest.approx(100 * area[dry.cell.values == 1].sum() / area.sum(), abs=0.05)
    assert change == pytest.approx(100 * area[dry.cell.values == 2].sum() / area.sum(), abs=0.05)
    assert 85 < whole < 100 and 0 < change < 15


def test_the_proved_stable_share_of_the_area_brackets_the_closed_form(dry):
    # what panel titles give: on this log axis the grid points' share is another number (80 %, the truth 69 %)
    exact = exact_stable_share()
    d0, d1 = dry.n_complex_pairs.dims
    (s,) = area_shares([dry.n_complex_pairs.values], [dry.cell.values], cell_sizes(dry, d0), cell_sizes(dry, d1), 0)
    assert s.stable + s.unstable + s.change + s.undecided == pytest.approx(1.0)
    # a proof cannot claim more than the truth, and what it leaves undecided holds the rest
    assert s.stable <= exact + 1e-3 and exact - 1e-3 <= s.stable + s.change + s.undecided
    assert s.unstable <= 1 - exact + 1e-3 and 0 < s.change <= s.change + s.undecided < 0.15
    assert abs(float((dry.n_complex_pairs == 0).mean()) - exact) > 0.05


def test_title_counts_grid_points_where_no_cell_is_proved():
    ds = stabmap.compute_atlas(stabmap.loads_scene(DRY_TOP), threads=1, prove_cells=False)
    assert set(np.unique(ds.cell.values)) == {0}  # node_only everywhere
    title = atlas_figure(ds).axes[0].get_title().replace("\n", " ")
    share = 100 * float((ds.n_complex_pairs == 0).mean())
    assert f"{share:.1f} % of {ds.n_complex_pairs.size:,} grid points stable" in title and "area" not in title


def test_panels_give_their_own_shares(dry):
    # two panels: the atlas, and the atlas with every cell node_only (nothing proved over its area)
    k = xr.DataArray([0.0, 1.0], dims="K_1", name="K_1", attrs={"long_name": "stiffness of joint 1", "units": "N m rad-1"})
    both = xr.concat([dry, dry.assign(cell=dry.cell * 0)], dim=k, combine_attrs="override")
    fig = atlas_figure(both.transpose("omega", "c_1", "K_1", ...), facet="K_1")
    one, none = (ax.get_title() for ax in fig.subfigs[0].axes)
    points = round(100 * float((dry.n_complex_pairs == 0).mean()))
    whole = 100 * float(area_shares([dry.n_complex_pairs.values], [dry.cell.values], *(cell_sizes(dry, d) for d in dry.cell.dims), 0)[0].whole)
    assert one.endswith(f"{points} % stable; {whole:.0f} % of area proved") and whole > 85
    assert none.endswith(f"({points} % stable)")  # nothing proved over a cell: no share of the area to give
