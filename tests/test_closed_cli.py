"""Closed chains through the one pipeline: scenes, atlases (netCDF, CF metadata), info, query, plot, critical,
and bad input (one line, exit status 2, no file)."""

from __future__ import annotations

import functools
import json
import math
import re

import matplotlib.colors
import numpy as np
import pytest
import xarray as xr

import stabmap
from stabmap import closed
from stabmap.cli import main
from stabmap.errors import StabmapError
from stabmap.systems.closed import SYSTEM

# The paper's planar model (the chain confined to its plane): these tests check the planar results;
# tests/test_closed_space.py checks stability in space.
planar_solve = functools.partial(closed.solve, model="planar")
planar_search = functools.partial(closed.search, model="planar")

HINGE = """system = "closed"
model = "planar"
title = "hinge against its length ratio"
family = "hinge"
c1sq = 2.0
[grid]
ratio = { start = 0.5, stop = 2.5, num = 41 }
"""
RINGS = """system = "closed"
model = "planar"
family = "ring"
[grid]
n = { values = [5, 6, 7, 8] }
j = { values = [1, 2] }
ratio = { values = [0.5, 1.0, 2.0] }
"""


@pytest.fixture()
def hinge_atlas(tmp_path):
    scene = tmp_path / "hinge.toml"
    scene.write_text(HINGE)
    out = tmp_path / "hinge.nc"
    assert main(["atlas", str(scene), "-o", str(out), "-q"]) == 0
    return out


def test_atlas_file_holds_every_variable_with_cf_metadata_and_the_scene(hinge_atlas):
    with xr.open_dataset(hinge_atlas) as ds:
        assert ds.attrs["stabmap_system"] == "closed" and ds.attrs["Conventions"].startswith("CF")
        assert stabmap.loads_scene(ds.attrs["scene"]) == stabmap.loads_scene(HINGE)
        assert ds["ratio"].attrs["units"] == "1" and "ratio" in ds["ratio"].attrs["long_name"]
        st = ds["stability"]
        assert st.attrs["flag_meanings"] == "undecided absent degenerate stable unstable" and list(st.attrs["flag_values"]) == [-3, -2, -1, 0, 1]
        by = ds["decided_by"]  # every point proved: the ratio's ball arithmetic, or exactly (absent, folded)
        assert set(np.unique(by.values)) == {0, 1} and by.attrs["flag_meanings"].split()[:2] == ["ball_arithmetic", "exact_rational_arithmetic"]
        assert ((by.values == 1) == (ds["ratio"].values >= 2.0)).all()
        assert ds["theta"].dims == ("ratio", "body") and ds["force_y"].dims == ("ratio", "loop") and ds.sizes["loop"] == 2
        assert ds["force_y"].attrs["units"] == "N" and ds["energy"].attrs["units"] == "J" and ds["theta"].attrs["units"] == "rad"
        assert float(ds["c1sq"]) == 2.0
        # every point equals the Python API's answer at that ratio
        for r in ds["ratio"].values[::7]:
            eq = planar_solve("hinge", [1, 1, r, 1, 1, r], c1sq=2.0)
            p = ds.sel(ratio=r)
            assert bool(p["exists"]) == eq.exists and int(p["stability"]) == {"stable": 0, "unstable": 1, "degenerate": -1, "absent": -2}[eq.stability]
            assert SYSTEM.variable("decided_by").meaning(int(p["decided_by"])) == eq.decided_by
            if eq.exists:
                np.testing.assert_allclose(p["theta"].values, eq.theta, atol=0)
                np.testing.assert_allclose(p["force_y"].values, eq.forces[:, 0], atol=0)
                assert int(p["index"]) == eq.index and int(p["nullity"]) == eq.nullity and int(p["rotation_index"]) == -1
                assert float(p["residual"]) <= 1e-12
            else:
                assert np.isnan(p["theta"].values).all() and int(p["index"]) == -1 and int(p["rotation_index"]) == -128


