"""The browser harness (tests/browser.py) on a toy page that keeps the interactive atlas's conventions.

The toy page: a ``figure(name="map")`` with a linear x axis and a log y axis, a 3 x 3 grid of quads whose label and
colour are known per cell and per position of the slider ``slider-K_1``, a tooltip and a hover callback writing
``Div(name="readout")``, and a slider callback that swaps the quads' data and writes ``Div(name="title")``.  What the
browser shows is checked against the grid as built here, in Python.

Without Chromium these tests skip, or fail when STABMAP_REQUIRE_BROWSER=1.
"""

from __future__ import annotations

import bisect
import math
import re

import pytest
from browser import Page, browser, chromium_or_skip

X_EDGES = (0.0, 1.0, 2.0, 3.0)
Y_EDGES = (1.0, 10.0, 100.0, 1000.0)  # on the log axis: cells of equal height
K = 3  # positions of the slider K_1
MAP_SIZE = (600, 450)  # the figure's size, pixels
# Points inside cells, and where a linear y mapping would put them in another row, so a hover there tells log from linear.
POINTS = ((0.5, 2.0), (1.5, 31.6), (2.5, 500.0), (0.25, 800.0), (2.9, 1.3), (1.1, 12.0))


def label(row: int, col: int, k: int) -> str:
    return f"r{row}c{col}k{k}"


def colour(row: int, col: int, k: int) -> tuple[int, int, int]:
    return 40 + 60 * col, 40 + 60 * row, 40 + 60 * k


def cell_at(x: float, y: float) -> tuple[int, int]:
    """(row, column) of the cell holding data point (x, y)."""
    return bisect.bisect(Y_EDGES, y) - 1, bisect.bisect(X_EDGES, x) - 1


def cells(k: int) -> dict[str, list]:
    """The quads' data at slider position k."""
    grid = [(row, col) for row in range(len(Y_EDGES) - 1) for col in range(len(X_EDGES) - 1)]
    return {
        "left": [X_EDGES[col] for _, col in grid],
        "right": [X_EDGES[col + 1] for _, col in grid],
        "bottom": [Y_EDGES[row] for row, _ in grid],
        "top": [Y_EDGES[row + 1] for row, _ in grid],
        "label": [label(row, col, k) for row, col in grid],
        "color": ["#{:02x}{:02x}{:02x}".format(*colour(row, col, k)) for row, col in grid],
    }


def write_toy_page(path) -> None:
    """Write the toy page, self-contained (bokeh's scripts inlined), to ``path``."""
    from bokeh.embed import file_html
    from bokeh.layouts import column
    from bokeh.models import ColumnDataSource, CustomJS, Div, HoverTool, Slider
    from bokeh.plotting import figure
    from bokeh.resources import INLINE

    data = [cells(k) for k in range(K)]
    source = ColumnDataSource(data[0], name="cells")
    fig = figure(
        name="map", y_axis_type="log", width=MAP_SIZE[0], height=MAP_SIZE[1], x_range=X_EDGES[::3], y_range=Y_EDGES[::3], tools=""
    )
    fig.quad(left="left", right="right", bottom="bottom", top="top", color="color", source=source)
    title = Div(name="title", text="<i>K_1</i> = 0")
    readout = Div(name="readout", text="")
    slider = Slider(name="slider-K_1", start=0, end=K - 1, step=1, value=0, title="K_1")
    readout_js = CustomJS(
        args={"source": source, "readout": readout, "slider": slider},
        code="""
        const inds = cb_data.index.indices;
        if (inds.length) {
          const {x, y} = cb_data.geometry;
          readout.text = `<b>label=${source.data.label[inds[0]]}</b> x=${x.toFixed(4)} y=${y.toPrecision(5)} slider=${slider.value}`;
        }""",
    )
    fig.add_tools(HoverTool(tooltips=[("label", "@label")], callback=readout_js))
    swap_js = "source.data = data[cb_obj.value]; title.text = `<i>K_1</i> = ${cb_obj.value}`;"
    slider.js_on_change("value", CustomJS(args={"source": source, "title": title, "data": data}, code=swap_js))
    path.write_text(file_html(column(title, fig, slider, readout), resources=INLINE, title="toy atlas"), encoding="utf-8")


@pytest.fixture(scope="module")
def new_page():
    with browser() as factory:
        yield factory


@pytest.fixture(scope="module")
def toy(tmp_path_factory):
    path = tmp_path_factory.mktemp("toy") / "toy.html"
    write_toy_page(path)
    return path


@pytest.fixture
def page(new_page, toy) -> Page:
    page = new_page().open(toy)
    assert page.errors() == []
    return page


