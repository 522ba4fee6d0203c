"""Spin rates in rpm and Hz, values in force, and parts of atlases written with their own scene.

- Units (stabmap.scene.units): a spin rate given as "14000 rpm" or "250 Hz" is stored in rad/s; the factors are
  checked against 2 pi / 60 and 2 pi in mpmath, and an atlas of a scene in rpm against the same scene in rad/s and
  against Maievskii's closed form for one top (C^2 omega^2 >= 4 (A + m c^2) m c g, decided in exact rationals).
- Fixed values: ``info`` and figure captions list the common omega only where a body takes it.
- ``write_atlas(ds.sel(...))``: the stored scene is the part's, so the atlas it computes is the file.
"""

from __future__ import annotations

import json
import math
from importlib import resources

import mpmath as mp
import numpy as np
import pytest

import stabmap
from stabmap import loads_scene
from stabmap.cli import main
from stabmap.errors import StabmapError
from stabmap.read.info import describe
from stabmap.read.plot import fixed_caption
from stabmap.scene import units
from stabmap.scene.grid import Axis
from scenes import maievskii_stable

C1 = (0.05, 0.1, 0.2)
RPM = 2 * math.pi / 60  # only to write the rad/s scene by hand; the conversions are checked in mpmath below

TOP = """
title = "one top"
support = "fixed"
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.1
[grid]
omega = {{ start = {start}, stop = {stop}, num = 31 }}
c_1 = {{ values = [0.05, 0.1, 0.2] }}
"""


def exact_si(number: str, per_unit) -> float:
    """``number`` times ``per_unit`` rounded once to a double: ``per_unit`` is "rpm" or "Hz" (evaluated here at 50
    digits, whatever mpmath's global precision another test module left), or an exact number."""
    with mp.workdps(50):
        factor = {"rpm": lambda: 2 * mp.pi / 60, "Hz": lambda: 2 * mp.pi}.get(per_unit, lambda: per_unit)()
        return float(mp.mpf(number) * factor)


# ------------------------------------------------------------------------------------------------ conversions
@pytest.mark.parametrize("text, number, per_unit", [
    ("14000 rpm", "14000", None), ("14000rpm", "14000", None), ("1.4e4 RPM", "14000", None), ("-50 rpm", "-50", None),
    ("250 Hz", "250", "Hz"), ("250hz", "250", "Hz"), ("0.5 Hz", "0.5", "Hz"),
    ("1500 rad/s", "1500", "rad"), ("1500 rad s-1", "1500", "rad"),
])
def test_conversions_against_two_pi(text, number, per_unit):
    with mp.workdps(50):
        factor = {None: 2 * mp.pi / 60, "Hz": 2 * mp.pi, "rad": mp.mpf(1)}[per_unit]
    got = units.in_si("omega", text, "rad s-1")
    assert got == pytest.approx(exact_si(number, factor), rel=2.3e-16, abs=0)  # one rounding of the factor, one of the product


def test_scene_values_in_rpm_and_hz_are_stored_in_rad_per_s():
    text = TOP.format(start='"50 rpm"', stop='"200 rpm"').replace("c = 0.1\n", 'c = 0.1\ns = 0.3\nomega = "5 Hz"\n', 1)
    text = text.replace("[grid]", '[[bodies]]\nm = 1.0\nA = 0.02\nC = 0.03\nc = 0.1\n[grid]')
    s = loads_scene('omega = "14000 rpm"\n' + text)
    assert s.omega == pytest.approx(exact_si("14000", "rpm"), rel=2.3e-16)
    assert s.bodies[0].omega == pytest.approx(exact_si("5", "Hz"), rel=2.3e-16)
    assert s.bodies[1].omega is None
    omega = s.grid[0]
    assert (omega.display_units, omega.scale) == ("rpm", "linear")
    assert omega.values[0] == pytest.approx(exact_si("50", "rpm"), rel=2.3e-16)
    assert omega.values[-1] == pytest.approx(exact_si("200", "rpm"), rel=2.3e-16)
    # the TOML written back holds rad/s and the display unit, and reads back to the same axis
    back = loads_scene(s.to_toml())
    assert back.grid == s.grid and back.omega == s.omega and back.bodies[0].omega == s.bodies[0].omega


def test_values_lists_and_hz_axes():
    s = loads_scene(TOP.format(start=0, stop=1, num=31).replace(
        "omega = { start = 0, stop = 1, num = 31 }", 'omega = { values = ["1 Hz", "2 Hz", "4 Hz"] }'))
    assert s.grid[0].display_units == "Hz" and s.grid[0].scale == "values"
    np.testing.assert_allclose(s.grid[0].values, [exact_si(v, "Hz") for v in "124"], rtol=2.3e-16)
    plain = loads_scene(TOP.format(start='"5 rad/s"', stop='"20 rad/s"'))  # rad/s: the stored unit, nothing to show
    assert plain.grid[0].display_units == "" and plain.grid[0].values[0] == 5.0


