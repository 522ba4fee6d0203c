"""A scene's input in the user's terms: units where none are read, grids too large to run, values that mean nothing.

- A unit on a quantity other than a spin rate ("1.2 kg", "9.81 m/s2") is one line naming the key's own unit, from the
  parameter's declaration.
- A grid is sized before any work: an axis of more values than memory holds, an atlas larger than the free disk (or,
  in memory, than the available memory) is one line, exit 2, no file; a large run says its points, its file's size
  and the probe's estimate before it starts.  Nothing here depends on the machine's speed: the disk and memory are
  stood in for, and the threshold of "large" is lowered.
- Values that cannot be or mean nothing: a liquid mode with |kappa| <= 1, joints on one body, a scan of s on the top
  body of a chain are refused; s on the top body is said to be unused; a descending axis is the same axis, stored
  increasing.
- The README's first command runs a second time.
"""

from __future__ import annotations

import re
import shlex
from collections import namedtuple
from pathlib import Path

import numpy as np
import pytest

import stabmap
from stabmap import loads_scene
from stabmap.cli import main
from stabmap.errors import StabmapError
from stabmap.run import sizes

ROOT = Path(__file__).resolve().parents[1]

TOP = """
title = "one top"
support = "fixed"
g = 9.81
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.1
fluid = { E = [1e-3], kappa = [1.31] }
[grid]
omega = { start = 1.0, stop = 40.0, num = 10 }
c_1 = { values = [0.05, 0.1, 0.15, 0.2] }
"""


def _run(tmp_path: Path, text: str, *options: str, capsys) -> tuple[int, list[str], list[Path]]:
    """``stabmap atlas`` of scene ``text``: exit status, stderr lines, files left in ``tmp_path`` besides the scene."""
    (tmp_path / "s.toml").write_text(text)
    status = main(["atlas", str(tmp_path / "s.toml"), "-o", str(tmp_path / "a.nc"), "--threads", "1", *options])
    lines = capsys.readouterr().err.replace("\r", "\n").strip().splitlines()
    return status, lines, sorted(p for p in tmp_path.iterdir() if p.name != "s.toml")


# ------------------------------------------------------------------------------------------------ units
@pytest.mark.parametrize("change, message", [
    (("m = 1.0", 'm = "1.2 kg"'), "bodies[1].m = '1.2 kg': a unit is accepted for spin rates only (rad/s, rpm or Hz); "
                                  "give bodies[1].m as a plain number in kg"),
    (("g = 9.81", 'g = "9.81 m/s2"'), "g = '9.81 m/s2': a unit is accepted for spin rates only (rad/s, rpm or Hz); "
                                      "give g as a plain number in m s-2"),
    (("A = 0.02", 'A = "0.02 kg m2"'), "give bodies[1].A as a plain number in kg m2"),
    (("kappa = [1.31]", 'kappa = ["1.31 x"]'), "give bodies[1].fluid.kappa[1] as a plain number (dimensionless)"),
    (("values = [0.05, 0.1", 'values = ["5 cm", "10 cm"'), "grid.c_1.values[1] = '5 cm': a unit is accepted for spin rates only"),
    (("g = 9.81", 'g = "9.81"'), "g must be a number, got '9.81' (remove the quotes: TOML reads a quoted number as text)"),
])
def test_a_unit_on_another_quantity_names_the_keys_unit(tmp_path, capsys, change, message):
    assert change[0] in TOP
    status, lines, left = _run(tmp_path, TOP.replace(change[0], change[1], 1), capsys=capsys)
    assert (status, left) == (2, [])
    assert len(lines) == 1 and message in lines[0], lines


# ------------------------------------------------------------------------------------------------ sizes
def test_an_axis_of_a_hundred_billion_values_is_one_line(tmp_path, capsys):
    status, lines, left = _run(tmp_path, TOP.replace("num = 10", "num = 100000000000"), capsys=capsys)
    assert (status, left) == (2, [])
    assert lines == ["stabmap: error: grid.omega.num = 100,000,000,000: an axis holds at most 1,000,000 values; give a "
                     "smaller num (to locate a boundary finely along one axis, use 'stabmap critical', docs/critical.md)"]