def test_info_query_plot_on_a_closed_atlas(hinge_atlas, tmp_path, capsys):
    # The reference's boundaries: stable below sqrt 2 (tests/test_closed_families.py), folded at 2, absent above.
    r = np.linspace(0.5, 2.5, 41)
    stable, folded, absent = int((r < math.sqrt(2)).sum()), int((r == 2.0).sum()), int((r > 2.0).sum())
    unstable = r.size - stable - folded - absent
    assert main(["info", str(hinge_atlas)]) == 0
    text = capsys.readouterr().out
    assert "family hinge" in text and "S1 S5 S6; S2 S3 S4" in text
    assert f"absent: {absent}," in text and f"stable: {stable}," in text and f"unstable: {unstable}" in text
    assert f"decided by: ball arithmetic {r.size - folded - absent}, exact rational arithmetic {folded + absent}" in text
    assert main(["query", str(hinge_atlas), "ratio=1.2"]) == 0
    text = capsys.readouterr().out
    assert "stability = stable (decided by ball arithmetic)" in text and "force_y = [" in text
    assert "nearest grid point 1.2\n" in text  # a ratio has no units to print (CF "1")
    assert main(["query", str(hinge_atlas), "--fraction", "--json"]) == 0
    f = json.loads(capsys.readouterr().out)
    assert (f["stable"], f["unstable"], f["degenerate"], f["absent"], f["points"]) == (stable, unstable, folded, absent, r.size)
    assert main(["query", str(hinge_atlas), "--boundaries", "ratio"]) == 0
    assert "1.4" in capsys.readouterr().out
    png = tmp_path / "map.png"
    assert main(["plot", str(hinge_atlas), "-o", str(png)]) == 0 and png.stat().st_size > 5000


def test_critical_from_the_command_line_finds_the_hinge_boundary(tmp_path, capsys):
    scene = tmp_path / "hinge.toml"
    scene.write_text(HINGE)
    out = tmp_path / "c.nc"
    assert main(["critical", str(scene), "--along", "ratio", "-o", str(out), "--png", str(tmp_path / "c.png")]) == 0
    assert "stable ratio" in capsys.readouterr().out
    with xr.open_dataset(out) as ds:
        upper = float(ds["ratio_stable_upper"].values.ravel()[0])
        assert abs(upper - math.sqrt(2)) <= 1e-10 * math.sqrt(2)
    assert main(["info", str(out)]) == 0


def test_critical_scans_the_closed_chains_default_axis_the_length_ratio(tmp_path, capsys):
    # no --along: the closed system's default_axis, ratio, as in the test above; a scene that does not scan it is
    # told which default was taken and how to choose another
    out = tmp_path / "c.nc"
    assert main(["critical", "--example", "closed-hinge", "-o", str(out), "-q"]) == 0
    with xr.open_dataset(out) as ds:
        assert ds.attrs["critical_along"] == "ratio"
        leaves = (math.sqrt(17) - 1) / 4  # in space the hinge leaves its plane here (docs/closed.md)
        assert abs(float(ds["ratio_stable_upper"].values.ravel()[0]) - leaves) <= 1e-10 * leaves
    assert main(["critical", "--example", "closed-ring-twisted", "-o", str(tmp_path / "t.nc")]) == 2
    assert ("--along not given, so the closed system's default axis 'ratio': not a grid axis of this scene; its grid "
            "axes are: c2sq") in capsys.readouterr().err and not (tmp_path / "t.nc").exists()


