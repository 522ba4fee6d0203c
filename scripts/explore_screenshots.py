"""The figures of the interactive pages for the docs: screenshots of real pages in headless Chromium.

    python scripts/explore_screenshots.py             # writes docs/figures/explore-atlas.png and explore-critical.png
    python scripts/explore_screenshots.py --out DIR   # elsewhere

explore-atlas.png: the page of the two tops' atlas (spin rate x mass of the top body, a slider for the joint's
stiffness K_1) at its second slider value, the mouse on a stable point, its tooltip and readout shown.
explore-critical.png: the page of the same scene's critical spin rates (against the mass of the top body, a slider
for K_1), the mouse on a stable stretch.  Both pages are written by ``stabmap plot``, as a reader would write them,
and driven by tests/browser.py (Chromium, chromedriver and selenium must be installed).  Each figure is cropped to the
page's content and stored with a small palette, to keep it small in the repository.
"""

from __future__ import annotations

import argparse
import importlib.util
import tempfile
import time
from pathlib import Path

import numpy as np

import stabmap
from stabmap.cli import main

ROOT = Path(__file__).resolve().parents[1]
# The two tops of tests/scenes.py on a grid fine enough for a picture (2,400 points; about ten seconds on 2 cores).
GRID = """[grid]
omega = { start = 1.0, stop = 150.0, num = 40 }
m_2 = { start = 0.1, stop = 5.0, num = 20, scale = "log" }
K_1 = { values = [5.0, 20.0, 60.0] }
"""
CRITICAL_ROWS = 12  # rows (values of m_2) of the critical-values page
MARGIN = 12  # [px] of white kept around the page's content
MAX_BYTES = 250_000


def load_test_module(name: str):
    """The module ``name`` of the tests folder, imported by its path (a library of the tests, not a package module)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "tests" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def load_browser():
    """tests/browser.py: headless Chromium."""
    return load_test_module("browser")


def scene_text() -> str:
    """The two tops (tests/scenes.py, TWO_TOPS) with this script's grid and a title for the docs."""
    tops = load_test_module("scenes").TWO_TOPS
    tops = tops.replace('title = "two tops, small grid"', 'title = "two tops on a fixed point, elastic joint"')
    return tops[: tops.index("[grid]")] + GRID


def save_cropped(page, path: Path) -> Path:
    """A screenshot of ``page`` cropped to its content (every pixel that is not white, plus MARGIN), in at most 256
    colours (the page's flat fills and anti-aliased text need no more)."""
    from PIL import Image

    with tempfile.TemporaryDirectory() as tmp:
        raw = page.screenshot(Path(tmp) / "raw.png")
        with Image.open(raw) as image:
            rgb = image.convert("RGB")
    ink = np.argwhere((np.asarray(rgb) < 250).any(axis=2))
    (top, left), (bottom, right) = ink.min(axis=0), ink.max(axis=0)
    box = (max(0, left - MARGIN), max(0, top - MARGIN), min(rgb.width, right + MARGIN + 1), min(rgb.height, bottom + MARGIN + 1))
    rgb.crop(box).quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(path, optimize=True)
    size = path.stat().st_size
    print(f"wrote {path} ({size / 1e3:.0f} kB, {box[2] - box[0]} x {box[3] - box[1]} px)")
    if size > MAX_BYTES:
        raise SystemExit(f"{path} is {size / 1e3:.0f} kB, over the {MAX_BYTES / 1e3:.0f} kB a docs figure may take")
    return path


def node(ds, dim: str, value: float) -> float:
    """The grid value of ``dim`` nearest to ``value``: the pointer goes on a grid node, inside its block, not on a
    block's edge (where the page shows no tooltip, see tests/test_explore_browser.py)."""
    values = np.asarray(ds[dim], dtype=float)
    return float(values[np.argmin(np.abs(values - value))])


def atlas_figure(new_page, work: Path, out: Path) -> None:
    ds = stabmap.compute_atlas(stabmap.loads_scene(scene_text()), progress=False)
    stabmap.write_atlas(ds, work / "atlas.nc")
    main(["plot", str(work / "atlas.nc"), "-o", str(work / "atlas.html")])
    page = new_page().open(work / "atlas.html")
    page.move_slider("slider-K_1", 1)
    page.wait_text("title", "K₁ = 20")
    page.hover("map", node(ds, "omega", 110.0), node(ds, "m_2", 0.6))  # stable, right of the boundary
    page.wait_text("readout", "N_c = 0")
    page.wait_tooltip("N_c = 0")
    time.sleep(0.3)  # the tooltip's fade-in
    save_cropped(page, out / "explore-atlas.png")


def scene_grid(scene) -> dict[str, np.ndarray]:
    """The scene's grid values by axis name."""
    return {a.name: np.asarray(a.values, dtype=float) for a in scene.grid}


def critical_figure(new_page, work: Path, out: Path) -> None:
    scene = stabmap.loads_scene(scene_text().replace("num = 20", f"num = {CRITICAL_ROWS}"))
    (work / "scene.toml").write_text(scene.to_toml(), encoding="utf-8")
    main(["critical", str(work / "scene.toml"), "-o", str(work / "critical.nc"), "-q"])
    main(["plot", str(work / "critical.nc"), "-o", str(work / "critical.html")])
    page = new_page().open(work / "critical.html")
    page.move_slider("slider-K_1", 1)
    page.wait_text("title", "K₁ = 20")
    page.hover("map", 100.0, node(scene_grid(scene), "m_2", 0.6))  # a row's middle
    page.wait_text("readout", "N_c = 0")
    page.wait_tooltip("N_c = 0")
    time.sleep(0.3)
    save_cropped(page, out / "explore-critical.png")


def main_() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "figures", help="directory of the figures")
    args = parser.parse_args()
    browser = load_browser()
    with tempfile.TemporaryDirectory(prefix="stabmap-explore-") as tmp, browser.browser() as new_page:
        atlas_figure(new_page, Path(tmp), args.out)
        critical_figure(new_page, Path(tmp), args.out)


if __name__ == "__main__":
    main_()
