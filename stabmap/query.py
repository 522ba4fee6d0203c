"""Questions asked of a saved atlas: the label at a point, what the file holds."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from .errors import StabmapError
from .variables import ATTRS, DECIDED_BY, N_COMPLEX_PAIRS, STABILITY, flag_meaning


@dataclass(frozen=True)
class Label:
    """The atlas label at the grid point nearest to a requested point."""

    requested: dict[str, float]
    grid_point: dict[str, float]
    n_complex_pairs: int
    stability: str
    decided_by: str
    outside: tuple[str, ...]  # axes on which the request lies outside the grid


def label_at(ds: xr.Dataset, **point: float) -> Label:
    """Label of the grid point nearest to ``point`` (one value per grid axis)."""
    dims = list(ds[N_COMPLEX_PAIRS].dims)
    unknown = [k for k in point if k not in dims]
    if unknown:
        raise StabmapError(f"{unknown[0]!r} is not an axis of this atlas; its axes are: {', '.join(dims) or '(none)'}")
    missing = [d for d in dims if d not in point]
    if missing:
        raise StabmapError(f"give a value for every axis; missing: {', '.join(missing)} (e.g. {missing[0]}={float(ds[missing[0]][0]):g})")
    sel = ds.sel({k: float(v) for k, v in point.items()}, method="nearest") if dims else ds
    outside = tuple(
        d for d in dims if not float(ds[d].min()) <= float(point[d]) <= float(ds[d].max())
    )
    return Label(
        requested={k: float(v) for k, v in point.items()},
        grid_point={d: float(sel[d]) for d in dims},
        n_complex_pairs=int(sel[N_COMPLEX_PAIRS]),
        stability=flag_meaning(STABILITY, int(sel[STABILITY])),
        decided_by=flag_meaning(DECIDED_BY, int(sel[DECIDED_BY])),
        outside=outside,
    )


def summary(ds: xr.Dataset) -> dict:
    """Counts that describe an atlas: points, stable fraction, N_c histogram, who decided."""
    nc = np.asarray(ds[N_COMPLEX_PAIRS]).ravel()
    by = np.asarray(ds[DECIDED_BY]).ravel()
    values, counts = np.unique(nc, return_counts=True)
    return {
        "points": int(nc.size),
        "stable": int((nc == 0).sum()),
        "degenerate": int((nc < 0).sum()),
        "stable_fraction": float((nc == 0).mean()) if nc.size else float("nan"),
        "n_complex_pairs": {int(v): int(c) for v, c in zip(values, counts)},
        "decided_by": {flag_meaning(DECIDED_BY, v): int((by == v).sum()) for v in ATTRS[DECIDED_BY]["flag_values"]},
    }
