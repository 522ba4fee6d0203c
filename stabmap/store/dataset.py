"""An atlas as a labelled Dataset: the grid axes and fixed parameters as CF coordinates, every variable
with its declared attributes, and global attributes that carry the scene that made it."""

from __future__ import annotations

import datetime as dt

import numpy as np
import xarray as xr

from ..version import __version__

BOUNDS_DIM = "bnds"  # the CF bounds variables' second dimension: a cell's two edges
# 4: stabmap_system; every variable of the system written as declared; 5: cell and axis bounds; 6: discrete axes (bounds
# equal to the value)
FORMAT_VERSION = 6
CRITICAL_KIND = "critical values"  # the global attribute stabmap_kind of every critical-values Dataset


def is_critical(ds) -> bool:
    """Whether ``ds`` holds critical values (``stabmap.run.critical``) rather than an atlas."""
    return ds.attrs.get("stabmap_kind") == CRITICAL_KIND


def edges(values) -> np.ndarray:
    """The edges of an axis's grid cells (one more than its values): midpoints between neighbouring values, the
    first and last values outside, so the cells tile the scanned interval.  One value: a cell of width 0."""
    values = np.asarray(values, dtype=np.float64)
    out = np.empty(values.size + 1)
    out[0], out[-1] = values[0], values[-1]
    out[1:-1] = 0.5 * values[:-1] + 0.5 * values[1:]
    return out


def bounds(values, discrete: bool = False) -> np.ndarray:
    """CF bounds of an axis, shape (len, 2): each grid cell's two edges, in the axis's order; along a discrete axis
    (separate cases, ``Axis.discrete``) both edges are the value itself, so no cell spans two cases."""
    if discrete:
        values = np.asarray(values, dtype=np.float64)
        return np.column_stack([values, values])
    e = edges(values)
    return np.column_stack([e[:-1], e[1:]])


def coordinates(system, scene, skip: tuple[str, ...] = ()) -> dict:
    """The grid axes (except ``skip``) with their cells' CF bounds, and every fixed parameter, as CF coordinates."""
    coords = {}
    for axis in scene.grid:
        if axis.name in skip:
            continue
        info = system.parameter(scene, axis.name)
        name = f"{axis.name}_bounds"
        attrs = {"units": info.units, "long_name": info.long_name, "scale": axis.scale, "bounds": name}
        if axis.display_units:  # the unit the scene gave (rpm, Hz): values stay SI, readers may show them in it
            attrs["display_units"] = axis.display_units
        coords[axis.name] = (axis.name, axis.array, attrs)
        what = "the value itself (a discrete axis: separate cases)" if axis.discrete else "midpoints between grid values"
        # CF 7.1: a bounds variable is part of its coordinate's metadata; it takes the coordinate's units and names,
        # and any long_name or units of its own must equal the coordinate's, so it carries only a comment.
        coords[name] = ((axis.name, BOUNDS_DIM), bounds(axis.array, bool(axis.discrete)),
                        {"comment": f"edges of the grid cells along {axis.name} ({what}), in the units of {axis.name}"})
    for key, value in system.fixed_values(scene).items():
        info = system.parameter(scene, key)
        coords[key] = ((), np.float64(value), {"units": info.units, "long_name": info.long_name})
    for key, (dims, values, attrs) in system.derived_coords(scene).items():  # a moved quantity replaces its fixed value
        coords.pop(key, None)
        if not set(dims) & set(skip):
            coords[key] = (dims, values, attrs)
    return coords


def global_attrs(system, scene, kind: str) -> dict:
    """CF global attributes of every file stabmap writes, with the scene that made it."""
    now = dt.datetime.now(dt.UTC).replace(microsecond=0).isoformat()
    return {
        "Conventions": "CF-1.10",
        "title": scene.title or kind,
        "source": f"stabmap {__version__}",
        "history": f"{now} computed by stabmap {__version__}",
        "references": system.references,
        "stabmap_format_version": FORMAT_VERSION,
        "stabmap_system": system.name,
        **system.attrs(scene),
        "scene": scene.to_toml(),
    }


def atlas_dataset(system, scene, arrays: dict) -> xr.Dataset:
    """The atlas Dataset of ``scene`` from one array (numpy or dask) per declared variable, in grid shape."""
    dims = tuple(a.name for a in scene.grid)
    data = {v.name: (dims + v.dims, arrays[v.name], v.attrs()) for v in system.atlas_outputs(scene)}
    coords = coordinates(system, scene)
    coords.update({d: (d, values, attrs) for d, (values, attrs) in system.dim_coords(scene).items()})
    return xr.Dataset(data, coords=coords, attrs=global_attrs(system, scene, "stabmap atlas"))


def finished_atlas(system, scene, arrays: dict) -> xr.Dataset:
    """``atlas_dataset`` once every point is computed, with what the system derives from whole lines of the grid
    (``System.finish``)."""
    return system.finish(scene, atlas_dataset(system, scene, arrays))


def empty_arrays(system, scene, shape: tuple[int, ...] | None = None) -> dict[str, np.ndarray]:
    """Uninitialised arrays of every variable for ``shape`` (default: the grid's)."""
    shape = scene.shape if shape is None else shape
    extra = system.dims(scene)
    return {v.name: np.empty(shape + tuple(extra[d] for d in v.dims), dtype=v.dtype) for v in system.atlas_outputs(scene)}
