"""Questions asked of a saved atlas (stabmap.read.query, ds.stabmap, stabmap query) against Maievskii's closed form.

A single top on a fixed point without liquid is stable (all characteristic roots real) exactly when
C^2 omega^2 >= 4 (A + m c^2) m c g. The tests decide that in exact rational arithmetic on the binary values of
every grid point, independently of the engine, and derive from it what every query must answer.
"""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np
import pytest
import xarray as xr

import stabmap
from stabmap.read.accessor import StabmapAccessor
from stabmap.read.located import located_boundaries, located_smallest_stable
from stabmap.cli import main
from stabmap.systems.gyroscopes.outputs import BY_INFERRED as INFERRED
from stabmap.read.report import render
from stabmap.systems.gyroscopes.scene import from_dict
from scenes import A, C, G, M, maievskii_stable, top_system

OMEGA = np.linspace(-60.0, 60.0, 97)  # step 1.25, holds 0
C1 = [-0.1, 0.05, 0.1, 0.2, 0.3, 1.0]  # hanging (always stable), four ordinary tops, one too slow for the whole scan


def omega_crit(c: float, m: float = M) -> float:
    return math.sqrt(4 * (A + m * c * c) * m * c * G) / C


def scene(grid: dict) -> stabmap.Scene:
    return from_dict(top_system(grid))


@pytest.fixture(scope="module")
def top():
    return stabmap.compute_atlas(
        scene({"omega": {"start": -60.0, "stop": 60.0, "num": 97}, "c_1": {"values": C1}}), threads=2, progress=False
    )


@pytest.fixture(scope="module")
def expected():
    """Closed-form stability, shape (omega, c_1)."""
    return np.array([[maievskii_stable(w, c) for c in C1] for w in OMEGA])


@pytest.fixture(scope="module")
def atlas_file(top, tmp_path_factory):
    return stabmap.write_atlas(top, tmp_path_factory.mktemp("query") / "top.nc")


def test_atlas_is_the_closed_form(top, expected):
    np.testing.assert_array_equal(top["omega"].values, OMEGA)
    assert ((top["n_complex_pairs"].values == 0) == expected).all()


# --- stable_fraction ------------------------------------------------------------------------------------------


def test_stable_fraction_counts_the_closed_form(top, expected):
    whole = stabmap.stable_fraction(top)
    assert (whole.stable, whole.points) == (int(expected.sum()), expected.size)
    assert whole.fraction == expected.sum() / expected.size
    assert whole.unstable == expected.size - expected.sum() and whole.degenerate == 0 and whole.inferred == 0
    assert whole.selected == {"omega": (-60.0, 60.0), "c_1": (-0.1, 1.0)}
    for j, c in enumerate(C1):
        f = stabmap.stable_fraction(top, c_1=c + 0.01 if c < 1 else c - 0.01)  # nearest grid value, inside the scan
        assert f.axes["c_1"].fixed and f.selected["c_1"] == c
        assert (f.stable, f.points) == (int(expected[:, j].sum()), OMEGA.size)
    assert stabmap.stable_fraction(top, c_1=-0.1).fraction == 1.0
    assert stabmap.stable_fraction(top, c_1=1.0).stable == 0


def test_stable_fraction_of_ranges(top, expected):
    f = stabmap.stable_fraction(top, omega=(10, 30), c_1=(0.1, 0.3))
    rows, cols = (OMEGA >= 10) & (OMEGA <= 30), [2, 3, 4]
    assert (f.stable, f.points) == (int(expected[rows][:, cols].sum()), int(rows.sum()) * 3)
    assert f.selected == {"omega": (10.0, 30.0), "c_1": (0.1, 0.3)}
    assert f.axes["omega"].values == tuple(OMEGA[rows])
    # either order, slices and open ends
    assert stabmap.stable_fraction(top, omega=(30, 10), c_1=slice(0.1, 0.3)) == f
    positive = stabmap.stable_fraction(top, omega=(0, None))
    assert positive.points == int((OMEGA >= 0).sum()) * len(C1)
    assert positive.stable == int(expected[OMEGA >= 0].sum())


