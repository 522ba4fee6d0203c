"""``stabmap.write_atlas``: an atlas, or a part of one (``ds.sel(...)``, ``ds.isel(...)``) with its own scene.

An atlas carries the scene that made it (global attribute ``scene``).  A part of it still carries the whole
grid, so that scene would no longer reproduce the file; :func:`scene_attrs` gives the scene on the part's own
grid instead: an axis cut by a slice or a list of values keeps those values, and an axis fixed at one value
(``ds.sel(omega=42.0)``, a scalar coordinate now) becomes a one-value axis.  What the scene chose from its
whole grid (a cavity's ``modes = "auto"``) is kept (``SceneBase.with_grid``), so the part's scene decides each
of its points as the whole atlas did.  (``store.files.write_atlas`` writes a Dataset as it is; it cannot call
this module, which reads scenes, without an import cycle: reading a scene file asks ``store.files`` what it is.)
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
import xarray as xr

from ..errors import StabmapError
from ..scene.grid import Axis, parse_axes
from ..scene.text import parse
from ..scene.values import Parameter
from ..store import files
from ..store.dataset import is_critical
from ..systems import loads_scene


def write_atlas(ds: xr.Dataset, path: str | Path) -> Path:
    """Write ``ds`` to ``path`` (netCDF4 ``.nc`` or Zarr ``.zarr``) atomically, as ``store.files.write_atlas``; a
    part of an atlas with its stored scene rewritten to the part's grid (:func:`scene_attrs`)."""
    return files.write_atlas(ds.assign_attrs(scene_attrs(ds)), path)


def scene_attrs(ds: xr.Dataset) -> dict:
    """The global attributes to change so that ``ds``'s stored scene reproduces its grid: ``{}`` when it does already
    (a whole atlas, critical values, a file without a scene); else ``scene`` rewritten and a ``history`` line."""
    text = ds.attrs.get("scene")
    if text is None or is_critical(ds):
        return {}
    # The grid alone first (a stored scene holds plain numbers): a whole atlas is written without validating its
    # scene again, which for a cavity chooses its modes over the grid (0.4 s for the bundled cavity example).
    stored = parse_axes(parse(str(text), "the atlas's scene").get("grid", {}), lambda name: Parameter("", "", ""))
    if all(a.name in ds.coords and np.array_equal(np.atleast_1d(ds[a.name].values), a.array) for a in stored):
        return {}
    scene = loads_scene(str(text), "the atlas's scene")
    grid, cut = [], []
    for axis in scene.grid:
        if axis.name not in ds.coords:
            raise StabmapError(
                f"cannot write this part of an atlas: its grid axis {axis.name!r} was dropped, so its stored scene could "
                f"not say where its points lie; select {axis.name} with .sel or .isel (a value keeps it as a coordinate) "
                "rather than dropping it"
            )
        values = np.atleast_1d(np.asarray(ds[axis.name].values, dtype=np.float64))
        if values.ndim != 1:
            raise StabmapError(f"cannot write this part of an atlas: its coordinate {axis.name!r} is no longer a grid axis (shape {values.shape})")
        if np.array_equal(values, axis.array):
            grid.append(axis)
            continue
        try:
            grid.append(Axis(axis.name, tuple(float(v) for v in values), axis.scale, axis.display_units, axis.discrete))
        except StabmapError as exc:
            raise StabmapError(f"cannot write this part of an atlas: {exc}; select values in grid order, each once") from None
        cut.append(axis.name)
    if not cut:
        return {}
    now = dt.datetime.now(dt.UTC).replace(microsecond=0).isoformat()
    history = str(ds.attrs.get("history", "")).rstrip("\n")
    line = f"{now} part of an atlas: scene grid rewritten to the part along {', '.join(cut)}"
    return {"scene": scene.with_grid(tuple(grid)).to_toml(), "history": f"{history}\n{line}" if history else line}
