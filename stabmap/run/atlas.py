"""Compute a stability atlas: the grid of a scene, cut into chunks, decided on threads or a dask cluster.

``compute`` returns the atlas in memory.  ``compute_to_file`` writes finished
chunks into a checkpoint (``stabmap.store.checkpoint``) and then into the
netCDF or Zarr file, so the writing process never holds the whole atlas, and an
interrupted run resumes where it stopped.  Both keep the seconds the run spent,
by stage, in the atlas's attributes (``stabmap.run.costs``).
"""

from __future__ import annotations

import math
import sys
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import systems
from ..errors import StabmapError
from ..store.checkpoint import Checkpoint, partial_dir
from ..store.dataset import empty_arrays, finished_atlas
from ..store.files import check_writable, write_streamed
from ..systems.base import SceneBase
from . import cells, costs, runner, sizes
from .chunks import (
    BLOCK_SECONDS,
    CELL_BLOCK_SECONDS,
    MIN_CHUNK_POINTS,
    check_chunk_points,
    chunk_locations,
    chunk_points_for,
    chunk_shape,
    probe_points,
    tile_locations,
)
from .progress import ProgressLine, Rate, wanted
from .tasks import evaluate_blocks, evaluate_points, point_order, probe, probe_tiles, prove_boxes


def compute(
    scene: SceneBase,
    *,
    client=None,
    workers: int | None = None,
    threads: int | None = None,
    progress: bool | None = None,
    chunk_points: int | None = None,
    prove_cells: bool = True,
):
    """Compute the atlas of ``scene`` as a labelled Dataset (in memory).

    Parameters
    ----------
    scene : a scene of any system (``stabmap.load_scene``, ``stabmap.example``)
        Its grid is the atlas's; a scene without grid gives a 0-d atlas (one point).
    client : dask.distributed.Client or str, optional
        Run the chunks on this cluster (a Client, or a scheduler address such as
        ``"tcp://10.0.0.5:8786"``).  Default: threads in this process.
    workers : int, optional
        Run the chunks on a local cluster of this many worker processes, started for the run.
    threads : int, optional
        Threads of an in-process run (default: all cores).
    progress : bool, optional
        Progress line on stderr for runs over two seconds (default: when stderr is a terminal).
    chunk_points : int, optional
        Points per chunk of the grid and per task (default: chunks of about an eighth of a second of work, as
        timed by a probe, and tasks of several chunks, about half a second each; see ``stabmap.run.chunks``).
    prove_cells : bool
        Decide the grid cell by cell (default): boxes proved first, nodes computed only where no box proves, and
        the ``cell`` variable saying what is proved about each cell (``stabmap.run.cells``).  False: every node
        computed on its own, every cell ``node_only``.

    The atlas's attributes ``stabmap_seconds_*`` keep the seconds of the run by stage (``stabmap.run.costs``);
    with the progress line, a run whose optional stage (growth rates) cost more than its labels ends with a note
    that says so, and how the scene skips it.
    """
    t0 = time.perf_counter()
    chunk_points = check_chunk_points(chunk_points)
    system = systems.of(scene)
    sizes.check_memory(sizes.of(scene))
    with runner.start(client, workers=workers, threads=threads, announce=wanted(progress)) as run:
        spent = costs.Costs(run, costs.columns(system), t0)
        arrays = decide_grid(run, scene, progress=progress, chunk_points=chunk_points, prove_cells=prove_cells)
    seconds = spent.take()
    del seconds[costs.WRITE]  # nothing written: a file written from the Dataset says nothing of its writing
    ds = finished_atlas(system, scene, arrays)
    ds.attrs.update(costs.attrs(seconds, run.most_threads))
    tell(costs.note(system, scene, seconds), progress)
    return ds


def tell(note: str | None, progress: bool | None) -> None:
    """``note`` on stderr, after the progress line, where the run shows one."""
    if note is not None and wanted(progress):
        print(note, file=sys.stderr)


