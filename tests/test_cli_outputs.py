"""The command line with a new user's mistakes: outputs kept unless --overwrite, wrong kinds of file named, the
example scenes printable, a progress line from the first second (issue 22)."""

from __future__ import annotations

import hashlib
import re
import subprocess
import sys
import tomllib

import pytest

import stabmap
from stabmap.cli import cli, main
from stabmap.kernels import options
from stabmap.run.progress import ProgressLine, Rate
from scenes import top_toml

SCENE = top_toml('omega = { start = 1.0, stop = 60.0, num = 6 }\nc_1 = { start = 0.02, stop = 0.30, num = 4 }\n',
                 head='title = "one top, small grid"\nomega = 20.0\n')


def _digest(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A scene, its atlas, its critical values and a picture, written once."""
    d = tmp_path_factory.mktemp("made")
    (d / "s.toml").write_text(SCENE)
    assert main(["atlas", str(d / "s.toml"), "-o", str(d / "a.nc"), "--png", str(d / "a.png"), "-q", "--threads", "1"]) == 0
    assert main(["critical", str(d / "s.toml"), "-o", str(d / "c.nc"), "-q", "--threads", "1"]) == 0
    return d


def _stabmap(*args, cwd) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "stabmap", *args], capture_output=True, text=True, cwd=cwd, timeout=600)


@pytest.mark.parametrize(
    "args,named,option",
    [
        (["atlas", "s.toml", "-o", "a.nc"], "a.nc", "-o"),
        (["atlas", "s.toml", "-o", "new.nc", "--png", "a.png"], "a.png", "--png"),
        (["atlas", "s.toml", "-o", "a.nc", "--resume"], "a.nc", "-o"),
        (["critical", "s.toml", "-o", "c.nc"], "c.nc", "-o"),
        (["critical", "s.toml", "-o", "new.nc", "--png", "a.png"], "a.png", "--png"),
        (["plot", "a.nc", "-o", "a.png"], "a.png", "-o"),
    ],
)
def test_an_existing_output_is_an_error_and_untouched(made, args, named, option):
    before = {p.name: _digest(p) for p in made.iterdir()}
    run = _stabmap(*args, cwd=made)
    assert run.returncode == 2, run.stderr
    lines = run.stderr.strip().splitlines()
    assert lines == [f"stabmap: error: '{named}' ({option}) already exists; add --overwrite to replace it"]
    assert {p.name: _digest(p) for p in made.iterdir()} == before  # nothing touched, nothing new


def test_overwrite_replaces(made, tmp_path, capsys):
    for name in ("s.toml", "a.nc", "a.png"):
        (tmp_path / name).write_bytes((made / name).read_bytes())
    args = ["atlas", str(tmp_path / "s.toml"), "-o", str(tmp_path / "a.nc"), "--png", str(tmp_path / "a.png"), "-q"]
    assert main([*args, "--overwrite", "--threads", "1"]) == 0
    assert stabmap.open_atlas(tmp_path / "a.nc").attrs["stabmap_format_version"]
    (tmp_path / "a.png").write_bytes(b"not a picture")
    assert main(["plot", str(tmp_path / "a.nc"), "-o", str(tmp_path / "a.png"), "--overwrite"]) == 0
    assert (tmp_path / "a.png").read_bytes()[:4] == b"\x89PNG"


def test_resume_finishes_an_interrupted_run_without_overwrite(tmp_path, capsys):
    """An interrupted run leaves no output, only OUTPUT.partial/: --resume needs no --overwrite to finish it."""
    from stabmap.store.checkpoint import partial_dir

    scene_file = tmp_path / "s.toml"
    scene_file.write_text(SCENE)
    out = tmp_path / "a.nc"
    scene = stabmap.load_scene(scene_file)
    system = stabmap.systems.of(scene)
    from stabmap.store.checkpoint import Checkpoint

    Checkpoint.create(partial_dir(out), system, scene, scene.shape)  # a run stopped before its first chunk
    assert main(["atlas", str(scene_file), "-o", str(out), "-q"]) == 2
    assert "--resume" in capsys.readouterr().err
    assert main(["atlas", str(scene_file), "-o", str(out), "-q", "--resume"]) == 0
    assert out.is_file() and not partial_dir(out).exists()


@pytest.mark.parametrize(
    "args,message",
    [
        (["info", "s.toml"], "'s.toml' is a scene (TOML), not an atlas; an atlas is a .nc or .zarr file that 'stabmap atlas s.toml -o atlas.nc' writes"),
        (["query", "s.toml", "omega=3"], "'s.toml' is a scene (TOML), not an atlas"),
        (["plot", "s.toml", "-o", "x.png"], "'s.toml' is a scene (TOML), not an atlas"),
        (["info", "junk.nc"], "'junk.nc' is not an atlas: expected a netCDF4 (.nc) or Zarr (.zarr) file"),
        (["atlas", "a.nc", "-o", "x.nc"], "'a.nc' is an atlas (netCDF), not a scene; a scene is a TOML text file"),
        (["critical", "a.nc", "-o", "x.nc"], "'a.nc' is an atlas (netCDF), not a scene"),
        (["atlas", "a.png", "-o", "x.nc"], "cannot read scene file 'a.png' (binary): a scene is a TOML text file"),
        (["atlas", "s.toml", "-o", "x.txt"], "cannot write 'x.txt': an atlas is written as netCDF4 (.nc) or Zarr (.zarr), got '.txt'"),
        (["atlas", "s.toml", "-o", "x"], "got no suffix"),
        (["critical", "s.toml", "-o", "x.csv"], "cannot write 'x.csv': an atlas is written as netCDF4 (.nc) or Zarr (.zarr)"),
        (["atlas", "nogrid.toml", "-o", "x.nc"], "the scene has no [grid]: an atlas scans at least one parameter"),
        (["examples", "--show", "nope"], "unknown example 'nope'; choose one of:"),
    ],
)
def test_wrong_kind_of_file_says_what_was_expected(made, args, message):
    (made / "junk.nc").write_text("not netCDF\n")
    (made / "nogrid.toml").write_text(SCENE.split("[grid]")[0])
    before = {p.name: _digest(p) for p in made.iterdir()}
    run = _stabmap(*args, cwd=made)
    assert run.returncode == 2, run.stderr
    assert message in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr
    assert {p.name: _digest(p) for p in made.iterdir()} == before


def test_a_one_value_axis_is_the_single_point_atlas(tmp_path):
    scene_file = tmp_path / "one.toml"
    scene_file.write_text(SCENE.split("[grid]")[0] + "[grid]\nomega = { values = [42.0] }\n")
    assert main(["atlas", str(scene_file), "-o", str(tmp_path / "one.nc"), "-q"]) == 0
    assert stabmap.open_atlas(tmp_path / "one.nc")["stability"].shape == (1,)


def test_examples_show_prints_a_scene_that_runs(tmp_path, capsys):
    assert main(["examples"]) == 0
    names = [line.split()[0] for line in capsys.readouterr().out.splitlines()]
    assert "paper-n1-fixed" in names
    for name in names:
        assert main(["examples", "--show", name]) == 0
        text = capsys.readouterr().out
        assert tomllib.loads(text)["title"]
        assert stabmap.loads_scene(text) == stabmap.example(name)


def test_every_command_has_a_description_line():
    run = subprocess.run([sys.executable, "-m", "stabmap", "--help"], capture_output=True, text=True, timeout=120)
    listed = run.stdout.split("Commands:")[1]
    for name, command in cli.commands.items():
        assert command.get_short_help_str(limit=200), name
        assert not command.get_short_help_str(limit=200).endswith("..."), name
        assert name in listed
    for name in cli.commands:
        out = subprocess.run([sys.executable, "-m", "stabmap", name, "--help"], capture_output=True, text=True, timeout=120)
        assert out.returncode == 0
        description = out.stdout.split("\n\n")[1].strip()
        assert description and not description.startswith("Options"), name
    assert "--overwrite" in subprocess.run([sys.executable, "-m", "stabmap", "plot", "--help"], capture_output=True, text=True).stdout


def test_compile_notice_shows_at_once_and_is_handed_back(capsys):
    told = []
    previous = options.set_compile_notice(told.append)
    try:
        line = ProgressLine(True)
        line.redraw = lambda: line.show(f"[atlas] 0/10 points | {line.note}")
        options._notice[0]("compiling kernels (once, ~20 s)")  # what the numba listener calls on a cache miss
        assert capsys.readouterr().err == "\r[atlas] 0/10 points | compiling kernels (once, ~20 s)   "
        line.close()
        assert options._notice[0] == told.append  # the line gave the notice back
        assert told == []
    finally:
        options.set_compile_notice(previous)


def test_atlas_progress_line_says_compiling(tmp_path, capsys, monkeypatch):
    """The atlas's own line carries the notice while its first task compiles (a cache miss, simulated)."""
    from stabmap.run import atlas as running

    real = running.evaluate_blocks

    def first_compiles(*args, **kwargs):
        options._notice[0]("compiling kernels (once, ~20 s)")
        return real(*args, **kwargs)

    monkeypatch.setattr(running, "evaluate_blocks", first_compiles)
    scene_file = tmp_path / "s.toml"
    scene_file.write_text(SCENE)
    assert main(["atlas", str(scene_file), "-o", str(tmp_path / "a.nc"), "--threads", "1"]) == 0
    err = capsys.readouterr().err
    # The elapsed seconds depend on the machine's load: any whole number of them.
    assert re.search(r"\[atlas\] 0/24 points \(0\.0 %\) \| \d+ s, compiling kernels \(once, ~20 s\)", err), err
    assert "to go" not in err


def test_no_time_to_go_before_a_measured_rate(monkeypatch):
    clock = [100.0]
    monkeypatch.setattr("stabmap.run.progress.time.perf_counter", lambda: clock[0])
    rate = Rate(1000)
    rate.add(100)
    assert "to go" not in rate.text() and rate.per_second() is None
    clock[0] += 0.01
    rate.add(100)  # two tasks held up together (by compilation): finished at once, no rate yet
    assert "to go" not in rate.text() and rate.per_second() is None
    clock[0] += 1.99
    rate.add(100)
    assert rate.per_second() == pytest.approx(100.0)
    assert "300/1,000 points (30.0 %), 100 points/s, about 7 s to go" == rate.text()


def test_a_zarr_atlas_opens_in_plain_xarray_without_a_warning(tmp_path):
    """Zarr atlases carry consolidated metadata (issue 30): xr.open_zarr reads them quietly, with the same values."""
    import warnings

    import xarray as xr

    import stabmap
    from stabmap.store.files import write_atlas

    scene = stabmap.loads_scene('system = "closed"\nfamily = "hinge"\n[grid]\nratio = { values = [0.5, 1.0, 1.5] }\n')
    ds = stabmap.compute_atlas(scene, threads=1, progress=False)
    path = write_atlas(ds, tmp_path / "a.zarr")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with xr.open_zarr(path) as back:
            assert back["stability"].values.tolist() == ds["stability"].values.tolist()