def test_outside_the_scan_is_an_error_unless_the_nearest_edge_is_asked(top):
    with pytest.raises(stabmap.StabmapError, match=r"c_1 = 5 m lies outside the scan of c_1, -0.1 \.\. 1 m; .* --nearest-edge"):
        stabmap.stable_fraction(top, c_1=5.0)
    f = stabmap.stable_fraction(top, c_1=5.0, nearest_edge=True)
    assert f.axes["c_1"].outside and f.selected["c_1"] == 1.0
    assert "outside the scan: nearest edge, as asked" in f.axes["c_1"].describe()


# --- boundaries -----------------------------------------------------------------------------------------------


def test_boundaries_bracket_the_critical_spin_rate(top, expected):
    b = stabmap.boundaries(top, "omega")
    assert b.attrs["n_lines"] == len(C1) and b.attrs["along"] == "omega"
    assert b["boundary_lower"].attrs["units"] == "rad s-1" and b["c_1"].attrs["units"] == "m"
    for j, c in enumerate(C1):
        line = b.where(b["c_1"] == c, drop=True)
        flips = [i for i in range(OMEGA.size - 1) if expected[i, j] != expected[i + 1, j]]
        np.testing.assert_array_equal(line["boundary_lower"].values, OMEGA[flips])
        np.testing.assert_array_equal(line["boundary_upper"].values, OMEGA[np.array(flips, dtype=int) + 1])
        if not 0 < c < 0.5:
            assert not flips  # hanging top: stable everywhere; c = 1: unstable over the whole scan
            continue
        assert len(flips) == 2
        w = omega_crit(c)
        (lo1, lo2), (hi1, hi2) = line["boundary_lower"].values, line["boundary_upper"].values
        assert lo1 <= -w < hi1 and lo2 < w <= hi2 and hi1 - lo1 == hi2 - lo2 == 1.25
        # N_c on each side: 0 where the closed form says stable
        assert list(line["n_complex_pairs_below"].values) == [0, 1] and list(line["n_complex_pairs_above"].values) == [1, 0]
        assert not line["inferred_below"].any() and not line["inferred_above"].any()


def test_boundaries_along_the_other_axis_and_tidy_table(top, expected):
    b = stabmap.boundaries(top, "c_1", omega=20.3)  # nearest grid value 20
    assert float(b["omega"]) == 20.0 and b["omega"].ndim == 0 and "nearest grid value 20 rad s-1" in b.attrs["selection"]
    i = int(np.flatnonzero(OMEGA == 20.0)[0])
    flips = [j for j in range(len(C1) - 1) if expected[i, j] != expected[i, j + 1]]
    assert [(float(lo), float(hi)) for lo, hi in zip(b["boundary_lower"].values, b["boundary_upper"].values)] == [
        (C1[j], C1[j + 1]) for j in flips
    ]
    table = stabmap.boundaries(top, "omega", c_1=(0.05, 0.1)).to_dataframe()
    assert list(table["c_1"]) == [0.05, 0.05, 0.1, 0.1] and "boundary_lower" in table
    # a range of the searched axis limits the search
    upper = stabmap.boundaries(top, "omega", omega=(0, None), c_1=0.1)
    assert upper.sizes["boundary"] == 1 and float(upper["boundary_lower"][0]) >= 0


# --- smallest_stable ------------------------------------------------------------------------------------------


def test_smallest_positive_stable_spin_rate_is_the_first_closed_form_one(top):
    s = stabmap.smallest_stable(top, "omega", over="c_1", omega=(0, None))
    assert s["smallest_stable"].dims == ("c_1",) and list(s["c_1"].values) == C1
    assert s["smallest_stable"].attrs["units"] == "rad s-1"
    positive = OMEGA[OMEGA >= 0]
    for j, c in enumerate(C1):
        first = next((w for w in positive if maievskii_stable(w, c)), None)
        got, below = s["smallest_stable"].values[j], s["unstable_below"].values[j]
        if first is None:  # c = 1: omega_crit ~ 210 rad/s lies beyond the scan
            assert np.isnan(got) and np.isnan(below) and s["n_complex_pairs_below"].values[j] == -2
            assert omega_crit(c) > 60
            continue
        assert got == first
        if first == positive[0]:  # hanging top: stable from the start of the search
            assert c < 0 and np.isnan(below) and s["n_complex_pairs_below"].values[j] == -2
        else:
            assert below == first - 1.25 and not maievskii_stable(below, c)
            assert below < omega_crit(c) <= got
            assert s["n_complex_pairs_below"].values[j] == 1
        assert bool(s["stable_to_scan_end"].values[j])
    assert not s["inferred"].any() and not s["inferred_below"].any()


