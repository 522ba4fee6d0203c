"""Pictures of an atlas: a 2-D map of the number of complex root pairs with the stability boundary."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import xarray as xr

from .errors import StabmapError
from .io import check_writable
from .variables import N_COMPLEX_PAIRS

# Okabe-Ito, colour-blind safe; stable gets the calm blue, unstable counts get warm colours.
_STABLE = "#56B4E9"
_UNSTABLE = ["#F0E442", "#E69F00", "#D55E00", "#CC79A7", "#882255", "#44AA99", "#999933", "#332288"]
_DEGENERATE = "#BBBBBB"


def _axis_label(ds: xr.Dataset, dim: str) -> str:
    units = ds[dim].attrs.get("units", "")
    return f"{dim} [{units}]" if units else dim


def select(ds: xr.Dataset, sel: dict[str, float], keep: int = 2) -> tuple[xr.Dataset, dict[str, float]]:
    """Reduce ``ds`` to ``keep`` axes by nearest selection; unselected extra axes take their first value."""
    dims = list(ds[N_COMPLEX_PAIRS].dims)
    for k in sel:
        if k not in dims:
            raise StabmapError(f"--sel {k}: not an axis of this atlas; its axes are: {', '.join(dims)}")
    chosen = dict(sel)
    free_dims = [d for d in dims if d not in chosen]
    for d in free_dims[keep:]:
        chosen[d] = float(ds[d][0])
    if not chosen:
        return ds, {}
    out = ds.sel(chosen, method="nearest")
    return out, {d: float(out[d]) for d in chosen}


def plot_atlas(ds: xr.Dataset, path: str | Path, *, x: str | None = None, y: str | None = None, sel: dict[str, float] | None = None) -> Path:
    """Draw ``ds`` (2-D map, or a strip for a 1-D atlas) to PNG or PDF at ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    path = check_writable(path)
    if path.suffix.lower() not in (".png", ".pdf"):
        raise StabmapError(f"plot file {str(path)!r}: use a .png or .pdf name")
    sub, fixed = select(ds, sel or {})
    nc = sub[N_COMPLEX_PAIRS]
    dims = list(nc.dims)
    if len(dims) == 0:
        raise StabmapError("this atlas has no axis to plot (a single point); use 'stabmap info' or 'stabmap query'")
    if x is not None or y is not None:
        for name in (x, y):
            if name is not None and name not in dims:
                raise StabmapError(f"--x/--y {name}: not a remaining axis; choose from {', '.join(dims)}")
    if len(dims) == 2:
        xd = x or (y and next(d for d in dims if d != y)) or dims[0]
        yd = y or next(d for d in dims if d != xd)
        nc = nc.transpose(yd, xd)
    else:
        xd, yd = dims[0], None
    values = np.asarray(nc)
    top = max(1, int(values.max()))
    colours = [_DEGENERATE, _STABLE] + [_UNSTABLE[(i - 1) % len(_UNSTABLE)] for i in range(1, top + 1)]
    cmap = ListedColormap(colours)
    norm = BoundaryNorm(np.arange(-1.5, top + 1.5), cmap.N)
    fig, ax = plt.subplots(figsize=(7.5, 5.5), constrained_layout=True)
    xs = np.asarray(sub[xd])
    if yd is None:
        ax.pcolormesh(_edges(xs, ds[xd].attrs.get("scale")), [0, 1], values[None, :], cmap=cmap, norm=norm)
        ax.set_yticks([])
    else:
        ys = np.asarray(sub[yd])
        ax.pcolormesh(_edges(xs, ds[xd].attrs.get("scale")), _edges(ys, ds[yd].attrs.get("scale")), values, cmap=cmap, norm=norm)
        if len(xs) > 1 and len(ys) > 1 and (values == 0).any() and (values != 0).any():
            ax.contour(xs, ys, (values == 0).astype(float), levels=[0.5], colors="k", linewidths=1.0)
        ax.set_ylabel(_axis_label(ds, yd))
        if ds[yd].attrs.get("scale") == "log":
            ax.set_yscale("log")
    ax.set_xlabel(_axis_label(ds, xd))
    if ds[xd].attrs.get("scale") == "log":
        ax.set_xscale("log")
    present = sorted(int(v) for v in np.unique(values))
    handles = [
        Patch(color=colours[v + 1], label="degenerate" if v < 0 else ("stable (all roots real)" if v == 0 else f"unstable, {v} complex pair{'s' if v > 1 else ''}"))
        for v in present
    ]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False, title="N_c")
    title = textwrap.fill(ds.attrs.get("title", "stabmap atlas"), 70)
    if fixed:
        title += "\n" + ", ".join(f"{k} = {v:.4g} {ds[k].attrs.get('units', '')}".strip() for k, v in fixed.items())
    ax.set_title(title, fontsize=10)
    return _save(fig, path)