def test_reactions_angular_velocity_in_rpm():
    text = resources.files("stabmap.examples").joinpath("reactions-spinning-stage.toml").read_text()
    s = loads_scene(text.replace("omega = [0.0, 0.0, 10.0]", 'omega = [0.0, 0.0, "600 rpm"]')
                    .replace("omega_z = { start = 0.0, stop = 30.0, num = 121 }", 'omega_z = { start = "0 Hz", stop = "4 Hz", num = 5 }'))
    assert s.body.omega[2] == pytest.approx(exact_si("600", "rpm"), rel=2.3e-16)
    assert s.grid[0].display_units == "Hz" and s.grid[0].values[-1] == pytest.approx(exact_si("4", "Hz"), rel=2.3e-16)


@pytest.mark.parametrize("change, message", [
    (("c = 0.1\n", 'c = "0.1 rpm"\n'), "bodies[1].c = '0.1 rpm': a unit is accepted for spin rates only (rad/s, rpm or Hz); give bodies[1].c as a plain number in m"),
    (("0.05, 0.1", '"0.05 rpm", "0.1 rpm"'), "a unit is accepted for spin rates only"),
    (('"50 rpm"', '"50 rps"'), "grid.omega.start = '50 rps': unknown unit 'rps'; a spin rate may be given in rad/s, rpm or Hz"),
    (('"50 rpm"', '"1 Hz"'), "grid.omega: mixed units (Hz, rpm); give every value of one axis in the same unit (rad/s, rpm or Hz)"),
    (('"50 rpm"', "5.0"), "grid.omega: mixed units (no unit, rpm)"),
    (('"50 rpm"', '"50"'), "grid.omega.start must be a number, got '50'"),  # a number in quotes is still no number
    (('"50 rpm"', '"fifty rpm"'), "grid.omega.start = 'fifty rpm': give a number, or a spin rate with its unit"),
    (("num = 31 }", 'num = 31, display_units = "rps" }'), "grid.omega.display_units = 'rps': a spin-rate axis is shown in rpm or Hz"),
    (('values = [0.05, 0.1, 0.2]', 'values = [0.05, 0.1, 0.2], display_units = "rpm"'),
     "grid.c_1.display_units: only a spin-rate axis [rad s-1] has display units; c_1 is in [m], remove display_units"),
])
def test_errors_name_the_key_and_the_accepted_units(change, message):
    text = TOP.format(start='"50 rpm"', stop='"200 rpm"')
    assert change[0] in text
    with pytest.raises(StabmapError) as err:
        loads_scene(text.replace(change[0], change[1], 1))
    assert message in str(err.value)


def test_mixed_units_in_a_values_list():
    text = TOP.format(start=0, stop=1).replace("omega = { start = 0, stop = 1, num = 31 }", 'omega = { values = ["1 Hz", "120 rpm"] }')
    with pytest.raises(StabmapError, match=r"grid.omega.values: mixed units \(Hz, rpm\)"):
        loads_scene(text)


# ------------------------------------------------------------------------------------------------ atlases in rpm
@pytest.fixture(scope="module")
def in_rpm():
    return stabmap.compute_atlas(loads_scene(TOP.format(start='"50 rpm"', stop='"200 rpm"')), threads=1, progress=False)


@pytest.fixture(scope="module")
def rpm_file(in_rpm, tmp_path_factory):
    return stabmap.write_atlas(in_rpm, tmp_path_factory.mktemp("units") / "rpm.nc")


def test_an_atlas_in_rpm_is_the_atlas_in_rad_per_s(in_rpm):
    by_hand = stabmap.compute_atlas(loads_scene(TOP.format(start=repr(50 * RPM), stop=repr(200 * RPM))), threads=1, progress=False)
    np.testing.assert_allclose(in_rpm["omega"].values, by_hand["omega"].values, rtol=4e-16, atol=0)
    np.testing.assert_array_equal(in_rpm["n_complex_pairs"].values, by_hand["n_complex_pairs"].values)
    expected = [[maievskii_stable(w, c) for c in C1] for w in in_rpm["omega"].values]
    np.testing.assert_array_equal(in_rpm["n_complex_pairs"].values == 0, expected)
    assert 0 < np.sum(expected) < np.size(expected)  # the scan crosses the critical spin rate
    assert in_rpm["omega"].attrs["display_units"] == "rpm" and in_rpm["omega"].attrs["units"] == "rad s-1"
    assert "display_units" not in in_rpm["c_1"].attrs and "display_units" not in by_hand["omega"].attrs


