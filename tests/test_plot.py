"""Pictures of atlases (stabmap.read.plot): boundaries on cell edges, facets, axes, legend, files and bad options.

The boundary tests compare the segments actually drawn with a brute-force list of the grid-cell edges
between neighbouring points whose N_c differ, on hand-made maps with log and irregular axes.
"""

from __future__ import annotations

import os
import re

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from matplotlib.colors import to_rgba

import stabmap
from stabmap.cli import main
from stabmap.errors import cli_spelling
from stabmap.read.plot import (
    atlas_figure,
    axis_label,
    cell_edge_boundaries,
    class_label,
    colour,
    fixed_caption,
    plan_figure,
    plot_atlas,
)
from stabmap.systems.gyroscopes import SYSTEM as GYRO
from stabmap.systems.gyroscopes.outputs import DECIDED_BY, N_COMPLEX_PAIRS

COORD_ATTRS = {
    "omega": {"long_name": "common spin rate", "units": "rad s-1"},
    "m_2": {"long_name": "mass of body 2 (liquid included)", "units": "kg"},
    "K_1": {"long_name": "stiffness of joint 1", "units": "N m rad-1"},
    "g": {"long_name": "gravitational acceleration", "units": "m s-2"},
}


def hand_atlas(axes: dict[str, tuple[np.ndarray, str]], nc: np.ndarray, decided_by: np.ndarray | None = None, title="hand-made") -> xr.Dataset:
    """An atlas Dataset built by hand: ``axes`` maps a name to (values, scale), in dimension order."""
    dims = tuple(axes)
    coords = {d: (d, np.asarray(v, dtype=float), {**COORD_ATTRS[d], "scale": s}) for d, (v, s) in axes.items()}
    if decided_by is None:
        decided_by = np.zeros(nc.shape, dtype=np.int8)
    data = {
        "n_complex_pairs": (dims, nc.astype(np.int16), N_COMPLEX_PAIRS.attrs()),
        "decided_by": (dims, decided_by.astype(np.int8), DECIDED_BY.attrs()),
    }
    return xr.Dataset(data, coords=coords, attrs={"title": title, "stabmap_format_version": 3})


def brute_force_edges(values: np.ndarray) -> tuple[set, set]:
    """Unit cell edges between neighbours that differ: ('v', j, i) between (j, i) and (j, i+1); ('h', j, i) between
    (j, i) and (j+1, i). First set: exactly one side stable; second: N_c differs otherwise."""
    stab, other = set(), set()
    ny, nx = values.shape
    for j in range(ny):
        for i in range(nx):
            for kind, jj, ii in (("v", j, i + 1), ("h", j + 1, i)):
                if jj >= ny or ii >= nx:
                    continue
                a, b = int(values[j, i]), int(values[jj, ii])
                if (a == 0) != (b == 0):
                    stab.add((kind, j, i))
                elif a != b:
                    other.add((kind, j, i))
    return stab, other


