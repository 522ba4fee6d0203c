"""Compute a stability atlas: the grid of a scene, cut into chunks, decided on threads or a dask cluster.

``compute`` returns the atlas in memory.  ``compute_to_file`` streams finished
chunks to disk (``partial``) and then into the netCDF or Zarr file, so the
writing process never holds the whole atlas, and an interrupted run resumes
where it stopped.
"""

from __future__ import annotations

import datetime as _dt
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr

from . import __version__
from .chunks import atlas_chunk, check_chunk_points, chunk_locations, chunk_shape, default_chunk_points
from .cluster import check_threads, cluster_threads, connect, run_tasks
from .errors import StabmapError
from .parameters import parse_name
from .partial import PartialRun, partial_dir
from .progress import ProgressLine
from .scene import Scene, fixed_values
from .variables import ATTRS, DECIDED_BY, N_COMPLEX_PAIRS, STABILITY, stability_from_pairs

FORMAT_VERSION = 3
REFERENCES = (
    "Yu. N. Kononov, On the motion of a system of coupled rigid bodies with cavities containing "
    "liquid (in Russian), Donetsk State University, received 22.11.1999: equations (22)-(34)"
)


def compute(
    scene: Scene,
    *,
    client=None,
    threads: int | None = None,
    progress: bool | None = None,
    chunk_points: int | None = None,
) -> xr.Dataset:
    """Compute the atlas of ``scene`` as a labelled Dataset (in memory).

    Parameters
    ----------
    scene : Scene
        Bodies, support and grid; a scene without grid gives a 0-d atlas (one point).
    client : dask.distributed.Client or str, optional
        Run the chunks on this cluster (a Client, or a scheduler address such as
        ``"tcp://10.0.0.5:8786"``).  Default: threads in this process.
    threads : int, optional
        Threads of an in-process run (default: all cores); ignored with ``client``.
    progress : bool, optional
        Progress line on stderr for runs over two seconds (default: when stderr is a terminal).
    chunk_points : int, optional
        Points per task (default: about half a second of work, see ``stabmap.chunks``).
    """
    shape = scene.shape
    nc = np.empty(shape, dtype=np.int16)
    decided_by = np.empty(shape, dtype=np.int8)

    def keep(i, block):
        where = tuple(slice(a, b) for a, b in locations[i])
        nc[where], decided_by[where] = block[0], block[1]

    with _Run(scene, client, threads, progress, chunk_points) as run:
        locations = run.locations
        run.run(list(range(len(locations))), keep)
    return _dataset(scene, nc, decided_by)


@dataclass
class FileReport:
    """What ``compute_to_file`` did: chunks computed now and reused from an interrupted run, and the atlas' counts."""

    path: Path
    chunks: int
    computed: int
    reused: int
    counts: dict = field(default_factory=dict)


def compute_to_file(
    scene: Scene,
    path: str | Path,
    *,
    client=None,
    threads: int | None = None,
    progress: bool | None = None,
    chunk_points: int | None = None,
    resume: bool = False,
) -> FileReport:
    """Compute the atlas of ``scene`` straight into ``path`` (``.nc``: netCDF4; ``.zarr``: Zarr).

    Finished chunks go to ``PATH.partial/`` as they arrive and the file is
    written from there chunk by chunk, then renamed into place: memory stays
    bounded by a few chunks whatever the size of the atlas, and ``path`` is
    either complete or absent.  If the run is interrupted, ``resume=True``
    computes only the chunks not yet in ``PATH.partial/`` and gives the same file.

    Parameters are those of ``compute``, and
    resume : bool
        Finish the interrupted run of the same scene saved in ``PATH.partial/``
        (start afresh if there is none).  Without it, an existing
        ``PATH.partial/`` is an error, so that no finished work is thrown away unasked.
    """
    from .io import check_writable, write_streamed

    path = check_writable(path)
    where = partial_dir(path)
    scene_toml = scene.to_toml()
    partial = None
    if where.exists():
        if not resume:
            raise StabmapError(
                f"an interrupted run of this output is saved in {str(where)!r}; add --resume (resume=True) to finish it, "
                f"or delete {str(where)!r} to start over"
            )
        partial = PartialRun.open(where)
        if partial.scene_toml != scene_toml:
            raise StabmapError(
                f"the interrupted run in {str(where)!r} was computed from a different scene; give the same scene to "
                f"resume it, or delete {str(where)!r} to start over"
            )
    with _Run(scene, client, threads, progress, chunk_points, partial) as run:
        if partial is None:
            partial = PartialRun.create(where, scene_toml, scene.shape, run.chunks)
        done = partial.done()
        todo = [i for i in range(len(run.locations)) if i not in done]
        run.done_before = len(done)
        try:
            run.run(todo, partial.save)
        except (StabmapError, KeyboardInterrupt):
            raise
        except Exception as exc:
            raise StabmapError(
                f"the run failed ({type(exc).__name__}: {exc}); {len(partial.done())} of {len(run.locations)} chunks are "
                f"saved in {str(where)!r}; fix the cause and run again with --resume"
            ) from exc
    counts = write_streamed(scene, partial, run.locations, path)
    partial.remove()
    return FileReport(path, len(run.locations), len(todo), len(done), counts)


