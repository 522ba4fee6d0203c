"""The Campbell diagram (stabmap plot --campbell): the curves drawn are the atlas's modes, the critical speed of one
top is where its closed form puts it, and bad requests exit with the option named and no file."""

from __future__ import annotations

import re

import numpy as np
import pytest

import stabmap
from stabmap.cli import main
from stabmap.read.plot import campbell_figure
from stabmap.read.plot.campbell import campbell_line, critical_speeds

M, A, C, c, g = 1.0, 0.02, 0.08, 0.1, 9.81
A1, mcg = A + M * c * c, M * c * g
TOP = f"""
title = "one top whose precession meets the spin line"
frequencies = true
[[bodies]]
m = {M}
A = {A}
C = {C}
c = {c}
[grid]
omega = {{ start = 4.3, stop = 10.0, num = 58, display_units = "rpm" }}
"""


@pytest.fixture(scope="module")
def top(tmp_path_factory):
    path = tmp_path_factory.mktemp("campbell") / "top.nc"
    stabmap.compute_to_file(stabmap.loads_scene(TOP), path, progress=False)
    return path


def test_the_critical_speed_of_one_top_is_its_closed_form(top):
    """p(lambda) = A1 lambda^2 + C omega lambda + m c g meets lambda = -omega where (C - A1) omega^2 = m c g."""
    ds = stabmap.open_atlas(top)
    line, along, _ = campbell_line(ds, x=None, sel=None)
    ones = [w for order, w, _ in critical_speeds(line, along) if order == -1]
    exact = np.sqrt(mcg / (C - A1))
    step = float(ds.omega[1] - ds.omega[0])
    j = int(np.searchsorted(ds.omega.values, ones[0]))
    # the root changes sign across the link the crossing is interpolated in, so the exact speed lies in that link
    assert len(ones) == 1 and ds.omega.values[j - 1] <= exact <= ds.omega.values[j] and abs(ones[0] - exact) < 0.05 * step


def test_the_curves_drawn_are_the_modes_of_the_atlas(top):
    ds = stabmap.open_atlas(top)
    fig = campbell_figure(ds)
    ax = fig.axes[0]
    for m in range(ds.sizes["mode"]):
        drawn = [coll for coll in ax.collections if (coll.get_gid() or "").startswith(f"mode-{m}-")]
        assert drawn, f"mode {m} is drawn"
        points = np.concatenate([p.vertices for coll in drawn for p in coll.get_paths()])
        expect = dict(zip(ds.omega.values, ds.frequency.values[:, m], strict=True))
        for x, y in points:
            assert y == pytest.approx(expect[x], rel=1e-12)
    assert "rpm" in ax.get_ylabel() and "critical speed" in ax.get_title()


def test_the_cli_draws_a_png_and_a_page(top, tmp_path):
    png, page = tmp_path / "c.png", tmp_path / "c.html"
    assert main(["plot", str(top), "--campbell", "-o", str(png)]) == 0
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert main(["plot", str(top), "--campbell", "-o", str(page)]) == 0
    text = page.read_text()
    assert "<svg" in text and "<title>mode 0:" in text and "Critical speeds" in text
    listed = re.findall(r"<td>1\u00d7</td><td>([-\d.e+]+)</td>", text)
    exact = np.sqrt(mcg / (C - A1)) * 60 / (2 * np.pi)  # the table is in the axis's display unit, rpm
    assert len(listed) == 1 and float(listed[0]) == pytest.approx(exact, abs=0.1)


def test_bad_requests_name_the_option_and_write_nothing(top, tmp_path, capsys):
    plain = tmp_path / "plain.nc"
    stabmap.compute_to_file(stabmap.loads_scene(TOP.replace("frequencies = true", "")), plain, progress=False)
    out = tmp_path / "c.png"
    for args, words in (([str(plain)], "frequencies = true"), ([str(top), "--facet", "omega"], "--facet"),
                        ([str(top), "--sel", "c_1=0.1"], "--sel")):
        assert main(["plot", *args, "--campbell", "-o", str(out)]) == 2
        err = capsys.readouterr().err
        assert words in err and "--campbell" in err or words == "--sel" and words in err
        assert not out.exists()
