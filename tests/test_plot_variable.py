"""Figures of a float variable (``stabmap plot --var growth_rate``, ``variable_figure``): the colours at the nodes
are the stable colour where every root is proved real and the colour of the rate elsewhere, ordered as the rates;
one free axis gives a line of the atlas's values; big lazy atlases are drawn in blocks no smaller than a pixel that
keep every stability change; and every bad use stops with the parameter named and no file written.

The rates are checked against the closed form of Maievskii's top (tests/scenes.py), where the rate of the pair is
√(4 (A + m c²) m c g − C² ω²) / (2 (A + m c²)) (docs/rates.md).
"""

from __future__ import annotations

import os
import runpy
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgba
from scenes import A, C, G, M, top_toml

import stabmap
from stabmap.cli import main
from stabmap.read import blocks
from stabmap.read.plot import DEGENERATE_COLOUR, STABLE_COLOUR, plot_atlas, variable_figure

SCRIPTS = Path(__file__).resolve().parents[1] / "scripts"
GRID = 'omega = { start = 0.0, stop = 60.0, num = 13 }\nc_1 = { start = 0.02, stop = 0.3, num = 8 }\n'


@pytest.fixture(scope="module")
def tops():
    """Maievskii's top over spin rate x height of the centre of mass: about half of it stable."""
    return stabmap.compute_atlas(stabmap.loads_scene(top_toml(GRID, 'title = "one top"\n')), threads=2, progress=False)


@pytest.fixture(scope="module")
def tops_file(tops, tmp_path_factory):
    return stabmap.write_atlas(tops, tmp_path_factory.mktemp("rates") / "tops.nc")


def closed_rate(omega, c):
    inertia = A + M * c * c
    return np.sqrt(np.maximum(4 * inertia * M * c * G - (C * omega) ** 2, 0.0)) / (2 * inertia)


# ------------------------------------------------------------------------------------------------------ pixels
def pixels(fig) -> np.ndarray:
    """The figure drawn by Agg, as (rows from the top, columns, RGB)."""
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3]


def at_node(image: np.ndarray, ax, x: float, y: float, half: int = 4) -> tuple[int, ...]:
    """The most frequent colour in a square around the data point (x, y) of ``ax``: the fill under a hatch. A node
    on the scan's end (the map's border) is sampled just inside, in its own cell."""
    (left, bottom), (right, top) = ax.transAxes.transform([(0, 0), (1, 1)])
    px, py = ax.transData.transform((x, y))
    px, py = np.clip(px, left + half + 3, right - half - 3), np.clip(py, bottom + half + 3, top - half - 3)
    row, col = int(round(image.shape[0] - py)), int(round(px))
    patch = image[row - half : row + half + 1, col - half : col + half + 1].reshape(-1, 3)
    colours, counts = np.unique(patch, axis=0, return_counts=True)
    return tuple(int(c) for c in colours[np.argmax(counts)])


def rgb(colour) -> tuple[int, ...]:
    return tuple(int(round(255 * c)) for c in to_rgba(colour)[:3])


def close(a, b, tol: int = 3) -> bool:
    return int(np.abs(np.subtract(a, b)).max()) <= tol


def node_colours(fig, ds, var: str = "growth_rate"):
    """(value, colour seen) at every grid node of the map (x = omega, y = c_1)."""
    image = pixels(fig)
    ax = fig.axes[0]
    values = ds[var].transpose("c_1", "omega").values
    return [(float(values[j, i]), at_node(image, ax, w, c)) for j, c in enumerate(ds.c_1.values) for i, w in enumerate(ds.omega.values)]


# ------------------------------------------------------------------------------------------------- the map
def test_stable_nodes_have_the_stable_colour_and_unstable_ones_the_colour_of_their_rate(tops):
    fig = variable_figure(tops, "growth_rate")
    mesh = next(a for a in fig.axes[0].get_children() if a.get_gid() == "values")
    seen = node_colours(fig, tops)
    stable = [colour for rate, colour in seen if rate == 0]
    unstable = [(rate, colour) for rate, colour in seen if rate > 0]
    assert len(stable) > 20 and len(unstable) > 20  # the grid crosses the boundary
    assert all(close(colour, rgb(STABLE_COLOUR)) for colour in stable), stable
    wrong = [(rate, colour) for rate, colour in unstable if not close(colour, rgb(mesh.cmap(mesh.norm(rate))))]
    assert not wrong, f"nodes not in the colour of their rate (rate, colour): {wrong}"
    assert all(not close(colour, rgb(STABLE_COLOUR), 30) for _, colour in unstable)


