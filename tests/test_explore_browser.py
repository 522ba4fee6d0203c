"""The interactive pages (``stabmap plot ... -o page.html``) of every system, read in headless Chromium.

For each system a tiny atlas is computed, written to netCDF and drawn to a page through the CLI, as a reader would
make it; the page is opened in Chromium and every grid point of the map is hovered.  The readout and the tooltip are
checked against the atlas file read back with xarray: the coordinates (symbols and units typed here), the label and
its class name, the meaning of the point's ``decided_by`` and ``cell`` flags (from the variables' CF attributes).  The
gyroscopes' atlas has a third axis: its slider is moved and the map hovered again at the new value.  A critical-values
file is drawn the same way and each stretch hovered, its class and ends checked against the file's boundaries and
stable intervals.  Every test saves a screenshot and checks that it shows a drawn page.

Without Chromium these tests skip, or fail when STABMAP_REQUIRE_BROWSER=1 (tests/browser.py).
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import xarray as xr
from browser import Page, browser
from scenes import TWO_TOPS

import stabmap
from stabmap.store.dataset import edges
from stabmap import systems
from stabmap.cli import main
from stabmap.scene.grid import resample

# The gyroscopes' grid: two tops against spin rate and the mass of the top one, at three joint stiffnesses (105 points).
GYRO_GRID = ('omega = { start = 1.0, stop = 150.0, num = 7 }\nm_2 = { start = 0.1, stop = 5.0, num = 5, scale = "log" }\n'
             "K_1 = { values = [5.0, 20.0, 60.0] }\n")


def gyroscopes_scene():
    grid = TWO_TOPS[TWO_TOPS.index("[grid]") :]
    return stabmap.loads_scene(TWO_TOPS.replace(grid, "[grid]\n" + GYRO_GRID))


# Each system's tiny scene (tens of points, every class of the example's map still present).
SCENES = {
    "gyroscopes": gyroscopes_scene,
    "closed": lambda: resample(stabmap.example("closed-eight-torsion"), c2sq=8),
    "reactions": lambda: resample(stabmap.example("reactions-square-plate"), c_x=7, c_y=5),
    "viscous": lambda: resample(stabmap.example("viscous-top-sphere"), omega=7, C_1=5),
}
# How a page names each axis and its units: the reference the coordinate lines are read against.
AXES = {
    "omega": ("ω", "rad s⁻¹"),
    "m_2": ("m₂", "kg"),
    "K_1": ("K₁", "N m rad⁻¹"),
    "ratio": ("h₂/h₁", ""),
    "c2sq": ("c₂²", "N m²"),
    "c_x": ("cₓ", "m"),
    "c_y": ("c_y", "m"),
    "C_1": ("C₁", "kg m²"),
}
LABEL_SYMBOL = {"gyroscopes": "N_c", "closed": "class", "reactions": "critical node", "viscous": "class"}
# What each meaning of the ``cell`` flag is explained as (docs/cells.md), in a few words.
CELL_WORDS = {
    "whole_cell": "every point of the cell",
    "contains_change": "hold a change of label",
    "node_only": "at the grid node only",
    "not_proved": "inferred",
}
COORDINATE = re.compile(r"^(?P<symbol>.+?) = (?P<value>[-+0-9.e]+)(?: (?P<unit>.+))?$")
WINDOW = (1400, 1000)  # tests/browser.py's default viewport: the screenshots' size


@pytest.fixture(scope="module")
def new_page():
    with browser() as factory:
        yield factory


@pytest.fixture(scope="module")
def atlas_page_of(tmp_path_factory):
    """``make(system)``: the atlas of the system's tiny scene as read back from its file, and its page (made once)."""
    made = {}

    def make(name: str) -> tuple[xr.Dataset, object]:
        if name not in made:
            folder = tmp_path_factory.mktemp(name)
            stabmap.write_atlas(stabmap.compute_atlas(SCENES[name](), threads=1, progress=False), folder / "atlas.nc")
            assert main(["plot", str(folder / "atlas.nc"), "-o", str(folder / "atlas.html")]) == 0
            with xr.open_dataset(folder / "atlas.nc") as ds:
                made[name] = (ds.load(), folder / "atlas.html")
        return made[name]

    return make


# ------------------------------------------------------------------------------------------------ reading pages
def flag_meaning(var: xr.DataArray, value: int) -> str:
    """The CF flag meaning of ``value`` in ``var``, from its attributes."""
    meanings = str(var.attrs["flag_meanings"]).split()
    return meanings[[int(v) for v in np.atleast_1d(var.attrs["flag_values"])].index(int(value))]