class _Run:
    """The chunk layout of one run, where its tasks go, and its progress line."""

    def __init__(self, scene, client, threads, progress, chunk_points, partial: PartialRun | None = None):
        self.scene, self.client_arg, self.partial = scene, client, partial
        self.threads = check_threads(threads)
        self.chunk_points = check_chunk_points(chunk_points)
        self.progress = ProgressLine(sys.stderr.isatty() if progress is None else progress)
        self.done_before = 0

    def __enter__(self):
        self._connection = connect(self.client_arg)
        self.client = self._connection.__enter__()
        try:
            if self.client is not None:
                self.threads = cluster_threads(self.client)
                if self.progress.enabled:
                    workers = len(self.client.nthreads())
                    print(
                        f"[atlas] on the dask cluster at {self.client.scheduler.address}: {workers} workers, "
                        f"{self.threads} threads; dashboard {self.client.dashboard_link}",
                        file=sys.stderr,
                    )
            self._layout()
        except BaseException:
            self.__exit__(*sys.exc_info())
            raise
        return self

    def __exit__(self, *exc):
        self.progress.close()
        return self._connection.__exit__(*exc)

    def _layout(self):
        shape = self.scene.shape
        if self.partial is not None:
            self.chunks = self.partial.chunks
            if self.chunk_points is not None and chunk_shape(shape, self.chunk_points) != self.chunks:
                raise StabmapError(
                    f"chunk_points {self.chunk_points} gives other chunks than the interrupted run's {list(self.chunks)}; "
                    "leave chunk_points (--chunk-points) out to resume"
                )
        else:
            points = self.chunk_points or default_chunk_points(self.scene, self.threads)
            self.chunks = chunk_shape(shape, points)
        self.locations = chunk_locations(shape, self.chunks)

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
        run_tasks(atlas_chunk, args, todo, handle, client=self.client, threads=self.threads)


def coordinates(scene: Scene, skip: tuple[str, ...] = ()) -> dict:
    """The grid axes (except ``skip``) and every fixed parameter as CF coordinates with units."""
    coords = {}
    for axis in scene.grid:
        if axis.name in skip:
            continue
        name = parse_name(axis.name, scene.n, scene.support)
        coords[axis.name] = (axis.name, axis.array, {"units": name.units, "long_name": name.long_name, "scale": axis.scale})
    for key, value in fixed_values(scene).items():
        name = parse_name(key, scene.n, scene.support)
        coords[key] = ((), np.float64(value), {"units": name.units, "long_name": name.long_name})
    return coords


def _dataset(scene: Scene, nc: np.ndarray, decided_by: np.ndarray, stability: np.ndarray | None = None) -> xr.Dataset:
    dims = tuple(a.name for a in scene.grid)
    coords = coordinates(scene)
    data = {
        N_COMPLEX_PAIRS: (dims, nc, ATTRS[N_COMPLEX_PAIRS]),
        STABILITY: (dims, stability_from_pairs(nc) if stability is None else stability, ATTRS[STABILITY]),
        DECIDED_BY: (dims, decided_by, ATTRS[DECIDED_BY]),
    }
    return xr.Dataset(data, coords=coords, attrs=global_attrs(scene, "stabmap atlas"))


def global_attrs(scene: Scene, kind: str) -> dict:
    """CF global attributes of every file stabmap writes, with the scene that made it."""
    now = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()
    attrs = {
        "Conventions": "CF-1.10",
        "title": scene.title or kind,
        "source": f"stabmap {__version__}",
        "history": f"{now} computed by stabmap {__version__}",
        "references": REFERENCES,
        "stabmap_format_version": FORMAT_VERSION,
        "support": scene.support,
        "n_bodies": scene.n,
        "polynomial_degree_bound": scene.degree,
        "scene": scene.to_toml(),
    }
    if scene.topology is not None:
        attrs["topology_parent"] = np.array(scene.topology.parent, dtype=np.int32)
    return attrs
