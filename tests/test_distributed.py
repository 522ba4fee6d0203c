"""Atlases on a real dask.distributed cluster (scheduler and workers as processes on loopback), streamed to
files, surviving killed, stopped, restarted and late workers and a lost scheduler, and resumed after an
interrupted run."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import stabmap
from stabmap import cli
from stabmap.run import atlas
from stabmap.run import runner as cluster
from stabmap.run.atlas import compute, compute_to_file
from stabmap.run.cells import tile_shape
from stabmap.run.chunks import (
    MIN_CHUNK_POINTS,
    TASK_SECONDS,
    chunk_locations,
    chunk_points_for,
    chunk_shape,
    probe_points,
)
from stabmap.run.runner import FIRST_TASK_POINTS, Pace
from stabmap.run.tasks import point_order, probe
from stabmap.scene.grid import resample
from stabmap.store.checkpoint import Checkpoint, partial_dir
from stabmap.store.files import open_atlas

# Degree 18 (three bodies, four liquid modes each): about 0.1 ms a point, so a run lasts seconds and can be
# interrupted or lose a worker while chunks are still pending.
SLOW = """
title = "three tops with liquid, four modes each"
support = "fixed"
omega = 40.0
joints = [30.0, 20.0]

[[bodies]]
m = 2.0
A = 0.04
C = 0.05
c = 0.2
s = 0.5
fluid = { E = [0.002, 0.0005, 0.0002, 0.0001], kappa = [1.6, 3.1, 5.2, 7.7] }