def test_a_larger_rate_gets_the_colour_of_a_larger_value(tops):
    """The colour seen at each unstable node, located on the colour map, rises with the rate (log scale)."""
    fig = variable_figure(tops, "growth_rate")
    mesh = next(a for a in fig.axes[0].get_children() if a.get_gid() == "values")
    table = np.array([rgb(mesh.cmap(k / 255)) for k in range(256)])
    found = sorted((rate, int(np.abs(table - np.array(colour)).sum(axis=1).argmin()))
                   for rate, colour in node_colours(fig, tops) if rate > 0)
    places = [k for _, k in found]
    assert places == sorted(places) and places[-1] - places[0] > 150
    assert type(mesh.norm).__name__ == "LogNorm" and mesh.norm.vmax == pytest.approx(float(tops.growth_rate.max()))


def test_title_colour_bar_and_legend_say_what_is_drawn(tops):
    fig = variable_figure(tops, "growth_rate")
    ax, bar = fig.axes
    title = ax.get_title().replace("\n", " ").replace("\u00a0", " ")
    rate = tops.growth_rate.values
    j, i = np.unravel_index(np.argmax(rate), rate.shape)  # dims (omega, c_1)
    assert f"max growth rate {rate.max():.3g} s$^{{-1}}$ at $\\omega$ = {float(tops.omega[j]):.4g} rad s$^{{-1}}$" in title
    assert f"$c_{{1}}$ = {float(tops.c_1[i]):.4g} m" in title
    assert f"{100 * (rate == 0).mean():.1f} % of {rate.size:,} grid points stable (growth rate 0)" in title
    assert bar.get_ylabel().replace("\n", " ").startswith("largest growth rate of a perturbation: the largest |Im\u00a0\u03bb|")
    assert bar.get_ylabel().endswith("[s$^{-1}$]")
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert texts == ["stable (all roots real): growth rate 0", "stability boundary"]
    # the axes are the class map's: the scan's ends, labels from the coordinates
    assert ax.get_xlim() == (0.0, 60.0) and ax.get_ylim() == pytest.approx((0.02, 0.3))
    assert ax.get_xlabel() == stabmap.atlas_figure(tops).axes[0].get_xlabel()


def test_the_rates_drawn_are_maievskiis():
    """The colour's value at each unstable node is the closed form's rate (to float32)."""
    ds = stabmap.compute_atlas(stabmap.loads_scene(top_toml(GRID)), threads=2, progress=False)
    want = closed_rate(ds.omega.values[:, None], ds.c_1.values[None, :])
    np.testing.assert_allclose(ds.growth_rate.values, want, rtol=1e-5, atol=1e-6)
    fig = variable_figure(ds, "growth_rate")
    mesh = next(a for a in fig.axes[0].get_children() if a.get_gid() == "values")
    drawn = mesh.get_array().reshape(ds.sizes["c_1"], ds.sizes["omega"])
    np.testing.assert_allclose(np.ma.filled(drawn, 0.0), want.T, rtol=1e-5, atol=1e-6)


def test_the_stability_boundary_runs_on_the_cell_edges_between_rate_0_and_rate_above_0(tops):
    from stabmap.read.plot.geometry import proved_cell_edges

    fig = variable_figure(tops, "growth_rate")
    lines = next(a for a in fig.axes[0].get_children() if a.get_gid() == "stability-boundary")
    stable = tops.growth_rate.transpose("c_1", "omega").values == 0
    xe, ye = proved_cell_edges(tops.omega.values, False), proved_cell_edges(tops.c_1.values, False)
    edges = set()
    for j, i in zip(*np.nonzero(stable[:, 1:] != stable[:, :-1]), strict=True):
        edges.add(("v", round(xe[i + 1], 9), round(ye[j], 9)))
    for j, i in zip(*np.nonzero(stable[1:, :] != stable[:-1, :]), strict=True):
        edges.add(("h", round(ye[j + 1], 9), round(xe[i], 9)))
    drawn = set()
    for (x0, y0), (x1, y1) in (seg for seg in lines.get_segments()):
        if x0 == x1:  # a vertical run: one edge a cell
            drawn |= {("v", round(x0, 9), round(y, 9)) for y in ye[:-1] if min(y0, y1) - 1e-12 <= y < max(y0, y1) - 1e-12}
        else:
            drawn |= {("h", round(y0, 9), round(x, 9)) for x in xe[:-1] if min(x0, x1) - 1e-12 <= x < max(x0, x1) - 1e-12}
    assert edges and drawn == edges