def _bytes_per_point(path: Path) -> int:
    """What the written atlas stores at a grid point, uncompressed: its variables on the grid, by their dtypes."""
    ds = stabmap.open_atlas(path)
    grid = set(ds["n_complex_pairs"].dims)
    return sum(int(np.prod([ds.sizes[d] for d in v.dims if d not in grid], dtype=int)) * v.dtype.itemsize
               for v in ds.data_vars.values() if grid <= set(v.dims))


def test_a_grid_larger_than_the_free_disk_is_refused(tmp_path, capsys, monkeypatch):
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(sizes.shutil, "disk_usage", lambda where: usage(10**6, 10**6 - 500, 500))
    status, lines, left = _run(tmp_path, TOP, capsys=capsys)
    assert (status, left) == (2, [])  # no file, no checkpoint
    assert len(lines) == 1, lines
    assert re.fullmatch(rf"stabmap: error: the atlas of 40 points would take up to [\d,]+ bytes before compression, and the run "
                        rf"keeps a checkpoint beside it, but '{re.escape(str(tmp_path.resolve()))}' has 500 bytes free; make "
                        r"the grid coarser \(smaller num\) or write to a disk with more room", lines[0]), lines[0]


def test_an_atlas_in_memory_larger_than_the_memory_is_refused(monkeypatch):
    monkeypatch.setattr(sizes, "available_memory", lambda: 100)
    with pytest.raises(StabmapError, match=r"an atlas in memory of 40 points needs [\d,]+ bytes, but 100 bytes of memory is "
                                           r"available; make the grid coarser"):
        stabmap.compute_atlas(loads_scene(TOP), threads=1, progress=False)
    with pytest.raises(StabmapError, match=r"an adaptive atlas, held in memory, of 40 points needs [\d,]+ bytes, but 100 bytes"):
        stabmap.compute_refined(loads_scene(TOP), threads=1, progress=False)


def test_a_large_run_says_its_size_and_time_before_it_starts(tmp_path, capsys, monkeypatch):
    status, lines, _ = _run(tmp_path, TOP, capsys=capsys)
    assert status == 0 and not [line for line in lines if "timing a probe" in line or "(timed on" in line], lines  # small
    monkeypatch.setattr(sizes, "ANNOUNCE_POINTS", 40)  # "large" from 40 points: the facts, not the threshold, are tested
    status, lines, _ = _run(tmp_path, TOP, "--overwrite", capsys=capsys)
    assert status == 0, lines
    said = [line for line in lines if line.startswith("[atlas] ") and "/40 points" not in line]
    assert len(said) == 2, lines
    nbytes = 40 * _bytes_per_point(tmp_path / "a.nc")
    assert said[0] == f"[atlas] 40 points (10 \u00d7 4), file at most {nbytes} bytes (before compression); timing a probe"
    assert re.fullmatch(r"\[atlas\] about \d+ (s|min|h|days) on 1 thread \(timed on [\d,]+ points\)", said[1]), said[1]
    assert lines.index(said[1]) < next(i for i, line in enumerate(lines) if line.startswith("wrote "))


# ------------------------------------------------------------------------------------------------ values that mean nothing
@pytest.mark.parametrize("change, message", [
    (("kappa = [1.31]", "kappa = [0.5]"), "bodies[1].fluid.kappa[1] = 0.5: a liquid mode has |kappa| > 1 (its frequency in the "
                                          "body, 2 omega / kappa, is below 2 omega; docs/cavities.md)"),
    (("kappa = [1.31]", "kappa = [-1.0]"), "bodies[1].fluid.kappa[1] = -1: a liquid mode has |kappa| > 1"),
    (("g = 9.81", "g = 9.81\njoints = [1.0, 2.0]"), "joints has 2 values, but one body has no joint between bodies (its base "
                                                    "joint is K_0); remove joints"),
])
def test_values_that_cannot_be_are_one_line(tmp_path, capsys, change, message):
    assert change[0] in TOP
    status, lines, left = _run(tmp_path, TOP.replace(change[0], change[1], 1), capsys=capsys)
    assert (status, left) == (2, [])
    assert len(lines) == 1 and lines[0].startswith(f"stabmap: error: {message}"), lines


