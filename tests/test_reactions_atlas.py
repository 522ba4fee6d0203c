"""The reactions system on stabmap's pipeline: scenes (TOML and Python), the load a moving body makes, atlases over
load, centre of mass and node coordinates, the CLI's atlas/info/query/plot, and bad scenes (exit 2, no file)."""

from __future__ import annotations

import json
import pathlib
import runpy
import subprocess
import sys

import numpy as np
import pytest

import stabmap
from stabmap.cli import main
from stabmap.reactions import solve
from stabmap.scene.grid import resample
from stabmap.systems.reactions import Body, Load, Release, Scene
from stabmap.systems.reactions.load import load

PLATE_NODES = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]
SCENE = """
system = "reactions"
title = "plate, weight moved"
nodes = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]
[body]
mass = 10.0
centre = [0.0, 0.0, 0.0]
[grid]
c_x = { start = -0.6, stop = 0.6, num = 13 }
c_y = { start = -0.6, stop = 0.6, num = 9 }
"""


def run_cli(tmp_path, *args):
    return subprocess.run([sys.executable, "-m", "stabmap", *args], capture_output=True, text=True, cwd=tmp_path)


# ---------------------------------------------------------------------------------------------------- scenes
def test_scene_round_trip_and_python_checks():
    scene = stabmap.loads_scene(SCENE)
    assert isinstance(scene, Scene) and scene.n == 4 and scene.kind == "body" and scene.shape == (13, 9)
    assert stabmap.loads_scene(scene.to_toml()) == scene
    built = Scene(nodes=PLATE_NODES, body=Body(mass=10.0), releases=(Release(1, (0, 2, 0)),), title="t")
    assert stabmap.loads_scene(built.to_toml()) == built
    with pytest.raises(stabmap.StabmapError, match=r"releases\[0\] direction is zero"):
        Scene(nodes=PLATE_NODES, load=Load((0, 0, -1)), releases=(Release(0, (0, 0, 0)),))


def test_examples_are_listed_and_load():
    names = [n for n in stabmap.example_names() if n.startswith("reactions-")]
    assert names == ["reactions-spinning-stage", "reactions-square-plate"]
    for name in names:
        scene = stabmap.example(name)
        assert scene.system == "reactions" and len(scene.grid) == 2


def test_body_load_is_dalembert():
    """Weight, centrifugal force and Euler's inertia torque of a spinning body, by hand at one point."""
    scene = Scene(
        nodes=PLATE_NODES,
        body=Body(mass=2.0, centre=(0.3, 0.1, 0.2), gravity=(0, 0, -9.81), omega=(0.0, 0.0, 5.0), alpha=(0.0, 0.0, 2.0),
                  inertia=((0.1, 0.0, 0.0), (0.0, 0.2, 0.0), (0.0, 0.0, 0.3))),
    )
    F, M = load(scene, {})
    # centripetal acceleration -omega^2 (x, y, 0) and tangential alpha x c = 2 (-0.1, 0.3, 0)
    a_c = np.array([-25 * 0.3 - 0.2, -25 * 0.1 + 0.6, 0.0])
    F_hand = 2.0 * (np.array([0, 0, -9.81]) - a_c)
    M_hand = np.cross([0.3, 0.1, 0.2], F_hand) - np.array([0.0, 0.0, 0.3 * 2.0])  # I alpha; omega x I omega = 0 here
    np.testing.assert_allclose(F, F_hand, rtol=1e-14)
    np.testing.assert_allclose(M, M_hand, rtol=1e-14, atol=1e-14)


