"""The finished chunks of a run, kept in a Zarr store beside the output, so an interrupted run resumes.

``atlas.nc`` is computed into the Zarr store ``atlas.nc.partial/``, which xarray
creates with the atlas's coordinates, attributes and empty variables, chunked
like the tasks (``to_zarr(compute=False)``).  Each finished task is written into
its region of the store's arrays, and then its flag in ``chunk_done`` (through
Zarr's arrays rather than ``to_zarr(region=...)``, which opens and checks the
store anew at every call: 3-6 ms a chunk against 15, BENCHMARKS.md).  Zarr
writes every chunk by an atomic rename, so a run killed at any instant leaves
whole chunks, and a chunk counts as finished only once its flag is set: resuming
computes the chunks whose flag is not.  The store itself is created under a
temporary name and renamed into place, so it is complete or absent.  The final
file is written from it chunk by chunk (bounded memory), and then it is deleted.

Each chunk also keeps, in ``chunk_seconds``, the seconds the run spent since
the chunk saved before it (work by stage, writing, wall clock:
``stabmap.run.costs``), written before its flag: the rows of the finished
chunks add up to what the run cost so far, so a resumed run's atlas reports
the interrupted run's time too.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np

from ..errors import StabmapError
from .dataset import atlas_dataset

FORMAT = 4  # 1: .npy files and a manifest.json (stabmap 0.1 before the Zarr checkpoint); 2: Zarr; 3: cell, prove_cells; 4: seconds
READS = (3, FORMAT)  # a checkpoint of format 3 resumes, its chunks untimed
DONE = "chunk_done"
SECONDS = "chunk_seconds"  # (chunk, stage): the seconds each chunk's save closed (stabmap.run.costs.Costs.take)


def partial_dir(output: str | Path) -> Path:
    output = Path(output)
    return output.with_name(output.name + ".partial")


class Checkpoint:
    """Finished chunks of one atlas run: the scene (TOML), the grid's shape and the chunk sizes fix its layout."""

    def __init__(self, path: Path, scene_toml: str, shape: tuple[int, ...], chunks: tuple[int, ...], dims: dict[str, tuple],
                 prove_cells: bool = True, stages: tuple[str, ...] = ()):
        self.path, self.scene_toml, self.prove_cells = Path(path), scene_toml, prove_cells
        self.shape, self.chunks = tuple(shape), tuple(chunks)
        self.dims = dims  # the dimensions of every variable, the grid's first
        self.stages = tuple(stages)  # the columns of SECONDS; () for a checkpoint of format 3, which has none
        self._arrays: dict | None = None  # the store's arrays, opened at the first save (Zarr region writes)

    @classmethod
    def create(cls, path: Path, system, scene, chunks: tuple[int, ...], prove_cells: bool = True,
               stages: tuple[str, ...] = ()) -> Checkpoint:
        """A new, empty checkpoint for ``scene`` cut into ``chunks``, created atomically at ``path``; ``prove_cells``:
        how its chunks are decided (``stabmap.run.atlas.compute``), kept for a resumed run; ``stages``: the names of
        the seconds each chunk keeps (``save``)."""
        import dask.array as da

        nchunks = int(np.prod([-(-n // c) for n, c in zip(scene.shape, chunks, strict=True)], dtype=np.int64))
        extra = system.dims(scene)
        lazy = {}
        for v in system.atlas_outputs(scene):
            sizes = tuple(extra[d] for d in v.dims)
            lazy[v.name] = da.zeros(scene.shape + sizes, chunks=tuple(chunks) + sizes, dtype=v.dtype)
        ds = atlas_dataset(system, scene, lazy)
        ds[DONE] = ("chunk", da.zeros((nchunks,), chunks=1, dtype=np.int8))
        if stages:
            ds[SECONDS] = (("chunk", "stage"), da.zeros((nchunks, len(stages)), chunks=(1, len(stages)), dtype=np.float64))
        ds.attrs.update({"stabmap_checkpoint_format": FORMAT, "stabmap_checkpoint_shape": list(scene.shape),
                         "stabmap_checkpoint_chunks": list(chunks), "stabmap_checkpoint_prove_cells": int(prove_cells),
                         "stabmap_checkpoint_stages": list(stages)})
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        try:
            ds.to_zarr(tmp, mode="w-", compute=False, consolidated=False)
            os.replace(tmp, path)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        return cls.open(path)

    @classmethod
    def open(cls, path: Path) -> Checkpoint:
        """The checkpoint at ``path``; a StabmapError if it is not one this version can resume."""
        import xarray as xr

        if (path / "manifest.json").exists():
            raise StabmapError(
                f"{str(path)!r} was saved by an older stabmap (chunk files and a manifest, before Zarr checkpoints) and "
                "cannot be resumed by this one; delete it and run again"
            )
        try:
            with xr.open_zarr(path, consolidated=False) as ds:
                a = ds.attrs
                if a.get("stabmap_checkpoint_format") not in READS:
                    raise ValueError(f"format {a.get('stabmap_checkpoint_format')!r}, expected one of {list(READS)}")
                dims = {k: ds[k].dims for k in ds.data_vars if k not in (DONE, SECONDS)}
                return cls(path, a["scene"], tuple(a["stabmap_checkpoint_shape"]), tuple(a["stabmap_checkpoint_chunks"]), dims,
                           bool(a["stabmap_checkpoint_prove_cells"]), tuple(a.get("stabmap_checkpoint_stages", ())))
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise StabmapError(f"{str(path)!r} is not a readable partial stabmap run ({exc}); delete it to start over") from None

    def done(self) -> set[int]:
        """The chunks (C order of the chunk grid) whose every variable is written."""
        import xarray as xr

        with xr.open_zarr(self.path, consolidated=False) as ds:
            return set(np.flatnonzero(ds[DONE].values == 1).tolist())

    def save(self, index: int, location: tuple[tuple[int, int], ...], block: dict[str, np.ndarray],
             seconds: dict[str, float] | None = None) -> None:
        """Write chunk ``index``, the grid region ``location`` ((start, stop) per axis), and the ``seconds`` it closes
        (by the names of ``stages``), then mark it finished."""
        arrays = self._arrays
        if arrays is None:
            import zarr

            group = zarr.open_group(str(self.path), mode="r+")
            arrays = self._arrays = {name: group[name] for name in [*self.dims, DONE, *([SECONDS] if self.stages else [])]}
        region = tuple(slice(a, b) for a, b in location)
        for name, values in block.items():
            arrays[name][region] = values
        if seconds is not None and self.stages:
            arrays[SECONDS][index, :] = np.array([seconds.get(k, 0.0) for k in self.stages])
        arrays[DONE][index] = 1

    def seconds(self, chunks: set[int]) -> dict[str, float] | None:
        """The seconds the rows of ``chunks`` (finished ones) add up to, by name; None for a checkpoint without
        them (format 3)."""
        if not self.stages:
            return None
        if not chunks:
            return dict.fromkeys(self.stages, 0.0)
        import zarr

        rows = zarr.open_group(str(self.path), mode="r")[SECONDS].get_orthogonal_selection((sorted(chunks), slice(None)))
        return dict(zip(self.stages, np.asarray(rows).sum(axis=0).tolist(), strict=True))

    def arrays(self):
        """Every variable as a dask array read chunk by chunk, and the open Dataset to close after use."""
        import xarray as xr

        ds = xr.open_zarr(self.path, consolidated=False)
        return {k: ds[k].data for k in self.dims}, ds

    def remove(self) -> None:
        shutil.rmtree(self.path, ignore_errors=True)
