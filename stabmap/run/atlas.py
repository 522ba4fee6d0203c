"""Compute a stability atlas: the grid of a scene, cut into chunks, decided on threads or a dask cluster.

``compute`` returns the atlas in memory.  ``compute_to_file`` writes finished
chunks into a checkpoint (``stabmap.store.checkpoint``) and then into the
netCDF or Zarr file, so the writing process never holds the whole atlas, and an
interrupted run resumes where it stopped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np


from .. import systems
from ..errors import StabmapError
from ..store.checkpoint import Checkpoint, partial_dir
from ..store.dataset import atlas_dataset, empty_arrays
from ..store.files import check_writable, write_streamed
from ..systems.base import SceneBase
from . import runner
from .chunks import check_chunk_points, chunk_locations, chunk_shape, default_chunk_points, spans
from .progress import ProgressLine, wanted
from .tasks import evaluate_block, evaluate_points


def compute(
    scene: SceneBase,
    *,
    client=None,
    workers: int | None = None,
    threads: int | None = None,
    progress: bool | None = None,
    chunk_points: int | None = None,
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
        Points per task (default: about half a second of work, see ``stabmap.run.chunks``).
    """
    chunk_points = check_chunk_points(chunk_points)
    with runner.start(client, workers=workers, threads=threads, announce=wanted(progress)) as run:
        arrays = decide_grid(run, scene, progress=progress, chunk_points=chunk_points)
    return atlas_dataset(systems.of(scene), scene, arrays)


def decide_grid(run: runner.Runner, scene: SceneBase, *, progress: bool | None = None, chunk_points: int | None = None) -> dict:
    """Every variable on the whole grid of ``scene`` (numpy arrays), decided by ``run``'s threads or cluster."""
    arrays = empty_arrays(systems.of(scene), scene)

    def keep(i, block):
        where = tuple(slice(a, b) for a, b in layout.locations[i])
        for k, v in block.items():
            arrays[k][where] = v

    with _Layout(run, scene, progress, chunk_points) as layout:
        layout.run(list(range(len(layout.locations))), keep)
    return arrays


def decide_points(run: runner.Runner, scene: SceneBase, values: dict[str, np.ndarray], *, chunk_points: int | None = None,
                  on_progress=None) -> dict[str, np.ndarray]:
    """Every variable at points given by equal-length 1-D arrays of grid-axis values, in tasks on ``run``.

    ``on_progress(points_done)`` is called as tasks finish (refinement's progress line).
    """
    npts = len(next(iter(values.values())))
    bounds = spans(npts, chunk_points or default_chunk_points(scene, run.threads, npts))
    out = {}
    done = [0]

    def keep(i, result):
        a, b = bounds[i]
        for k, v in result.items():
            out.setdefault(k, np.empty((npts,) + v.shape[1:], dtype=v.dtype))[a:b] = v
        done[0] += b - a
        if on_progress is not None:
            on_progress(done[0])

    args = [(scene, {k: v[a:b] for k, v in values.items()}) for a, b in bounds]
    run.run(evaluate_points, args, list(range(len(bounds))), keep)
    return out


@dataclass
class FileReport:
    """What ``compute_to_file`` did: chunks computed now and reused from an interrupted run."""

    path: Path
    chunks: int
    computed: int
    reused: int


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
    """
    path = check_writable(path)
    where = partial_dir(path)
    system = systems.of(scene)
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
    chunk_points = check_chunk_points(chunk_points)
    with runner.start(client, workers=workers, threads=threads, announce=wanted(progress)) as run, _Layout(
        run, scene, progress, chunk_points, checkpoint
    ) as layout:
        if checkpoint is None:
            checkpoint = Checkpoint.create(where, system, scene, layout.chunks)
        done = checkpoint.done()
        todo = [i for i in range(len(layout.locations)) if i not in done]
        layout.done_before = len(done)
        try:
            layout.run(todo, lambda i, block: checkpoint.save(i, layout.locations[i], block))
        except (StabmapError, KeyboardInterrupt):
            raise
        except Exception as exc:
            raise StabmapError(
                f"the run failed ({type(exc).__name__}: {exc}); {len(checkpoint.done())} of {len(layout.locations)} chunks are "
                f"saved in {str(where)!r}; fix the cause and run again with --resume"
            ) from exc
    arrays, store = checkpoint.arrays()
    with store:
        write_streamed(atlas_dataset(system, scene, arrays), path)
    checkpoint.remove()
    return FileReport(path, len(layout.locations), len(todo), len(done))


class _Layout:
    """The blocks of one run's grid (a resumed run keeps its checkpoint's), where their tasks go, and the run's
    progress line (closed on leaving the ``with``)."""

    def __init__(self, run: runner.Runner, scene, progress, chunk_points: int | None, checkpoint: Checkpoint | None = None):
        if checkpoint is not None:
            chunks = checkpoint.chunks
            if chunk_points is not None and chunk_shape(scene.shape, chunk_points) != chunks:
                raise StabmapError(
                    f"chunk_points {chunk_points} gives other chunks than the interrupted run's {list(chunks)}; "
                    "leave chunk_points (--chunk-points) out to resume"
                )
        else:
            chunks = chunk_shape(scene.shape, chunk_points or default_chunk_points(scene, run.threads))
        self.scene, self.runner, self.chunks = scene, run, chunks
        self.locations = chunk_locations(scene.shape, chunks)
        self.progress = ProgressLine(wanted(progress))
        self.done_before = 0

    def __enter__(self) -> _Layout:
        return self

    def __exit__(self, *exc) -> None:
        self.progress.close()

    def run(self, todo: list[int], on_result) -> None:
        total, per = len(self.locations), max(1, math.prod(self.chunks))
        finished = [0]

        def handle(i, block):
            on_result(i, block)
            finished[0] += 1
            done = self.done_before + finished[0]
            rate = finished[0] / max(self.progress.elapsed, 1e-9)
            eta = (len(todo) - finished[0]) / rate if rate else float("nan")
            self.progress.show(
                f"[atlas] {done:,}/{total:,} chunks of ~{per:,} points | {self.progress.elapsed:.0f} s, "
                f"about {eta:.0f} s to go"
            )

        args = [(self.scene, location) for location in self.locations]
        self.runner.run(evaluate_block, args, todo, handle)


__all__ = ["FileReport", "compute", "compute_to_file", "decide_grid", "decide_points"]