def test_smallest_stable_over_the_whole_scan_sees_negative_spin(top):
    # stable for |omega| >= omega_crit: the smallest stable grid value is -60, followed by an unstable band
    s = stabmap.smallest_stable(top)  # along omega, over every other axis
    for j, c in enumerate(C1):
        if 0 < c < 0.5:
            assert s["smallest_stable"].values[j] == -60.0 and np.isnan(s["unstable_below"].values[j])
            assert not s["stable_to_scan_end"].values[j]
    assert bool(s["stable_to_scan_end"].sel(c_1=-0.1))


def test_three_axes_over_one_needs_the_others_fixed():
    ds = stabmap.compute_atlas(
        scene({"omega": {"start": 0.5, "stop": 60.5, "num": 61}, "c_1": {"values": [0.1, 0.2]}, "m_1": {"values": [1.0, 2.0]}}),
        threads=2, progress=False,
    )
    with pytest.raises(stabmap.StabmapError, match=r"over='c_1': fix the other axes as well \(m_1=1"):
        stabmap.smallest_stable(ds, "omega", over="c_1")
    s = stabmap.smallest_stable(ds, "omega", over="c_1", m_1=1.9)
    assert float(s["m_1"]) == 2.0 and "m_1 = 1.9 kg -> nearest grid value 2 kg" in s.attrs["selection"]
    every = stabmap.smallest_stable(ds, "omega")
    assert every["smallest_stable"].dims == ("c_1", "m_1")
    for c in (0.1, 0.2):
        for m in (1.0, 2.0):
            first = next(w for w in ds["omega"].values if maievskii_stable(w, c, m))
            assert every["smallest_stable"].sel(c_1=c, m_1=m) == first
            assert first - 1.0 < omega_crit(c, m) <= first
    np.testing.assert_array_equal(s["smallest_stable"].values, every["smallest_stable"].sel(m_1=2.0).values)


def test_one_axis_atlas(tmp_path):
    ds = stabmap.compute_atlas(scene({"omega": {"start": 0.5, "stop": 30.5, "num": 31}}), threads=1, progress=False)
    s = stabmap.smallest_stable(ds)
    first = next(w for w in ds["omega"].values if maievskii_stable(w, 0.1))
    assert s["smallest_stable"].ndim == 0 and float(s["smallest_stable"]) == first
    assert "smallest stable omega" in render(s) and render(s, "csv").splitlines()[1].startswith(f"{first},")
    b = stabmap.boundaries(ds, "omega")
    assert b.sizes["boundary"] == 1 and float(b["boundary_upper"][0]) == first
    assert stabmap.stable_fraction(ds).points == 31


# --- inferred points (adaptive atlases) -----------------------------------------------------------------------


@pytest.fixture(scope="module")
def refined():
    sc = scene({"omega": {"start": 0.5, "stop": 60.5, "num": 121}, "m_1": {"start": 0.5, "stop": 4.5, "num": 17}})
    return stabmap.compute_refined(sc, threads=2, progress=False, coarse_stride=8)


