"""Compute a stability atlas: the grid of a scene, chunked, decided by dask threads."""

from __future__ import annotations

import datetime as _dt
import os
import sys

import dask
import dask.array as da
import numpy as np
import xarray as xr
from dask.diagnostics import ProgressBar

from . import __version__
from .decide import decide
from .errors import StabmapError
from .parameters import parse_name
from .points import block_arrays, spin_axes_last
from .scene import Scene, fixed_values
from .variables import ATTRS, DECIDED_BY, N_COMPLEX_PAIRS, STABILITY, stability_from_pairs

FORMAT_VERSION = 3
REFERENCES = (
    "Yu. N. Kononov, On the motion of a system of coupled rigid bodies with cavities containing "
    "liquid (in Russian), Donetsk State University, received 22.11.1999: equations (22)-(34)"
)


def chunk_shape(shape: tuple[int, ...], workers: int, target: int | None = None) -> tuple[int, ...]:
    """Chunk sizes per axis: about ``target`` points a chunk, trailing axes kept whole first."""
    total = int(np.prod(shape, dtype=np.int64)) if shape else 1
    if target is None:
        target = int(min(32768, max(1024, total // (4 * max(1, workers)))))
    chunks = []
    budget = target
    for size in reversed(shape):
        c = max(1, min(size, budget))
        chunks.append(c)
        budget = max(1, budget // c)
    return tuple(reversed(chunks))


def _block(template, scene: Scene, block_info=None):
    location = block_info[0]["array-location"] if template.ndim else []
    order = spin_axes_last(scene)
    nc, decided_by = decide(block_arrays(scene, location, order))
    permuted = tuple(template.shape[d] for d in order)
    back = np.argsort(order)
    nc = nc.reshape(permuted).transpose(back)
    decided_by = decided_by.reshape(permuted).transpose(back)
    return np.stack([nc, decided_by.astype(np.int16)], axis=-1)


def compute(scene: Scene, *, workers: int | None = None, progress: bool | None = None, chunk_points: int | None = None) -> xr.Dataset:
    """Compute the atlas of ``scene`` as a labelled Dataset.

    Parameters
    ----------
    scene : Scene
        Bodies, support and grid; a scene without grid gives a 0-d atlas (one point).
    workers : int, optional
        Threads (default: all cores).
    progress : bool, optional
        Progress bar on stderr for runs over two seconds (default: when stderr is a terminal).
    chunk_points : int, optional
        Points per chunk (default: about 32768, fewer for small grids).
    """
    workers = workers or os.cpu_count() or 1
    if workers < 1:
        raise StabmapError(f"workers must be >= 1, got {workers}")
    shape = scene.shape
    chunks = chunk_shape(shape, workers, chunk_points)
    template = da.zeros(shape, chunks=chunks, dtype=np.int8)
    stacked = da.map_blocks(
        _block, template, scene, dtype=np.int16, new_axis=len(shape), chunks=template.chunks + ((2,),)
    )
    if progress is None:
        progress = sys.stderr.isatty()
    with dask.config.set(scheduler="threads", num_workers=workers):
        if progress:
            with ProgressBar(minimum=2.0, out=sys.stderr, dt=0.5):
                result = stacked.compute()
        else:
            result = stacked.compute()
    nc = result[..., 0].astype(np.int16)
    decided_by = result[..., 1].astype(np.int8)
    return _dataset(scene, nc, decided_by)


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


def _dataset(scene: Scene, nc: np.ndarray, decided_by: np.ndarray) -> xr.Dataset:
    dims = tuple(a.name for a in scene.grid)
    coords = coordinates(scene)
    data = {
        N_COMPLEX_PAIRS: (dims, nc, ATTRS[N_COMPLEX_PAIRS]),
        STABILITY: (dims, stability_from_pairs(nc), ATTRS[STABILITY]),
        DECIDED_BY: (dims, decided_by, ATTRS[DECIDED_BY]),
    }
    return xr.Dataset(data, coords=coords, attrs=global_attrs(scene, "stabmap atlas"))


def global_attrs(scene: Scene, kind: str) -> dict:
    """CF global attributes of every file stabmap writes, with the scene that made it."""
    now = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()
    return {
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