def test_the_critical_plot_draws_each_stretch_in_its_class_and_never_calls_absent_unstable():
    # Hinge along h2/h1: stable below sqrt 2, unstable to 2, degenerate at 2, no equilibrium above (docs/closed.md).
    from stabmap.read.plot import ABSENT_COLOUR, STABLE_COLOUR, UNSTABLE_COLOUR, critical_figure
    from stabmap.run.critical import critical

    scene = stabmap.loads_scene(HINGE)
    ds = critical(scene, "ratio", progress=False)
    assert int(ds["stability_at_scan_start"]) == SYSTEM.stable_label  # ratio 0.05: stable
    fig = critical_figure(ds)
    ax = fig.axes[0]
    spans = {}
    for coll in ax.collections:
        xs = np.concatenate([p.vertices[:, 0] for p in coll.get_paths()])
        spans[matplotlib.colors.to_hex(coll.get_facecolor()[0]).upper()] = (xs.min(), xs.max())
    lo, hi = (float(v) for v in ds.attrs["critical_scan_range"])
    assert spans[STABLE_COLOUR.upper()] == pytest.approx((lo, math.sqrt(2)), abs=1e-9)
    assert spans[UNSTABLE_COLOUR[0].upper()] == pytest.approx((math.sqrt(2), 2.0), abs=1e-9)
    assert spans[ABSENT_COLOUR.upper()] == pytest.approx((2.0, hi), abs=1e-9)  # white here means no equilibrium
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "absent (no equilibrium)" in legend and "unstable" in legend
    assert "unstable" not in ax.get_title()  # no "white: unstable"


def test_rings_over_n_and_j_and_the_bundled_examples(tmp_path):
    ds = stabmap.compute_atlas(stabmap.loads_scene(RINGS), threads=1, progress=False)
    assert ds.sizes["body"] == 8
    even = ds.sel(n=[6, 8])
    assert bool((even["exists"] == 1).all())  # alternating lengths close for even n
    np.testing.assert_array_equal(even["rotation_index"].values, np.broadcast_to(np.array([1, 2])[None, :, None], (2, 2, 3)))
    odd = ds.sel(n=[5, 7])
    np.testing.assert_array_equal(odd["exists"].values, np.broadcast_to(np.array([0, 1, 0]), (2, 2, 3)))  # only ratio 1
    assert np.isnan(ds["theta"].sel(n=5).values[..., 5:]).all() and not np.isnan(ds["theta"].sel(n=8, ratio=2.0).values).any()
    for n, j in ((6, 1), (8, 1), (7, 1)):
        assert int(ds["stability"].sel(n=n, j=j, ratio=1.0)) == 0
    assert int(ds["stability"].sel(n=8, j=2, ratio=1.0)) == -1  # n = 4j: degenerate
    assert int(ds["stability"].sel(n=6, j=2, ratio=0.5)) == 1
    names = stabmap.example_names()
    assert {"closed-figure-eight-6", "closed-hinge"} <= set(names)
    for name in ("closed-figure-eight-6", "closed-hinge"):
        scene = stabmap.example(name)
        assert scene.system == "closed" and scene.grid
    out = tmp_path / "e.nc"
    assert main(["atlas", "--example", "closed-figure-eight-6", "-o", str(out), "-q"]) == 0
    with xr.open_dataset(out) as ds6:
        assert set(np.unique(ds6["stability"].values)) == {-2, 0, 1}


