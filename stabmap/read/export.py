"""A whole atlas as CSV, one row per grid point: ``stabmap query ATLAS --csv -o atlas.csv``.

Columns: the grid axes (SI, the units in the header as in the tables of critical values: ``omega [rad s-1]``; a
spin-rate axis with a display unit gets a second column in it, ``omega [rpm]``), the derived quantities
(``S_g``), the label, and where the atlas stores them the stability, the cell flag (as their meanings) and the
growth rate.  The atlas is read a slab of its first axis at a time, about a lazy chunk's worth of points
(``stabmap.store.files.READ_CHUNK_POINTS``), and each slab is written before the next is read: memory stays
bounded whatever the size of the atlas.  A file is written to a temporary name and renamed once complete.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import TextIO

import numpy as np
import pandas as pd
import xarray as xr

from .. import systems
from ..store.files import READ_CHUNK_POINTS, atomic_text
from . import derived, shown
from .blocks import compute
from .query import grid_axes

OPTIONAL = ("stability", "cell", "growth_rate")  # written where the atlas stores them, after the label


def columns(ds: xr.Dataset) -> list[str]:
    """The variables written, after the axes and derived quantities: the label, then those of OPTIONAL stored."""
    system = systems.of_atlas(ds.attrs)
    return [system.label, *(k for k in OPTIONAL if k in ds.data_vars and k != system.label)]


def _header(ds: xr.Dataset, name: str) -> str:
    units = shown.stored_units(ds, name) if "flag_values" not in ds[name].attrs else ""
    return f"{name} [{units}]" if units else name


def write_csv(ds: xr.Dataset, out: TextIO, *, points: int = READ_CHUNK_POINTS) -> int:
    """Write every grid point of the atlas ``ds`` to ``out`` as CSV, a slab of the first axis at a time; the rows written."""
    axes = grid_axes(ds)
    extra = derived.names(ds, axes)
    names = columns(ds)
    system = systems.of_atlas(ds.attrs)
    meanings = {k: dict(system.variable(k).flags) for k in names if k in {v.name for v in system.atlas_variables}
                and system.variable(k).flags}
    header = []
    for d in axes:
        header.append(_header(ds, d))
        if shown.display_unit(ds, d):
            header.append(f"{d} [{shown.display_unit(ds, d)}]")
    header += [_header(ds, k) for k in extra] + [_header(ds, k) for k in names]
    out.write(",".join(header) + "\n")
    slabs: Iterable[xr.Dataset] = [ds]
    if axes:
        rest = int(np.prod([ds.sizes[d] for d in axes[1:]], dtype=np.int64)) if len(axes) > 1 else 1
        step = max(1, points // max(rest, 1))
        slabs = (ds.isel({axes[0]: slice(i, i + step)}) for i in range(0, ds.sizes[axes[0]], step))
    rows = 0
    for slab in slabs:
        values = compute(*(slab[k].transpose(*axes) for k in names))
        shape = values[0].shape
        frame: dict[str, np.ndarray] = {}
        grids = np.meshgrid(*(np.asarray(slab[d].values, dtype=np.float64) for d in axes), indexing="ij") if axes else []
        for d, g in zip(axes, grids, strict=True):
            frame[_header(ds, d)] = g.ravel()
            unit = shown.display_unit(ds, d)
            if unit:
                frame[f"{d} [{unit}]"] = shown.in_display(g.ravel(), unit)
        for k in extra:
            frame[_header(ds, k)] = np.broadcast_to(_spread(slab, k, axes), shape).ravel()
        for k, v in zip(names, values, strict=True):
            flat = np.asarray(v.values).ravel()
            frame[_header(ds, k)] = pd.Series(flat).map(meanings[k]).to_numpy() if k in meanings else flat
        table = pd.DataFrame(frame, columns=header)
        table.to_csv(out, header=False, index=False, lineterminator="\n", na_rep="", float_format=None)
        rows += len(table)
    return rows


def _spread(slab: xr.Dataset, name: str, axes: list[str]) -> np.ndarray:
    """A derived quantity over some axes, broadcast over all of them in their order."""
    c = compute(slab[name])[0]
    return np.asarray(c.expand_dims([d for d in axes if d not in c.dims]).transpose(*axes).values, dtype=np.float64)


def save_csv(ds: xr.Dataset, path: str | Path) -> tuple[Path, int]:
    """:func:`write_csv` to ``path`` atomically (``store.files.atomic_text``): (path, rows)."""
    with atomic_text(path, newline="") as f:
        rows = write_csv(ds, f)
    return Path(path), rows
