"""The interactive pages (stabmap/read/explore/) without a browser: what a page holds is checked against the atlas
read with xarray and numpy, block by block; the size bound, the thinning of sliders and the errors.

tests/test_explore_browser.py opens the pages in Chromium and checks what a reader sees."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import stabmap
from stabmap.errors import StabmapError
from stabmap.read.explore import atlas_page, critical_page
from stabmap.read.explore.frames import map_grid, read_frame
from stabmap.read.explore.plan import PagePlan, plan_page, thin
from stabmap.read.explore.states import CELL_SHIFT, Legend, point_bits, unpack
from stabmap.read.explore.text import plain, value_text
from stabmap.read.plot.geometry import cell_edges


def models(page, kind: str) -> list:
    """Every bokeh model of ``kind`` (class name) in a page's layout."""
    return [m for m in page.layout.references() if type(m).__name__ == kind]


def shown_states(page) -> tuple[np.ndarray, list[str]]:
    """The first frame's state index per block and the text of every state, as the page stores them."""
    (source,) = [s for s in models(page, "ColumnDataSource") if "state" in s.data]
    (hover,) = models(page, "CustomJSHover")
    return np.asarray(source.data["state"]), list(hover.args["tables"]["texts"].data["v"])


def test_plain_text_of_mathtext():
    assert plain(r"$m_{2}$") == "m₂"
    assert plain(r"$\omega$") == "ω"
    assert plain("rad\u00a0s$^{-1}$") == "rad\u00a0s⁻¹"
    assert plain(r"$c_1^2$") == "c₁²"
    assert plain(r"$2\times10^{-5}$") == "2×10⁻⁵"
    assert plain(r"$h_{2/1}$") == "h_2/1"  # no Unicode subscript for '/': said plainly, not dropped


@given(low=st.integers(-5, 300), span=st.integers(0, 40), boundary=st.booleans(), colour=st.integers(0, 63),
       bits=st.integers(0, 2**20 - 1))
def test_states_pack_and_unpack(low, span, boundary, colour, bits):
    from stabmap.read.blocks import Blocks
    from stabmap.read.explore.states import pack

    one = np.ones((1, 1))
    blocks = Blocks((1, 1), (one * low).astype(np.int16), (one * (low + span)).astype(np.int16), one.astype(bool) & boundary,
                    (one * bits).astype(np.int32), {})
    assert unpack(int(pack(blocks, (one * colour).astype(np.int64))[0, 0])) == (low, low + span, boundary, colour, bits)


def test_every_grid_point_of_the_page_shows_the_atlas_label(two_tops_atlas):
    """Read back from the page's data: each point's state names the atlas's label, decided_by and cell there."""
    ds = two_tops_atlas
    page = atlas_page(ds)
    state, texts = shown_states(page)
    label, by, cell = (np.asarray(ds[v].transpose("m_2", "omega")).ravel() for v in ("n_complex_pairs", "decided_by", "cell"))
    var = stabmap.systems.of_atlas(ds.attrs)
    for i, s in enumerate(state):
        text = texts[s].split("\n")
        assert text[0] == f"N_c = {label[i]}: {var.class_name(int(label[i]))}"
        assert text[1] == "decided by: " + ds.decided_by.attrs["flag_meanings"].split()[int(by[i])].replace("_", " ")
        assert text[2].startswith("cell: " + ds.cell.attrs["flag_meanings"].split()[int(cell[i])].replace("_", " ") + ",")
    assert page.notes == ()


def test_blocks_hold_the_lowest_and_highest_label_and_every_way_decided(two_tops_atlas):
    """A map finer than its pixels is drawn in blocks: each block's state holds the min and max label of its points
    and the union of their decided_by and cell values (numpy over the same blocks)."""
    ds = two_tops_atlas
    system = stabmap.systems.of_atlas(ds.attrs)
    plan = plan_page(ds, list(ds.n_complex_pairs.dims))
    grid = map_grid(ds, plan, pixels=(3, 4))
    assert grid.factors == (3, 3)
    legend = Legend(system, True)
    frame = read_frame(ds.n_complex_pairs, point_bits(ds, system), plan, {}, grid, legend)
    label = np.asarray(ds.n_complex_pairs.transpose("m_2", "omega"))
    by = np.asarray(ds.decided_by.transpose("m_2", "omega"))
    cell = np.asarray(ds.cell.transpose("m_2", "omega"))
    for r in range(grid.shape[0]):
        for c in range(grid.shape[1]):
            part = (slice(3 * r, 3 * r + 3), slice(3 * c, 3 * c + 3))
            low, high, _, _, bits = unpack(int(frame.keys[r, c]))
            assert (low, high) == (label[part].min(), label[part].max())
            assert {p for p in range(16) if bits & (1 << p)} == set(np.unique(by[part]).tolist())
            assert {q for q in range(4) if bits & (1 << (CELL_SHIFT + q))} == set(np.unique(cell[part]).tolist())
    assert sum(frame.counts.values()) == label.size
    assert frame.counts == {int(v): int((label == v).sum()) for v in np.unique(label)}