[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.15
s = 0.4
fluid = { E = [0.001, 0.0002, 0.0001, 0.00005], kappa = [1.8, 2.9, 4.8, 8.1] }

[[bodies]]
m = 0.5
A = 0.01
C = 0.012
c = 0.1
s = 0.3
fluid = { E = [0.0005, 0.0001, 0.00005, 0.00002], kappa = [1.7, 3.3, 5.5, 7.9] }

[grid]
omega = { start = 1.0, stop = 120.0, num = 240 }
m_2 = { start = 0.2, stop = 4.0, num = 160 }
"""
SLOW_CHUNK = 1024  # 40 chunks: one tile of 32 x 32 cells each (stabmap.run.cells)


def _same_atlas(a: xr.Dataset, b: xr.Dataset) -> None:
    """Cell for cell, coordinate for coordinate, attribute for attribute (but the time in 'history' and the run's
    seconds, threads and what they cover: stabmap.run.costs)."""
    xr.testing.assert_identical(a.drop_attrs(), b.drop_attrs())
    for name in set(a.variables) | set(b.variables):
        assert a[name].dtype == b[name].dtype, name
    keys = {k for k in set(a.attrs) | set(b.attrs) if not k.startswith(("stabmap_seconds_", "stabmap_run_"))} - {"history"}
    assert {k: str(a.attrs.get(k)) for k in keys} == {k: str(b.attrs.get(k)) for k in keys}


@pytest.fixture(scope="module")
def slow_scene_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("scene") / "slow.toml"
    path.write_text(SLOW)
    return path


@pytest.fixture(scope="module")
def big_scene_file(tmp_path_factory):
    """The slow scene on 4 x the points: chunks sized by measured cost are few and short, and an interrupt must
    land while work is left whatever the machine's speed (kernels loaded from an install-time cache are fast)."""
    path = tmp_path_factory.mktemp("scene") / "big.toml"
    path.write_text(SLOW.replace("num = 160", "num = 640"))
    return path


@pytest.fixture(scope="module")
def big_local(big_scene_file):
    return compute(stabmap.load_scene(big_scene_file), threads=2, progress=False)


@pytest.fixture(scope="module")
def slow_local(slow_scene_file):
    """The in-process atlas; computing it also fills the kernel cache that worker processes then load."""
    return compute(stabmap.load_scene(slow_scene_file), threads=2, progress=False)


class LoopbackCluster:
    """``dask scheduler`` and ``dask worker`` processes on 127.0.0.1, importing this checkout of stabmap.

    ``nanny=False`` starts each worker as one process; ``nanny=True`` the default way, a nanny process that starts
    the worker process and restarts it when it dies.  ``worker_pid(i)`` is the process that runs the tasks.
    """

    def __init__(self, tmp_path, workers: int, nanny: bool = False, wait: bool = True):
        self.tmp, self.nanny = Path(tmp_path), nanny
        self.tmp.mkdir(parents=True, exist_ok=True)
        self.file = self.tmp / "scheduler.json"
        self.file.unlink(missing_ok=True)
        self.scheduler = self._start("scheduler", "--host", "127.0.0.1", "--port", "0", "--scheduler-file", str(self.file))
        self.procs = [self.scheduler]
        deadline = time.monotonic() + 60
        while not self.file.exists():
            assert time.monotonic() < deadline, "the dask scheduler did not start"
            time.sleep(0.1)
        time.sleep(0.2)  # the file is written whole, but give it a moment
        self.address = json.loads(self.file.read_text())["address"]
        self.workers = []
        for _ in range(workers):
            self.add_worker()
        if wait:
            self.wait_for(workers)

    def add_worker(self) -> subprocess.Popen:
        extra = [] if self.nanny else ["--no-nanny"]
        p = self._start("worker", self.address, "--nthreads", "1", *extra, "--name", f"w{len(self.workers)}")
        self.workers.append(p)
        self.procs.append(p)
        return p

    def wait_for(self, n: int) -> None:
        from distributed import Client

        with Client(self.address, timeout=60, set_as_default=False) as c:
            c.wait_for_workers(n, timeout=120)

    def worker_pid(self, i: int) -> int:
        """The pid of worker ``i``'s task-running process (under its nanny, if it has one)."""
        if not self.nanny:
            return self.workers[i].pid
        import psutil

        deadline = time.monotonic() + 60
        while True:
            children = [c for c in psutil.Process(self.workers[i].pid).children() if "spawn" in " ".join(c.cmdline())]
            if children:
                return children[0].pid
            assert time.monotonic() < deadline, "the nanny started no worker"
            time.sleep(0.1)

    @staticmethod
    def _start(*args):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(stabmap.__file__).parents[1]), os.environ.get("PYTHONPATH", "")]))
        return subprocess.Popen(
            [sys.executable, "-m", "dask", *args, "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            env=env,
        )

    def close(self):
        for p in reversed(self.procs):
            if p.poll() is None:
                with __import__("contextlib").suppress(OSError):
                    os.kill(p.pid, signal.SIGCONT)
                p.terminate()
        for p in self.procs:
            try:
                p.wait(20)
            except subprocess.TimeoutExpired:
                p.kill()


@pytest.fixture(scope="module")
def loopback(tmp_path_factory, slow_local):
    c = LoopbackCluster(tmp_path_factory.mktemp("cluster"), workers=2)
    yield c
    c.close()


def test_chunk_layout_covers_the_grid_once():
    cases = [((7, 5, 3), 4, None), ((7, 5, 3), 20, (2, 0, 1)), ((240, 160), 1024, None), ((240, 160), 1024, (1, 0)),
             ((1,), 100, None), ((3, 4), 1, None), ((), 10, None)]
    for shape, points, order in cases:
        chunks = chunk_shape(shape, points, order)
        seen = np.zeros(shape, dtype=int)
        for loc in chunk_locations(shape, chunks):
            seen[tuple(slice(a, b) for a, b in loc)] += 1
        assert (seen == 1).all()
        assert int(np.prod(chunks)) <= points
        if order is not None:  # the axis visited fastest is kept whole first
            assert chunks[order[-1]] == min(shape[order[-1]], points)
    # chunks of whole tiles (stabmap.run.cells): multiples of the tile or the whole axis, at least one tile
    for shape, points, order, tile in [((240, 160), 1024, (1, 0), (32, 32)), ((240, 160), 5000, (1, 0), (32, 32)),
                                       ((100000,), 3000, None, (1024,)), ((20, 10), 50, None, (32, 32))]:
        chunks = chunk_shape(shape, points, order, tile)
        assert all(c == n or c % t == 0 for c, n, t in zip(chunks, shape, tile))
        assert int(np.prod(chunks)) <= max(points, int(np.prod([min(n, t) for n, t in zip(shape, tile)])))
        seen = np.zeros(shape, dtype=int)
        for loc in chunk_locations(shape, chunks):
            seen[tuple(slice(a, b) for a, b in loc)] += 1
        assert (seen == 1).all()
    assert chunk_shape((240, 160), 1024, (1, 0), (32, 32)) == (32, 32)


def test_chunks_follow_the_measured_cost(slow_scene_file):
    scene = stabmap.load_scene(slow_scene_file)
    big = resample(scene, omega=4000, m_2=4000)
    # 16 M points: the time rule decides, a chunk being a quarter of a second at the measured cost.
    assert chunk_points_for(big, 1e-4, threads=2) == 2500
    assert chunk_points_for(big, 1e-3, threads=2) == 250
    assert chunk_points_for(big, 1.0, threads=2) == MIN_CHUNK_POINTS  # never tiny chunks, however slow the points
    assert chunk_points_for(big, 1e-9, threads=2) == (64 << 20) // 400  # 64 MiB of inputs (400 bytes a point)
    dry = stabmap.example("paper-n1-fixed-dry")  # degree 2: small inputs, so the cap on points decides
    assert chunk_points_for(resample(dry, **{a.name: 4000 for a in dry.grid}), 1e-9, threads=2) == 1 << 18
    assert chunk_points_for(scene, 1e-6, threads=2) == 38400 // 16  # a small grid: at least eight chunks a thread


def test_task_size_follows_the_measured_pace():
    pace = Pace()
    assert pace.task_points(10**6, 2) == FIRST_TASK_POINTS  # nothing timed yet: a small first task
    for cost in (1e-5, 1e-2):  # a scene turns out cheap, then a region 1000x dearer (exact fallbacks, say)
        for _ in range(60):
            points = pace.task_points(10**9, 2)
            pace.record(points, points * cost)
        assert pace.task_points(10**9, 2) == pytest.approx(TASK_SECONDS / cost, rel=1e-3)
    # The end of a batch: tasks shrink so the threads finish together, down to an eighth of a full task.
    assert pace.task_points(40, 2) == 10 and pace.task_points(8, 2) == int(TASK_SECONDS / 1e-2 / 8)
    assert Pace(1e-3).task_points(10**9, 4) == pytest.approx(TASK_SECONDS / 1e-3)  # a probe's measurement


def test_probe_times_neighbouring_points_spread_over_the_grid(slow_scene_file):
    scene = stabmap.load_scene(slow_scene_file)
    values = probe_points(scene, point_order(scene))
    assert set(values) == {"omega", "m_2"} and len(values["omega"]) == 512
    assert np.isin(values["omega"], scene.grid[0].array).all() and np.isin(values["m_2"], scene.grid[1].array).all()
    assert len(np.unique(values["m_2"])) > 4  # spread over the grid ...
    assert (np.diff(values["omega"].reshape(8, 64), axis=1) > 0).all()  # ... in runs along the fastest axis
    points, seconds = probe(scene, values)
    assert 1 <= points <= 512 and seconds > 0


def test_cluster_equals_in_process(loopback, slow_scene_file, slow_local):
    ds = compute(stabmap.load_scene(slow_scene_file), client=loopback.address, progress=False, chunk_points=4096)
    _same_atlas(ds, slow_local)
    # the seconds by stage came back from the workers' processes with their results
    assert ds.attrs["stabmap_seconds_labels"] > 0 and ds.attrs["stabmap_seconds_rates"] > 0
    assert ds.attrs["stabmap_run_threads"] == 2


@pytest.mark.slow
def test_client_object_and_stream_to_zarr(loopback, slow_scene_file, slow_local, tmp_path):
    from distributed import Client

    with Client(loopback.address, set_as_default=False) as client:
        report = compute_to_file(stabmap.load_scene(slow_scene_file), tmp_path / "a.zarr", client=client, progress=False)
    assert report.computed == report.chunks and report.reused == 0
    _same_atlas(open_atlas(tmp_path / "a.zarr"), slow_local)
    assert not partial_dir(tmp_path / "a.zarr").exists()


@pytest.mark.slow
def test_cli_scheduler_and_local_workers_give_the_in_process_file(loopback, slow_scene_file, tmp_path, capsys):
    base = ["atlas", str(slow_scene_file), "-q"]
    assert cli.main(base + ["-o", str(tmp_path / "here.nc"), "--threads", "2"]) == 0
    assert cli.main(base + ["-o", str(tmp_path / "remote.nc"), "--scheduler", loopback.address]) == 0
    assert cli.main(base + ["-o", str(tmp_path / "local.nc"), "--workers", "2", "--chunk-points", "2000"]) == 0
    here = open_atlas(tmp_path / "here.nc")
    _same_atlas(open_atlas(tmp_path / "remote.nc"), here)
    _same_atlas(open_atlas(tmp_path / "local.nc"), here)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["here.nc", "local.nc", "remote.nc"]


def test_refine_and_critical_on_the_cluster_equal_in_process(loopback, tmp_path, capsys):
    """One task runner for every kind of run: adaptive atlases and critical values on the loopback cluster and on
    a local cluster give what they give in this process."""
    scene = resample(stabmap.example("paper-n2-fixed"), omega=129, K_1=65)
    here = stabmap.compute_refined(scene, coarse_stride=8, threads=2, progress=False)
    there = stabmap.compute_refined(scene, coarse_stride=8, client=loopback.address, chunk_points=512, progress=False)
    _same_atlas(there, here)
    assert int(here.attrs["n_evaluated_points"]) < scene.shape[0] * scene.shape[1] / 2  # it did refine

    scan = resample(stabmap.example("paper-n2-fixed"), omega=40, K_1=6)
    here = stabmap.critical(scan, "omega", threads=2, progress=False)
    there = stabmap.critical(scan, "omega", client=loopback.address, chunk_points=64, progress=False)
    _same_atlas(there, here)
    assert (here["n_stable_intervals"] > 0).any()

    small = tmp_path / "scan.toml"
    small.write_text(scan.to_toml())
    assert cli.main(["critical", str(small), "-o", str(tmp_path / "local.nc"), "--workers", "2", "-q"]) == 0
    assert cli.main(["atlas", str(small), "-o", str(tmp_path / "refined.nc"), "--refine", "--scheduler", loopback.address, "-q"]) == 0
    _same_atlas(open_atlas(tmp_path / "local.nc"), here)
    _same_atlas(open_atlas(tmp_path / "refined.nc"), stabmap.compute_refined(scan, threads=1, progress=False))


def _in_thread(fn):
    """Run ``fn()`` in a thread; returns the thread and a dict that gets its 'result' or 'error'."""
    out = {}

    def run():
        try:
            out["result"] = fn()
        except BaseException as exc:  # noqa: BLE001 - handed to the test thread
            out["error"] = exc

    t = threading.Thread(target=run)
    t.start()
    return t, out


def _wait_until(condition, t, out, timeout=180):
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline and t.is_alive(), out
        time.sleep(0.02)


def _finished_run(t, out):
    t.join(300)
    assert not t.is_alive(), "the run did not finish"
    assert "error" not in out, out.get("error")
    return out["result"]


@pytest.mark.slow
@pytest.mark.parametrize("nanny", [False, True], ids=["no-nanny", "nanny"])
def test_killed_worker_does_not_lose_the_atlas(nanny, tmp_path, slow_scene_file, slow_local):
    """The issue's reproduction: SIGKILL of a 'dask worker' process mid-run (with a nanny: the nanny itself)."""
    c = LoopbackCluster(tmp_path, workers=2, nanny=nanny)
    try:
        out = tmp_path / "a.nc"
        saved = partial_dir(out)
        t, result = _in_thread(lambda: compute_to_file(
            stabmap.load_scene(slow_scene_file), out, client=c.address, chunk_points=SLOW_CHUNK, progress=False
        ))
        _wait_until(lambda: len(_finished(saved)) >= 4, t, result)
        victim = c.workers[0]
        victim.send_signal(signal.SIGKILL)
        done_at_kill = len(_finished(saved))
        report = _finished_run(t, result)
        assert victim.wait(10) == -signal.SIGKILL
        assert done_at_kill < report.chunks  # the worker died with chunks still to do
        assert report.computed == report.chunks
        _same_atlas(open_atlas(out), slow_local)
    finally:
        c.close()


@pytest.mark.slow
@pytest.mark.parametrize("nanny", [False, True], ids=["no-nanny", "nanny"])
def test_late_frozen_lost_and_restarted_workers_do_not_change_the_atlas(nanny, tmp_path, slow_scene_file, slow_local):
    """A run that starts on a cluster without workers: the first worker joins during start-up, is frozen (SIGSTOP)
    mid-run, a second one joins, and the frozen one is killed (with a nanny: restarted).  The run's probe and
    default task sizes are used, so every kind of task meets the faults."""
    c = LoopbackCluster(tmp_path, workers=0, nanny=nanny, wait=False)
    try:
        out = tmp_path / "a.nc"
        saved = partial_dir(out)
        t, result = _in_thread(lambda: compute_to_file(stabmap.load_scene(slow_scene_file), out, client=c.address, progress=False))
        time.sleep(1.0)  # the run waits for a worker
        c.add_worker()
        _wait_until(lambda: len(_finished(saved)) >= 2, t, result)
        first = c.worker_pid(0)
        os.kill(first, signal.SIGSTOP)  # its tasks hang: the scheduler still counts it
        c.add_worker()
        c.wait_for(2)
        os.kill(first, signal.SIGKILL)  # now it is lost, its tasks go to the late worker (and, with a nanny, its restart)
        report = _finished_run(t, result)
        assert report.computed == report.chunks
        _same_atlas(open_atlas(out), slow_local)
    finally:
        c.close()


@pytest.mark.slow
@pytest.mark.parametrize("nanny", [False, True], ids=["no-nanny", "nanny"])
def test_worker_that_dies_during_start_up_is_not_asked_anything(nanny, tmp_path, slow_scene_file, slow_local):
    """Before this change the start-up version check went to every worker (Client.run) and failed the run with
    CommClosedError when one died meanwhile; a frozen worker made it hang.  Now no call goes to every worker."""
    c = LoopbackCluster(tmp_path, workers=2, nanny=nanny)
    try:
        victim = c.worker_pid(0)
        os.kill(victim, signal.SIGSTOP)
        threading.Timer(2.0, os.kill, (victim, signal.SIGKILL)).start()
        ds = compute(stabmap.load_scene(slow_scene_file), client=c.address, progress=False)
        _same_atlas(ds, slow_local)
    finally:
        c.close()


@pytest.mark.slow
def test_lost_scheduler_ends_the_run_and_resume_on_a_new_one_finishes_it(tmp_path, slow_scene_file, slow_local):
    out = tmp_path / "a.nc"
    saved = partial_dir(out)
    args = ["atlas", str(slow_scene_file), "-o", str(out), "--chunk-points", str(SLOW_CHUNK), "-q"]
    first = LoopbackCluster(tmp_path / "first", workers=1)
    try:
        proc = _start_cli(args + ["--scheduler", first.address])
        _wait_for_chunks(saved, proc, 3)
        first.scheduler.send_signal(signal.SIGKILL)
        _, stderr = proc.communicate(timeout=120)
    finally:
        first.close()
    assert proc.returncode == 3, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr  # one line, no traceback or log
    assert lines[0].startswith(f"stabmap: error: lost the dask scheduler at {first.address}")
    assert "--resume" in lines[0] and str(saved) in lines[0]
    done = _finished(saved)
    assert len(done) >= 3
    second = LoopbackCluster(tmp_path / "second", workers=1)
    try:
        assert cli.main(args + ["--resume", "--scheduler", second.address]) == 0
    finally:
        second.close()
    assert not saved.exists()
    _same_atlas(open_atlas(out), slow_local)


def _start_cli(args, **kw):
    # SIGINT restored to its default in the child: a test run started in the background has it ignored.
    return subprocess.Popen([sys.executable, "-m", "stabmap", *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL), **kw)


def _finished(saved) -> set[int]:
    """The chunks a run has finished so far (its checkpoint is created whole, by a rename)."""
    return Checkpoint.open(saved).done() if saved.exists() else set()


def _wait_for_chunks(saved, proc, n):
    deadline = time.monotonic() + 120
    while len(_finished(saved)) < n:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline
        time.sleep(0.02)


@pytest.mark.slow
@pytest.mark.parametrize(
    "how,where,sizing",
    [
        (signal.SIGKILL, "threads", "fixed"),
        (signal.SIGINT, "threads", "fixed"),
        (signal.SIGTERM, "threads", "fixed"),
        (signal.SIGINT, "threads", "measured"),
        (signal.SIGINT, "cluster", "measured"),
    ],
)
def test_interrupted_run_leaves_no_file_and_resume_computes_only_the_rest(
    how, where, sizing, request, tmp_path, monkeypatch, capsys
):
    size = "slow" if sizing == "fixed" else "big"
    scene_file, local = request.getfixturevalue(f"{size}_scene_file"), request.getfixturevalue(f"{size}_local")
    shape = (240, 160) if sizing == "fixed" else (240, 640)
    out = tmp_path / "a.nc"
    saved = partial_dir(out)
    args = ["atlas", str(scene_file), "-o", str(out), "-q"]
    if sizing == "fixed":
        args += ["--chunk-points", str(SLOW_CHUNK)]
    here = ["--threads", "1"]
    proc = _start_cli(args + (here if where == "threads" else ["--scheduler", request.getfixturevalue("loopback").address]))
    _wait_for_chunks(saved, proc, 3)
    before = len(_finished(saved))
    proc.send_signal(how)
    _, stderr = proc.communicate(timeout=60)
    if how == signal.SIGKILL:
        assert proc.returncode == -signal.SIGKILL
    else:  # Ctrl-C and kill: a clean stop that says how to go on
        assert proc.returncode == 130, stderr
        assert "--resume" in stderr and str(saved) in stderr
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir()] == [saved.name]  # no temporary file left beside it
    done = _finished(saved)
    chunks = Checkpoint.open(saved).chunks
    total = len(chunk_locations(shape, chunks))
    assert before <= len(done) < total
    if sizing == "fixed":
        # chunks of whole tiles of cells (stabmap.run.cells), as many along omega, the fastest axis, as fit
        assert chunks == chunk_shape((240, 160), SLOW_CHUNK, (1, 0), tile_shape(stabmap.load_scene(scene_file)))

    # Without --resume the finished work is not thrown away silently.
    assert cli.main(args + here) == 2
    assert "--resume" in capsys.readouterr().err
    # --resume computes exactly the missing chunks (counted at the task function itself), in this process.
    calls = []
    task = atlas.evaluate_blocks
    monkeypatch.setattr(atlas, "evaluate_blocks", lambda scene, locs, *rest: calls.extend(locs) or task(scene, locs, *rest))
    assert cli.main(args + here + ["--resume"]) == 0
    err = capsys.readouterr().err
    assert len(calls) == total - len(done)
    assert f"resumed: {len(done)} of {total} chunks were already done" in err
    assert not saved.exists()
    _same_atlas(open_atlas(out), local)


