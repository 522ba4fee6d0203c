"""Counts that describe a whole atlas, read chunk by chunk when the atlas is lazy (any size, bounded memory)."""

from __future__ import annotations

import numpy as np
import xarray as xr

from .. import systems
from ..errors import StabmapError
from ..store.dataset import edges, is_critical
from ..store.variables import CELL
from .headline import Headline


def _counts(values) -> dict[int, int]:
    """How often each value occurs; a dask array is counted chunk by chunk (:func:`stabmap.read.blocks.counts`)."""
    from .blocks import counts

    return counts(values)


def summary(ds: xr.Dataset) -> dict:
    """Points, the stable fraction, a histogram of the label and of who decided.

    A critical-values Dataset (``stabmap critical``) gets its own counts instead, per line of its other axes:
    :func:`stabmap.read.table.critical_summary`.

    Keys: ``points``, ``stable``, ``degenerate`` (label < 0, but for ``absent`` and ``undecided``), ``absent`` (the
    system's ``absent_label``: nothing to decide there), ``undecided`` (its ``undecided_label``: not proved),
    ``stable_fraction``, the label's name (a
    histogram, e.g. ``n_complex_pairs``) and the provenance variable's name (counts by flag meaning, e.g.
    ``decided_by``).  An atlas with cells (``stabmap.run.cells``) adds ``cell`` (counts by flag meaning) and
    ``cell_volume`` (each meaning's share of the scanned region, cells weighted by their size).  ``headline``: the
    sentence that sums it all up (:mod:`stabmap.read.headline`), as ``stabmap info`` and figure titles print it.
    """
    if is_critical(ds):  # its own counts: intervals, boundaries, gaps per line
        from .table import critical_summary

        return critical_summary(ds)
    system = systems.of_atlas(ds.attrs)
    if system.label not in ds:
        raise StabmapError(f"this Dataset is not a stabmap atlas or critical-values file (no {system.label}); "
                           "open one with stabmap.open_atlas(PATH)")
    label = _counts(ds[system.label].data)
    points = sum(label.values())
    stable = label.get(system.stable_label, 0) if system.stable_label is not None else 0
    out = {
        "points": points,
        "stable": stable,
        "degenerate": sum(c for v, c in label.items() if v < 0 and v not in (system.absent_label, system.undecided_label)),
        "absent": label.get(system.absent_label, 0) if system.absent_label is not None else 0,
        "undecided": label.get(system.undecided_label, 0) if system.undecided_label is not None else 0,
        "stable_fraction": stable / points if points else float("nan"),
        system.label: dict(sorted(label.items())),
    }
    if system.provenance is not None and system.provenance in ds:
        flags = system.variable(system.provenance)
        by = _counts(ds[system.provenance].data)
        out[system.provenance] = {m: by.get(v, 0) for v, m in flags.flags}
    if CELL.name in ds:
        cells = _counts(ds[CELL.name].data)
        out[CELL.name] = {m: cells.get(v, 0) for v, m in CELL.flags}
        out["cell_volume"] = volume_shares(ds)
    if "growth_rate" in ds:
        out["growth_rate"] = growth_rates(ds, system)
    out["headline"] = headline(ds, out).text(system)
    return out


def headline(ds: xr.Dataset, s: dict) -> Headline:
    """What the headline of the whole atlas says (:mod:`stabmap.read.headline`), from its :func:`summary` ``s``."""
    system = systems.of_atlas(ds.attrs)
    cells, shares = s.get(CELL.name), s.get("cell_volume")
    return Headline(
        points=s["points"], stable=s["stable"] if system.stable_label is not None else None,
        inferred=cells["not_proved"] if cells else 0, undecided=s["undecided"],
        whole=shares["whole_cell"] if shares else None, change=shares["contains_change"] if shares else 0.0,
        axes=scanned_axes(ds, ds[system.label].dims),
    )


def growth_rates(ds: xr.Dataset, system) -> dict:
    """The largest growth rate of the atlas with its proved upper bound, and how the rates were obtained (counts by
    ``growth_rate_method``'s meanings); NaN points (inferred, degenerate) are left out of the maxima.  The rate's
    variables are written together (``System.outputs``)."""
    import dask.array as da

    from .blocks import as_dask, compute

    top, top_upper = compute(*(da.nanmax(as_dask(ds[k].data)) for k in ("growth_rate", "growth_rate_upper")))
    if "growth_rate_method" not in ds:  # a system whose provenance says how the rates were proved (viscous)
        return {"max": float(top), "max_upper": float(top_upper), "method": {}}
    by = _counts(ds["growth_rate_method"].data)
    return {"max": float(top), "max_upper": float(top_upper),
            "method": {m: by.get(v, 0) for v, m in system.variable("growth_rate_method").flags}}


def cell_sizes(ds: xr.Dataset, dim: str) -> np.ndarray:
    """The widths of the grid cells along ``dim``: from its CF bounds variable when the atlas has one (the cells its
    labels are proved on), else the midpoints between its values (``stabmap.store.dataset.edges``).

    An axis whose cells all have width 0 weighs 1 per value: an axis of one value (it then weighs nothing), and a
    discrete axis (a list of cases, bounds with both edges at the value), whose cases shares then average over.
    """
    w = _widths(ds, dim)
    return w if np.any(w > 0) else np.ones(ds[dim].size)


def _widths(ds: xr.Dataset, dim: str) -> np.ndarray:
    name = ds[dim].attrs.get("bounds", f"{dim}_bounds")
    if name in ds.variables and ds[name].ndim == 2 and ds[name].dims[0] == dim:
        b = np.asarray(ds[name].values, dtype=np.float64)
        return np.abs(b[:, 1] - b[:, 0])
    return np.abs(np.diff(edges(ds[dim].values)))


def scanned_axes(ds: xr.Dataset, dims) -> int:
    """How many of ``dims`` span the region that cells tile: cells of some width (not one value, not a list of cases)."""
    return sum(1 for d in dims if np.any(_widths(ds, d) > 0))


def volume_shares(ds: xr.Dataset) -> dict[str, float]:
    """Each ``cell`` meaning's share of the scanned region (cells weighted by their size), chunk by chunk."""
    import dask.array as da

    from .blocks import as_dask, compute

    cell = as_dask(ds[CELL.name].data)
    weight = da.ones((), dtype=np.float64)
    total = 1.0
    for axis, dim in enumerate(ds[CELL.name].dims):
        w = cell_sizes(ds, dim)
        total *= float(w.sum())
        shape = [1] * cell.ndim
        shape[axis] = -1
        weight = weight * da.from_array(w, chunks=(cell.chunks[axis],)).reshape(shape)
    sums = compute(*(da.where(cell == v, weight, 0.0).sum() for v, _ in CELL.flags))
    return {m: float(x) / total if total else float("nan") for (_, m), x in zip(CELL.flags, sums, strict=True)}
