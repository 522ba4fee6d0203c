"""Boundaries and smallest stable values located to 1e-10 and complete: critical values of the lines a query asks.

``query.boundaries`` and ``query.smallest_stable`` read the grid: a change is bracketed by two grid values, and
one hidden between two agreeing values is not seen.  The functions here answer the same questions from the
atlas's own scene, with ``stabmap.run.critical`` along each selected line: every change in the scanned range,
however narrow, located to ``rtol``, and the stretches no proof decided listed as undecided gaps (docs/critical.md).
The answers have the layout of the grid ones (the same report prints them), with ``located = 1``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import xarray as xr

from .. import systems
from ..errors import StabmapError, given
from ..scene.grid import Axis
from . import shown
from .query import check_axis, fixed_coords, fixed_names, grid_axes, select, selection_text, stable_system

RTOL = 1e-10


def _critical(ds: xr.Dataset, along: str, sel: dict, progress: bool | None, threads: int | None, nearest_edge: bool = False):
    """Critical values along ``along`` of the lines ``sel`` selects: (Dataset with the other axes' dims, axes)."""
    from ..run.critical import critical

    if "scene" not in ds.attrs:
        raise StabmapError("this atlas holds no scene (attribute 'scene'), so its boundaries cannot be located; use the grid answer")
    sub, axes = select(ds, sel, along=along, nearest_edge=nearest_edge)
    scene = systems.loads_scene(str(ds.attrs["scene"]), "the atlas's scene")
    grid = []
    for axis in scene.grid:
        values = np.atleast_1d(np.asarray(sub[axis.name].values, dtype=np.float64))
        grid.append(Axis(axis.name, tuple(float(v) for v in values), "values" if values.size != len(axis.values) else axis.scale,
                         discrete=axis.discrete))
    line = dataclasses.replace(scene, grid=tuple(grid))
    crit = critical(line, along, rtol=RTOL, progress=progress, threads=threads)
    fixed = [d for d in grid_axes(ds) if d != along and axes[d].fixed]
    return crit.isel(dict.fromkeys(fixed, 0)), sub, axes


def _attrs(ds, crit, along: str, axes, kind: str, label, system) -> dict:
    units = str(ds[along].attrs.get("units", ""))
    x = np.asarray(axes[along].values, dtype=np.float64)
    gaps = int(np.sum(crit["n_undecided"].values))
    return {
        "title": ds.attrs.get("title", ""), "stabmap_query": kind, "label": label.name, "label_symbol": system.label_symbol,
        "label_fill": label.fill, "along": along, "along_units": units, "along_display_units": shown.display_unit(ds, along),
        "along_range": [float(x.min()), float(x.max())],
        "along_grid_values": int(x.size), "selection": selection_text(axes),
        "fixed_axes": fixed_names(axes), "located": 1, "n_undecided": gaps,
        "located_by": f"located to {RTOL:g} relative by critical values of the atlas's scene (docs/critical.md)",
    }


def located_boundaries(ds: xr.Dataset, along: str | None = None, /, *, progress: bool | None = None, threads: int | None = None,
                       nearest_edge: bool = False, **sel) -> xr.Dataset:
    """Every change of the label along ``along`` in the selected lines, located to 1e-10 and complete.

    As ``query.boundaries`` (same variables and coordinates, one row per boundary), but ``boundary_lower`` and
    ``boundary_upper`` bracket the change to 1e-10 relative, and a change between two grid values with equal
    labels is found too.  ``undecided_lower``/``undecided_upper`` (dimension ``gap``) list the stretches no proof
    decided: a change may hide only there.
    """
    dims = grid_axes(ds)
    along = check_axis(ds, along, dims)  # None: the system's default_axis
    system = systems.of_atlas(ds.attrs)
    label = system.variable(system.label)
    crit, sub, axes = _critical(ds, along, sel, progress, threads, nearest_edge)
    others = [d for d in crit["boundary_lower"].dims if d not in ("boundary",)]
    table = crit[["boundary_lower", "boundary_upper", f"{label.name}_below", f"{label.name}_above"]]
    table = table.stack(row=others + ["boundary"]) if others else table.rename({"boundary": "row"})
    keep = np.isfinite(table["boundary_lower"].values)
    coords = {d: ("boundary", table[d].values[keep], dict(ds[d].attrs)) for d in others}
    coords.update(fixed_coords(sub, axes))
    units = str(ds[along].attrs.get("units", ""))
    out = xr.Dataset(
        {
            "boundary_lower": ("boundary", table["boundary_lower"].values[keep], {"long_name": f"{along} just below the change", "units": units}),
            "boundary_upper": ("boundary", table["boundary_upper"].values[keep], {"long_name": f"{along} just above the change", "units": units}),
            f"{label.name}_below": ("boundary", table[f"{label.name}_below"].values[keep], {"units": "1"}),
            f"{label.name}_above": ("boundary", table[f"{label.name}_above"].values[keep], {"units": "1"}),
            "inferred_below": ("boundary", np.zeros(int(keep.sum()), dtype=bool)),
            "inferred_above": ("boundary", np.zeros(int(keep.sum()), dtype=bool)),
        },
        coords=coords,
    )
    gaps = crit[["undecided_lower", "undecided_upper"]]
    gaps = gaps.stack(g=others + ["gap"]) if others else gaps.rename({"gap": "g"})
    open_ = np.isfinite(gaps["undecided_lower"].values)
    for name, end in (("undecided_lower", "start"), ("undecided_upper", "end")):
        out[name] = ("gap", gaps[name].values[open_], {"units": units, "long_name": f"{end} of a stretch of {along} not decided"})
    for d in others:
        out.coords[f"gap_{d}"] = ("gap", gaps[d].values[open_], dict(ds[d].attrs))
    lines = int(np.prod([crit.sizes[d] for d in others])) if others else 1
    with_boundary = int(np.sum(np.isfinite(crit["boundary_lower"].values).reshape(lines, -1).any(axis=1)))
    out.attrs = {**_attrs(ds, crit, along, axes, "boundaries", label, system), "n_lines": lines, "n_lines_with_boundary": with_boundary,
                 "comment": (f"every change of {label.name} along {along} in the selection, located to {RTOL:g} relative "
                             "(critical values); the list is complete outside the undecided gaps listed")}
    return out


def located_smallest_stable(ds: xr.Dataset, /, along: str | None = None, over: str | None = None, *, progress: bool | None = None,
                            threads: int | None = None, nearest_edge: bool = False, **sel) -> xr.Dataset:
    """The smallest stable value of ``along`` on each selected line, located to 1e-10 (``query.smallest_stable``'s
    layout): ``smallest_stable`` is the lower end of the first stable interval, ``unstable_below`` the value just
    below it, and ``undecided_below`` True where a stretch below it is not decided (a smaller stable value may
    lie there)."""
    dims = grid_axes(ds)
    along = check_axis(ds, along, dims)
    system = stable_system(ds, "smallest_stable")
    label = system.variable(system.label)
    if over is not None:
        over = check_axis(ds, over, dims, "over")
        extra = [d for d in dims if d not in (along, over) and d not in sel]
        if extra:
            raise StabmapError(f"{given('over', over)}: fix the other axes as well ({', '.join(f'{d}=...' for d in extra)})")
    crit, sub, axes = _critical(ds, along, sel, progress, threads, nearest_edge)
    others = list(crit["n_stable_intervals"].dims)
    lower = crit[f"{along}_stable_lower"].isel(interval=0).values
    outer = crit[f"{along}_stable_lower_outer"].isel(interval=0).values
    upper_outer = crit[f"{along}_stable_upper_outer"].isel(interval=0).values
    n_int = crit["n_stable_intervals"].values
    has = n_int > 0
    # the label just below the first stable interval: the boundary whose upper end is its lower end
    bu, below_label = crit["boundary_upper"].values, crit[f"{label.name}_below"].values
    match = np.isclose(bu, lower[..., None], rtol=0, atol=0) & np.isfinite(bu)
    nb = np.where(match.any(axis=-1), np.take_along_axis(below_label, match.argmax(axis=-1)[..., None], axis=-1)[..., 0], label.fill)
    gl = crit["undecided_lower"].values
    undecided_below = np.any(np.isfinite(gl) & (gl < np.where(has, lower, np.inf)[..., None]), axis=-1)
    units = str(ds[along].attrs.get("units", ""))

    def var(values, long_name, **attrs):
        return (others, values, {"long_name": long_name, **attrs})

    coords = {d: (d, crit[d].values, dict(ds[d].attrs)) for d in others}
    coords.update(fixed_coords(sub, axes))
    out = xr.Dataset(
        {
            "smallest_stable": var(np.where(has, lower, np.nan), f"smallest stable {along}", units=units),
            "unstable_below": var(np.where(has, outer, np.nan), f"{along} just below it, not stable", units=units),
            f"{label.name}_below": var(np.where(has, nb, label.fill).astype(label.dtype), f"{label.name} just below smallest_stable", units="1"),
            "stable_to_scan_end": var(has & (n_int == 1) & np.isnan(upper_outer), "stable from smallest_stable to the end of the range"),
            "undecided_below": var(undecided_below, "a stretch below smallest_stable is not decided (critical values' gaps)"),
            "inferred": var(np.zeros(lower.shape, dtype=bool), "not computed (never, here)"),
            "inferred_below": var(np.zeros(lower.shape, dtype=bool), "not computed (never, here)"),
        },
        coords=coords,
    )
    out.attrs = {**_attrs(ds, crit, along, axes, "smallest_stable", label, system),
                 "comment": (f"smallest_stable is the lower end of the first stable interval of {along}, located to "
                             f"{RTOL:g} relative (critical values): stable just above it, unstable just below "
                             "(unstable_below); where undecided_below is true a stretch below it was not decided")}
    return out


__all__ = ["located_boundaries", "located_smallest_stable"]