# ---------------------------------------------------------------------------------------------------- atlases
def test_plate_atlas_matches_the_linear_distribution():
    """R_z,i = G/4 (1 + c_x x_i / a^2 + c_y y_i / a^2) for a weight G at (c_x, c_y) on corners (+-a, +-a)."""
    ds = stabmap.compute_atlas(stabmap.loads_scene(SCENE), threads=1)
    assert ds["R"].dims == ("c_x", "c_y", "node", "component") and ds["R_norm"].dims == ("c_x", "c_y", "node")
    for name in ("R_max", "critical_node", "n_critical", "rank", "free_motions", "compatible", "balance_residual"):
        assert ds[name].dims == ("c_x", "c_y")
    assert ds["R"].attrs["units"] == "N" and ds["compatible"].attrs["flag_meanings"] == "incompatible compatible"
    assert list(ds["component"].values) == ["x", "y", "z"] and list(ds["node"].values) == [0, 1, 2, 3]
    assert ds.attrs["stabmap_system"] == "reactions" and float(ds["mass"]) == 10.0
    G, a = 10.0 * 9.81, 0.5
    x, y = np.array(PLATE_NODES)[:, 0], np.array(PLATE_NODES)[:, 1]
    cx, cy = ds["c_x"].values[:, None, None], ds["c_y"].values[None, :, None]
    want = G / 4 * (1 + cx * x / a**2 + cy * y / a**2)
    np.testing.assert_allclose(ds["R"].values[..., 2], want, rtol=0, atol=1e-12 * G)
    assert np.abs(ds["R"].values[..., :2]).max() <= 1e-12 * G
    assert (ds["rank"] == 6).all() and (ds["compatible"] == 1).all() and (ds["balance_residual"] <= 1e-12).all()
    winner = np.argmax(np.round(want, 9), axis=-1)  # ties (on the plate's axes) go to the lowest-numbered node
    assert np.array_equal(ds["critical_node"].values, winner)
    np.testing.assert_allclose(ds["R_max"].values, want.max(axis=-1), rtol=1e-12)


def test_direction_scan_on_collinear_nodes_marks_incompatible_loads():
    """A shaft on three bearings along x with its centre of mass off the axis, gravity turned: the weight has a
    moment about the shaft (which the bearings cannot take) unless gravity lies in the plane of the axis and the
    centre of mass, here the xy-plane (elevation 0)."""
    scene = stabmap.loads_scene("""
system = "reactions"
title = "shaft"
nodes = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.5, 0.0, 0.0]]
[body]
mass = 10.0
centre = [1.0, 0.2, 0.0]
gravity = [0.0, 0.0, -10.0]
[grid]
g_azimuth = { values = [-90.0, 0.0, 45.0, 90.0] }
g_elevation = { values = [-90.0, -30.0, 0.0, 30.0] }
""")
    ds = stabmap.compute_atlas(scene, threads=1)
    assert (ds["rank"] == 5).all() and (ds["free_motions"] == 1).all()
    assert (ds["compatible"].values == (ds["g_elevation"].values == 0.0)[None, :]).all()
    for i, az in enumerate(ds["g_azimuth"].values):
        for j, el in enumerate(ds["g_elevation"].values):
            F = 100.0 * np.array([np.cos(np.radians(el)) * np.cos(np.radians(az)), np.cos(np.radians(el)) * np.sin(np.radians(az)), np.sin(np.radians(el))])
            one = solve(scene.nodes, F, np.cross([1.0, 0.2, 0.0], F))
            assert bool(ds["compatible"][i, j]) == one.compatible
            if one.compatible:
                np.testing.assert_allclose(ds["R"].values[i, j], one.R, atol=1e-12 * 100)
            else:
                assert int(ds["critical_node"][i, j]) == -1 and np.isnan(ds["R"].values[i, j]).all()


def test_node_coordinate_and_load_factor_axes_match_solve_point_by_point():
    scene = Scene(
        nodes=PLATE_NODES, load=Load((5.0, -3.0, -100.0), (10.0, 0.0, 2.0)), releases=(Release(2, (0.0, 0.0, 1.0)),),
        grid=(stabmap.Axis("x_0", (-1.0, -0.7, -0.2, 0.3)), stabmap.Axis("load_factor", (0.5, 1.0, 2.0))),
    )
    ds = stabmap.compute_atlas(scene, threads=1, chunk_points=5)
    for i, x0 in enumerate(ds["x_0"].values):
        nodes = np.array(PLATE_NODES)
        nodes[0, 0] = x0
        for j, f in enumerate(ds["load_factor"].values):
            one = solve(nodes, f * np.array([5.0, -3.0, -100.0]), f * np.array([10.0, 0.0, 2.0]), releases=[(2, [0, 0, 1])])
            np.testing.assert_allclose(ds["R"].values[i, j], one.R, atol=1e-12 * 200)
            assert int(ds["rank"][i, j]) == 7 and int(ds["critical_node"][i, j]) == one.critical_node


