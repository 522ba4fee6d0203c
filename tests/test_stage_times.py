"""Where the time goes: the seconds of a run by stage (labels, cells, rates), the writing and the wall clock, kept in
the atlas's attributes, printed by ``stabmap info``, and the note that ends a run whose growth rates cost more than
its labels (stabmap.run.costs, stabmap.systems.stages).  No test asserts how long anything took: only what a clock
cannot break (names, signs, sums, and the note's logic on seconds set by the test)."""

from __future__ import annotations

import pytest

import stabmap
from stabmap.cli import main
from stabmap.run import atlas as running
from stabmap.run import costs
from stabmap.store.checkpoint import Checkpoint, partial_dir
from stabmap.store.files import open_atlas, write_atlas
from stabmap.systems import stages

# Maievskii's top with a little liquid: unstable below ~30 rad/s, so growth rates are computed at some nodes.
SCENE = """
support = "fixed"
g = 9.81
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.1
fluid = { E = [1e-4], kappa = [1.31] }
[grid]
omega = { start = 1.0, stop = 60.0, num = 64 }
c_1 = { start = 0.05, stop = 0.15, num = 16 }
"""
STAGES = ("labels", "cells", "rates")


def _scene(tmp_path, head: str = ""):
    path = tmp_path / "s.toml"
    path.write_text(head + SCENE)
    return path


def _work(attrs) -> float:
    return sum(attrs[f"stabmap_seconds_{k}"] for k in STAGES)


def test_stages_nest_and_count_each_second_once(monkeypatch):
    ticks = iter(range(100))
    monkeypatch.setattr(stages.time, "perf_counter", lambda: float(next(ticks)))
    with stages.timed() as seconds:  # clock 0
        with stages.stage("cells"):  # 1
            with stages.stage("rates"):  # 2
                pass  # 3: back to cells
            # 4: back to labels
        with stages.stage("rates"):  # 5
            pass  # 6
    # 7: the block is left
    assert seconds == {"labels": 1 + 1 + 1, "cells": 1 + 1, "rates": 1 + 1}
    with stages.stage("rates"):  # outside a timed task: nothing is timed, nothing fails
        pass
    assert seconds == {"labels": 3, "cells": 2, "rates": 2}


def test_the_file_keeps_each_stage_and_info_prints_them(tmp_path, capsys):
    out = tmp_path / "a.nc"
    assert main(["atlas", str(_scene(tmp_path)), "-o", str(out), "-q", "--threads", "1"]) == 0
    a = open_atlas(out).attrs
    for k in (*STAGES, "write", "wall"):
        assert a[f"stabmap_seconds_{k}"] >= 0, k
    assert a["stabmap_seconds_labels"] > 0 and a["stabmap_seconds_rates"] > 0  # rates were computed, and timed
    assert a["stabmap_run_threads"] == 1 and a["stabmap_run_timed"] == costs.WHOLE
    # on one thread the work is done inside the run's wall time
    assert _work(a) <= a["stabmap_seconds_wall"]
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    times = " ".join(text.split("\n  time: ")[1].split("\n  history")[0].split())  # the section, its lines joined
    assert times.startswith("work ") and "summed over tasks: labels " in times
    assert ", cells (box proofs) " in times and ", rates " in times and "; writing " in times and "; wall " in times
    assert "timed:" not in text


def test_growth_rate_false_times_no_rates(tmp_path):
    ds = stabmap.compute_atlas(stabmap.load_scene(_scene(tmp_path, "growth_rate = false\n")), threads=2, progress=False)
    assert ds.attrs["stabmap_seconds_rates"] == 0 and ds.attrs["stabmap_seconds_labels"] > 0
    assert "stabmap_seconds_write" not in ds.attrs  # nothing written yet: the file written from it says nothing of it
    assert ds.attrs["stabmap_run_threads"] == 2


def test_an_atlas_without_the_seconds_is_described_without_them(tmp_path, capsys):
    out, old = tmp_path / "a.nc", tmp_path / "old.nc"
    assert main(["atlas", str(_scene(tmp_path)), "-o", str(out), "-q"]) == 0
    ds = open_atlas(out)
    ds.attrs = {k: v for k, v in ds.attrs.items() if not k.startswith(("stabmap_seconds_", "stabmap_run_"))}
    write_atlas(ds, old)  # as an atlas written before stabmap kept them
    capsys.readouterr()
    assert main(["info", str(old)]) == 0
    text = capsys.readouterr().out
    assert "time:" not in text and "points:" in text


def _rates_cost(monkeypatch, stage: str, extra: float = 100.0) -> None:
    """Every run's recorded seconds get ``extra`` more in ``stage``: the note's logic, whatever the machine's speed."""
    take = costs.Costs.take

    def more(self):
        out = take(self)
        if not getattr(self, "charged", False):
            out[stage] += extra
            self.spent[stage] += extra
            self.charged = True
        return out

    monkeypatch.setattr(costs.Costs, "take", more)


def test_a_run_whose_rates_cost_more_than_its_labels_says_so_last(tmp_path, capsys, monkeypatch):
    _rates_cost(monkeypatch, "rates")
    out, png = tmp_path / "a.nc", tmp_path / "a.png"
    assert main(["atlas", str(_scene(tmp_path)), "-o", str(out), "--png", str(png), "-q"]) == 0
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert last.startswith("note: growth rates took 1") and "s of work (labels and cells " in last
    assert last.endswith("; set growth_rate = false in the scene to skip them")
    assert open_atlas(out).attrs["stabmap_seconds_rates"] >= 100