BAD = [
    ('family = "figure-eight-4"\nlengths = [1.0, 0.5, 1.0]', "even number of bodies"),
    ('family = "figure-eight-4"\nn = 5\nratio = 0.5', "n = 5: a figure-eight needs an even number of bodies"),
    ('family = "ring"\nlengths = [1.0, -0.5, 1.0, 0.5]', r"lengths\[2\] must be > 0"),
    ('family = "ring"\nlengths = [1.0, 5.0, 1.0]', "cannot close"),
    ('family = "ring"\nn = 3\n[grid]\nratio = { start = 0.5, stop = 3.0, num = 6 }', r"ratio = 2\.5 with n = 3: .* cannot close"),
    ('family = "ring"\nn = 5\nj = 3', "j = 3 is out of range"),
    ('family = "ring"\nn = 6\n[grid]\nj = { values = [1, 2, 3] }', r"grid.j = 3 is out of range .* j <= 2"),
    ('family = "ring"\n[grid]\nn = { values = [5, 6] }\nj = { values = [1, 2, 3] }', r"grid.j \(with the grid's smallest n = 5\) = 3 is out of range"),
    ('family = "hinge"\nratio = 0.5\nj = 2', 'j applies to family = "ring" only'),
    ('family = "ring"\nn = 6.5', "n must be a whole number"),
    ('family = "figure-eight-6"', "ratio is missing"),
    ('family = "figure-eight-6"\nratio = -1', "ratio must be > 0"),
    ('family = "figure-eight-6"\nratio = 6\nc1sq = 0', "c1sq must be > 0"),
    ('family = "loop"', "not a closed-chain family"),
    ('family = "hinge"\n[grid]\nn = { values = [6] }', "grid axis 'n' applies to family = \"ring\" only"),
    ('family = "ring"\nlengths = [1.0, 1.0, 1.0, 1.0]\n[grid]\nratio = { values = [1, 2] }', "remove lengths"),
    ('family = "ring"\nn = 6\nwinding = 2', "unknown key 'winding'"),
    # in space (docs/closed.md, section 1b)
    ('family = "figure-eight-6"\nratio = 7\nc2sq = -1', "c2sq must be > 0"),
    ('family = "hinge"\nratio = 1.2\ntwist = 1', 'twist applies to family = "ring" only'),
    ('family = "hinge"\nratio = 1.2\n[grid]\ntwist = { values = [0, 1] }', "grid axis 'twist' applies to family = \"ring\" only"),
    ('family = "ring"\nn = 8\nratio = 2\ntwist = 1', "a twisted ring needs equal lengths"),
    ('family = "ring"\nn = 8\ntwist = 4', "twist = 4 is out of range"),
    ('family = "ring"\nn = 8\ntwist = 1\nmodel = "planar"', "equilibrium in space only"),
    ('family = "ring"\nn = 8\nmodel = "flat"', "model = 'flat'"),
    ('family = "ring"\nn = 8\nmodel = "planar"\n[grid]\nc2sq = { values = [1, 2] }', "acts out of the plane only"),
    ('family = "ring"\nn = 8\n[grid]\nc2sq = { values = [0, 2] }', r"grid.c2sq"),
]


@pytest.mark.parametrize("body,message", BAD, ids=[str(i) for i in range(len(BAD))])
def test_bad_scenes_give_one_line_exit_2_and_no_file(tmp_path, capsys, body, message):
    scene = tmp_path / "bad.toml"
    scene.write_text('system = "closed"\n' + body + "\n")
    out = tmp_path / "bad.nc"
    assert main(["atlas", str(scene), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("stabmap: error: ")
    assert re.search(message, err), err
    assert not out.exists() and list(tmp_path.iterdir()) == [scene]
    with pytest.raises(StabmapError):
        stabmap.loads_scene('system = "closed"\n' + body + "\n")


def test_refinement_is_declined_with_one_line_and_no_file(tmp_path, capsys):
    scene = tmp_path / "hinge.toml"
    scene.write_text(HINGE)
    out = tmp_path / "r.nc"
    assert main(["atlas", str(scene), "-o", str(out), "--refine", "-q"]) == 2
    assert "not available for closed atlases" in capsys.readouterr().err and not out.exists()


def test_a_family_without_equilibrium_is_data_not_an_error(tmp_path):
    scene = tmp_path / "none.toml"
    # one point: a one-value axis (a scene without [grid] is an error, not a one-point atlas)
    scene.write_text('system = "closed"\nmodel = "planar"\nfamily = "figure-eight-4"\n[grid]\nratio = { values = [1.5] }\n')
    out = tmp_path / "none.nc"
    assert main(["atlas", str(scene), "-o", str(out), "-q"]) == 0
    with xr.open_dataset(out) as ds:
        assert ds["exists"].item() == 0 and ds["stability"].item() == -2 and np.isnan(ds["theta"].values).all()


def test_python_scene_gets_the_same_checks_as_toml():
    from stabmap.systems.closed import Scene

    assert Scene(family="hinge", ratio=1.0) == stabmap.loads_scene('system = "closed"\nfamily = "hinge"\nratio = 1.0\n')
    with pytest.raises(StabmapError, match="j = 3 is out of range"):
        Scene(family="ring", n=6, j=3)
    scene = Scene(family="ring", lengths=(1.0, 2.0, 1.0, 2.0), j=1, title="rectangle")
    assert stabmap.loads_scene(scene.to_toml()) == scene