@pytest.mark.parametrize("bodies, note", [
    (1, "note: bodies[1].s = 0.3 is not used: a single body has no joint above it (s is the distance from a body's lower "
        "joint to the joint of the body above it)"),
    (2, "note: bodies[2].s = 0.3 is not used: body 2 is the top of the chain and has no joint above it"),
])
def test_s_on_the_top_body_is_said_to_be_unused(tmp_path, capsys, bodies, note):
    body = "[[bodies]]\nm = 1.0\nA = 0.02\nC = 0.03\nc = 0.1\ns = 0.3\n"
    text = 'support = "fixed"\n' + body * bodies + "[grid]\nomega = { start = 1.0, stop = 40.0, num = 5 }\n"
    status, lines, _ = _run(tmp_path, text, "-q", capsys=capsys)
    assert status == 0 and any(line.startswith(note) for line in lines), lines
    status, lines, _ = _run(tmp_path, text.replace("s = 0.3\n[grid]", "[grid]"), "-q", "--overwrite", capsys=capsys)
    assert status == 0 and not [line for line in lines if "is not used" in line], lines  # without it, no note


BODY = "[[bodies]]\nm = 1.0\nA = 0.02\nC = 0.03\nc = 0.1\ns = 0.3\n"
CHAIN = 'support = "fixed"\nomega = 10.0\n{joints}' + BODY * 2 + "[[bodies]]\nm = 1.0\nA = 0.02\nC = 0.03\nc = 0.1\n{top}{grid}"


@pytest.mark.parametrize("joints, top, grid, message", [
    ("joints = [1.0]\n", "", "", "joints has 1 value; a chain of 3 bodies has 2 joints between bodies (K_1..K_2); give one "
                                 "stiffness per joint"),
    ("", "s = 0.0\n", "[grid]\ns_3 = { values = [0.1, 0.2] }\n",
     "grid axis 's_3' has no effect: s_k is the distance to the joint of the body above body k, and body 3 is the top of the "
     "chain; scan s_k of a lower body"),
])
def test_a_chain_counts_its_joints_and_scans_no_s_on_top(joints, top, grid, message):
    with pytest.raises(StabmapError) as err:
        loads_scene(CHAIN.format(joints=joints, top=top, grid=grid))
    assert str(err.value) == message


def test_two_bodies_have_one_joint():
    with pytest.raises(StabmapError) as err:
        loads_scene('support = "fixed"\nomega = 10.0\njoints = [1.0, 2.0]\n' + BODY + BODY.replace("s = 0.3\n", ""))
    assert str(err.value) == "joints has 2 values; a chain of 2 bodies has 1 joint between bodies (K_1); give one stiffness per joint"


def test_a_descending_axis_is_the_same_axis_stored_increasing():
    down = stabmap.compute_atlas(loads_scene(TOP.replace("start = 1.0, stop = 40.0", "start = 40.0, stop = 1.0")),
                                 threads=1, progress=False)
    up = stabmap.compute_atlas(loads_scene(TOP), threads=1, progress=False)
    assert np.all(np.diff(down["omega"].values) > 0)
    for name in ("omega", "n_complex_pairs", "cell", "growth_rate"):
        np.testing.assert_array_equal(down[name].values, up[name].values, err_msg=name)
    assert loads_scene(down.attrs["scene"]).grid[0].values == loads_scene(TOP).grid[0].values


# ------------------------------------------------------------------------------------------------ the README's first command
def test_the_readmes_first_command_runs_again(tmp_path, monkeypatch, capsys):
    """Run after a first run (or a failed install): its outputs exist, and the line still works."""
    first = re.search(r"```bash\n(.*)\n", (ROOT / "README.md").read_text())[1]
    command = shlex.split(first.split("&&")[-1])
    assert command[0] == "stabmap" and "--overwrite" in command, first
    monkeypatch.chdir(tmp_path)
    outputs = [command[command.index(option) + 1] for option in ("-o", "--png")]
    for name in outputs:
        (tmp_path / name).write_bytes(b"the first run's")
    assert main(command[1:] + ["--threads", "1", "-q"]) == 0, capsys.readouterr().err
    assert stabmap.open_atlas(tmp_path / outputs[0]).attrs["stabmap_format_version"]
    assert (tmp_path / outputs[1]).read_bytes()[:4] == b"\x89PNG"
