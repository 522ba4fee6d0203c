"""The interactive page and the PNG of one atlas show one map: for every bundled example (its grid resampled to a few
points an axis) and for a scene whose spin rate is given in rpm, the page is made through the CLI, opened in headless
Chromium, and what its axes show (their titles, the tick values and the tick texts BokehJS renders) and the fills of
its blocks (colours and marks) are compared with the matplotlib figure the PNG is saved from, drawn for the same
slice (the page's sliders at their first values).

Without Chromium these tests skip, or fail when STABMAP_REQUIRE_BROWSER=1 (tests/browser.py).
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from browser import browser

import stabmap
from stabmap.cli import main
from stabmap.examples import example, example_names
from stabmap.read.explore.states import INFERRED_HATCH, NODE_ONLY_HATCH
from stabmap.read.explore.text import plain
from stabmap.read.plot import atlas_figure
from stabmap.read.plot.marks import PAGE_HATCH
from stabmap.scene.grid import resample

MAX_POINTS = {2: 6, 3: 4}  # points an axis of a resampled example, by the number of its axes (more axes: 3)
# A liquid-filled top against its spin rate given in rpm (its axis is shown in rpm) and the cavity's half height,
# whose name half_height_1 is shown as written.
RPM_SCENE = """
title = "a top with a cylinder of water, spin rate in rpm"
support = "fixed"
g = 9.81

[[bodies]]
m = 3.0
A = 0.05
C = 0.02
c = 0.2
cavity = { shape = "cylinder", radius = 0.05, half_height = 0.05, density = 1000.0, modes = 2 }

[grid]
omega = { start = "200 rpm", stop = "1900 rpm", num = 7 }
half_height_1 = { start = 0.01, stop = 0.15, num = 5 }
"""
# The same top over a log scan of its spin rate in rpm: round rpm ticks on a log axis, on both.
LOG_RPM_SCENE = RPM_SCENE.replace('omega = { start = "200 rpm", stop = "1900 rpm", num = 7 }',
                                  'omega = { start = "100 rpm", stop = "5000 rpm", num = 7, scale = "log" }')
# The page's marks (bokeh hatch patterns) and the PNG's (gids of its hatch patches).
MARKS = {NODE_ONLY_HATCH: "node-only-cells", INFERRED_HATCH: "inferred-cells", PAGE_HATCH: "change-cells"}

# What the page shows: per axis its title, the values of its major ticks and the texts BokehJS renders at them; the
# colours and hatch patterns of the blocks drawn at the sliders' current values.
READ_PAGE = """
const p = model('map');
const axes = {};
for (const [side, ax] of [['x', p.below[0]], ['y', p.left[0]]]) {
  if (!ax.visible) continue;
  const v = Bokeh.index.find_one(ax);
  const ticks = Array.from(v.tick_coords.major[v.dimension]);
  axes[side] = {title: ax.axis_label, ticks: ticks, texts: v.compute_labels(ticks).items.map((b) => b.text)};
}
const q = p.renderers.find((r) => r.data_source.data.c0 !== undefined);
const ids = [...new Set(Array.from(q.data_source.data.colour))];
const palette = q.glyph.properties.fill_color.get_value().transform.palette;
const args = q.glyph.properties.hatch_pattern.get_value().transform.args;
const hatches = args instanceof Map ? args.get('h') : args.h;
return {axes: axes, fills: ids.map((i) => [palette[i], hatches[i] || ''])};
"""


def small(scene):
    """``scene`` with every axis resampled to at most a few points (the ends kept)."""
    n = MAX_POINTS.get(len(scene.grid), 3)
    return resample(scene, **{a.name: n for a in scene.grid if len(a.values) > n})


SCENES = {name: (lambda name=name: small(example(name))) for name in example_names()}
SCENES["rpm-scene"] = lambda: stabmap.loads_scene(RPM_SCENE)
SCENES["log-rpm-scene"] = lambda: stabmap.loads_scene(LOG_RPM_SCENE)


@pytest.fixture(scope="module")
def new_page():
    with browser() as factory:
        yield factory


def png_axes(fig, ds: xr.Dataset, x: str, y: str | None) -> dict[str, dict]:
    """Per axis of the PNG's first map (the x axis of one free axis: of the plots' bottom one): its title and its
    labelled ticks (value, text as shown: mathtext in Unicode)."""
    fig.canvas.draw()
    ax, bottom = fig.axes[0], fig.axes[-1]  # one free axis: the label's plot over the growth rate's, x labelled beneath
    out = {}
    for side, dim, axis, label in (("x", x, bottom.xaxis, bottom.get_xlabel()), ("y", y, ax.yaxis, ax.get_ylabel())):
        if dim is None:
            continue
        lo, hi = sorted(axis.get_view_interval())
        slack = 1e-9 * (np.log(hi / lo) if axis.get_scale() == "log" else hi - lo)
        lo, hi = (lo * np.exp(-slack), hi * np.exp(slack)) if axis.get_scale() == "log" else (lo - slack, hi + slack)
        ticks = [(float(loc), plain(t.get_text())) for locs, texts in ((axis.get_majorticklocs(), axis.get_majorticklabels()),
                                                                        (axis.get_minorticklocs(), axis.get_minorticklabels()))
                 for loc, t in zip(locs, texts, strict=True) if t.get_text() and lo <= loc <= hi]
        out[side] = {"title": " ".join(plain(label).replace("\u00a0", " ").split()), "ticks": sorted(ticks)}
    return out


def png_fills(fig) -> set[tuple[str, str]]:
    """The PNG map's class colours and marks: (colour, "") per class, ("", gid) per kind of hatch."""
    from matplotlib.colors import to_hex

    ax = fig.axes[0]
    colours = {(to_hex(c.get_facecolor()[0]).upper(), "") for c in ax.collections if str(c.get_gid()).startswith("cells-")}
    marks = {("", str(p.get_gid())) for p in ax.patches if p.get_gid() in MARKS.values()}
    return colours | marks