def test_inferred_points_are_counted_and_flagged(refined):
    by = refined["decided_by"]
    assert (by == INFERRED).sum() > 500
    f = stabmap.stable_fraction(refined, m_1=1.0)
    line = refined.sel(m_1=1.0)
    assert f.inferred == int((line["decided_by"] == INFERRED).sum()) > 0
    assert f.inferred_stable == int(((line["decided_by"] == INFERRED) & (line["n_complex_pairs"] == 0)).sum())
    assert f.computed_fraction == (f.stable - f.inferred_stable) / (f.points - f.inferred)
    assert "not computed" in render(f)
    # a search that starts inside a stretch the refinement filled: the first stable point was inferred
    s = stabmap.smallest_stable(refined, "omega", omega=(30.2, None))
    first = refined["decided_by"].sel(omega=s["smallest_stable"])  # pointwise, one per m_1
    np.testing.assert_array_equal(s["inferred"].values, (first == INFERRED).values)
    assert s["inferred"].any()
    # the labels still agree with the closed form
    for m in refined["m_1"].values:
        w = next(w for w in refined["omega"].values if maievskii_stable(w, 0.1, m))
        assert stabmap.smallest_stable(refined, over="m_1")["smallest_stable"].sel(m_1=m) == w


def test_boundaries_flag_inferred_sides(top, capsys, tmp_path):
    marked = top.copy(deep=True)
    marked["decided_by"].values[OMEGA > 0, :] = INFERRED  # pretend every positive spin rate was inferred
    b = stabmap.boundaries(marked, "omega", c_1=0.1)
    assert list(b["inferred_below"].values) == [False, True] and list(b["inferred_above"].values) == [False, True]
    assert list(b["boundary_upper"].values > 0) == [False, True]
    text = render(b)
    assert "0*" in text and "* not computed: inferred" in text
    path = stabmap.write_atlas(marked, tmp_path / "marked.nc")
    assert main(["query", str(path), "--smallest-stable", "omega=0:", "c_1=0.1"]) == 0
    assert "* not computed" in capsys.readouterr().out


# --- the accessor ---------------------------------------------------------------------------------------------


def test_accessor_gives_the_functions_answers(top, tmp_path):
    assert isinstance(top.stabmap, StabmapAccessor)
    assert top.stabmap.label_at(omega=42.5, c_1=0.1) == stabmap.label_at(top, omega=42.5, c_1=0.1)
    assert top.stabmap.stable_fraction(c_1=0.1, omega=(0, 30)) == stabmap.stable_fraction(top, c_1=0.1, omega=(0, 30))
    xr.testing.assert_identical(top.stabmap.boundaries("omega", c_1=(0, 0.2)), stabmap.boundaries(top, "omega", c_1=(0, 0.2)))
    xr.testing.assert_identical(
        top.stabmap.smallest_stable("omega", over="c_1", omega=(0, None)),
        stabmap.smallest_stable(top, "omega", over="c_1", omega=(0, None)),
    )
    xr.testing.assert_identical(top.stabmap.smallest_stable(), stabmap.smallest_stable(top))
    assert top.stabmap.summary() == stabmap.summary(top)
    assert "stabmap.stable_fraction" in top.stabmap.stable_fraction.__doc__
    png = top.stabmap.plot(tmp_path / "map.png", x="c_1")  # keywords go to plot_atlas
    assert png.read_bytes()[:4] == b"\x89PNG"
    # an answer is a plain Dataset that can be saved
    stabmap.smallest_stable(top).to_netcdf(tmp_path / "s.nc")


# --- errors ---------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call,message",
    [
        (lambda ds: stabmap.stable_fraction(ds, K_1=3), "'K_1' is not an axis of this atlas; its axes are: omega, c_1"),
        (lambda ds: stabmap.stable_fraction(ds, m_1=3), "'m_1' is fixed at 1 kg in this atlas, not a grid axis"),
        (lambda ds: stabmap.stable_fraction(ds, c_1="x"), "c_1='x': give a number"),
        (lambda ds: stabmap.stable_fraction(ds, c_1=(1, 2, 3)), "a range is a pair"),
        (lambda ds: stabmap.stable_fraction(ds, c_1=(2, 3)), r"c_1 in \[2, 3\] holds no grid value; .* run from -0.1 to 1 m"),
        (lambda ds: stabmap.boundaries(ds, "omegaa"), "along='omegaa' is not an axis"),
        (lambda ds: stabmap.boundaries(ds, "omega", omega=3), "omega=3 would fix omega, the axis searched along; give a range"),
        (lambda ds: stabmap.smallest_stable(ds, "omega", over="omega"), "over='omega' is the axis searched along"),
        (lambda ds: stabmap.smallest_stable(ds, "omega", over="c_1", c_1=0.1), "over='c_1' is also fixed"),
        (lambda ds: stabmap.label_at(ds, omega=(1, 2), c_1=0.1), "the label is asked at one point"),
        (lambda ds: stabmap.stable_fraction(ds.drop_vars("decided_by")), "not a stabmap atlas"),
        (lambda ds: stabmap.smallest_stable(ds, "omegaa"), "along='omegaa' is not an axis of this atlas; its axes are: omega, c_1"),
        # read.located: the same check, the same words
        (lambda ds: located_boundaries(ds, "omegaa"), "along='omegaa' is not an axis of this atlas"),
        (lambda ds: located_smallest_stable(ds, over="K_1"), "over='K_1' is not an axis of this atlas"),
    ],
)
def test_bad_questions_name_the_parameter(top, call, message):
    with pytest.raises(stabmap.StabmapError, match=message):
        call(top)