def coordinates(lines: list[str]) -> list[tuple[str, float, str]]:
    """(symbol, value, unit) of each line that shows a coordinate's value."""
    out = []
    for line in lines:
        m = COORDINATE.match(line)
        if m is not None:
            out.append((m["symbol"], float(m["value"]), m["unit"] or ""))
    return out


def at_point(text: str, point: dict[str, float]) -> bool:
    """Whether ``text`` shows the coordinates of ``point`` (to the six digits shown): the page has caught up."""
    shown = coordinates(text.splitlines())
    return len(shown) == len(point) and all(s == AXES[d][0] and np.isclose(v, point[d], rtol=1e-5, atol=1e-12)
                                            for (s, v, _), d in zip(shown, point, strict=True))


def assert_point_text(text: str, ds: xr.Dataset, system, name: str, at: dict[str, int]) -> None:
    """``text`` (a readout or a tooltip) is what the atlas says at grid indices ``at`` (in the order of the label's
    axes: x, y, then the sliders)."""
    point = ds.isel(at)
    value = int(point[system.label])
    lines = text.splitlines()
    n = len(at)
    assert [(s, u) for s, _, u in coordinates(lines[:n])] == [AXES[d] for d in at], text
    np.testing.assert_allclose([v for _, v, _ in coordinates(lines[:n])], [float(point[d]) for d in at], rtol=1e-5, atol=1e-12)
    expected = [f"{LABEL_SYMBOL[name]} = {value}: {system.class_name(value)}"]
    if system.provenance in ds:
        expected.append("decided by: " + flag_meaning(ds[system.provenance], int(point[system.provenance])).replace("_", " "))
    assert lines[n : n + len(expected)] == expected, text
    cell = flag_meaning(ds["cell"], int(point["cell"]))
    assert lines[n + len(expected) :] == [lines[-1]] and lines[-1].startswith(f"cell: {cell.replace('_', ' ')}, "), text
    assert CELL_WORDS[cell] in lines[-1], text


def hover_every_point(page: Page, ds: xr.Dataset, name: str, sliders: dict[str, int]) -> set[int]:
    """Hover every grid point of the map at slider setting ``sliders``; check the readout and the tooltip of each.

    Returns
    -------
    set of int
        The labels hovered.
    """
    system = systems.of_atlas(ds.attrs)
    x, y, *rest = ds[system.label].dims
    assert list(rest) == list(sliders)
    seen = set()
    for i in range(ds.sizes[x]):
        for j in range(ds.sizes[y]):
            at = {x: i, y: j, **sliders}
            point = {d: float(ds[d][k]) for d, k in at.items()}
            page.hover("map", *(inside(ds, d, at[d]) for d in (x, y)))
            readout = page.wait(f"the readout of {point}", lambda: page.text("readout"), lambda t, p=point: at_point(t, p))
            assert_point_text(readout, ds, system, name, at)
            tooltip = page.wait(f"the tooltip of {point}", page.tooltip_text, lambda t, p=point: at_point(t, p))
            assert tooltip == readout
            seen.add(int(ds[system.label].isel(at)))
    return seen


def inside(ds: xr.Dataset, dim: str, i: int) -> float:
    """The middle of grid point ``i``'s cell along ``dim`` as drawn: its CF bounds (at the ends of the scan the cell
    ends at the point itself, which lies on the map's border, where a pointer may fall outside the map); along a
    discrete axis, whose cells are the values themselves, the strip the map draws for it (midpoints between
    values)."""
    lo, hi = (float(v) for v in ds[f"{dim}_bounds"][i])
    if lo == hi and ds.sizes[dim] > 1:
        lo, hi = (float(v) for v in edges(ds[dim].values)[[i, i + 1]])
    return (lo + hi) / 2


def assert_drawn_png(path) -> None:
    """``path`` is a PNG of the browser's window showing a drawn page: ink, and the many colours of a map and text."""
    from PIL import Image

    with Image.open(path) as image:
        assert image.format == "PNG" and image.size == WINDOW
        rgb = np.asarray(image.convert("RGB"))
    inked = (rgb < 230).any(axis=2).mean()
    assert inked > 0.05, f"{path}: {100 * inked:.1f} % of the pixels are not white"
    assert len(np.unique(rgb.reshape(-1, 3), axis=0)) > 20