def test_hover_shows_the_cell_under_the_mouse_in_tooltip_and_readout(page):
    for x, y in POINTS:
        row, col = cell_at(x, y)
        page.hover("map", x, y)
        assert label(row, col, 0) in page.wait_tooltip(label(row, col, 0))
        readout = page.wait_text("readout", f"label={label(row, col, 0)} ")
        # the readout's coordinates are those hovered, to within the pixel the mouse moves by
        shown = dict(re.findall(r"(\w+)=(\S+)", readout))
        assert abs(float(shown["x"]) - x) < 1.5 * (X_EDGES[-1] - X_EDGES[0]) / MAP_SIZE[0]
        assert abs(math.log10(float(shown["y"]) / y)) < 1.5 * math.log10(Y_EDGES[-1] / Y_EDGES[0]) / (MAP_SIZE[1] - 50)
        assert shown["slider"] == "0"
    # the text is the shown text: the Div's HTML has its tags, the text read has not
    assert "<b>" in page.model("readout").text and "<" not in readout


def test_hover_outside_the_frame_is_refused(page):
    with pytest.raises(ValueError, match="outside"):
        page.hover("map", 1.5, 5000.0)


def test_slider_changes_data_title_and_hover(page):
    assert page.text("title") == "K_1 = 0"
    assert page.move_slider("slider-K_1", 1) == 1
    assert page.wait_text("title", "K_1 = 1") == "K_1 = 1"
    assert page.model("cells").data["label"] == cells(1)["label"]
    x, y = POINTS[1]
    page.hover("map", x, y)
    assert "slider=1" in page.wait_text("readout", f"label={label(*cell_at(x, y), 1)} ")
    page.wait_tooltip(label(*cell_at(x, y), 1))
    # the same point again, after the data under it changed: the hover moves the mouse, so the readout follows
    assert page.move_slider("slider-K_1", 5) == K - 1  # stops at the end
    page.hover("map", x, y)
    page.wait_text("readout", f"label={label(*cell_at(x, y), K - 1)} ")
    assert page.move_slider("slider-K_1", -K) == 0
    assert page.wait_text("title", "K_1 = 0") == "K_1 = 0"
    assert page.model("cells").data["label"] == cells(0)["label"]


def test_screenshot_is_the_page_as_drawn(page, tmp_path):
    from PIL import Image

    page.move_slider("slider-K_1", 2)
    page.wait_text("title", "K_1 = 2")
    path = page.screenshot(tmp_path / "page.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with Image.open(path) as image:
        image.load()
        assert image.size == tuple(page.js("return [innerWidth, innerHeight]")) == (1400, 1000)
        rgb = image.convert("RGB")
    assert len(rgb.getcolors(maxcolors=1 << 24)) > 10  # not blank
    # each cell's centre, placed by the harness's data-to-pixel mapping, has that cell's colour as the browser drew it
    for row in range(len(Y_EDGES) - 1):
        for col in range(len(X_EDGES) - 1):
            x, y = (X_EDGES[col] + X_EDGES[col + 1]) / 2, math.sqrt(Y_EDGES[row] * Y_EDGES[row + 1])
            px, py = page.point("map", x, y)
            drawn = rgb.getpixel((round(px), round(py)))
            assert max(abs(a - b) for a, b in zip(drawn, colour(row, col, 2), strict=True)) <= 2, (row, col, drawn)


def test_model_reads_properties_and_refuses_unknown_ones(page):
    assert page.model("slider-K_1").end == K - 1
    assert page.model("map").y_scale["type"] == "LogScale"
    assert page.model("cells").data["top"] == cells(0)["top"]
    with pytest.raises(Exception, match="no property"):
        page.model("slider-K_1").nonsense  # noqa: B018
    with pytest.raises(Exception, match="no model named"):
        page.model("no-such-model").value  # noqa: B018


def test_errors_reports_what_the_page_logs(page):
    page.js("console.error('toy failure')")
    assert any("toy failure" in message for message in page.errors())
    assert page.errors() == []


def test_without_chromium_the_tests_skip(monkeypatch):
    monkeypatch.setattr("browser.CHROMIUM", ("/nonexistent/chromium",))
    monkeypatch.delenv("STABMAP_REQUIRE_BROWSER", raising=False)
    with pytest.raises(pytest.skip.Exception, match="apt-get install chromium chromium-driver"):
        chromium_or_skip()


def test_without_chromium_ci_fails(monkeypatch):
    monkeypatch.setattr("browser.CHROMEDRIVER", ("/nonexistent/chromedriver",))
    monkeypatch.setenv("STABMAP_REQUIRE_BROWSER", "1")
    with pytest.raises(pytest.fail.Exception, match="apt-get install chromium chromium-driver"):
        chromium_or_skip()