# --- the command line -----------------------------------------------------------------------------------------


def run(capsys, *args) -> tuple[int, str, str]:
    code = main(["query", *map(str, args)])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_label_keeps_its_form(atlas_file, capsys):
    code, out, _ = run(capsys, atlas_file, "omega=42.4", "c_1=0.1")
    assert code == 0
    assert out.splitlines() == [
        "omega = 42.4 rad s-1 -> nearest grid point 42.5 rad s-1",
        "c_1 = 0.1 m -> nearest grid point 0.1 m",
        "n_complex_pairs = 0",
        "stability = stable (decided by interval sturm sequence)",
        "growth_rate = 0 s-1 (proved in [0, 0] s-1)",
        "efolding_time = inf s",
        "growth_rate_method = all_roots_real",
        "cell = node_only (the label is proved at the grid point only; at the requested point it is not decided)",
    ]
    code, out, _ = run(capsys, atlas_file, "omega=0", "c_1=0.1", "--json")
    assert json.loads(out)["n_complex_pairs"] == 1 and json.loads(out)["grid_point"] == {"omega": 0.0, "c_1": 0.1}


def test_cli_fraction(atlas_file, expected, capsys):
    j = C1.index(0.2)
    code, out, _ = run(capsys, atlas_file, "--fraction", "c_1=0.21")
    n = int(expected[:, j].sum())
    assert code == 0
    assert f"{n} of 97 grid points stable" in out and "c_1 = 0.21 m -> nearest grid value 0.2 m" in out
    assert "omega: all 97 grid values, -60 .. 60 rad s-1" in out and "inferred: 0" in out
    code, out, _ = run(capsys, atlas_file, "--fraction", "omega=0:", "--json")
    data = json.loads(out)
    assert data["stable"] == int(expected[OMEGA >= 0].sum()) and data["axes"]["omega"]["grid_lo"] == 0.0
    code, out, _ = run(capsys, atlas_file, "c_1=:0.1", "--fraction", "--csv")  # selection before the question
    row = next(csv.DictReader(io.StringIO(out)))
    assert int(row["points"]) == 97 * 3 and int(row["stable"]) == int(expected[:, :3].sum())


def test_cli_boundaries(atlas_file, top, capsys):
    code, out, _ = run(capsys, atlas_file, "--boundaries", "omega", "c_1=0.05:0.3")
    assert code == 0
    assert "8 changes of N_c on 4 of 4 lines" in out and "c_1 [m]  omega lower  omega upper  N_c below  N_c above" in out
    assert "stabmap critical SCENE --along omega" in out
    w = omega_crit(0.1)
    lo = OMEGA[OMEGA < w].max()
    assert any(line.split() == ["0.1", f"{lo:.8g}", f"{lo + 1.25:.8g}", "1", "0"] for line in out.splitlines())
    code, out, _ = run(capsys, atlas_file, "--boundaries", "omega", "--csv")
    rows = list(csv.DictReader(io.StringIO(out)))
    b = stabmap.boundaries(top, "omega")
    assert len(rows) == b.sizes["boundary"] == 8
    assert [float(r["boundary_lower"]) for r in rows] == list(b["boundary_lower"].values)
    assert list(rows[0]) == ["c_1", "boundary_lower", "boundary_upper", "n_complex_pairs_below", "n_complex_pairs_above", "inferred_below", "inferred_above"]
    code, out, _ = run(capsys, atlas_file, "--boundaries", "omega", "c_1=0.1", "--json")
    data = json.loads(out)
    assert data["fixed"] == {"c_1": 0.1} and len(data["rows"]) == 2 and data["along_units"] == "rad s-1"