def decide_grid(run: runner.Runner, scene: SceneBase, *, progress: bool | None = None, chunk_points: int | None = None,
                prove_cells: bool = True) -> dict:
    """Every variable on the whole grid of ``scene`` (numpy arrays), decided by ``run``'s threads or cluster."""
    arrays = empty_arrays(systems.of(scene), scene)

    def keep(i, block):
        where = tuple(slice(a, b) for a, b in layout.locations[i])
        for k, v in block.items():
            arrays[k][where] = v

    with _Layout(run, scene, progress, chunk_points, prove_cells=prove_cells) as layout:
        layout.run(list(range(len(layout.locations))), keep)
    return arrays


def decide_points(run: runner.Runner, scene: SceneBase, values: dict[str, np.ndarray], *, chunk_points: int | None = None,
                  on_progress=None) -> dict[str, np.ndarray]:
    """Every variable at points given by equal-length 1-D arrays of grid-axis values, in tasks on ``run``.

    Tasks hold ``chunk_points`` points each, or (default) as many as ``run``'s measured pace puts in about half a
    second.  ``on_progress(points_done)`` is called as tasks finish (refinement's progress line).
    """
    npts = len(next(iter(values.values())))
    out: dict = {}
    done = [0]

    def keep(bounds, result):
        a, b = bounds
        for k, v in result.items():
            out.setdefault(k, np.empty((npts,) + v.shape[1:], dtype=v.dtype))[a:b] = v
        done[0] += b - a
        if on_progress is not None:
            on_progress(done[0])

    run.run(evaluate_points, scene, _Points(values, npts, chunk_points), keep)
    return out