def test_info_shows_the_axis_in_its_display_unit(rpm_file):
    text = describe(stabmap.open_atlas(rpm_file), "rpm.nc")
    line = next(line for line in text.splitlines() if line.strip().startswith("omega"))
    assert "5.23599 .. 20.944 rad s-1 (= 50 .. 200 rpm)" in line


def test_cli_queries_in_rpm(rpm_file, in_rpm, capsys):
    omega = in_rpm["omega"].values
    assert main(["query", str(rpm_file), "omega=110 rpm", "c_1=0.1"]) == 0
    nearest = omega[np.argmin(np.abs(omega - exact_si("110", "rpm")))]
    out = capsys.readouterr().out
    assert f"nearest grid point {nearest / exact_si('1', 'rpm'):.8g} rpm ({nearest:.8g} rad s-1)" in out
    assert ("n_complex_pairs = 0" in out) == maievskii_stable(nearest, 0.1)
    # a range with one unit for both ends, and the same range with a unit on each
    # (ends between grid values, 5 rpm apart: which side a grid value falls on does not hang on a rounding)
    lo, hi = exact_si("102.5", "rpm"), exact_si("152.5", "rpm")
    inside = (omega >= lo) & (omega <= hi)
    stable = sum(maievskii_stable(w, c) for w in omega[inside] for c in C1)
    for item in ("omega=102.5:152.5rpm", "omega=102.5 rpm:2.5 Hz"):
        status = main(["query", str(rpm_file), "--fraction", item, "--json"])
        out, err = capsys.readouterr()
        if item.endswith("Hz"):
            assert status == 2 and "mixed units (Hz, rpm)" in err
            continue
        assert status == 0
        answer = json.loads(out)
        assert answer["stable"] == stable and answer["points"] == 3 * int(inside.sum())
    # the Python API takes the same strings
    assert stabmap.label_at(in_rpm, omega="110 rpm", c_1=0.1).grid_point["omega"] == nearest


def test_cli_unit_errors(rpm_file, capsys):
    for items, message in (
        (["omega=110 rps", "c_1=0.1"], "omega = '110 rps': unknown unit 'rps'; a spin rate may be given in rad/s, rpm or Hz"),
        (["omega=110", "c_1=0.1 rpm"], "c_1 = '0.1 rpm': a unit is accepted for spin rates only (rad/s, rpm or Hz); give c_1 as a plain number in m"),
    ):
        assert main(["query", str(rpm_file), *items]) == 2
        assert message in capsys.readouterr().err


def test_plot_sel_in_rpm(rpm_file, tmp_path, capsys):
    assert main(["plot", str(rpm_file), "-o", str(tmp_path / "a.png"), "--sel", "omega=110 rpm"]) == 0
    assert main(["plot", str(rpm_file), "-o", str(tmp_path / "b.png"), "--sel", "c_1=0.1 rpm"]) == 2
    assert "c_1 = '0.1 rpm': a unit is accepted for spin rates only" in capsys.readouterr().err


# ------------------------------------------------------------------------------------------------ values in force
TWO = """
title = "two tops, each with its own spin"
support = "fixed"
omega = 999.0
joints = [50.0]
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.1
s = 0.3
omega = {w1}
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.1
{w2}
[grid]
m_1 = {{ values = [1.0, 2.0] }}
{axis}
"""


@pytest.mark.parametrize("w2, axis, common", [
    ("omega = 20.0", "", False),  # every body sets its own: the common 999 is nowhere in force
    ("", "omega_2 = { values = [20.0, 30.0] }", False),  # body 2's rate is scanned instead
    ("", "", True),  # body 2 takes the common rate
])
def test_omega_is_listed_only_where_in_force(w2, axis, common, tmp_path):
    s = loads_scene(TWO.format(w1=10.0, w2=w2, axis=axis))
    ds = stabmap.compute_atlas(s, threads=1, progress=False)
    text = describe(ds, "two.nc")
    fixed = text.split("  fixed:")[1].split("  points:")[0]
    caption = fixed_caption(ds, 400)
    assert ("999" in fixed) == common and ("999" in caption) == common
    assert ("omega" in ds.coords and ds["omega"].ndim == 0) == common
    assert "body 1: " in fixed and "omega = 10 rad s-1" in fixed.split("body 1: ")[1].split("body 2")[0]
    if w2:
        assert "omega = 20 rad s-1" in fixed.split("body 2: ")[1]