@pytest.mark.slow
def test_resume_refuses_another_scene_and_other_chunks(tmp_path, slow_scene_file, capsys):
    out = tmp_path / "a.nc"
    proc = _start_cli(["atlas", str(slow_scene_file), "-o", str(out), "--threads", "1", "--chunk-points", str(SLOW_CHUNK), "-q"])
    _wait_for_chunks(partial_dir(out), proc, 1)
    proc.kill()
    proc.wait()
    other = tmp_path / "other.toml"
    other.write_text(SLOW.replace("omega = 40.0", "omega = 41.0"))
    assert cli.main(["atlas", str(other), "-o", str(out), "--resume"]) == 2
    assert "different scene" in capsys.readouterr().err
    assert cli.main(["atlas", str(slow_scene_file), "-o", str(out), "--resume", "--chunk-points", "5000"]) == 2
    assert "leave chunk_points (--chunk-points) out to resume" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize(
    "extra,message",
    [
        (["--scheduler", "tcp://127.0.0.1:9", "--workers", "2"], "not both"),
        (["--workers", "0"], "--workers 0: must be a whole number >= 1"),
        (["--threads", "0"], "--threads 0: must be a whole number >= 1"),
        (["--workers", "2", "--threads", "2"], "--threads sets the threads of an in-process run"),
        (["--refine", "--resume"], "--resume applies to dense atlases"),
        (["--margin", "1"], "--margin applies to adaptive atlases only"),
        (["--chunk-points", "0"], "--chunk-points 0: must be a whole number >= 1"),
    ],
)
def test_bad_cluster_options_fail_before_any_work(extra, message, tmp_path, capsys):
    out = tmp_path / "a.nc"
    assert cli.main(["atlas", "--example", "paper-n1-fixed", "-o", str(out), *extra]) == 2
    assert message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_unreachable_scheduler_is_a_clear_error(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT", 1.0)
    assert cli.main(["atlas", "--example", "paper-n1-fixed", "-o", str(tmp_path / "a.nc"), "--scheduler", "tcp://127.0.0.1:9"]) == 2
    err = capsys.readouterr().err
    assert "cannot reach the dask scheduler at 'tcp://127.0.0.1:9'" in err
    assert list(tmp_path.iterdir()) == []