def decide_boxes(run: runner.Runner, scene: SceneBase, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray], *,
                 chunk_points: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(label, proved) of boxes with corners ``lower`` and ``upper`` (``System.prove_boxes``), in tasks on ``run``.

    A scene whose system proves boxes along none of its axes (``System.box_axes``) answers without a task.
    """
    system = systems.of(scene)
    npts = len(next(iter(lower.values())))
    label = system.variable(system.label)
    out = {"label": np.full(npts, label.fill, dtype=label.dtype), "proved": np.zeros(npts, dtype=bool)}

    def keep(bounds, result):
        a, b = bounds
        for k, v in result.items():
            out[k][a:b] = v

    if npts and system.box_axes(scene):
        run.run(prove_boxes, scene, _Boxes(lower, upper, npts, chunk_points), keep)
    return out["label"], out["proved"]


class _Points:
    """A list of points, handed out as runs of consecutive points (``chunk_points`` each, or as asked)."""

    def __init__(self, values: dict[str, np.ndarray], npts: int, fixed: int | None):
        self.values, self.fixed, self.start, self.remaining = values, fixed, 0, npts

    def take(self, points: int):
        a = self.start
        b = a + min(self.remaining, max(1, self.fixed or points))
        self.start, self.remaining = b, self.remaining - (b - a)
        return ({k: v[a:b] for k, v in self.values.items()},), (a, b), b - a


class _Boxes(_Points):
    """A list of boxes (their two corners), handed out as runs of consecutive boxes."""

    def __init__(self, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray], npts: int, fixed: int | None):
        super().__init__(lower, npts, fixed)
        self.upper = upper

    def take(self, points: int):
        (lower,), (a, b), n = super().take(points)
        return (lower, {k: v[a:b] for k, v in self.upper.items()}), (a, b), n


class _Chunks:
    """Chunks of the grid, handed out as tasks of one chunk or (``batch``) of as many as fit the points asked."""

    def __init__(self, locations: list, todo: list[int], batch: bool, prove_cells: bool):
        self.locations, self.batch, self.prove_cells = locations, batch, prove_cells
        self.size = {i: math.prod(b - a for a, b in locations[i]) for i in todo}
        self.queue = deque(todo)
        self.remaining = sum(self.size.values())

    def take(self, points: int):
        chunks = [self.queue.popleft()]
        n = self.size[chunks[0]]
        while self.batch and self.queue and n + self.size[self.queue[0]] <= points:
            chunks.append(self.queue.popleft())
            n += self.size[chunks[-1]]
        self.remaining -= n
        return ([self.locations[i] for i in chunks], self.prove_cells), chunks, n


class _Once:
    """One task (the probe)."""

    def __init__(self, *args):
        self.args, self.remaining = args, 1

    def take(self, points: int):
        self.remaining = 0
        return self.args, None, 0


@dataclass
class FileReport:
    """What ``compute_to_file`` did: chunks computed now and reused from an interrupted run, the seconds by stage
    that the file keeps (``stabmap.run.costs``), and ``note``: the line that says an optional stage cost more than
    the labels, and how to skip it (None otherwise)."""

    path: Path
    chunks: int
    computed: int
    reused: int
    seconds: dict[str, float] = field(default_factory=dict)
    note: str | None = None


def compute_to_file(
    scene: SceneBase,
    path: str | Path,
    *,
    client=None,
    workers: int | None = None,
    threads: int | None = None,
    progress: bool | None = None,
    chunk_points: int | None = None,
    resume: bool = False,
    prove_cells: bool = True,
    note: bool | None = None,
) -> FileReport:
    """Compute the atlas of ``scene`` straight into ``path`` (``.nc``: netCDF4; ``.zarr``: Zarr).

    Finished chunks go to the checkpoint ``PATH.partial/`` as they arrive and the
    file is written from there chunk by chunk, then renamed into place: memory
    stays bounded by a few chunks whatever the size of the atlas, and ``path`` is
    either complete or absent.  If the run is interrupted, ``resume=True``
    computes only the chunks not yet in ``PATH.partial/`` and gives the same file.

    Parameters are those of ``compute``, and
    resume : bool
        Finish the interrupted run of the same scene saved in ``PATH.partial/``
        (start afresh if there is none).  Without it, an existing
        ``PATH.partial/`` is an error, so that no finished work is thrown away unasked.
    prove_cells : bool
        As for ``compute``; a resumed run keeps the interrupted run's choice.
    note : bool, optional
        Print ``FileReport.note`` on stderr at the end (default: where the progress line is shown); a caller that
        prints more after the run (the CLI) prints it last itself.

    The file's attributes ``stabmap_seconds_*`` keep the seconds of the run by stage; a resumed run adds those
    that the interrupted run's saved chunks kept (``stabmap.run.costs``).
    """
    t0 = time.perf_counter()
    path = check_writable(path)
    where = partial_dir(path)
    system = systems.of(scene)
    size = sizes.of(scene)
    sizes.check_disk(size, path)
    checkpoint = None
    if where.exists():
        if not resume:
            raise StabmapError(
                f"an interrupted run of this output is saved in {str(where)!r}; add --resume (resume=True) to finish it, "
                f"or delete {str(where)!r} to start over"
            )
        checkpoint = Checkpoint.open(where)
        if checkpoint.scene_toml != scene.to_toml():
            raise StabmapError(
                f"the interrupted run in {str(where)!r} was computed from a different scene; give the same scene to "
                f"resume it, or delete {str(where)!r} to start over"
            )
        prove_cells = checkpoint.prove_cells
    chunk_points = check_chunk_points(chunk_points)
    said = wanted(progress) and sizes.worth_saying(size)
    if said:  # at once: a large grid's checkpoint alone takes a while to create
        print(f"[atlas] {size.text()}; timing a probe", file=sys.stderr)
    try:
        with runner.start(client, workers=workers, threads=threads, announce=wanted(progress)) as run, _Layout(
            run, scene, progress, chunk_points, checkpoint, prove_cells, said=said
        ) as layout:
            spent = costs.Costs(run, costs.columns(system), t0)
            resumed = checkpoint is not None
            if checkpoint is None:
                checkpoint = Checkpoint.create(where, system, scene, layout.chunks, prove_cells, costs.columns(system))
            done = checkpoint.done()
            todo = [i for i in range(len(layout.locations)) if i not in done]

            def save(i, block):
                row = spent.take()  # the seconds since the last save, kept with this chunk for a resumed run
                with spent.writing():
                    checkpoint.save(i, layout.locations[i], block, row)

            try:
                layout.run(todo, save)
            except (StabmapError, KeyboardInterrupt):
                raise
            except Exception as exc:
                raise StabmapError(
                    f"the run failed ({type(exc).__name__}: {exc}); {len(checkpoint.done())} of {len(layout.locations)} "
                    f"chunks are saved in {str(where)!r}; fix the cause and run again with --resume"
                ) from exc
    except runner.SchedulerLost as exc:
        if checkpoint is None:
            raise runner.SchedulerLost(f"{exc}; nothing was saved yet: run the same command again on a working cluster") from None
        raise runner.SchedulerLost(
            f"{exc}; {len(checkpoint.done()):,} of {len(chunk_locations(checkpoint.shape, checkpoint.chunks)):,} chunks are saved "
            f"in {str(where)!r}: start a scheduler and workers and run the same command with --resume (and the new --scheduler ADDRESS)"
        ) from None
    before = checkpoint.seconds(done)  # what the interrupted run's saved chunks kept (None: untimed)
    timed = costs.RESUMED_ONLY if resumed and before is None else costs.RESUMED if resumed else costs.WHOLE
    seconds: dict[str, float] = {}

    def late_attrs() -> dict:  # once the data are written: the writing's seconds are known
        spent.take()
        seconds.update(costs.added(before or {}, spent.spent))
        return costs.attrs(seconds, run.most_threads, timed)

    arrays, store = checkpoint.arrays()
    with store, spent.writing():
        write_streamed(finished_atlas(system, scene, arrays), path, late_attrs)
    checkpoint.remove()
    report = FileReport(path, len(layout.locations), len(todo), len(done), seconds, costs.note(system, scene, seconds))
    tell(report.note, progress if note is None else note)
    return report


def _tiles(shape: tuple[int, ...], tile: tuple[int, ...]) -> int:
    """How many tiles cover a grid of ``shape``."""
    return math.prod(-(-n // t) for n, t in zip(shape, tile, strict=True))


class _Layout:
    """The chunks of one run's grid (a resumed run keeps its checkpoint's), where their tasks go, and the run's
    progress line (closed on leaving the ``with``).

    Without a checkpoint or ``chunk_points``, a probe task first times a few hundred points spread over the grid
    (``stabmap.run.tasks.probe``): the chunks hold about BLOCK_SECONDS of work at that pace, and tasks of several
    chunks about TASK_SECONDS, resized as tasks finish.  A large run (``stabmap.run.sizes.worth_saying``) says the time
    the probe predicts before it starts (and its size, unless ``said`` already); one whose chunks need no probe is
    probed for that alone.
    """

    def __init__(self, run: runner.Runner, scene, progress, chunk_points: int | None, checkpoint: Checkpoint | None = None,
                 prove_cells: bool = True, said: bool = False):
        self.scene, self.runner, self.prove_cells = scene, run, prove_cells
        self.progress = ProgressLine(wanted(progress))
        self.progress.redraw = lambda: self._show(self._rate)
        self._rate: Rate | None = None
        self.total = math.prod(scene.shape)
        self.cost: float | None = None  # seconds a point on one thread, once a probe has timed some
        self.timed = 0  # the points (or tiles' points) the probe timed
        self.done_before = 0  # points finished by an earlier, interrupted run
        self.batch = chunk_points is None
        order = point_order(scene)
        tile = cells.tile_shape(scene) if prove_cells and cells.provable(scene) else None  # chunks of whole tiles
        if checkpoint is not None:
            chunks = checkpoint.chunks
            if chunk_points is not None and chunk_shape(scene.shape, chunk_points, order, tile) != chunks:
                raise StabmapError(
                    f"chunk_points {chunk_points} gives other chunks than the interrupted run's {list(chunks)}; "
                    "leave chunk_points (--chunk-points) out to resume"
                )
        elif chunk_points is not None:
            chunks = chunk_shape(scene.shape, chunk_points, order, tile)
        elif self.total // (8 * run.slots()) <= MIN_CHUNK_POINTS or (tile is not None and _tiles(scene.shape, tile) <= 8 * run.slots()):
            # a small grid, or one of few tiles (a chunk holds at least one): balance decides, not time
            chunks = chunk_shape(scene.shape, chunk_points_for(scene, 0.0, run.slots()), order, tile)
        else:
            try:
                seconds = BLOCK_SECONDS if tile is None else CELL_BLOCK_SECONDS
                chunks = chunk_shape(scene.shape, chunk_points_for(scene, self._probe(tile), run.slots(), seconds=seconds), order, tile)
            except BaseException:
                self.progress.close()
                raise
        self.chunks = chunks
        self.locations = chunk_locations(scene.shape, chunks)
        try:
            self._say_size(tile, said)
        except BaseException:
            self.progress.close()
            raise

    def _say_size(self, tile: tuple[int, ...] | None, said: bool) -> None:
        """The size and the predicted time of a large run, on stderr where the progress line is shown."""
        if not self.progress.enabled:
            return
        size = sizes.of(self.scene)
        if said and self.cost is None:
            self._probe(tile)  # for the estimate alone: the chunks were chosen without it
        if self.cost is None:
            return
        threads = self.runner.slots()
        if said or sizes.worth_saying(size, self.total * self.cost / threads):
            estimate = sizes.estimate(size, self.cost, threads, self.timed)
            self.progress.say(f"[atlas] {estimate}" if said else f"[atlas] {size.text()}; {estimate}")

    def __enter__(self) -> _Layout:
        return self

    def __exit__(self, *exc) -> None:
        self.progress.close()

    def _show(self, rate: Rate | None = None) -> None:
        where = f" | {self.runner.workers} workers, {self.runner.threads} threads" if self.runner.client is not None else ""
        if rate is None or rate.done == self.done_before:
            doing = self.progress.note or "starting (loading kernels)"
            text = f"{rate.text() if rate else f'0/{self.total:,} points'} | {self.progress.elapsed:.0f} s, {doing}"
        else:
            text = f"{rate.text()} | {self.progress.elapsed:.0f} s"
        self.progress.show(f"[atlas] {text}{where}")

    def _probe(self, tile: tuple[int, ...] | None) -> float:
        """Seconds per point, timed on the probe's points (on the runner: a worker, or a thread here); on whole tiles
        where ``tile`` is given (an atlas decided cell by cell)."""
        measured: list = []  # (points, seconds) of the one probe task
        task: Callable
        job: dict | list
        if tile is None:
            task, job = probe, probe_points(self.scene, point_order(self.scene))
        else:
            task, job = probe_tiles, tile_locations(self.scene.shape, tile)
        self.runner.run(task, self.scene, _Once(job), lambda _, r: measured.append(r), self._show)
        points, seconds = measured[0]
        cost = seconds / max(1, points)
        self.runner.pace = runner.Pace(cost)
        self.cost, self.timed = cost, points
        return cost

    def run(self, todo: list[int], on_result) -> None:
        """Decide the chunks ``todo`` (indices into ``locations``), in a shuffled order so that the rate measured
        on the first chunks holds for the whole grid; ``on_result(i, block)`` as each chunk arrives."""
        sizes = [math.prod(b - a for a, b in loc) for loc in self.locations]
        self.done_before = self.total - sum(sizes[i] for i in todo)
        rate = self._rate = Rate(self.total, self.done_before)
        order = [todo[k] for k in np.random.default_rng(0).permutation(len(todo))]

        def handle(chunks, blocks):
            for i, block in zip(chunks, blocks, strict=True):
                on_result(i, block)
            rate.add(sum(sizes[i] for i in chunks))
            self._show(rate)

        self.runner.run(evaluate_blocks, self.scene, _Chunks(self.locations, order, self.batch, self.prove_cells), handle,
                        lambda: self._show(rate))


__all__ = ["FileReport", "compute", "compute_to_file", "decide_boxes", "decide_grid", "decide_points"]
