"""docs/tutorial.ipynb runs as a reader runs it, and what it shows is right.

The notebook is executed once per module by nbclient on the ``python3`` kernel. The kernel runs in an empty
directory with this checkout first on PYTHONPATH, and each cell may take up to CELL_TIMEOUT seconds. The notebook scans
Maievskii's top, whose stability is known in closed form. So each number it prints is checked two ways. The first is
the same question asked here of the atlas file it wrote. The second is independent of stabmap: the grid it should
have kept, and Maievskii's condition in exact rationals (tests/scenes.py ``maievskii_stable``). Its two interactive
pages are checked in their iframes' bytes. Where Chromium is installed, they are also opened and hovered
(tests/browser.py).

Cells are found by their tags (cell metadata), so the prose around them may change freely.
"""

from __future__ import annotations

import ast
import html
import json
import math
import os
import re
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from browser import browser
from scenes import maievskii_stable, maievskii_w2

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "docs" / "tutorial.ipynb"
CELL_TIMEOUT = 300  # seconds per cell; the whole notebook takes seconds
EXAMPLE = "paper-n1-fixed-dry"
KEEP = {"omega": 10, "c_1": 20}  # the notebook keeps every 10th spin rate and every 20th height of the bundled grid
# The points the label-at cell asks about, as it asks them; 100 rpm is 100 * 2 pi / 60 rad/s.
ASKED = ({"omega": 30.0, "c_1": 0.1}, {"omega": "100 rpm", "c_1": 0.2})
RTOL = 1e-10  # stabmap.critical's default width of a located bracket


# ------------------------------------------------------------------------------------------------ helpers


def tagged(nb, tag: str):
    """The one code cell carrying ``tag``."""
    found = [c for c in nb.cells if tag in c.metadata.get("tags", [])]
    assert len(found) == 1, f"docs/tutorial.ipynb: {len(found)} cells tagged {tag!r}, expected one"
    return found[0]


def printed(cell) -> str:
    """What the cell printed (its stdout)."""
    return "".join(o.text for o in cell.outputs if o.output_type == "stream" and o.name == "stdout")


def shown(cell, mime: str) -> str:
    """The cell's result (its last line's value) as ``mime``."""
    results = [o for o in cell.outputs if o.output_type == "execute_result"]
    assert results and mime in results[0].data, f"cell {cell.source[:60]!r} shows no {mime}"
    return results[0].data[mime]


def table_rows(text: str) -> list[dict[str, float]]:
    """The rows of a pandas DataFrame's text, as numbers by column name.

    The text may be wrapped into blocks of columns (a trailing backslash on the header, a blank line between blocks),
    each with its own header and, when the index is named, an index-name line; a row starts with its integer index.
    """
    rows: dict[int, dict[str, float]] = {}
    for block in text.strip("\n").split("\n\n"):
        lines = block.splitlines()
        header = lines[0].replace("\\", " ").split()
        for line in lines[1:]:
            words = line.replace("\\", " ").split()
            if words and words[0].isdigit():
                assert len(words) == len(header) + 1, f"cannot read the row {line!r} under {header}"
                rows.setdefault(int(words[0]), {}).update(zip(header, map(float, words[1:]), strict=True))
    return [rows[i] for i in sorted(rows)]


def bokeh_names(cell) -> tuple[str, set[str]]:
    """The page inside the cell's iframe, and the names of the models of the Bokeh document it carries."""
    frame = re.search(r'<iframe srcdoc="([^"]*)"', shown(cell, "text/html"))
    assert frame, "the explore cell shows no iframe with a srcdoc"
    page = html.unescape(frame.group(1))
    docs = re.findall(r'<script type="application/json" id="[^"]*">\s*(.*?)\s*</script>', page, re.S)
    assert len(docs) == 1, "the iframe's page carries no Bokeh document (application/json script)"
    names: set[str] = set()

    def walk(node):
        if isinstance(node, dict):
            attributes = node.get("attributes")
            if isinstance(attributes, dict) and isinstance(attributes.get("name"), str):
                names.add(attributes["name"])
            for value in node.values():
                walk(value)
        elif isinstance(node, list):
            for value in node:
                walk(value)

    (doc,) = json.loads(docs[0]).values()
    assert doc["roots"], "the Bokeh document has no roots"
    walk(doc)
    return page, names


def critical_omega(c: float) -> float:
    return math.sqrt(maievskii_w2(c))


# ------------------------------------------------------------------------------------------------ fixtures