# ------------------------------------------------------------------------------------------------ atlas pages
@pytest.mark.parametrize("name", list(SCENES))
def test_hover_shows_the_atlas_at_every_grid_point(new_page, atlas_page_of, name, tmp_path):
    ds, html = atlas_page_of(name)
    page = new_page().open(html)
    assert page.errors() == []
    system = systems.of_atlas(ds.attrs)
    assert system.name == name
    sliders = dict.fromkeys(ds[system.label].dims[2:], 0)
    labels = hover_every_point(page, ds, name, sliders)
    assert len(labels) >= 2  # the map crosses a change of label: points of different labels were hovered
    assert_drawn_png(page.screenshot(tmp_path / f"{name}.png"))
    assert page.errors() == []


def title_lines(ds: xr.Dataset, k: int) -> list[str]:
    """The gyroscopes page's title at position ``k`` of its slider K_1, from the atlas."""
    frame = ds["n_complex_pairs"].isel(K_1=k)
    share = 100 * float((frame == 0).mean())
    return [ds.attrs["title"], f"{share:.1f} % of the {frame.size} grid points of this map stable"]


def test_gyroscopes_slider_shows_the_atlas_at_its_value(new_page, atlas_page_of, tmp_path):
    ds, html = atlas_page_of("gyroscopes")
    page = new_page().open(html)
    assert ds.sizes["K_1"] == 3 and page.model("slider-K_1").end == 2
    titles = []
    for k in (0, 1, 2):
        if k:
            assert page.move_slider("slider-K_1", 1) == k
        title = page.wait(f"the title at K_1 index {k}", lambda: page.text("title").splitlines(),
                          lambda t, k=k: len(t) == 3 and at_point(t[2], {"K_1": float(ds["K_1"][k])}))
        assert title[:2] == title_lines(ds, k)
        titles.append(title)
        if k:
            hover_every_point(page, ds, "gyroscopes", {"K_1": k})
    assert len({"\n".join(t) for t in titles}) == 3  # the title changes with the slider
    assert page.move_slider("slider-K_1", -2) == 0
    assert page.wait_text("title", titles[0][2]).splitlines() == titles[0]
    assert_drawn_png(page.screenshot(tmp_path / "slider.png"))
    assert page.errors() == []


def hover_pixel(page: Page, px: int, py: int) -> None:
    """Move the mouse off the map (waiting for its tooltip to go), then onto the viewport pixel (px, py): a tooltip
    seen afterwards is that pixel's, not one left from before."""
    from selenium.webdriver.common.action_chains import ActionChains

    for x, y in ((1, 1), (px, py)):
        actions = ActionChains(page.driver, duration=0)
        actions.w3c_actions.pointer_action.move_to_location(x, y)
        actions.perform()
        if (x, y) == (1, 1):
            page.wait("the tooltip to go", page.tooltip_text, lambda t: t == "")


def test_a_pointer_on_the_edge_between_two_rows_hovers_one_of_them(new_page, atlas_page_of, tmp_path):
    """A pointer on the edge between two rows (the atlas's cell bounds) must show one of the two rows' points, as on
    either side of it, also where the edge lies on a whole pixel.  (A real mouse
    stops on whole pixels; on an axis of 300 values, every other pixel column is such an edge.)"""
    ds, html = atlas_page_of("gyroscopes")
    page = new_page().open(html)
    page.timeout = 3.0  # a tooltip shows within milliseconds; not waiting 20 s for each that does not
    i = 3
    for j in range(ds.sizes["m_2"] - 1):
        below, above = ({"omega": float(ds["omega"][i]), "m_2": float(ds["m_2"][r]), "K_1": float(ds["K_1"][0])} for r in (j, j + 1))
        edge = float(ds["m_2_bounds"][j, 1])  # the cells the atlas proves its labels on: midpoints, on the log axis too
        px, py = page.point("map", below["omega"], edge)
        for dy in (1, 0, -1):  # the row below the edge, the edge, the row above (screen y grows downwards)
            hover_pixel(page, round(px), round(py) + dy)
            page.wait(f"a tooltip at m_2 = {edge:g} {dy:+d} px", page.tooltip_text, lambda t, b=below, a=above: at_point(t, b) or at_point(t, a))
    assert_drawn_png(page.screenshot(tmp_path / "edge.png"))
    assert page.errors() == []


