"""Atlases: labelled Datasets, netCDF files, queries, plots and the command line."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

import reference as ref
import stabmap
from stabmap.cli import main
from systems import engine_point, reference_args
from scenes import TWO_TOPS, two_tops

SCENE = TWO_TOPS


@pytest.fixture
def scene(two_tops_scene):
    return two_tops_scene


@pytest.fixture
def atlas(two_tops_atlas):
    return two_tops_atlas


def test_dataset_layout(atlas):
    assert atlas["n_complex_pairs"].dims == ("omega", "m_2")
    assert atlas["n_complex_pairs"].dtype == np.int16
    assert atlas["stability"].attrs["flag_meanings"] == "unstable stable degenerate"
    assert list(atlas["stability"].attrs["flag_values"]) == [0, 1, 2]
    assert atlas["omega"].attrs["units"] == "rad s-1" and atlas["m_2"].attrs["units"] == "kg"
    assert atlas["m_2"].attrs["scale"] == "log"
    assert float(atlas["K_1"]) == 20.0 and atlas["K_1"].attrs["long_name"] == "stiffness of joint 1"
    assert float(atlas["omega_2"]) == 45.0
    for key in ("Conventions", "title", "source", "history", "references", "stabmap_format_version", "scene"):
        assert key in atlas.attrs
    assert stabmap.loads_scene(atlas.attrs["scene"]) == stabmap.loads_scene(SCENE)


def test_atlas_equals_point_by_point_and_reference(atlas, scene):
    system = two_tops()
    system["bodies"][1]["omega"] = 45.0
    for i, omega in enumerate(atlas["omega"].values):
        for j, m2 in enumerate(atlas["m_2"].values):
            system["omega"] = float(omega)
            system["bodies"][1]["m"] = float(m2)
            got = int(atlas["n_complex_pairs"][i, j])
            assert got == engine_point(system)[0]
            if (i + j) % 5 == 0:
                assert got == ref.count_complex_pairs(ref.char_poly(**reference_args(system)))
    assert set(np.unique(atlas["n_complex_pairs"])) >= {0, 1}  # the grid crosses a boundary


def test_chunking_does_not_change_the_atlas(scene, atlas):
    # Node by node, every variable is the same whatever the chunks.  Cell by cell, the labels are; which nodes a
    # box proved, and so decided_by and cell, follow the chunks' boxes (each claim a proof either way).
    nodes = stabmap.compute_atlas(scene, threads=1, progress=False, prove_cells=False)
    other = stabmap.compute_atlas(scene, threads=1, chunk_points=1000, progress=False, prove_cells=False)
    xr.testing.assert_identical(other.drop_attrs(), nodes.drop_attrs())
    cells = stabmap.compute_atlas(scene, threads=1, chunk_points=1000, progress=False)
    for name in ("n_complex_pairs", "stability"):
        xr.testing.assert_identical(cells[name], atlas[name])
        xr.testing.assert_identical(cells[name], nodes[name])


def test_write_open_query_roundtrip(atlas, tmp_path):
    path = stabmap.write_atlas(atlas, tmp_path / "a.nc")
    back = stabmap.open_atlas(path)
    xr.testing.assert_equal(back, atlas)
    label = stabmap.label_at(back, omega=145.0, m_2=0.12)
    assert label.grid_point == {"omega": 150.0, "m_2": pytest.approx(0.1)}
    assert label.n_complex_pairs == int(atlas["n_complex_pairs"][-1, 0])
    with pytest.raises(stabmap.StabmapError, match="missing: m_2"):
        stabmap.label_at(back, omega=1.0)


def test_failed_write_leaves_nothing(atlas, tmp_path, monkeypatch):
    def broken(self, path, *args, **kwargs):
        open(path, "wb").write(b"partial")
        raise KeyboardInterrupt

    monkeypatch.setattr(xr.Dataset, "to_netcdf", broken)
    with pytest.raises(KeyboardInterrupt):
        stabmap.write_atlas(atlas, tmp_path / "a.nc")
    assert os.listdir(tmp_path) == []


def test_cli_end_to_end(tmp_path, capsys):
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(SCENE)
    out, png = tmp_path / "a.nc", tmp_path / "a.png"
    assert main(["atlas", str(scene_file), "-o", str(out), "--png", str(png), "-q"]) == 0
    assert out.is_file() and png.read_bytes()[:4] == b"\x89PNG"
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    assert "omega" in text and "stable" in text and "decided by" in text
    assert main(["query", str(out), "omega=42.5", "m_2=1.3"]) == 0
    text = capsys.readouterr().out
    assert "nearest grid point" in text and "n_complex_pairs =" in text
    assert main(["plot", str(out), "-o", str(tmp_path / "b.pdf"), "--x", "m_2"]) == 0
    assert (tmp_path / "b.pdf").read_bytes()[:4] == b"%PDF"


def test_cli_example_three_axes_and_sel(tmp_path):
    scene_file = tmp_path / "s.toml"
    scene_file.write_text(SCENE.replace("[grid]", "[grid]\nK_1 = { values = [0.0, 50.0] }"))
    out = tmp_path / "a.nc"
    assert main(["atlas", str(scene_file), "-o", str(out), "-q"]) == 0
    assert stabmap.open_atlas(out)["n_complex_pairs"].dims == ("K_1", "omega", "m_2")
    assert main(["plot", str(out), "-o", str(tmp_path / "p.png"), "--sel", "K_1=50"]) == 0


@pytest.mark.parametrize(
    "args,message",
    [
        (["atlas", "missing.toml", "-o", "OUT"], "scene file 'missing.toml' does not exist"),
        (["atlas", "--example", "nope", "-o", "OUT"], "unknown example 'nope'"),
        (["atlas", "--example", "paper-n1-fixed", "-o", "no/such/dir/a.nc"], "does not exist"),
        (["query", "OUT", "omega=abc"], "does not exist"),
    ],
)
def test_cli_bad_input_clear_error_no_file(tmp_path, args, message):
    args = [a.replace("OUT", str(tmp_path / "out.nc")) for a in args]
    run = subprocess.run([sys.executable, "-m", "stabmap", *args], capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 2
    assert message in run.stderr and "Traceback" not in run.stderr
    assert not (tmp_path / "out.nc").exists()


def test_cli_bad_scene_value(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(SCENE.replace("m = 0.5", "m = -1.0"))
    assert main(["atlas", str(bad), "-o", str(tmp_path / "a.nc")]) == 2
    assert "bodies[2].m must be > 0, got -1.0" in capsys.readouterr().err
    assert not (tmp_path / "a.nc").exists()