def test_efolding_time_infinite_where_stable_is_drawn_stable(tops):
    fig = variable_figure(tops, "efolding_time")
    seen = node_colours(fig, tops, "efolding_time")
    assert all(close(colour, rgb(STABLE_COLOUR)) for value, colour in seen if np.isinf(value))
    assert not any(close(colour, rgb(STABLE_COLOUR), 30) for value, colour in seen if np.isfinite(value))
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert legend[0] == "stable (all roots real): e-folding time \u221e"


def test_points_without_a_value_are_grey_and_hatched(tops):
    """NaN (an inferred or degenerate point: not computed) is the class map's grey, cross-hatched, in the legend."""
    ds = tops.copy(deep=True)
    ds["growth_rate"][{"omega": slice(0, 3), "c_1": slice(5, 8)}] = np.nan
    fig = variable_figure(ds, "growth_rate")
    seen = node_colours(fig, ds)
    nan = [colour for value, colour in seen if np.isnan(value)]
    assert len(nan) == 9 and all(close(colour, rgb(DEGENERATE_COLOUR)) for colour in nan)
    ax = fig.axes[0]
    assert next(a for a in ax.get_children() if a.get_gid() == "no-value-hatch").get_hatch()
    assert "no value (NaN): not computed or degenerate" in [t.get_text() for t in ax.get_legend().get_texts()]
    assert "9 without a value (NaN)" in ax.get_title().replace("\u00a0", " ")


# ------------------------------------------------------------------------------------------------ the line
@pytest.mark.parametrize("one_axis", [True, False])
def test_one_free_axis_is_a_line_of_the_atlas_values_without_a_colour_bar(tops, one_axis):
    if one_axis:
        ds = stabmap.compute_atlas(stabmap.loads_scene(top_toml("omega = { start = 0.0, stop = 40.0, num = 21 }\n")), progress=False)
        fig, line_ds = variable_figure(ds, "growth_rate"), ds
    else:
        fig, line_ds = variable_figure(tops, "growth_rate", sel={"c_1": 0.14}), tops.sel(c_1=0.14, method="nearest")
    assert len(fig.axes) == 1  # no colour bar
    ax = fig.axes[0]
    assert ax.get_yscale() == "log"
    (line,) = [a for a in ax.get_lines() if a.get_gid() == "values"]
    rate = line_ds.growth_rate.values
    np.testing.assert_array_equal(line.get_xdata(), line_ds.omega.values)
    got = np.asarray(line.get_ydata(), dtype=float)
    np.testing.assert_array_equal(got[rate > 0], rate[rate > 0])
    assert np.isnan(got[rate == 0]).all() and (rate == 0).any() and (rate > 0).any()
    kinds = {a.get_gid() for a in ax.get_children()}
    assert {"stable-cells", "stability-boundary", "enclosure"} <= kinds
    labels = [t.get_text().replace("\n", " ") for t in fig.legends[0].get_texts()]
    assert labels[0] == "growth rate" and labels[-1] == "stability boundary"
    assert "stable (all roots real): growth rate 0" in labels
    assert any(t.startswith("proved enclosure, lower to upper bound") for t in labels)


def test_the_band_is_the_proved_enclosure(tops):
    fig = variable_figure(tops, "growth_rate", sel={"c_1": 0.3})
    band = next(a for a in fig.axes[0].get_children() if a.get_gid() == "enclosure")
    one = tops.sel(c_1=0.3, method="nearest")
    lo, hi = band.get_paths()[0].vertices[:, 1].min(), band.get_paths()[0].vertices[:, 1].max()
    up = one.growth_rate_upper.values
    assert lo == pytest.approx(float(one.growth_rate_lower.values[up > 0].min()))
    assert hi == pytest.approx(float(up.max()))


# ----------------------------------------------------------------------------------------- big atlases
@settings(max_examples=30, deadline=None)
@given(arrays(np.int16, st.tuples(st.integers(1, 13), st.integers(1, 15)), elements=st.integers(-1, 2)),
       st.integers(2, 5), st.integers(2, 5), st.integers(1, 4), st.integers(1, 4), st.integers(0, 2**31))