# ------------------------------------------------------------------------------------------------ parts of atlases
def test_a_part_of_an_atlas_is_written_with_its_own_scene(in_rpm, tmp_path):
    whole = stabmap.write_atlas(in_rpm, tmp_path / "whole.nc")
    assert stabmap.open_atlas(whole).attrs["scene"] == in_rpm.attrs["scene"]  # a whole atlas: its scene untouched
    parts = {
        "slice": in_rpm.sel(omega=slice(8.0, 16.0)),
        "list": in_rpm.isel(omega=[0, 3, 4, 30], c_1=[0, 2]),
        "one": in_rpm.sel(c_1=0.1),
    }
    for name, part in parts.items():
        back = stabmap.open_atlas(stabmap.write_atlas(part, tmp_path / f"{name}.nc"))
        scene = loads_scene(back.attrs["scene"])
        assert "part of an atlas" in back.attrs["history"].splitlines()[-1]
        again = stabmap.compute_atlas(scene, threads=1, progress=False)
        if name == "one":  # the fixed axis is a one-value axis of the scene
            assert again.sizes["c_1"] == 1
            again = again.isel(c_1=0)
        for d in ("omega", "c_1"):
            np.testing.assert_array_equal(again[d].values, back[d].values)
        np.testing.assert_array_equal(again["n_complex_pairs"].values, back["n_complex_pairs"].values)
        assert scene.grid[0].display_units == "rpm"
    assert loads_scene(stabmap.open_atlas(tmp_path / "slice.nc").attrs["scene"]).grid[0].to_dict()["num"] == 15


def test_parts_that_are_no_grid_are_refused(in_rpm, tmp_path):
    with pytest.raises(StabmapError, match="grid axis 'c_1' was dropped"):
        stabmap.write_atlas(in_rpm.isel(c_1=0).drop_vars("c_1"), tmp_path / "dropped.nc")
    with pytest.raises(StabmapError, match=r"grid.omega: values must be distinct and sorted .*; select values in grid order, each once"):
        stabmap.write_atlas(in_rpm.isel(omega=[3, 1, 2]), tmp_path / "shuffled.nc")
    assert not list(tmp_path.iterdir())


def test_a_part_keeps_the_modes_its_whole_grid_chose():
    # modes = "auto" chooses its count from the grid's tallest cavity; a part of the short ones alone would choose
    # fewer and decide its points differently (test_mode_tolerance).
    text = """
support = "fixed"
[[bodies]]
m = 3.0
A = 0.05
C = 0.02
c = 0.2
cavity = { shape = "cylinder", radius = 0.05, half_height = 0.05, density = 1000.0, mode_tolerance = 5e-3 }
[grid]
omega = { start = 60.0, stop = 200.0, num = 4 }
half_height_1 = { start = 0.0125, stop = 0.05, num = 4 }
"""
    s = loads_scene(text)
    short = (s.grid[0], Axis("half_height_1", (0.0125,), "linear"))
    chosen = s.bodies[0].cavity.kept
    assert loads_scene(text.replace("stop = 0.05, num = 4", "stop = 0.0125, num = 1")).bodies[0].cavity.kept < chosen
    part = s.with_grid(short)
    assert (part.bodies[0].cavity.modes, part.bodies[0].cavity.kept) == (chosen, chosen)
    assert loads_scene(part.to_toml()).bodies[0].cavity.kept == chosen


def test_figures_label_a_spin_rate_axis_in_its_display_unit(in_rpm):
    from stabmap.read.plot import atlas_figure

    for x, y in (("omega", "c_1"), ("c_1", "omega")):
        fig = atlas_figure(in_rpm, x=x, y=y)
        fig.canvas.draw()
        ax = fig.axes[0]
        i = 0 if x == "omega" else 1  # omega along x, then along y
        axis, label, (lo, hi) = (ax.xaxis, ax.get_xlabel(), ax.get_xlim()) if i == 0 else (ax.yaxis, ax.get_ylabel(), ax.get_ylim())
        assert label.endswith("[rpm]")
        ticks = [(t.get_position()[i], t.get_text()) for t in axis.get_ticklabels() if lo <= t.get_position()[i] <= hi]
        assert len(ticks) >= 3
        for where, text in ticks:  # data in rad/s, labels at round rpm
            assert float(text) == pytest.approx(where / RPM, rel=1e-12) and float(text) % 10 == 0
    plain = atlas_figure(stabmap.compute_atlas(loads_scene(TOP.format(start=5.0, stop=20.0)), threads=1, progress=False))
    assert plain.axes[0].get_xlabel().endswith("[rad\u00a0s$^{-1}$]")