# ------------------------------------------------------------------------------------------------ critical values
def stretches(row: xr.Dataset, scan: tuple[float, float]) -> list[tuple[float, float, int]]:
    """(start, end, N_c) of every stretch of one row of a critical-values file: between the scan's ends and the located
    changes, whose brackets are left out."""
    lo, hi = row["boundary_lower"].values, row["boundary_upper"].values
    ok = np.isfinite(lo)
    below, above = row["n_complex_pairs_below"].values[ok], row["n_complex_pairs_above"].values[ok]
    classes = [int(row["n_complex_pairs_at_scan_start"]), *map(int, above)]
    assert list(map(int, below)) == classes[:-1]  # each change starts from the class before it
    ends = [scan[0], *np.column_stack([lo[ok], hi[ok]]).ravel(), scan[1]]
    return [(float(ends[2 * i]), float(ends[2 * i + 1]), c) for i, c in enumerate(classes)]


def stable_intervals(row: xr.Dataset) -> set[tuple[float, float]]:
    lo, hi = row["omega_stable_lower"].values, row["omega_stable_upper"].values
    return {(float(a), float(b)) for a, b in zip(lo, hi, strict=True) if np.isfinite(a)}


@pytest.fixture(scope="module")
def critical_file(tmp_path_factory):
    """The critical spin rates of the gyroscopes' scene (against m_2, a slider for K_1), read back, and its page."""
    folder = tmp_path_factory.mktemp("critical")
    (folder / "scene.toml").write_text(gyroscopes_scene().to_toml(), encoding="utf-8")
    assert main(["critical", str(folder / "scene.toml"), "-o", str(folder / "c.nc"), "--threads", "1", "-q"]) == 0
    assert main(["plot", str(folder / "c.nc"), "-o", str(folder / "c.html")]) == 0
    with xr.open_dataset(folder / "c.nc") as ds:
        return ds.load(), folder / "c.html"


def test_hover_shows_each_stretch_of_the_critical_values(new_page, critical_file, tmp_path):
    ds, html = critical_file
    assert ds.attrs["critical_along"] == "omega"
    system = systems.of_atlas(ds.attrs)
    scan = tuple(float(v) for v in ds.attrs["critical_scan_range"])
    page = new_page().open(html)
    assert page.errors() == []
    px = (scan[1] - scan[0]) / 600  # the map is 600 px wide
    hovered = set()
    for k in (0, 1):
        if k:
            assert page.move_slider("slider-K_1", 1) == 1
            page.wait("the title at K_1 index 1", lambda: page.text("title").splitlines()[-1], lambda t: at_point(t, {"K_1": float(ds["K_1"][1])}))
        for j in range(ds.sizes["m_2"]):
            row = ds.isel(m_2=j, K_1=k)
            gaps = [(a, b) for a, b in zip(row["undecided_lower"].values, row["undecided_upper"].values, strict=True) if np.isfinite(a)]
            for start, end, c in stretches(row, scan):
                if c == system.stable_label:
                    assert (start, end) in stable_intervals(row)
                mid = (start + end) / 2
                if end - start < 8 * px or any(a - 2 * px < mid < b + 2 * px for a, b in gaps):
                    continue  # too narrow to hover, or under an undecided gap drawn over it
                page.hover("map", mid, float(row["m_2"]))
                where = {"m_2": float(row["m_2"]), "K_1": float(row["K_1"])}

                def caught_up(text, mid=mid, where=where):
                    m = re.fullmatch(r"ω from (\S+) to (\S+) rad s⁻¹", (text.splitlines() + ["", ""])[1])
                    return m is not None and float(m[1]) <= mid <= float(m[2]) and at_point("\n".join(text.splitlines()[2:]), where)

                readout = page.wait(f"the readout at omega = {mid}, {where}", lambda: page.text("readout"), caught_up)
                lines = readout.splitlines()
                assert lines[0] == f"N_c = {c}: {system.class_name(c)}"
                shown = re.fullmatch(r"ω from (\S+) to (\S+) rad s⁻¹", lines[1])
                np.testing.assert_allclose([float(shown[1]), float(shown[2])], [start, end], rtol=1e-9)
                assert page.wait_tooltip(lines[1]) == readout
                hovered.add(c)
    assert hovered == {0, 1}  # stable and unstable stretches were both hovered
    assert_drawn_png(page.screenshot(tmp_path / "critical.png"))
    assert page.errors() == []