def test_a_refined_run_keeps_its_work_and_says_so_too(tmp_path, capsys, monkeypatch):
    _rates_cost(monkeypatch, "rates")
    out = tmp_path / "r.nc"
    assert main(["atlas", str(_scene(tmp_path)), "-o", str(out), "--refine", "--coarse-stride", "2", "-q"]) == 0
    assert capsys.readouterr().err.strip().splitlines()[-1].startswith("note: growth rates took")
    a = open_atlas(out).attrs
    assert a["stabmap_seconds_rates"] >= 100 and a["stabmap_seconds_wall"] > 0
    assert "stabmap_seconds_write" not in a  # written after the run, by the command: not timed


@pytest.mark.parametrize("head,stage", [("growth_rate = false\n", "rates"), ("", "labels")])
def test_no_note_without_rates_or_when_the_labels_cost_more(tmp_path, capsys, monkeypatch, head, stage):
    _rates_cost(monkeypatch, stage)
    assert main(["atlas", str(_scene(tmp_path, head)), "-o", str(tmp_path / "a.nc"), "-q"]) == 0
    assert "note:" not in capsys.readouterr().err


def test_the_python_runs_report_the_note(tmp_path, capsys, monkeypatch):
    _rates_cost(monkeypatch, "rates")
    scene = stabmap.load_scene(_scene(tmp_path))
    report = stabmap.compute_to_file(scene, tmp_path / "a.zarr", progress=False)
    assert report.note is not None and report.note.startswith("note: growth rates took")
    assert report.seconds["rates"] >= 100 and open_atlas(tmp_path / "a.zarr").attrs["stabmap_seconds_rates"] >= 100
    assert capsys.readouterr().err == ""  # no progress line asked, no note printed
    stabmap.compute_atlas(scene, progress=True)
    assert capsys.readouterr().err.strip().splitlines()[-1].startswith("note: growth rates took")


def test_the_note_names_every_key_that_computes_the_rates(tmp_path):
    scene = stabmap.load_scene(_scene(tmp_path, "frequencies = true\n"))
    system = stabmap.systems.of(scene)
    seconds = {"labels": 1.0, "cells": 0.5, "rates": 3.0, "write": 9.0, "wall": 9.0}
    assert costs.note(system, scene, seconds) == (
        "note: growth rates and frequencies took 3.0 s of 4.5 s of work (labels and cells 1.5 s); "
        "set growth_rate = false and frequencies = false in the scene to skip them"
    )
    assert costs.note(system, scene, {**seconds, "rates": 1.4}) is None
    assert "(labels 1.0 s)" in costs.note(system, scene, {**seconds, "cells": 0.0})  # node by node: no cells


def test_a_resumed_run_adds_the_interrupted_runs_seconds(tmp_path, monkeypatch, capsys):
    scene = stabmap.load_scene(_scene(tmp_path))
    out = tmp_path / "a.nc"
    save, saved = Checkpoint.save, []

    def interrupt(self, *args, **kwargs):
        if len(saved) == 2:
            raise KeyboardInterrupt
        save(self, *args, **kwargs)
        saved.append(args[0])

    monkeypatch.setattr(Checkpoint, "save", interrupt)
    with pytest.raises(KeyboardInterrupt):  # node by node: chunks of 128 points, not whole tiles of cells
        running.compute_to_file(scene, out, threads=1, chunk_points=128, progress=False, prove_cells=False)
    monkeypatch.undo()
    checkpoint = Checkpoint.open(partial_dir(out))
    before = checkpoint.seconds(checkpoint.done())
    assert checkpoint.done() == set(saved) and before["wall"] > 0 and before["labels"] > 0
    report = running.compute_to_file(scene, out, threads=1, resume=True, progress=False)
    assert report.reused == 2
    a = open_atlas(out).attrs
    assert a["stabmap_run_timed"] == costs.RESUMED
    for k, v in before.items():
        assert a[f"stabmap_seconds_{k}"] >= v - 1e-6, k
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    assert f"timed: {costs.RESUMED}" in capsys.readouterr().out


def test_a_checkpoint_without_seconds_resumes_and_says_what_was_timed(tmp_path, capsys):
    scene = stabmap.load_scene(_scene(tmp_path))
    out = tmp_path / "a.nc"
    Checkpoint.create(partial_dir(out), stabmap.systems.of(scene), scene, scene.shape)  # as a checkpoint of format 3
    running.compute_to_file(scene, out, resume=True, progress=False)
    assert open_atlas(out).attrs["stabmap_run_timed"] == costs.RESUMED_ONLY
    assert main(["info", str(out)]) == 0
    assert "timed: only the resumed part" in capsys.readouterr().out


def test_a_stage_its_system_does_not_declare_is_an_error():
    class Run:
        seconds = {"labels": 1.0, "mystery": 2.0}

    with pytest.raises(ValueError, match="'mystery', which its system does not declare"):
        costs.Costs(Run(), ("labels", "cells", "write", "wall")).take()  # type: ignore[arg-type]