@pytest.fixture(scope="module")
def grid():
    """The grid the notebook should scan, taken here from the bundled scene's own values."""
    import stabmap

    return {a.name: np.asarray(a.values[:: KEEP[a.name]]) for a in stabmap.example(EXAMPLE).grid}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The notebook executed top to bottom in an empty directory: (notebook with outputs, that directory)."""
    import nbformat
    from nbclient import NotebookClient

    nb = nbformat.read(NOTEBOOK, as_version=4)
    cwd = tmp_path_factory.mktemp("tutorial")
    env = dict(os.environ)  # the kernel imports this checkout's stabmap, as test_docs's commands run it
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    client = NotebookClient(nb, kernel_name="python3", timeout=CELL_TIMEOUT, resources={"metadata": {"path": str(cwd)}})
    client.execute(env=env)  # raises CellExecutionError, with the traceback, on the first cell that raises
    return nb, cwd


@pytest.fixture(scope="module")
def atlas(run):
    import stabmap

    return stabmap.open_atlas(run[1] / "atlas.nc")


@pytest.fixture(scope="module")
def crit(run):
    import stabmap

    return stabmap.open_atlas(run[1] / "critical.nc")


# ------------------------------------------------------------------------------------------------ the file as committed


def test_the_notebook_is_committed_without_outputs_for_the_python3_kernel():
    import nbformat

    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbformat.validate(nb)
    assert nb.metadata.kernelspec.name == "python3"
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert code and all(not c.outputs and c.execution_count is None for c in code)


# ------------------------------------------------------------------------------------------------ the run


def test_every_cell_ran_without_an_error_or_a_warning(run):
    nb, cwd = run
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert all(c.execution_count is not None for c in code)
    errors = [o for c in code for o in c.outputs if o.output_type == "error"]
    assert not errors, errors[0]
    # a reader would see stderr as a red box: a warning in a newcomer's first notebook is a bug of the notebook
    stderr = [o.text for c in code for o in c.outputs if o.output_type == "stream" and o.name == "stderr"]
    assert not stderr, stderr
    assert {"atlas.nc", "critical.nc", "map.png", "critical.png"} <= {p.name for p in cwd.iterdir()}
    for png in ("map.png", "critical.png"):
        assert (cwd / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_atlas_it_wrote_is_the_reduced_grid_and_agrees_with_maievskii(atlas, grid):
    for name, values in grid.items():
        assert np.array_equal(atlas[name].values, values)
    labels = atlas.n_complex_pairs.transpose("omega", "c_1").values
    expected = [[0 if maievskii_stable(w, c) else 1 for c in grid["c_1"]] for w in grid["omega"]]
    assert labels.tolist() == expected
    assert 0 < (labels == 0).sum() < labels.size  # the grid crosses the boundary, so the map shows both classes


def test_both_explore_cells_show_an_iframe_holding_the_bokeh_page(run):
    nb, _ = run
    for tag in ("explore-atlas", "explore-critical"):
        page, names = bokeh_names(tagged(nb, tag))
        assert page.lstrip().lower().startswith("<!doctype html>")
        assert {"map", "readout", "title", "legend", "caption"} <= names, (tag, names)


def test_label_at_prints_the_nearest_grid_point_and_its_label(run, atlas, grid):
    import stabmap

    out = printed(tagged(run[0], "label-at"))
    points = [ast.literal_eval(p) for p in re.findall(r"^nearest grid point: (\{.*\})$", out, re.M)]
    labels = re.findall(r"^N_c = (\d+) -> (\w+) \| decided by (\w+)$", out, re.M)
    assert len(points) == len(labels) == len(ASKED)
    for asked, point, (n_c, stability, decided_by) in zip(ASKED, points, labels, strict=True):
        here = stabmap.label_at(atlas, **asked)
        assert point == here.grid_point
        assert (int(n_c), stability, decided_by) == (here.n_complex_pairs, here.stability, here.decided_by)
        # independently: the nearest value of each axis, and Maievskii's condition there
        for name, value in asked.items():
            value = value if isinstance(value, float) else float(value.split()[0]) * 2 * math.pi / 60
            assert point[name] == grid[name][np.argmin(np.abs(grid[name] - value))]
        stable = maievskii_stable(point["omega"], point["c_1"])
        assert (int(n_c), stability) == ((0, "stable") if stable else (1, "unstable"))
    assert {n for n, _, _ in labels} == {"0", "1"}  # one stable point and one unstable, as the prose says


def test_stable_fraction_prints_the_counts_of_maievskii_stable_points(run, atlas, grid):
    import stabmap

    out = printed(tagged(run[0], "fraction"))
    counts = [(int(a), int(b)) for a, b in re.findall(r"(\d+) of (\d+) grid points stable", out)]
    whole = stabmap.stable_fraction(atlas)
    line = stabmap.stable_fraction(atlas, c_1=0.1)
    fast = stabmap.stable_fraction(atlas, omega=(40, None))
    assert counts == [(f.stable, f.points) for f in (whole, line, fast)]
    omega, c_1 = grid["omega"], grid["c_1"]
    c_near = c_1[np.argmin(np.abs(c_1 - 0.1))]
    assert f"c_1 = {c_near}:" in out
    assert counts == [
        (sum(maievskii_stable(w, c) for w in omega for c in c_1), omega.size * c_1.size),
        (sum(maievskii_stable(w, c_near) for w in omega), omega.size),
        (sum(maievskii_stable(w, c) for w in omega[omega >= 40] for c in c_1), (omega >= 40).sum() * c_1.size),
    ]


def test_boundaries_table_brackets_maievskiis_critical_spin_rate_on_every_line(run, atlas, grid):
    import stabmap

    rows = table_rows(shown(tagged(run[0], "boundaries"), "text/plain"))
    ours = stabmap.boundaries(atlas, "omega").to_dataframe()
    assert len(rows) == len(ours) == grid["c_1"].size  # one change per height: the top is stable from one spin rate up
    omega = grid["omega"]
    for row, (_, want) in zip(rows, ours.iterrows(), strict=True):
        for column in ("c_1", "boundary_lower", "boundary_upper", "n_complex_pairs_below", "n_complex_pairs_above"):
            assert row[column] == pytest.approx(want[column], rel=1e-6, abs=1e-6)  # pandas prints 6 decimals
        # independently: two neighbouring grid values, Maievskii unstable at the lower and stable at the upper
        c = want["c_1"]
        i = int(np.flatnonzero(omega == want["boundary_lower"])[0])
        assert omega[i + 1] == want["boundary_upper"]
        assert (maievskii_stable(omega[i], c), maievskii_stable(omega[i + 1], c)) == (False, True)
        assert (row["n_complex_pairs_below"], row["n_complex_pairs_above"]) == (1, 0)


def test_critical_values_locate_maievskiis_spin_rate_to_rtol(crit, atlas, grid):
    assert np.array_equal(crit.c_1.values, grid["c_1"])
    assert crit.attrs["critical_along"] == "omega"
    brackets = stabmap_brackets(atlas)
    for c in grid["c_1"]:
        line = crit.sel(c_1=c)
        assert int(line.n_stable_intervals) == 1
        lower, outer = float(line.omega_stable_lower[0]), float(line.omega_stable_lower_outer[0])
        # proved stable at the end, proved unstable just outside it, in exact rationals on the binary values
        assert maievskii_stable(lower, c) and not maievskii_stable(outer, c)
        assert Fraction(lower) - Fraction(outer) <= Fraction(RTOL) * Fraction(lower)
        # the stable interval runs to the end of the scan (no unstable value beyond it), and the grid's bracket holds the located value
        assert float(line.omega_stable_upper[0]) == grid["omega"][-1] and np.isnan(line.omega_stable_upper_outer[0])
        low, high = brackets[float(c)]
        assert low < lower < high


def stabmap_brackets(atlas) -> dict[float, tuple[float, float]]:
    import stabmap

    table = stabmap.boundaries(atlas, "omega").to_dataframe()
    return {float(r.c_1): (float(r.boundary_lower), float(r.boundary_upper)) for r in table.itertuples()}


def test_the_printed_comparison_with_maievskii_agrees_to_ten_digits(run, crit, grid):
    out = printed(tagged(run[0], "maievskii"))
    rows = table_rows(out)
    assert [r["c_1"] for r in rows] == pytest.approx(list(grid["c_1"]), abs=1e-10)
    for row, c in zip(rows, grid["c_1"], strict=True):
        exact = critical_omega(c)
        # printed with 10 decimals: the closed form to its rounding, the located value to its bracket and rounding
        assert row["maievskii"] == pytest.approx(exact, abs=6e-11)
        assert row["omega_stable_lower"] == pytest.approx(float(crit.omega_stable_lower.sel(c_1=c)[0]), abs=6e-11)
        assert row["omega_stable_lower"] == pytest.approx(exact, rel=RTOL, abs=6e-11)


# ------------------------------------------------------------------------------------------------ in a browser


@pytest.fixture(scope="module")
def new_page():
    with browser() as factory:
        yield factory


def test_the_pages_in_a_browser_read_out_maievskiis_answer(run, grid, new_page, tmp_path):
    """Open each iframe's page as the notebook's reader sees it, and hover either side of the boundary of a few lines."""
    nb, _ = run
    omega = grid["omega"]
    lines = grid["c_1"][[1, 4, 8]]  # a few heights, inside the map (the edge rows' cells end at the frame)

    path = tmp_path / "atlas.html"
    path.write_text(bokeh_names(tagged(nb, "explore-atlas"))[0], encoding="utf-8")
    page = new_page().open(path)
    for c in lines:
        above = int(np.flatnonzero([maievskii_stable(w, c) for w in omega])[0])  # the first stable grid spin rate
        for i, want in ((above - 1, "N_c = 1: unstable"), (above, "N_c = 0: stable")):
            page.hover("map", omega[i], c)
            readout = page.wait_text("readout", want)
            assert f"ω = {omega[i]:.6g} rad s⁻¹" in readout and f"c₁ = {c:.6g} m" in readout, readout
    assert not page.errors()

    path = tmp_path / "critical.html"
    path.write_text(bokeh_names(tagged(nb, "explore-critical"))[0], encoding="utf-8")
    page = new_page().open(path)
    for c in lines:
        w = critical_omega(c)
        page.hover("map", w - 0.5, c)
        page.wait_text("readout", "N_c = 1: unstable")
        page.hover("map", w + 0.5, c)
        readout = page.wait_text("readout", "N_c = 0: stable")
        start = re.search(r"ω from (\S+) to", readout)
        assert start and float(start.group(1)) == pytest.approx(w, rel=1e-8), readout  # printed to 10 digits
    assert not page.errors()