def test_a_slider_per_further_axis_and_its_frames(two_tops_atlas):
    """A third axis becomes a slider; frame k of the page is the atlas at its k-th value."""
    ds = two_tops_atlas.expand_dims(K_1=[0.0, 20.0]).transpose("omega", "m_2", "K_1", ...)
    ds = ds.assign(n_complex_pairs=ds.n_complex_pairs + ds.K_1.astype(int) // 20 * (ds.n_complex_pairs == 0))  # differs per K_1
    ds.K_1.attrs.update(units="N m rad-1", long_name="stiffness of joint 1")
    page = atlas_page(ds)
    (slider,) = models(page, "Slider")
    assert slider.name == "slider-K_1" and (slider.start, slider.end) == (0, 1)
    (switch,) = {id(c): c for s in models(page, "Slider") for c in s.js_property_callbacks["change:value"]}.values()
    _, texts = shown_states(page)
    for k, value in enumerate([0.0, 20.0]):
        want = np.asarray(ds.n_complex_pairs.sel(K_1=value).transpose("m_2", "omega")).ravel()
        got = [int(texts[s].split(" = ")[1].split(":")[0]) for s in switch.args["frames"][k][1]]
        assert got == want.tolist()
        assert value_text(ds, "K_1", value) in switch.args["titles"][k]


def test_the_map_colours_the_atlas_cells_and_nothing_beyond(two_tops_atlas):
    """The blocks are drawn on the cells the atlas proves its labels on (its CF bounds; on the log axis too), the map
    ends where the scan ends, and the rectangles of one colour cover every block once, in that block's colour."""
    from stabmap.read.explore.frames import colour_rectangles

    ds = two_tops_atlas
    grid = map_grid(ds, plan_page(ds, ["omega", "m_2"]))
    for edges, dim in ((grid.xe, "omega"), (grid.ye, "m_2")):
        bounds = ds[f"{dim}_bounds"].values
        assert edges.tolist() == [*bounds[:, 0], bounds[-1, 1]]
        assert (edges[0], edges[-1]) == (ds[dim].values[0], ds[dim].values[-1])
    page = atlas_page(ds)
    (fig,) = [m for m in page.layout.references() if m.name == "map"]
    assert (fig.x_range.start, fig.x_range.end) == (ds.omega.values[0], ds.omega.values[-1])
    colours = np.random.default_rng(1).integers(0, 3, size=(40, 30))
    colours[10:30, 5:25] = 7
    rects = colour_rectangles(colours)
    painted = np.full(colours.shape, -1)
    for c0, c1, r0, r1, c in rects:
        assert (painted[r0:r1, c0:c1] == -1).all()  # no block twice
        painted[r0:r1, c0:c1] = c
    assert (painted == colours).all()
    assert len(rects) < colours.size / 2  # merged: the 20 x 20 square of one colour is few rectangles


def test_a_page_is_fitted_under_its_bound_by_measuring_it():
    """The bound holds on the page as written: a page too big with every setting is made again with fewer, evenly
    spaced, and says so once."""
    from stabmap.read.explore.page import Page, fitted

    class Sized(Page):
        @property
        def size(self) -> int:  # a page whose every slider setting costs 50 kB
            return int(1.7e6 + 50_000 * len(self.layout.frames))

    full = PagePlan("x", "y", ("a",), {"a": tuple(range(40))})
    made = []
    page = fitted(full, {"a": 40}, 2.5, 40, lambda plan: made.append(plan) or Sized(plan, "t", plan.notes))
    assert page.size <= 2.5e6 and len(page.layout.frames) >= 14
    assert page.layout.positions["a"][0] == 0 and page.layout.positions["a"][-1] == 39
    assert len(page.notes) == 1 and page.notes[0].startswith(f"a: {len(page.layout.frames)} of 40 values on its slider, evenly spaced")
    assert len(made[0].frames) == 40
    with pytest.raises(StabmapError, match="one map of this file makes a page of"):
        fitted(full, {"a": 40}, 1.72, 40, lambda plan: Sized(plan, "t", plan.notes))


def test_a_strip_of_one_free_axis(two_tops_atlas):
    """With every axis but one fixed, the page is a strip along it: one block per grid value, the atlas's label at
    the nearest value of the fixed axis, which the hover names."""
    ds = two_tops_atlas
    page = atlas_page(ds, sel={"m_2": 1.0})
    state, texts = shown_states(page)
    m2 = float(ds.m_2.sel(m_2=1.0, method="nearest"))
    want = ds.n_complex_pairs.sel(m_2=m2).transpose("omega").values
    assert [int(texts[s].split(" = ")[1].split(":")[0]) for s in state] == want.tolist()
    (hover,) = models(page, "CustomJSHover")
    assert hover.args["tables"]["where"].data["v"] == [value_text(ds, "m_2", m2)]
    assert not models(page, "Slider")


def test_thinning_keeps_evenly_spaced_values_and_says_so():
    plan = PagePlan("x", "y", ("a", "b"), {"a": tuple(range(40)), "b": tuple(range(5))})
    small = thin(plan, {"a": 40, "b": 5}, 60, "the bound")
    assert len(small.frames) <= 60
    assert small.positions["a"][0] == 0 and small.positions["a"][-1] == 39  # both ends kept
    assert small.positions["b"] == tuple(range(5))  # the longer slider loses values first
    assert small.notes == ("a: 12 of 40 values on its slider, evenly spaced (the bound)",)
    assert thin(plan, {"a": 40, "b": 5}, 200, "the bound") is plan


def test_a_page_over_its_bound_leaves_slider_values_out(two_tops_atlas, monkeypatch):
    """With room for three frames, a slider of five values keeps three (its ends and middle) and the page says so."""
    import stabmap.read.explore.atlas as page_module

    ds = two_tops_atlas.expand_dims(K_1=[0.0, 10.0, 20.0, 30.0, 40.0]).transpose("omega", "m_2", "K_1", ...)
    monkeypatch.setattr(page_module, "frame_bytes", lambda frame: 1)
    monkeypatch.setattr(page_module, "budget", lambda max_mb: 3)  # room for three frames
    page = atlas_page(ds, max_mb=5)
    assert page.notes and "K_1: 3 of 5 values on its slider, evenly spaced" in page.notes[0] and "max_mb=5" in page.notes[0]
    (slider,) = models(page, "Slider")
    assert slider.end == 2


def test_page_file_is_written_atomically_and_within_its_bound(two_tops_atlas, tmp_path):
    path = atlas_page(two_tops_atlas).save(tmp_path / "a.html")
    text = path.read_text()
    assert path.stat().st_size < 20e6 and "Bokeh" in text
    assert "<script src=" not in text and "<link" not in text  # BokehJS inlined: the page needs no network
    assert [p.name for p in tmp_path.iterdir()] == ["a.html"]


@pytest.mark.parametrize("kw, message", [
    ({"x": "nope"}, "not an axis of this atlas"),
    ({"sel": {"omega": 10.0, "m_2": 1.0}}, "fixes every axis"),
    ({"max_mb": 0.5}, "a page needs at least"),
    ({"max_mb": -1}, "positive number of megabytes"),
])
def test_bad_options_are_errors_naming_the_parameter(two_tops_atlas, kw, message):
    with pytest.raises(StabmapError, match=message):
        atlas_page(two_tops_atlas, **kw)


def run(*args, cwd):
    """``stabmap ARGS`` in ``cwd``, in this process (``stabmap.cli.main``: the exit status and the messages a shell
    sees, without starting Python again for each command)."""
    import contextlib
    import io
    import os

    from stabmap.cli import main

    here, out, err = os.getcwd(), io.StringIO(), io.StringIO()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = main(list(args))
    finally:
        os.chdir(here)
    return subprocess.CompletedProcess(args, status, out.getvalue(), err.getvalue())


def test_cli_writes_a_page_and_refuses_bad_options_without_a_file(two_tops_atlas, tmp_path):
    stabmap.write_atlas(two_tops_atlas, tmp_path / "a.nc")
    done = run("plot", "a.nc", "-o", "a.html", cwd=tmp_path)
    assert done.returncode == 0 and "wrote a.html" in done.stderr
    for args, message in [(["--facet", "m_2"], "--facet applies to PNG and PDF figures"),
                          (["--max-mb", "0.1"], "--max-mb 0.1: a page needs at least"),
                          (["--x", "K_9"], "--x K_9: not an axis of this atlas")]:
        bad = run("plot", "a.nc", "-o", "b.html", *args, cwd=tmp_path)
        assert bad.returncode == 2 and message in bad.stderr, bad.stderr
        assert not (tmp_path / "b.html").exists()
    png = run("plot", "a.nc", "-o", "b.png", "--max-mb", "5", cwd=tmp_path)
    assert png.returncode == 2 and "--max-mb applies to .html pages" in png.stderr
    again = run("plot", "a.nc", "-o", "a.html", cwd=tmp_path)
    assert again.returncode == 2 and "--overwrite" in again.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.html", "a.nc"]


def test_critical_page_shows_the_files_stable_intervals(two_tops_scene, tmp_path):
    """The stable stretches drawn are the file's stable intervals less its undecided gaps, which are drawn as such:
    a stretch whose inside no proof settled is never shown as stable."""
    crit = stabmap.critical(two_tops_scene, along="omega", progress=False)
    page = critical_page(crit)
    (source,) = [s for s in models(page, "ColumnDataSource") if "text" in s.data]
    edges = cell_edges(crit.m_2.values, crit.m_2.attrs.get("scale"))

    def drawn(prefix: str) -> set:
        return {(round(float(lo), 9), round(float(hi), 9), round(float(crit.m_2[int(np.searchsorted(edges, b, side="right")) - 1]), 9))
                for lo, hi, b, t in zip(source.data["left"], source.data["right"], source.data["bottom"], source.data["text"], strict=True)
                if t.startswith(prefix)}

    want, gaps = set(), set()
    for m in crit.m_2.values:
        holes = [(a, b) for a, b in zip(crit.undecided_lower.sel(m_2=m).values, crit.undecided_upper.sel(m_2=m).values, strict=True)
                 if np.isfinite(a)]
        gaps |= {(round(float(a), 9), round(float(b), 9), round(float(m), 9)) for a, b in holes}
        for lo, hi in zip(crit.omega_stable_lower.sel(m_2=m).values, crit.omega_stable_upper.sel(m_2=m).values, strict=True):
            if not np.isfinite(lo):
                continue
            cuts = sorted([lo, hi] + [e for a, b in holes if lo <= a and b <= hi for e in (a, b)])
            want |= {(round(float(a), 9), round(float(b), 9), round(float(m), 9)) for a, b in zip(cuts[::2], cuts[1::2], strict=True) if b > a}
    assert drawn("N_c = 0:") == want and want
    assert drawn("undecided gap") == gaps and gaps  # this grid has gaps: the test sees them drawn


def painted_fills(page) -> tuple[np.ndarray, object]:
    """The fill id the first frame paints on every block (rows along y), read from the page's quads, and their glyph
    (its colour mapper and hatch table turn an id into what the browser draws)."""
    (blocks,) = [r for r in models(page, "GlyphRenderer") if type(r.glyph).__name__ == "Quad"]
    rects = blocks.data_source
    ids = np.full((max(rects.data["r1"]), max(rects.data["c1"])), -1)
    for c0, c1, r0, r1, k in zip(*(rects.data[n] for n in ("c0", "c1", "r0", "r1", "colour")), strict=True):
        ids[r0:r1, c0:c1] = k
    return ids, blocks.glyph


def test_a_cell_holding_a_change_keeps_its_class_colour_under_a_hatch(monkeypatch):
    """Every block of one class is painted in its class's colour, as the PNG paints it (never lighter), hatched dark
    exactly where a cell in it is proved to hold a change, dotted where proved at its node only, lightly hatched
    where inferred: node by node, and in blocks of 2 x 2 nodes of one class, some holding a change."""
    from flagged import CELLS, CHANGE, LABELS, NODE_ONLY, NOT_PROVED, flagged_atlas

    import stabmap.read.explore.atlas as page_module
    from stabmap.read.explore.states import INFERRED_HATCH, NODE_ONLY_HATCH
    from stabmap.read.plot.marks import PAGE_HATCH
    from stabmap.read.plot.palette import system_colour

    for repeat, pixels in ((1, None), (2, (5, 6))):
        ds = flagged_atlas(repeat=repeat)
        system = stabmap.systems.of_atlas(ds.attrs)
        if pixels is not None:  # a map of 10 x 12 points on 5 x 6 pixels: blocks of 2 x 2, each one node of LABELS
            monkeypatch.setattr(page_module, "map_grid", lambda ds_, plan, p=pixels: map_grid(ds_, plan, pixels=p))
        page = atlas_page(ds, x="omega", y="K_1")
        ids, quad = painted_fills(page)
        assert ids.shape == LABELS.shape
        colour = np.array(quad.fill_color.transform.palette, dtype=object)[ids]
        want = np.array([[system_colour(int(v), system) for v in row] for row in LABELS], dtype=object)
        assert (colour == want).all(), (colour, want)
        hatch = np.array(quad.hatch_pattern.transform.args["h"], dtype=object)[ids]
        assert ((hatch == PAGE_HATCH) == (CELLS == CHANGE)).all()
        assert ((hatch == NODE_ONLY_HATCH) == (CELLS == NODE_ONLY)).all()
        assert ((hatch == INFERRED_HATCH) == (CELLS == NOT_PROVED)).all()
        (legend,) = [m for m in page.layout.references() if getattr(m, "name", None) == "legend"]
        assert "hatched: a change of label is proved inside the cell (colour: the label at its grid point)" in legend.text