@pytest.mark.parametrize("name", sorted(SCENES))
def test_the_page_shows_the_png_axes_ticks_and_colours(new_page, name, tmp_path):
    ds = stabmap.compute_atlas(SCENES[name](), threads=1, progress=False)
    stabmap.write_atlas(ds, tmp_path / "atlas.nc")
    assert main(["plot", str(tmp_path / "atlas.nc"), "-o", str(tmp_path / "atlas.html")]) == 0
    with xr.open_dataset(tmp_path / "atlas.nc") as f:
        ds = f.load()
    system = stabmap.systems.of_atlas(ds.attrs)
    dims = [str(d) for d in ds[system.label].dims]
    x, y = dims[0], dims[1] if len(dims) > 1 else None
    sliders = {d: float(ds[d][0]) for d in dims[2:]}  # the page opens at every slider's first value
    fig = atlas_figure(ds, x=x, y=y, sel=sliders)

    shown = new_page().open(tmp_path / "atlas.html").js(READ_PAGE)
    png = png_axes(fig, ds, x, y)
    assert set(shown["axes"]) == set(png), name
    for side, axis in png.items():
        page = shown["axes"][side]
        assert page["title"] == axis["title"], (name, side)
        page_ticks = sorted(zip(page["ticks"], page["texts"], strict=True))
        assert [t for _, t in page_ticks] == [t for _, t in axis["ticks"]], (name, side)
        np.testing.assert_allclose([v for v, _ in page_ticks], [v for v, _ in axis["ticks"]], rtol=1e-9, err_msg=f"{name} {side}")
    page_fills = {(c.upper(), "") for c, _ in shown["fills"]} | {("", MARKS[h]) for _, h in shown["fills"] if h}
    assert page_fills == png_fills(fig), name


def test_an_rpm_axis_reads_rpm_and_half_height_1_as_written(new_page, tmp_path):
    """The case the PNG and the page disagreed on: a spin rate given in rpm is shown in rpm on both (round rpm
    ticks, '[rpm]' in the title), and the name half_height_1 keeps its underscores on the page, as on the PNG."""
    stabmap.write_atlas(stabmap.compute_atlas(SCENES["rpm-scene"](), threads=1, progress=False), tmp_path / "atlas.nc")
    assert main(["plot", str(tmp_path / "atlas.nc"), "-o", str(tmp_path / "atlas.html")]) == 0
    axes = new_page().open(tmp_path / "atlas.html").js(READ_PAGE)["axes"]
    assert axes["x"]["title"].endswith("ω [rpm]")
    assert [float(t) for t in axes["x"]["texts"]] == [200.0 * k for k in range(1, 10)]
    assert "(half_height_1) [m]" in axes["y"]["title"]


def test_a_log_rpm_axis_reads_rpm_at_round_rpm_on_both(new_page, tmp_path):
    """A log scan given in rpm is labelled in rpm at 1, 2 and 5 times powers of ten of rpm, on the page as on the PNG
    (before, a log spin axis stayed in rad/s on both)."""
    stabmap.write_atlas(stabmap.compute_atlas(SCENES["log-rpm-scene"](), threads=1, progress=False), tmp_path / "atlas.nc")
    assert main(["plot", str(tmp_path / "atlas.nc"), "-o", str(tmp_path / "atlas.html")]) == 0
    axes = new_page().open(tmp_path / "atlas.html").js(READ_PAGE)["axes"]
    assert axes["x"]["title"].endswith("ω [rpm]")
    assert sorted(float(t) for t in axes["x"]["texts"]) == [100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0]
