"""scripts/figure_gallery.py in quick mode (this checkout only, tiny grids, no git), so that the script behind
docs/plots.md's "Before and after" pictures cannot rot."""

from __future__ import annotations

import pathlib
import runpy

import pytest

SCRIPT = pathlib.Path(__file__).resolve().parents[1] / "scripts" / "figure_gallery.py"
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow  # eight stabmap processes: about 20 s on 2 cores
def test_figure_gallery_quick(tmp_path):
    gallery = runpy.run_path(str(SCRIPT))
    written = gallery["main"](["--quick", "--out", str(tmp_path)])
    names = [k.name for k in gallery["KINDS"]]
    assert sorted(written) == sorted(names)
    for name in names:
        for path in (tmp_path / f"compare-{name}.png", tmp_path / "after" / f"{name}.png"):
            assert path.read_bytes()[:8] == PNG, path