def unit_edges(segments: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> list:
    """Split drawn segments back into unit cell edges (a list, so that an edge drawn twice would show)."""
    xi = {float(v): k for k, v in enumerate(xe)}
    yi = {float(v): k for k, v in enumerate(ye)}
    out = []
    for (x0, y0), (x1, y1) in np.asarray(segments).reshape(-1, 2, 2):
        if x0 == x1:  # vertical: on column edge xi, from row edge a to b
            k, a, b = xi[float(x0)], yi[float(y0)], yi[float(y1)]
            out += [("v", j, k - 1) for j in range(min(a, b), max(a, b))]
        else:
            assert y0 == y1, "a boundary segment must be horizontal or vertical"
            k, a, b = yi[float(y0)], xi[float(x0)], xi[float(x1)]
            out += [("h", k - 1, i) for i in range(min(a, b), max(a, b))]
    return out


def panels_of(fig):
    """Small multiples live in the left subfigure (with their title), the legend in the right one."""
    return fig.subfigs[0]


def legend_of(fig):
    return (fig.legends or fig.subfigs[1].legends)[0]


def drawn(ax, gid: str):
    found = [a for a in ax.get_children() if a.get_gid() == gid]
    return found


# ------------------------------------------------------------------------------------------------ boundaries
@settings(max_examples=60, deadline=None)
@given(arrays(np.int16, st.tuples(st.integers(1, 6), st.integers(1, 6)), elements=st.integers(-1, 3)))
def test_boundary_segments_are_the_differing_cell_edges(values):
    xe = np.cumsum(np.r_[0.0, np.arange(1, values.shape[1] + 1) ** 1.5])  # irregular edges
    ye = np.geomspace(0.1, 100.0, values.shape[0] + 1)
    stab, other = cell_edge_boundaries(values, xe, ye)
    want_stab, want_other = brute_force_edges(values)
    got_stab, got_other = unit_edges(stab, xe, ye), unit_edges(other, xe, ye)
    assert sorted(got_stab) == sorted(want_stab) and len(got_stab) == len(set(got_stab))
    assert sorted(got_other) == sorted(want_other) and len(got_other) == len(set(got_other))


def test_drawn_boundaries_on_log_and_values_axes_match_brute_force():
    rng = np.random.default_rng(7)
    omega = np.array([1.0, 2.0, 5.0, 20.0, 21.0, 60.0, 100.0])  # a non-uniform "values" axis
    m2 = np.geomspace(0.1, 10.0, 9)
    base = (np.add.outer(np.arange(7), np.arange(9)) // 3).clip(0, 3)
    nc = np.where(rng.random((7, 9)) < 0.15, -1, base)
    ds = hand_atlas({"omega": (omega, "values"), "m_2": (m2, "log")}, nc)
    fig = atlas_figure(ds)
    ax = fig.axes[0]
    assert ax.get_xscale() == "linear" and ax.get_yscale() == "log"
    # the cells the atlas proves its labels on (its bounds): midpoints, on the log axis too, ending at the scan's ends
    xe = np.r_[1.0, (omega[1:] + omega[:-1]) / 2, 100.0]
    ye = np.r_[m2[0], (m2[1:] + m2[:-1]) / 2, m2[-1]]
    values = nc.T  # rows along y = m_2
    want_stab, want_other = brute_force_edges(values)
    (stab,), (other,) = drawn(ax, "stability-boundary"), drawn(ax, "class-boundary")
    snap = lambda segs: np.array([[[_near(xe, p[0]), _near(ye, p[1])] for p in s] for s in segs])  # noqa: E731
    got_stab = unit_edges(snap(stab.get_segments()), xe, ye)
    got_other = unit_edges(snap(other.get_segments()), xe, ye)
    assert want_stab and want_other
    assert sorted(got_stab) == sorted(want_stab) and sorted(got_other) == sorted(want_other)
    assert max(stab.get_linewidth()) > max(other.get_linewidth())  # stable/unstable drawn thicker
    np.testing.assert_allclose(ax.get_xlim(), (xe[0], xe[-1]))
    np.testing.assert_allclose(ax.get_ylim(), (ye[0], ye[-1]))


def _near(edges: np.ndarray, v: float) -> float:
    k = int(np.argmin(np.abs(edges - v)))
    assert np.isclose(edges[k], v, rtol=1e-12), f"{v} is not a cell edge"
    return float(edges[k])


# ------------------------------------------------------------------------------------- classes, legend, cells
def test_legend_has_one_entry_per_class_present_and_fixed_colours():
    nc = np.array([[0, 0, 1, 3], [0, 1, 1, 3], [-1, 1, 3, 3]])
    by = np.array([[0, 3, 3, 0], [0, 3, 3, 0], [0, 0, 0, 0]])
    ds = hand_atlas({"K_1": ([0.0, 5.0, 10.0], "linear"), "omega": ([1.0, 2.0, 3.0, 4.0], "linear")}, nc, by)
    fig = atlas_figure(ds)
    labels = [t.get_text() for t in legend_of(fig).get_texts()]
    assert labels == [class_label(v, GYRO) for v in (-1, 0, 1, 3)] + ["stability boundary", "N$_c$ changes", "inferred from cell\ncorners (not computed)"]
    assert labels[1] == "stable (all roots real)" and labels[2] == "unstable: 1 complex pair" and labels[3] == "unstable: 3 complex pairs"
    ax = fig.axes[0]
    for v in (-1, 0, 1, 3):  # class colours do not depend on which classes are present
        (cells,) = drawn(ax, f"cells-{v}")
        assert tuple(cells.get_facecolor()[0]) == to_rgba(colour(v))
    assert colour(0) == "#56B4E9" and len({colour(v) for v in range(-1, 9)}) == 10
    # hatches cover exactly the inferred and the degenerate cells (x = K_1 is the first axis)
    xc, yc = np.meshgrid([1.25, 5.0, 8.75], [1.25, 2.0, 3.0, 3.75])  # the middles of the cells (K_1 = 0, 5, 10; y = 1 .. 4)
    centres = np.column_stack([xc.ravel(), yc.ravel()])
    for gid, mask in (("inferred-cells", by.T == 3), ("degenerate-cells", nc.T == -1)):
        (patch,) = drawn(ax, gid)
        assert patch.get_hatch()
        np.testing.assert_array_equal(patch.get_path().contains_points(centres).reshape(mask.shape), mask)
    title = ax.get_title()
    assert "hand-made" in title and "25.0 % of 12 grid points stable" in title


def test_single_class_map_draws_no_boundary():
    ds = hand_atlas({"omega": ([1.0, 2.0, 3.0], "linear"), "m_2": ([1.0, 2.0], "log")}, np.zeros((3, 2), dtype=int))
    fig = atlas_figure(ds)
    assert [t.get_text() for t in legend_of(fig).get_texts()] == ["stable (all roots real)"]
    assert all(len(c.get_segments()) == 0 for c in drawn(fig.axes[0], "stability-boundary") + drawn(fig.axes[0], "class-boundary"))
    assert "100.0 % of 6 grid points stable" in fig.axes[0].get_title()


def test_one_free_axis_draws_the_label_as_a_line():
    """One free axis: N_c against it as a line (its grid values on the y axis, not a strip with an empty y axis),
    over its classes' colours, with the stability boundary between the stretches; the growth rate beneath where the
    atlas stores it, on the same x axis."""
    nc = np.array([0, 0, 1, 1, 2, 0])
    ds = hand_atlas({"omega": (np.linspace(0, 10, 6), "linear")}, nc)
    fig = atlas_figure(ds)
    (ax,) = fig.axes
    assert [int(v) for v in ax.get_yticks()] == [0, 1, 2] and "N" in ax.get_ylabel()
    (line,) = [a for a in ax.patches if a.get_gid() == "label-line"]  # stairs: one step a grid point, at its N_c
    np.testing.assert_array_equal(line.get_data().values, nc)
    np.testing.assert_array_equal(line.get_data().edges, [0, 1, 3, 5, 7, 9, 10])
    (stab,) = drawn(ax, "stability-boundary")
    xs = sorted(float(s[0][0]) for s in stab.get_segments())
    assert xs == [3.0, 9.0]  # between omega = 2|4 and 8|10
    assert all(s[0][0] == s[1][0] for s in stab.get_segments())

    growth = np.where(nc > 0, nc * 0.5, 0.0)
    ds["growth_rate"] = ("omega", growth, {"long_name": "largest growth rate", "units": "s-1"})
    fig = atlas_figure(ds)
    top, bottom = fig.axes
    assert bottom.get_shared_x_axes().joined(top, bottom) and "growth rate" in bottom.get_ylabel()
    (values,) = [a for a in bottom.lines if a.get_gid() == "values"]
    np.testing.assert_array_equal(values.get_ydata()[nc > 0], growth[nc > 0])
    assert "growth rate" in [t.get_text() for t in legend_of(fig).get_texts()]


def test_one_free_axis_of_a_flag_label_names_its_classes():
    """A closed chain's label is a flag variable, whose codes order nothing (absent is -2): its line's y ticks are the
    classes' names, not the codes."""
    import stabmap
    from stabmap.scene.grid import resample

    ds = stabmap.compute_atlas(resample(stabmap.example("closed-hinge"), ratio=24), threads=1, progress=False)
    (ax,) = atlas_figure(ds).axes
    names = [t.get_text() for t in ax.get_yticklabels()]
    assert "stable" in names and "unstable" in names and "absent (no equilibrium)" in names, names
    assert not any(n.lstrip("\u2212-").isdigit() for n in names), names


# --------------------------------------------------------------------------------------------- real atlases
SCENE = """
title = "two tops, tiny grid"
support = "fixed"
g = 9.81
omega = 50.0
joints = [20.0]

[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25
fluid = { E = [1e-3], kappa = [1.31] }

[[bodies]]
m = 0.5
A = 0.01
C = 0.015
c = 0.08

[grid]
omega = { start = 1.0, stop = 150.0, num = 12 }
m_2 = { start = 0.1, stop = 5.0, num = 9, scale = "log" }
K_1 = { values = [0.0, 10.0, 20.0, 50.0, 100.0] }
"""


@pytest.fixture(scope="module")
def atlas3():
    return stabmap.compute_atlas(stabmap.loads_scene(SCENE), threads=2, progress=False)


@pytest.fixture(scope="module")
def atlas3_file(atlas3, tmp_path_factory):
    return stabmap.write_atlas(atlas3, tmp_path_factory.mktemp("plot") / "a3.nc")


def test_two_axes_map_is_axes_zero_in_grid_coordinates(atlas3):
    fig = atlas_figure(atlas3, sel={"K_1": 12.0})
    ax = fig.axes[0]
    assert len(fig.axes) == 1
    assert ax.get_xscale() == "linear" and ax.get_yscale() == "log"
    assert ax.get_xlabel() == "common spin rate $\\omega$ [rad\u00a0s$^{-1}$]"
    assert ax.get_ylabel() == "mass of body 2 $m_{2}$ [kg]"
    assert ax.get_xlim() == (1.0, 150.0)  # the scan's ends: nothing is drawn beyond what was computed
    assert "$K_{1}$\u00a0=\u00a010\u00a0N\u00a0m\u00a0rad$^{-1}$\u00a0(nearest\u00a0to\u00a012)" in ax.get_title()
    limits = ax.get_xlim(), ax.get_ylim()
    ax.plot([-1e3, 1e3], [1e-3, 1e3])  # an overlaid curve does not move the map
    assert (ax.get_xlim(), ax.get_ylim()) == limits
    fig = atlas_figure(atlas3, sel={"K_1": 0.0}, x="m_2")
    assert fig.axes[0].get_xscale() == "log" and fig.axes[0].get_yscale() == "linear"


def test_facets_one_panel_per_value_with_titles(atlas3):
    fig = atlas_figure(atlas3)  # x = omega, y = m_2, panels over K_1
    assert len(fig.axes) == 5 and len(fig.legends) == 0 and len(fig.subfigs[1].legends) == 1
    titles = [ax.get_title() for ax in fig.axes]
    for ax, title, k in zip(fig.axes, titles, [0, 10, 20, 50, 100]):
        assert title.startswith(f"$K_{{1}}$ = {k:g} N\u00a0m\u00a0rad$^{{-1}}$")
        values = atlas3["n_complex_pairs"].sel(K_1=k).values
        assert f"({100 * np.mean(values == 0):.0f} % stable)" in title
        assert ax.get_yscale() == "log"
    assert "panels: stiffness of joint 1" in panels_of(fig).get_suptitle()
    assert "of 5 values drawn" not in panels_of(fig).get_suptitle()
    labels = [t.get_text() for t in legend_of(fig).get_texts()]
    present = sorted(int(v) for v in np.unique(atlas3["n_complex_pairs"]))
    assert labels[: len(present)] == [class_label(v, GYRO) for v in present]


def test_facets_subset_and_choice(atlas3):
    fig = atlas_figure(atlas3, max_panels=3)
    assert [ax.get_title().split("  ")[0] for ax in fig.axes] == [f"$K_{{1}}$ = {k:g} N\u00a0m\u00a0rad$^{{-1}}$" for k in (0, 20, 100)]
    assert "K_1: 3 of 5 values drawn, evenly spaced" in panels_of(fig).get_suptitle()
    fig = atlas_figure(atlas3, facet="omega", max_panels=4)
    assert len(fig.axes) == 4
    assert fig.axes[0].get_xlabel() == "" and panels_of(fig).get_supxlabel() == "mass of body 2 $m_{2}$ [kg]"
    assert "stiffness of joint 1" in panels_of(fig).get_supylabel()
    assert fig.axes[0].get_xscale() == "log" and fig.axes[0].get_yscale() == "linear"  # x = m_2, y = K_1
    assert plan_figure(atlas3, facet="omega", max_panels=4).facet_index == (0, 4, 7, 11)
    fig = atlas_figure(atlas3, x="K_1", y="omega")
    assert len(fig.axes) == 9 and panels_of(fig).get_suptitle().count("panels: mass of body 2") == 1


def test_four_axes_rows_and_columns():
    shape = (4, 3, 7, 5)
    nc = (np.indices(shape).sum(axis=0) % 3).astype(int)
    ds = hand_atlas(
        {"omega": (np.linspace(1, 4, 4), "linear"), "m_2": ([0.1, 1.0, 10.0], "log"), "K_1": (np.arange(7.0), "linear"), "g": (np.linspace(1, 5, 5), "linear")},
        nc,
    )
    plan = plan_figure(ds)
    assert (plan.x, plan.y, plan.facet, plan.row) == ("omega", "m_2", "K_1", "g")
    assert len(plan.facet_index) * len(plan.row_index) <= 12 and (len(plan.row_index), len(plan.facet_index)) == (3, 4)
    fig = atlas_figure(ds)
    assert len(fig.axes) == 12
    assert fig.axes[5].get_title().startswith("$K_{1}$ = 2 N\u00a0m\u00a0rad$^{-1}$, $g$ = 3 m\u00a0s$^{-2}$")
    assert "g: 3 of 5 values drawn" in panels_of(fig).get_suptitle() and "K_1: 4 of 7 values drawn" in panels_of(fig).get_suptitle()
    assert len(atlas_figure(ds, max_panels=1).axes) == 1
    five = ds.expand_dims(C_1=[0.01, 0.02]).assign_coords(C_1=("C_1", [0.01, 0.02], {"long_name": "axial", "units": "kg m2", "scale": "linear"}))
    plan = plan_figure(five.transpose("omega", "m_2", "K_1", "g", "C_1"))
    assert plan.fixed == {"C_1": (0, None)} and "C_1 fixed at its first value" in plan.notes[-1]


def test_errors_and_notes_name_parameters_as_python_or_the_command_line_spells_them(atlas3):
    """One message each way: ``x='foo'`` from Python, ``--x foo`` under the CLI's spelling (stabmap.errors)."""
    cases = [
        ({"x": "foo"}, "x='foo': not an axis of this atlas; choose from omega, m_2, K_1", "--x foo: not an axis"),
        ({"max_panels": 0}, "max_panels must be a whole number >= 1, got 0", "--max-panels must be a whole number >= 1"),
        ({"sel": {"nope": 1.0}}, "sel={'nope': ...}: not an axis of this atlas", "--sel nope=...: not an axis"),
        ({"x": "K_1", "sel": {"K_1": 10.0}}, "x='K_1': this axis is also fixed by sel={'K_1': ...}",
         "--x K_1: this axis is also fixed by --sel K_1=...; drop one of the two"),
    ]
    for options, python, cli in cases:
        with pytest.raises(stabmap.StabmapError, match=re.escape(python)):
            plan_figure(atlas3, **options)
        with cli_spelling(), pytest.raises(stabmap.StabmapError, match=re.escape(cli)):
            plan_figure(atlas3, **options)
    assert plan_figure(atlas3, max_panels=2).notes[0].endswith("(more with max_panels, now 2; one with sel)")
    with cli_spelling():
        assert plan_figure(atlas3, max_panels=2).notes[0].endswith("(more with --max-panels, now 2; one with --sel)")
    five = atlas3[["n_complex_pairs"]].expand_dims(p=[1.0, 2.0], q=[1.0, 2.0])  # p, q, omega, m_2 drawn; K_1 left over
    assert plan_figure(five).notes[-1] == "K_1 fixed at its first value (choose with sel={'K_1': VALUE})"
    with cli_spelling():
        assert plan_figure(five).notes[-1] == "K_1 fixed at its first value (choose with --sel K_1=VALUE)"


def test_axis_label_and_caption_as_the_gyroscopes_write_them_in_a_figure():
    """An inertia axis drops "about its centre of mass" (every body's A says it), and a liquid's E is in kg m² as
    mathtext, as every other unit of the figure (``System.figure_text``)."""
    scene = stabmap.loads_scene(
        "support = \"fixed\"\n[[bodies]]\nm = 1.0\nA = 0.02\nC = 0.03\nc = 0.1\nfluid = { E = [1e-4], kappa = [1.31] }\n"
        "[grid]\nomega = { values = [10.0, 20.0] }\nA_1 = { values = [0.02, 0.03] }\n"
    )
    ds = stabmap.compute_atlas(scene, threads=1, progress=False)
    assert "about its centre of mass" in ds["A_1"].attrs["long_name"]  # the atlas keeps the whole name
    assert axis_label(ds, "A_1", width=500) == "equatorial moment of inertia of body 1 $A_{1}$ [kg\u00a0m$^{2}$]"
    caption = fixed_caption(ds, 500)
    assert "E\u00a0=\u00a00.0001\u00a0kg\u00a0m$^{2}$," in caption and " m2" not in caption.replace("\u00a0", " ")


# -------------------------------------------------------------------------------------------------- files, CLI
def test_cli_png_and_pdf_are_valid_and_vector(atlas3_file, tmp_path, capsys):
    png, pdf = tmp_path / "map.png", tmp_path / "map.pdf"
    assert main(["plot", str(atlas3_file), "-o", str(png), "--max-panels", "2"]) == 0
    assert "note: K_1: 2 of 5 values drawn" in capsys.readouterr().err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["plot", str(atlas3_file), "-o", str(pdf), "--sel", "K_1=50", "--x", "m_2"]) == 0
    data = pdf.read_bytes()
    assert data[:5] == b"%PDF-" and data.rstrip().endswith(b"%%EOF")
    assert b"/Subtype /Image" not in data  # colours, lines and text are vector
    assert main(["plot", str(atlas3_file), "-o", str(tmp_path / "f.png"), "--facet", "omega", "--max-panels", "4"]) == 0
    assert sorted(os.listdir(tmp_path)) == ["f.png", "map.pdf", "map.png"]  # no temporary files left
    capsys.readouterr()
    assert main(["plot", str(atlas3_file), "-o", str(tmp_path / "far.png"), "--sel", "K_1=1e9"]) == 0  # beyond the grid
    assert "note: K_1 = 1e+09 lies outside the grid" in capsys.readouterr().err


@pytest.mark.parametrize(
    "args,message",
    [
        (["--facet", "nope"], "--facet nope: not an axis of this atlas; choose from omega, m_2, K_1"),
        (["--sel", "nope=1"], "--sel nope=...: not an axis of this atlas"),
        (["--sel", "g=9"], "--sel g=...: fixed at 9.81 m s-2 in this atlas, not a grid axis"),
        (["--sel", "K_1"], "--sel 'K_1': write NAME=VALUE"),
        (["--x", "nope"], "--x nope: not an axis of this atlas"),
        (["--x", "omega", "--y", "omega"], "--x and --y both name omega"),
        (["--x", "K_1", "--sel", "K_1=10"], "--x K_1: this axis is also fixed by --sel"),
        (["--sel", "K_1=10", "--facet", "omega"], "--facet omega: only 2 axes left to draw (omega, m_2)"),
        (["--sel", "K_1=10", "m_2=1", "--y", "omega"], "--y omega: only one axis is left"),
        (["--sel", "K_1=10", "m_2=1", "omega=3"], "--sel fixes every axis"),
        (["--max-panels", "0"], "--max-panels must be a whole number >= 1, got 0"),
    ],
)
def test_cli_bad_options_clear_error_no_file(atlas3_file, tmp_path, capsys, args, message):
    out = tmp_path / "map.png"
    assert main(["plot", str(atlas3_file), "-o", str(out), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert os.listdir(tmp_path) == []


def test_bad_suffix_and_failed_save_leave_no_file(atlas3, tmp_path, monkeypatch):
    with pytest.raises(stabmap.StabmapError, match="use a .png or .pdf name"):
        plot_atlas(atlas3, tmp_path / "map.jpg")
    from matplotlib.figure import Figure

    def broken(self, fname, *args, **kwargs):
        open(fname, "wb").write(b"partial")
        raise KeyboardInterrupt

    monkeypatch.setattr(Figure, "savefig", broken)
    with pytest.raises(KeyboardInterrupt):
        plot_atlas(atlas3, tmp_path / "map.pdf")
    assert os.listdir(tmp_path) == []


def test_spin_rates_in_the_scenes_unit_with_rad_s_beside():
    """A spin-rate axis the scene gave in rpm: a panel's title, the page's hover and the critical-values figure give
    its values in rpm with rad/s beside them (they gave rad/s only), and its axis is labelled in rpm."""
    from stabmap.read.explore.text import value_text as page_text
    from stabmap.read.plot.critical import critical_figure
    from stabmap.run.critical import critical

    ds = hand_atlas({"omega": ([2 * np.pi, 4 * np.pi], "linear"), "m_2": ([1.0, 2.0], "log"), "K_1": ([5.0, 20.0], "linear")},
                    np.zeros((2, 2, 2), dtype=int))
    ds["omega"].attrs["display_units"] = "rpm"
    fig = atlas_figure(ds, x="m_2", y="K_1", facet="omega")
    assert [ax.get_title().split("\n")[0].split("  ")[0] for ax in fig.axes[:2]] == \
        ["$\\omega$ = 60 rpm (6.283 rad\u00a0s$^{-1}$)", "$\\omega$ = 120 rpm (12.57 rad\u00a0s$^{-1}$)"]
    assert page_text(ds, "omega", 2 * np.pi) == "ω = 60 rpm (6.28319 rad s⁻¹)"

    grid = SCENE[SCENE.index("[grid]"):]
    scene = stabmap.loads_scene(SCENE.replace(grid, '[grid]\nomega = { start = "100 rpm", stop = "1400 rpm", num = 8 }\n'
                                                    'm_2 = { start = 0.1, stop = 5.0, num = 3, scale = "log" }\n'))
    fig = critical_figure(critical(scene, "omega", rtol=1e-6, threads=1, progress=False))
    ax = fig.axes[0]
    fig.canvas.draw()
    assert ax.get_xlabel().endswith("[rpm]")
    lo, hi = ax.get_xlim()  # 100 .. 1400 rpm, in rad/s
    shown = [t.get_text() for t, v in zip(ax.get_xticklabels(), ax.get_xticks(), strict=True) if lo <= v <= hi]
    assert shown[:2] == ["200", "400"] and np.isclose(hi, 1400 * 2 * np.pi / 60)