def _save(fig, path: Path) -> Path:
    """Write the figure atomically (a temporary file renamed into place), then close it."""
    import matplotlib.pyplot as plt

    tmp = path.with_name(f".{path.name}.tmp{path.suffix}")
    try:
        fig.savefig(tmp, dpi=150)
        tmp.replace(path)
    finally:
        plt.close(fig)
        tmp.unlink(missing_ok=True)
    return path


def _edges(centres: np.ndarray, scale: str | None) -> np.ndarray:
    """Cell edges around grid values (geometric midpoints on a log axis)."""
    if len(centres) == 1:
        c = centres[0]
        return np.array([c - 0.5, c + 0.5]) if scale != "log" else np.array([c / 1.1, c * 1.1])
    if scale == "log" and np.all(centres > 0):
        lc = np.log(centres)
        mid = (lc[1:] + lc[:-1]) / 2
        return np.exp(np.concatenate([[2 * lc[0] - mid[0]], mid, [2 * lc[-1] - mid[-1]]]))
    mid = (centres[1:] + centres[:-1]) / 2
    return np.concatenate([[2 * centres[0] - mid[0]], mid, [2 * centres[-1] - mid[-1]]])


def plot_critical(ds: xr.Dataset, path: str | Path, *, sel: dict[str, float] | None = None) -> Path:
    """Draw a critical-values Dataset: stable intervals of the scanned parameter (shaded) and their ends (curves)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = check_writable(path)
    if path.suffix.lower() not in (".png", ".pdf"):
        raise StabmapError(f"plot file {str(path)!r}: use a .png or .pdf name")
    along = ds.attrs["critical_along"]
    lower, upper = ds[f"{along}_stable_lower"], ds[f"{along}_stable_upper"]
    dims = [d for d in lower.dims if d != "interval"]
    for k in sel or {}:
        if k not in dims:
            raise StabmapError(f"--sel {k}: not an axis of this file; its axes are: {', '.join(dims) or '(none)'}")
    chosen = dict(sel or {})
    free = [d for d in dims if d not in chosen]
    if len(free) > 1:
        raise StabmapError(f"this file has {len(free)} other axes ({', '.join(free)}); fix all but one with --sel NAME=VALUE")
    # Curves only where an end is a located boundary, not where the interval meets the end of the scan.
    lower_b = lower.where(ds[f"{along}_stable_lower_outer"].notnull())
    upper_b = upper.where(ds[f"{along}_stable_upper_outer"].notnull())
    if chosen:
        lower, upper, lower_b, upper_b = (v.sel(chosen, method="nearest") for v in (lower, upper, lower_b, upper_b))
    fig, ax = plt.subplots(figsize=(7.5, 5.5), constrained_layout=True)
    lo, hi = np.atleast_2d(np.asarray(lower)), np.atleast_2d(np.asarray(upper))
    lo_b, hi_b = np.atleast_2d(np.asarray(lower_b)), np.atleast_2d(np.asarray(upper_b))
    scan = ds.attrs["critical_scan_range"]
    if free:
        from matplotlib.collections import PolyCollection

        x = np.asarray(ds[free[0]])
        edges = _edges(x, ds[free[0]].attrs.get("scale"))
        # One box per point and interval, and the ends as dots: joining neighbouring points would draw boundaries
        # (and shade regions) that were never computed wherever the number of intervals changes between points.
        i, k = np.nonzero(np.isfinite(lo))
        boxes = [[(edges[a], lo[a, b]), (edges[a + 1], lo[a, b]), (edges[a + 1], hi[a, b]), (edges[a], hi[a, b])] for a, b in zip(i, k)]
        ax.add_collection(PolyCollection(boxes, facecolors=_STABLE, edgecolors="none", alpha=0.6, label="stable"))
        xs = np.broadcast_to(x[:, None], lo.shape).ravel()
        ax.plot(np.concatenate([xs, xs]), np.concatenate([lo_b.ravel(), hi_b.ravel()]), "k.", ms=2.5, label="boundary")
        ax.set_xlim(edges[0], edges[-1])
        ax.set_xlabel(_axis_label(ds, free[0]))
        if ds[free[0]].attrs.get("scale") == "log":
            ax.set_xscale("log")
    else:
        for k in range(lo.shape[1]):
            if np.isfinite(lo[0, k]):
                ax.axhspan(lo[0, k], hi[0, k], color=_STABLE, alpha=0.6, label="stable" if k == 0 else None)
        ax.set_xticks([])
    ax.set_ylim(float(scan[0]), float(scan[-1]))
    units = lower.attrs.get("units", "")
    ax.set_ylabel(f"{along} [{units}]" if units else along)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    title = textwrap.fill(ds.attrs.get("title", "stabmap critical values"), 70) + f"\nstable {along} (white: unstable); ends to rtol {ds.attrs['critical_rtol']:g}"
    if chosen:
        title += "; " + ", ".join(f"{k} = {v:.4g}" for k, v in chosen.items())
    ax.set_title(title, fontsize=10)
    return _save(fig, path)