def test_cli_smallest_stable(atlas_file, capsys):
    code, out, _ = run(capsys, atlas_file, "--smallest-stable", "omega", "omega=0:", "--over", "c_1")
    assert code == 0
    lines = out.splitlines()
    assert lines[0] == "smallest stable omega [rad s-1], searched upward over 49 grid values 0 .. 60 rad s-1"
    first = next(w for w in OMEGA if w >= 0 and maievskii_stable(w, 0.1))
    assert any(line.split()[:5] == ["0.1", f"{first:g}", f"{first - 1.25:g}", "1", "yes"] for line in lines)
    assert any(line.split()[:2] == ["1", "none"] for line in lines)
    assert any(line.split()[:3] == ["-0.1", "0", "(scan"] for line in lines)
    code, out, _ = run(capsys, atlas_file, "--smallest-stable", "--over", "c_1", "omega=0:", "--csv")  # default omega
    rows = {float(r["c_1"]): r for r in csv.DictReader(io.StringIO(out))}
    assert float(rows[0.1]["smallest_stable"]) == first and rows[1.0]["smallest_stable"] == ""
    code, out, _ = run(capsys, atlas_file, "--smallest-stable", "omega=0:", "--limit", "2")
    assert "... and 4 more rows" in out


@pytest.mark.parametrize(
    "args,message",
    [
        (["--fraction", "K_1=3"], "'K_1' is not an axis of this atlas; its axes are: omega, c_1"),
        (["--fraction", "c_1=abc"], "'c_1=abc': 'abc' is not a number or a range LO:HI"),
        (["--fraction", "c_1"], "'c_1': write NAME=VALUE"),
        (["--fraction", "c_1=1:2:3"], "a range is NAME=LO:HI"),
        (["--fraction", "c_1=2:3"], "c_1 in [2, 3] holds no grid value"),
        (["--fraction", "c_1=0.1", "c_1=0.2"], "c_1 is given twice"),
        (["omega=1"], "missing: c_1"),
        ([], "give the point: omega=VALUE c_1=VALUE"),
        (["omega=1:2", "c_1=0.1"], "a range belongs to stable_fraction"),
        (["--boundaries", "c_1=0.1"], "--boundaries: name the axis to search along first"),
        (["--boundaries", "Omega"], "--boundaries Omega is not an axis"),
        (["--over", "c_1"], "--over applies to --smallest-stable only"),
        (["--smallest-stable", "omega", "--over", "K_1"], "--over K_1 is not an axis"),
        (["--smallest-stable", "omegaa"], "--smallest-stable omegaa is not an axis"),
        (["--smallest-stable", "omega", "--over", "omega"], "--over omega is the axis searched along; choose another axis for --over, e.g. c_1"),
        (["--boundaries", "omega", "--limit", "-1"], "--limit -1: must be >= 0"),
    ],
)
def test_cli_bad_input_exit_2(atlas_file, capsys, args, message):
    code, out, err = run(capsys, atlas_file, *args)
    assert code == 2 and out == ""
    assert message in err and err.startswith("stabmap: error:")


def test_cli_critical_values_file_and_missing_file(tmp_path, capsys):
    crit = stabmap.critical(scene({"omega": {"start": 0.5, "stop": 30.5, "num": 7}}), "omega")
    path = stabmap.write_atlas(crit, tmp_path / "crit.nc")
    code, _, err = run(capsys, path, "--boundaries", "omega")
    assert code == 2 and "holds critical values, not an atlas, and --boundaries asks an atlas; 'stabmap query" in err
    with pytest.raises(stabmap.StabmapError, match="holds critical values"):
        crit.stabmap.stable_fraction()
    code, _, err = run(capsys, tmp_path / "nope.nc", "--fraction")
    assert code == 2 and "does not exist" in err
