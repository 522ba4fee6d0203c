"""Answers in the user's terms: ``stabmap query``, ``stabmap critical`` and ``stabmap info`` on a scene in rpm.

The atlas is a rigid shell on its centre of mass (p = A lam^2 + C omega lam + M_alpha) scanned in rpm. Its reference
is the classical rigid-shell criterion, stable exactly where S_g = C^2 omega^2 / (4 A M_alpha) >= 1, with growth rate
|Im lam| = sqrt(4 A M_alpha - C^2 omega^2) / (2 A) below it. With A = 1, C = 0.5 and M_alpha = 4, S_g = omega^2 / 64:
the boundary is omega = 8 rad/s = 240 / pi rpm, and S_g = 2 at omega = 8 sqrt 2.

- Spin rates are echoed in rpm with rad/s beside (points, --smallest-stable, --boundaries, critical values).
- Every printed value carries the units of its variable.
- S_g, a derived quantity, is shown at a point and may stand for omega, along which it rises.
- A value outside the scan is an error unless --nearest-edge is given.
- -o FILE's suffix picks the format; the whole atlas goes to CSV one row per grid point, a slab at a time.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re

import numpy as np
import pytest

import stabmap
from stabmap import loads_scene
from stabmap.cli import main
from stabmap.read.info import intervals
from stabmap.read.report import render
from stabmap.run.critical import critical

A, C, M = 1.0, 0.5, 4.0
RPM = 2 * math.pi / 60  # rad/s per rpm

SHELL = """
title = "rigid shell in rpm"
support = "fixed"
M_alpha = 4.0
[[bodies]]
m = 1.0
A = 1.0
C = 0.5
c = 0.0
[grid]
omega = {{ start = "30 rpm", stop = "150 rpm", num = 25 }}
{other}
"""


def scene(other: str = "m_1 = { values = [1.0, 2.0] }"):
    return loads_scene(SHELL.format(other=other))


def S_g(w):
    return C * C * np.asarray(w) ** 2 / (4 * A * M)


@pytest.fixture(scope="module")
def shell():
    return stabmap.compute_atlas(scene(), threads=1, progress=False)


@pytest.fixture(scope="module")
def shell_file(shell, tmp_path_factory):
    return stabmap.write_atlas(shell, tmp_path_factory.mktemp("terms") / "shell.nc")


def run(capsys, *args) -> tuple[int, str, str]:
    code = main([*map(str, args)])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_the_reference_holds_on_the_atlas(shell):
    w = shell.omega.values
    assert shell.omega.attrs["display_units"] == "rpm"
    np.testing.assert_allclose(shell["S_g"].values, S_g(w), rtol=1e-15)
    assert ((shell.n_complex_pairs.values == 0) == (S_g(w) >= 1)[:, None]).all()


# --- 1. spin rates in the scene's unit, SI beside ------------------------------------------------------------------


def test_a_point_is_echoed_in_rpm_with_rad_per_s_beside(shell_file, capsys):
    code, out, _ = run(capsys, "query", shell_file, "omega=101 rpm", "m_1=1")
    assert code == 0
    assert out.splitlines()[0] == f"omega = 101 rpm ({101 * RPM:.6g} rad s-1) -> nearest grid point 100 rpm ({100 * RPM:.8g} rad s-1)"


def test_smallest_stable_and_boundaries_in_rpm(shell_file, shell, capsys):
    w = shell.omega.values
    first = int(np.argmax(S_g(w) >= 1))  # the first grid spin at or above the boundary, 8 rad/s = 76.4 rpm: 80 rpm
    assert round(w[first] / RPM) == 80
    code, out, _ = run(capsys, "query", shell_file, "--smallest-stable", "omega", "--over", "m_1")
    lines = out.splitlines()
    assert code == 0
    assert lines[0] == (f"smallest stable omega [rpm (rad s-1)], searched upward over 25 grid values "
                        f"30 .. 150 rpm ({30 * RPM:.8g} .. {150 * RPM:.8g} rad s-1)")
    row = lines[2].split()
    assert row[:5] == ["1", "80", f"({w[first]:.8g})", "75", f"({w[first - 1]:.8g})"]
    code, out, _ = run(capsys, "query", shell_file, "--boundaries", "omega", "m_1=2")
    lines = out.splitlines()
    assert code == 0 and lines[0].startswith("boundaries along omega [rpm (rad s-1)]: 1 change")
    assert lines[-2].split() == ["75", f"({w[first - 1]:.8g})", "80", f"({w[first]:.8g})", "1", "0"]


def test_critical_values_are_printed_in_rpm(capsys, tmp_path):
    crit = critical(scene("m_1 = { values = [1.0] }"), "omega", rtol=1e-10)
    (line,) = [x for x in intervals(crit) if "stable omega" in x]
    # 8 rad/s = 240 / pi rpm, located to 1e-10 relative; 150 rpm is the scan's end
    found = re.search(r"stable omega ([0-9.]+) rpm \(([0-9.]+) rad s-1, boundary\) to 150 rpm \(([0-9.]+) rad s-1, scan end\)", line)
    assert found, line
    assert abs(float(found[1]) - 240 / math.pi) <= 1e-8 and abs(float(found[2]) - 8.0) <= 1e-8
    path = tmp_path / "crit.nc"
    stabmap.write_atlas(crit, path)
    code, out, _ = run(capsys, "query", path)
    assert code == 0 and "omega lower [rpm (rad s-1)]" in out.splitlines()[1]
    code, _, err = run(capsys, "query", path, "m_1=3")  # outside the scan of the other axis: refused, as for an atlas
    assert code == 2 and "m_1 = 3 kg lies outside the scan of m_1" in err
    assert run(capsys, "query", path, "m_1=3", "--nearest-edge")[0] == 0


# --- 2. every printed value carries its unit -------------------------------------------------------------------


def test_every_printed_value_carries_its_units(shell_file, shell, capsys):
    code, out, _ = run(capsys, "query", shell_file, "omega=60 rpm", "m_1=1")
    assert code == 0
    w = 60 * RPM
    rate = math.sqrt(4 * A * M - (C * w) ** 2) / (2 * A)
    values = dict(line.split(" = ", 1) for line in out.splitlines()[2:] if " = " in line)
    number, unit = values["growth_rate"].split()[:2]
    assert abs(float(number) - rate) <= 1e-6 * rate and unit == "s-1" and values["growth_rate"].endswith("s-1)")
    number, unit = values["efolding_time"].split()
    assert abs(float(number) - 1 / rate) <= 1e-6 / rate and unit == "s"
    # the rule, for every variable with units: its value is followed by them (taken from the file, not a list)
    for name, text in values.items():
        units = shell[name].attrs.get("units", "1") if name in shell.variables else "1"
        if units != "1" and "flag_values" not in shell[name].attrs:
            assert text.split()[1] == units, (name, text)


# --- 3. derived quantities ------------------------------------------------------------------------------------------


def test_S_g_is_shown_at_the_point(shell, shell_file, capsys):
    label = stabmap.label_at(shell, omega="100 rpm", m_1=1)
    assert label.derived["S_g"] == pytest.approx(S_g(100 * RPM), rel=1e-14)
    code, out, _ = run(capsys, "query", shell_file, "omega=100 rpm", "m_1=1")
    assert f"S_g = {S_g(100 * RPM):.8g} at that grid point (derived from omega)" in out.splitlines()


def test_a_value_of_S_g_stands_for_the_spin_where_S_g_takes_it(shell, shell_file, capsys):
    w = shell.omega.values
    target = 8 * math.sqrt(2)  # S_g = 2
    label = stabmap.label_at(shell, S_g=2, m_1=1)
    assert label.grid_point["omega"] == w[np.argmin(np.abs(w - target))]
    assert label.n_complex_pairs == 0 and abs(label.requested["omega"] - target) < 0.01 * target  # linear between grid spins
    code, out, _ = run(capsys, "query", shell_file, "S_g=2", "m_1=1")
    assert code == 0 and out.startswith("S_g = 2 -> omega = ") and "where S_g = 2 along omega" in out
    # a range of S_g: the grid spins where 1 <= S_g <= 3 (no grid spin lies near either end)
    f = stabmap.stable_fraction(shell, S_g=(1, 3))
    inside = (S_g(w) >= 1) & (S_g(w) <= 3)
    assert f.points == 2 * int(inside.sum()) and f.stable == f.points
    assert stabmap.stable_fraction(shell, S_g=(None, 1)).stable == 0


def test_S_g_over_two_axes_or_outside_its_range_is_refused(tmp_path, capsys, shell_file):
    ds = stabmap.compute_atlas(scene("A_1 = { values = [1.0, 2.0] }"), threads=1, progress=False)
    assert ds["S_g"].dims == ("omega", "A_1")
    path = stabmap.write_atlas(ds, tmp_path / "two.nc")
    code, _, err = run(capsys, "query", path, "S_g=2", "A_1=1")
    assert code == 2 and err.strip() == ("stabmap: error: S_g depends on omega and A_1, so a value of it is no single grid "
                                         "point; give the grid axes instead (omega, A_1)")
    code, _, err = run(capsys, "query", shell_file, "S_g=9", "m_1=1")
    assert code == 2 and "S_g = 9 lies outside this atlas" in err and "--nearest-edge" in err


# --- 8. outside the scan -----------------------------------------------------------------------------------------


def test_a_value_outside_the_scan_is_an_error_unless_the_nearest_edge_is_asked(shell_file, shell, capsys):
    code, out, err = run(capsys, "query", shell_file, "omega=4200", "m_1=1")
    assert code == 2 and out == ""
    assert err.strip() == (f"stabmap: error: omega = {4200 / RPM:.6g} rpm (4200 rad s-1) lies outside the scan of omega, "
                           f"30 .. 150 rpm ({30 * RPM:.8g} .. {150 * RPM:.8g} rad s-1); give a value inside it, or "
                           "--nearest-edge (Python: nearest_edge=True) to use the nearest end of the scan")
    code, out, _ = run(capsys, "query", shell_file, "omega=4200", "m_1=1", "--nearest-edge")
    assert code == 0 and "nearest grid point 150 rpm" in out and "(outside the scan: nearest edge, as asked)" in out
    for question in (["--fraction"], ["--boundaries", "omega"]):
        code, _, err = run(capsys, "query", shell_file, *question, "m_1=7")
        assert code == 2 and "m_1 = 7 kg lies outside the scan of m_1" in err
    with pytest.raises(stabmap.StabmapError, match="outside the scan"):
        stabmap.label_at(shell, omega=4200, m_1=1)
    assert stabmap.label_at(shell, omega=4200, m_1=1, nearest_edge=True).grid_point["omega"] == shell.omega.values[-1]
    # the grid's own ends, as printed (8 digits), are inside
    assert stabmap.label_at(shell, omega=float(f"{shell.omega.values[0]:.8g}"), m_1=1).grid_point["omega"] == shell.omega.values[0]


# --- 9. -o FILE: its suffix is the format ------------------------------------------------------------------------


def test_output_suffix_picks_the_format(shell_file, tmp_path, capsys):
    code, out, _ = run(capsys, "query", shell_file, "--fraction", "m_1=1", "-o", tmp_path / "frac.csv")
    assert code == 0 and out.strip() == f"wrote {tmp_path / 'frac.csv'}"
    (row,) = list(csv.DictReader(open(tmp_path / "frac.csv")))
    assert int(row["points"]) == 25 and int(row["stable"]) == int((S_g(stabmap.open_atlas(shell_file).omega.values) >= 1).sum())
    code, _, _ = run(capsys, "query", shell_file, "--boundaries", "omega", "-o", tmp_path / "b.json")
    assert code == 0 and json.loads((tmp_path / "b.json").read_text())["stabmap_query"] == "boundaries"
    code, _, _ = run(capsys, "query", shell_file, "omega=100rpm", "m_1=1", "-o", tmp_path / "point.csv")
    assert code == 0 and next(csv.DictReader(open(tmp_path / "point.csv")))["n_complex_pairs"] == "0"
    code, _, err = run(capsys, "query", shell_file, "--fraction", "-o", tmp_path / "frac.xlsx")
    assert code == 2 and "-o " in err and ".csv" in err and len(err.strip().splitlines()) == 1
    code, _, err = run(capsys, "query", shell_file, "--fraction", "--json", "-o", tmp_path / "frac2.csv")
    assert code == 2 and "--json" in err
    assert not (tmp_path / "frac.xlsx").exists() and not (tmp_path / "frac2.csv").exists()


# --- 12. the whole atlas as CSV ------------------------------------------------------------------------------------


def _rows(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


def test_the_whole_atlas_as_csv_one_row_per_grid_point(shell_file, shell, tmp_path, capsys):
    out_file = tmp_path / "atlas.csv"
    code, out, _ = run(capsys, "query", shell_file, "--csv", "-o", out_file)
    assert code == 0 and out.strip() == f"wrote {out_file}: 50 rows, one per grid point"
    rows = _rows(out_file.read_text())
    assert list(rows[0]) == ["omega [rad s-1]", "omega [rpm]", "m_1 [kg]", "S_g", "n_complex_pairs", "stability", "cell",
                             "growth_rate [s-1]"]
    assert len(rows) == shell.omega.size * shell.m_1.size
    w, m = np.meshgrid(shell.omega.values, shell.m_1.values, indexing="ij")
    np.testing.assert_array_equal([float(r["omega [rad s-1]"]) for r in rows], w.ravel())
    np.testing.assert_array_equal([float(r["m_1 [kg]"]) for r in rows], m.ravel())
    np.testing.assert_allclose([float(r["omega [rpm]"]) for r in rows], w.ravel() / RPM, rtol=1e-15)
    np.testing.assert_array_equal([float(r["S_g"]) for r in rows], np.repeat(shell["S_g"].values, 2))
    stable = S_g(w.ravel()) >= 1
    assert [r["stability"] for r in rows] == ["stable" if s else "unstable" for s in stable]
    assert [int(r["n_complex_pairs"]) for r in rows] == [0 if s else 1 for s in stable]
    # float32 in the file, written as the shortest text that reads back to it
    np.testing.assert_array_equal(np.array([r["growth_rate [s-1]"] for r in rows], dtype=np.float32), shell.growth_rate.values.ravel())
    # printed without -o, and the same text a slab of 7 points at a time (slabs cut through the grid's rows)
    code, out, _ = run(capsys, "query", shell_file, "--csv")
    assert code == 0 and out == out_file.read_text()
    from stabmap.read import export  # here, so the other tests run on a stabmap without it

    buf = io.StringIO()
    with stabmap.open_atlas(shell_file, lazy=True) as lazy:
        assert export.write_csv(lazy, buf, points=7) == 50
    assert buf.getvalue() == out_file.read_text()
    code, _, err = run(capsys, "query", shell_file, "--csv", "-o", out_file)
    assert code == 2 and "already exists" in err


def test_the_answers_render_the_same_from_python(shell):
    text = render(stabmap.label_at(shell, omega="100 rpm", m_1=1), atlas=shell)
    assert text.splitlines()[0] == f"omega = 100 rpm ({100 * RPM:.6g} rad s-1) -> nearest grid point 100 rpm ({100 * RPM:.8g} rad s-1)"


def test_a_monotone_derived_quantity_becomes_an_axis_for_plots(shell):
    from stabmap.read.derived import as_axis

    swapped = as_axis(shell, "S_g")
    assert swapped["n_complex_pairs"].dims == ("S_g", "m_1")
    np.testing.assert_array_equal(swapped["omega"].values, shell["omega"].values)
    assert ((swapped["n_complex_pairs"].sel(m_1=1.0).values == 0) == (swapped["S_g"].values >= 1)).all()
    with pytest.raises(stabmap.StabmapError, match="no derived quantity"):
        as_axis(shell, "m_1")


def test_a_unit_on_an_axis_that_takes_none_is_refused_for_that(shell_file, capsys):
    """m_1 is a mass: '1 kg' on it is refused as a unit where none is read, not as an unknown spin unit; a range's
    unit goes the same way, and an unknown unit on the spin axis is still named as such."""
    code, _, err = run(capsys, "query", shell_file, "omega=100 rpm", "m_1=1 kg")
    assert code == 2 and "a unit is accepted for spin rates only" in err and "m_1 as a plain number in kg" in err
    code, _, err = run(capsys, "query", shell_file, "--fraction", "m_1=1:2kg")
    assert code == 2 and "a unit is accepted for spin rates only" in err
    code, _, err = run(capsys, "query", shell_file, "omega=100 rpx", "m_1=1")
    assert code == 2 and "unknown unit 'rpx'" in err


def test_a_plot_against_S_g_puts_the_boundary_at_S_g_1(shell_file, tmp_path, capsys):
    """``stabmap plot --x S_g``: the spin axis drawn as the stability factor it moves, so the stability boundary of
    the rigid shell lies at S_g = 1 (its closed form), inside the one grid cell proved to contain a change."""
    from stabmap.read import derived
    from stabmap.read.plot.atlas import atlas_figure

    code, out, err = run(capsys, "plot", shell_file, "--x", "S_g", "--sel", "m_1=1", "-o", tmp_path / "sg.png")
    assert code == 0 and (tmp_path / "sg.png").stat().st_size > 0, err
    ds = derived.as_axis(stabmap.open_atlas(shell_file), "S_g").sel(m_1=1)
    fig = atlas_figure(ds, x="S_g")
    assert "S_g" in fig.axes[0].get_xlabel() or "S_g" in fig.axes[-1].get_xlabel()
    change = ds.S_g.values[ds.cell.values == 2]  # contains_change
    assert change.size == 1 and abs(change[0] - 1) < np.diff(ds.S_g.values).max()
    code, _, err = run(capsys, "plot", shell_file, "--x", "nothing_like_it", "-o", tmp_path / "bad.png")
    assert code == 2 and not (tmp_path / "bad.png").exists()