def test_spinning_stage_example_balances_with_its_releases():
    scene = resample(stabmap.example("reactions-spinning-stage"), omega_z=7, c_x=6)
    ds = stabmap.compute_atlas(scene, threads=1)
    assert (ds["compatible"] == 1).all() and (ds["rank"] == 6 + 5).all()
    R = ds["R"].values
    assert np.abs(R[..., 1, 1]).max() <= 1e-12 * np.nanmax(np.abs(R))  # hinge 1 slides along y
    assert np.abs(R[..., 2:, :2]).max() <= 1e-12 * np.nanmax(np.abs(R))  # the latches carry z only
    F, M = load(scene, {a.name: a.array[(slice(None),) + (None,) * (1 - d)] for d, a in enumerate(scene.grid)})
    np.testing.assert_allclose(R.sum(axis=-2), -np.broadcast_to(F, R.shape[:2] + (3,)), atol=1e-9)


# ---------------------------------------------------------------------------------------------------- the CLI
def test_cli_atlas_info_query_plot(tmp_path, capsys):
    scene_file = tmp_path / "plate.toml"
    scene_file.write_text(SCENE)
    out, png = tmp_path / "a.nc", tmp_path / "a.png"
    assert main(["atlas", str(scene_file), "-o", str(out), "--png", str(png), "-q"]) == 0
    assert "117 grid points (every point proved); cells: nothing proved between grid points; node 0:" in capsys.readouterr().err
    assert out.is_file() and png.read_bytes()[:4] == b"\x89PNG"
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    assert "4 nodes, load given as a body's weight and motion" in text and "critical_node (critical node):" in text
    assert "stable" not in text
    assert main(["query", str(out), "c_x=0.3", "c_y=0.45"]) == 0
    text = capsys.readouterr().out
    assert "critical_node = 2 (decided by " in text and "compatible = compatible" in text and "R = [[" in text
    assert text.count("decided by") == 1  # on the label it qualifies, not on whichever variable is last
    assert main(["query", str(out), "c_x=0.3", "c_y=0.45", "--json"]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["critical_node"] == 2 and len(answer["R"]) == 4 and answer["rank"] == 6
    np.testing.assert_allclose(sum(r[2] for r in answer["R"]), 98.1, rtol=1e-12)
    assert main(["atlas", str(scene_file), "-o", str(tmp_path / "a.zarr"), "-q"]) == 0
    assert stabmap.open_atlas(tmp_path / "a.zarr")["R"].identical(stabmap.open_atlas(out)["R"])
    assert float(stabmap.open_atlas(out)["R"].sel(c_x=0.0, c_y=0.0, component="z", node=3)) == pytest.approx(98.1 / 4, rel=1e-15)
    assert main(["plot", str(out), "-o", str(tmp_path / "b.pdf"), "--x", "c_y"]) == 0
    assert (tmp_path / "b.pdf").read_bytes()[:4] == b"%PDF"
    fig = stabmap.atlas_figure(stabmap.open_atlas(out))
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend[:4] == ["node 0", "node 1", "node 2", "node 3"] and "stable" not in fig.axes[0].get_title()


def test_cli_boundaries_follow_the_critical_node(tmp_path, capsys):
    scene_file = tmp_path / "plate.toml"
    scene_file.write_text(SCENE)
    out = tmp_path / "a.nc"
    assert main(["atlas", str(scene_file), "-o", str(out), "-q"]) == 0
    assert main(["query", str(out), "--boundaries", "c_x", "c_y=0.3"]) == 0
    text = capsys.readouterr().out
    assert "1 change of critical node" in text and "stabmap critical" not in text
    # the reactions' default axis is c_x, where the centre of mass lies: the same boundary without naming it
    ds = stabmap.open_atlas(out)
    b = stabmap.boundaries(ds, c_y=0.3)
    assert b.attrs["along"] == "c_x" and b.sizes["boundary"] == 1
    lo, hi = float(b.boundary_lower[0]), float(b.boundary_upper[0])
    line = ds["critical_node"].sel(c_y=0.3, method="nearest")
    assert lo < hi and line.sel(c_x=lo) != line.sel(c_x=hi)
    assert main(["query", str(out), "--fraction"]) == 2
    assert "reactions atlases have none" in capsys.readouterr().err


BAD = [
    (SCENE.replace("mass = 10.0", "mass = nan"), "body.mass must be finite"),
    (SCENE.replace("centre = [0.0, 0.0, 0.0]", "centre = [0.0, 0.0]"), "body.centre must be a 3-vector"),
    (SCENE.replace("[0.5, 0.5, 0.0], [-0.5", "[0.5, 0.5], [-0.5"), "nodes[2] must be a 3-vector"),
    (SCENE.replace("[0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]", "[0.5, 0.5, 0.0], [0.5, 0.5, 0.0]"), "nodes 2 and 3 are at the same point"),
    (SCENE.replace("[body]", 'releases = [{ node = 1, direction = [0.0, 0.0, 0.0] }]\n[body]'), "releases[0] direction is zero"),
    (SCENE.replace("[body]", 'releases = [{ node = 7, direction = [0.0, 0.0, 1.0] }]\n[body]'), "node 7 does not exist"),
    (SCENE.replace("c_y = {", "x_0 = { values = [-0.5, 0.5] }\nc_y = {"), "nodes 0 and 1 are at the same point"),
    (SCENE.replace("c_y = {", "F_x = {"), "belongs to a scene whose load is given by a [load] table"),
    (SCENE.replace("c_y = {", "spin = {"), "unknown parameter name 'spin'"),
    (SCENE.replace("c_y = {", "g_x = { values = [0.0, 1.0] }\ng_azimuth = {"), "scan its components or its direction, not both"),
    (SCENE.replace("c_y = {", "g_azimuth = {"), "grid axis g_azimuth has no effect: body.gravity is vertical"),
    (SCENE.replace("[body]", "[load]\nF = [0.0, 0.0, -1.0]\n[body]"), "exactly one of the two"),
    (SCENE.replace("mass = 10.0", "mass = 10.0\ninertia = [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]"), "body.inertia must be symmetric"),
]


@pytest.mark.parametrize("text,message", BAD)
def test_cli_bad_scene_one_line_exit_2_no_file(tmp_path, text, message):
    scene_file = tmp_path / "bad.toml"
    scene_file.write_text(text)
    run = run_cli(tmp_path, "atlas", str(scene_file), "-o", str(tmp_path / "out.nc"))
    assert run.returncode == 2, run.stderr
    assert message in run.stderr and "Traceback" not in run.stderr
    assert run.stderr.count("\n") == 1  # one line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


@pytest.mark.parametrize("args,message", [
    (["--refine"], "not available for reactions atlases"),
])
def test_cli_options_a_reactions_atlas_cannot_take(tmp_path, args, message):
    scene_file = tmp_path / "plate.toml"
    scene_file.write_text(SCENE)
    run = run_cli(tmp_path, "atlas", str(scene_file), "-o", str(tmp_path / "out.nc"), *args)
    assert run.returncode == 2 and message in run.stderr
    assert not (tmp_path / "out.nc").exists()
    run = run_cli(tmp_path, "critical", str(scene_file), "--along", "c_x", "-o", str(tmp_path / "c.nc"))
    assert run.returncode == 2 and "no stability" in run.stderr and not (tmp_path / "c.nc").exists()


def test_figure_script_and_its_benchmark_run(tmp_path, capsys):
    """scripts/reactions_figure.py, once, so that it cannot rot (docs/reactions.md shows its figures)."""
    script = runpy.run_path(str(pathlib.Path(__file__).resolve().parents[1] / "scripts" / "reactions_figure.py"))
    script["main"](["--out", str(tmp_path)])
    for name in ("reactions-square-plate.png", "reactions-spinning-stage.png"):
        assert (tmp_path / name).read_bytes()[:4] == b"\x89PNG"
    script["main"](["--bench", "--quick"])
    assert capsys.readouterr().out.count("us per point") == 5


@pytest.mark.slow
def test_a_local_dask_cluster_gives_the_same_atlas(tmp_path):
    scene_file = tmp_path / "plate.toml"
    scene_file.write_text(SCENE)
    assert main(["atlas", str(scene_file), "-o", str(tmp_path / "here.nc"), "-q"]) == 0
    assert main(["atlas", str(scene_file), "-o", str(tmp_path / "cluster.nc"), "--workers", "1", "--chunk-points", "20", "-q"]) == 0
    here, there = stabmap.open_atlas(tmp_path / "here.nc"), stabmap.open_atlas(tmp_path / "cluster.nc")
    for name in ("R", "critical_node", "rank", "compatible"):
        assert here[name].identical(there[name])