def test_value_blocks_against_brute_force(labels, rows, cols, fy, fx, seed):
    rng = np.random.default_rng(seed)
    values = np.where(labels == 0, 0.0, rng.random(labels.shape) * 10).astype(np.float32)
    values[labels < 0] = np.nan
    got = blocks.reduce_values(blocks.as_dask(values).rechunk((rows, cols)), blocks.as_dask(labels).rechunk((cols, rows)), 0, (fy, fx))
    ny, nx = -(-labels.shape[0] // fy), -(-labels.shape[1] // fx)
    for j in range(ny):
        for i in range(nx):
            v, lab = values[j * fy : (j + 1) * fy, i * fx : (i + 1) * fx], labels[j * fy : (j + 1) * fy, i * fx : (i + 1) * fx]
            shown = v[np.isfinite(v) & (v > 0)]
            assert np.array_equal(got.top["log"][j, i], shown.max() if shown.size else np.nan, equal_nan=True)
            assert got.off["log"][j, i] == ((lab == 0) & (v == 0)).any()
            assert got.state[j, i] == (2 if (lab == 0).any() and not (lab == 0).all() else int((lab == 0).all()))
    s = got.stats
    assert (s.points, s.nan, s.off["log"]) == (values.size, int(np.isnan(values).sum()), int((labels == 0).sum()))
    if np.isfinite(values).any():
        assert values[s.argmax] == np.nanmax(values)


@pytest.fixture(scope="module")
def big(tmp_path_factory):
    """A synthetic 2400 x 900 atlas (scripts/bench_read.py): more points than the map has pixels, an unstable line
    one grid value thin across its stable region, a degenerate and an inferred patch (NaN rates)."""
    make_atlas = runpy.run_path(str(SCRIPTS / "bench_read.py"))["make_atlas"]
    ds = stabmap.open_atlas(make_atlas(tmp_path_factory.mktemp("big") / "atlas.nc", (2400, 900)), lazy=True)
    yield ds
    ds.close()


def test_a_big_map_is_drawn_in_blocks_no_smaller_than_pixels_and_says_so(big):
    fig = variable_figure(big, "growth_rate")
    ax = fig.axes[0]
    title = ax.get_title().replace("\n", " ")
    assert "2,400 × 900 grid points drawn in blocks of" in title
    assert "a block shows the largest growth rate of its points" in title
    fig.set_dpi(150)
    fig.draw_without_rendering()
    box = ax.get_window_extent()
    rows, cols = next(a for a in ax.get_children() if a.get_gid() == "values").get_array().shape
    assert cols <= box.width and rows <= box.height  # no block is smaller than a pixel
    assert cols > box.width / 2 and rows > box.height / 2  # ... and not much larger


def test_a_thin_unstable_line_stays_visible_in_a_big_map(big):
    """One omega grid value of N_c = 1 across the stable region, far below a pixel: drawn black across the map."""
    fig = variable_figure(big, "growth_rate")
    fig.set_dpi(150)
    image = pixels(fig)
    ax = fig.axes[0]
    omega = float(big["omega"][int(0.8 * (big.sizes["omega"] - 1))])
    x, _ = ax.transData.transform((omega, 0))
    box = ax.get_window_extent()
    top, bottom = image.shape[0] - int(box.y1) + 2, image.shape[0] - int(box.y0) - 2
    band = image[top:bottom, int(x) - 2 : int(x) + 3]
    assert (band.max(axis=2) < 40).any(axis=1).all()


def test_a_big_line_is_reduced_to_its_largest_value_per_block(big):
    fig = variable_figure(big, "growth_rate", sel={"K_1": 3.0})
    assert "2,400 grid points drawn in blocks of" in fig.axes[0].get_title().replace("\n", " ")
    steps = next(a for a in fig.axes[0].get_children() if a.get_gid() == "values")
    values, edges, _ = steps.get_data()
    assert len(values) <= fig.axes[0].get_window_extent().width
    rate = big.growth_rate.sel(K_1=3.0, method="nearest").values
    assert np.nanmax(values) == pytest.approx(float(np.nanmax(rate)))


# ------------------------------------------------------------------------------------------- files, CLI
def test_cli_draws_png_and_vector_pdf(tops_file, tmp_path):
    png, pdf = tmp_path / "g.png", tmp_path / "g.pdf"
    assert main(["plot", str(tops_file), "--var", "growth_rate", "-o", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["plot", str(tops_file), "c_1=0.1", "--var", "efolding_time", "-o", str(pdf)]) == 0
    data = pdf.read_bytes()
    assert data[:5] == b"%PDF-" and b"/Subtype /Image" not in data
    assert sorted(os.listdir(tmp_path)) == ["g.pdf", "g.png"]


@pytest.fixture(scope="module")
def without_rates(tmp_path_factory):
    scene = stabmap.loads_scene(top_toml(GRID, "growth_rate = false\n"))
    return stabmap.write_atlas(stabmap.compute_atlas(scene, progress=False), tmp_path_factory.mktemp("norates") / "plain.nc")


@pytest.fixture(scope="module")
def three_axes(tmp_path_factory):
    grid = GRID + "m_1 = { values = [0.5, 1.0] }\n"
    return stabmap.write_atlas(stabmap.compute_atlas(stabmap.loads_scene(top_toml(grid)), progress=False),
                               tmp_path_factory.mktemp("three") / "three.nc")


@pytest.fixture(scope="module")
def critical_file(tmp_path_factory):
    scene = stabmap.loads_scene(top_toml("omega = { start = 1.0, stop = 60.0, num = 9 }\nc_1 = { values = [0.1, 0.2] }\n"))
    return stabmap.write_atlas(stabmap.critical(scene, rtol=1e-6, progress=False), tmp_path_factory.mktemp("critical") / "c.nc")


@pytest.mark.parametrize(
    "atlas, name, args, message",
    [
        ("without_rates", "g.png", ["--var", "growth_rate"],
         "--var growth_rate: the atlas has no growth_rate: it was computed with growth_rate = false; rerun without it; "
         "this atlas holds no float variable to draw"),
        ("without_rates", "g.png", ["--var", "efolding_time"], "it was computed with growth_rate = false; rerun without it"),
        ("tops_file", "g.png", ["--var", "nope"],
         "--var nope: not a variable of this atlas; variables to draw: growth_rate, growth_rate_lower, growth_rate_upper, efolding_time"),
        ("tops_file", "g.png", ["--var", "growth_rate_method"], "--var growth_rate_method: a flag variable, classes rather than values; "
                                                                 "draw the class map without --var"),
        ("tops_file", "g.png", ["--var", "n_complex_pairs"], "--var n_complex_pairs: the atlas's label"),
        ("tops_file", "g.png", ["--var", "omega"], "--var omega: a coordinate"),
        ("tops_file", "g.html", ["--var", "growth_rate"], "--var draws PNG and PDF figures; an .html page shows the classes"),
        ("tops_file", "g.png", ["--var", "growth_rate", "--facet", "c_1"], "--facet applies to the class map; --var growth_rate draws one map"),
        ("tops_file", "g.png", ["--var", "growth_rate", "--max-panels", "3"], "--max-panels applies to the class map"),
        ("three_axes", "g.png", ["--var", "growth_rate"],
         "--var growth_rate draws one map of at most two axes, and 3 are free (omega, c_1, m_1): fix m_1 with --sel m_1=VALUE"),
        ("critical_file", "g.png", ["--var", "growth_rate"], "--var applies to atlases"),
    ],
)
def test_cli_errors_name_the_parameter_and_write_nothing(request, tmp_path, capsys, atlas, name, args, message):
    out = tmp_path / name
    assert main(["plot", str(request.getfixturevalue(atlas)), "-o", str(out), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err, err
    assert os.listdir(tmp_path) == []


def test_python_errors_name_the_parameters_as_python_spells_them(tops, tmp_path):
    with pytest.raises(stabmap.StabmapError, match=r"^var='nope': not a variable of this atlas; variables to draw: growth_rate"):
        variable_figure(tops, "nope")
    with pytest.raises(stabmap.StabmapError, match=r"^facet applies to the class map; var='growth_rate' draws one map"):
        plot_atlas(tops, tmp_path / "g.png", var="growth_rate", facet="c_1")
    with pytest.raises(stabmap.StabmapError, match=r"^x='nope': not an axis of this atlas"):
        variable_figure(tops, "growth_rate", x="nope")
    assert os.listdir(tmp_path) == []


def test_a_map_or_line_with_no_rate_to_colour_draws_stable_and_says_so(tops, tmp_path):
    """Every point stable (rate 0): no colour bar, no maximum in the title, a line plot with an empty y axis; every
    point without a value: grey, and no point drawn stable."""
    stable = tops.sel(omega=slice(45.0, 60.0))
    assert (stable.growth_rate == 0).all()
    fig = variable_figure(stable, "growth_rate")
    assert len(fig.axes) == 1 and "max" not in fig.axes[0].get_title()
    assert "100.0 % of 32 grid points stable (growth rate 0)" in fig.axes[0].get_title().replace("\u00a0", " ").replace("\n", " ")
    plot_atlas(stable, tmp_path / "line.png", var="growth_rate", sel={"c_1": 0.1})  # a log axis over nothing is not drawn
    empty = stable.copy(deep=True)
    empty["growth_rate"][:] = np.nan
    title = variable_figure(empty, "growth_rate").axes[0].get_title().replace("\u00a0", " ").replace("\n", " ")
    assert "no finite growth rate" in title and "no grid point drawn stable" in title and "32 without a value (NaN)" in title
