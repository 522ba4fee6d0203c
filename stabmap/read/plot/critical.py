"""The figure of a critical-values file (``stabmap critical``): the scanned parameter along x, as on the atlas
maps, each stretch between located changes in its class's colour, against the one other axis left free."""

from __future__ import annotations

import numpy as np
import xarray as xr

from ... import systems
from ...errors import StabmapError, given
from ..shown import display_unit
from .captions import captioned_figure, fill_title
from .geometry import cell_edges
from .labels import axis_label, mathtext, symbol, value_text
from .layout import VALUE
from .palette import HATCH_DEGENERATE, HATCH_NODE_ONLY, class_patch, system_colour
from .ticks import set_axis

CRITICAL_INCHES, CRITICAL_INCHES_Y = 5.4, 4.0  # [inch] the axes' lengths their ticks are chosen for, on the PNG and the page


def scanned_attrs(ds: xr.Dataset, system, along: str, lower: xr.DataArray) -> dict:
    """long_name, units and display unit (rpm, Hz) of the scanned parameter, as an atlas's axis has them (from the
    stored scene)."""
    try:
        info = system.parameter(systems.loads_scene(str(ds.attrs["scene"]), "the file's scene"), along)
        shown = display_unit(ds, along)  # the stored scene's, as the text answers read it
        return {"long_name": info.long_name, "units": info.units, **({"display_units": shown} if shown else {})}
    except (KeyError, StabmapError):  # no scene, or one this version does not read: the symbol and units only
        return {"units": lower.attrs.get("units", "")}


def critical_figure(ds: xr.Dataset, *, sel: dict[str, float] | None = None):
    """Draw a critical-values Dataset into a new Figure: the scanned parameter along x (as on the atlas maps),
    each stretch between located boundaries in the colour of its class (as on the maps), the boundaries as dots,
    against the one other axis (y) left free by ``sel``.

    A file without ``<label>_at_scan_start`` (written before it existed) shows its stable intervals only.
    """
    system = systems.of_atlas(ds.attrs)
    along = ds.attrs["critical_along"]
    free, chosen = free_axes(ds, along, sel)
    rows, start = critical_rows(ds, system, along, free, chosen)
    scan = [float(v) for v in ds.attrs["critical_scan_range"]]
    stretches, gaps = critical_stretches(rows, system, along, start, scan)

    fig = captioned_figure(ds, (7.5, 5.5 if free else 2.4))
    ax = fig.subplots()
    if free:
        y = np.asarray(ds[free[0]])
        edges = cell_edges(y, ds[free[0]].attrs.get("scale"))
    else:
        edges = np.array([0.0, 1.0])
    present = sorted(set(draw_stretches(ax, stretches, edges, system)) | set(draw_stretches(ax, gaps, edges, system)))
    draw_gaps(ax, gaps, edges)
    b_lo, b_hi = np.asarray(rows["boundary_lower"]), np.asarray(rows["boundary_upper"])
    ends = np.concatenate([b_lo.ravel(), b_hi.ravel()])
    ys = np.broadcast_to(((edges[:-1] + edges[1:]) / 2 if free else np.array([0.5]))[:, None], b_lo.shape).ravel()
    ax.plot(ends, np.concatenate([ys, ys]), "k.", ms=2.5 if free else 6)
    if free:
        shown_y = set_axis(ax, "y", ds, free[0], edges[0], edges[-1], CRITICAL_INCHES_Y)
        ax.set_ylabel(axis_label(ds, free[0], width=45, shown=shown_y))
    else:
        ax.set_ylim(edges[0], edges[-1])
        ax.set_yticks([])
    names = scanned_names(ds, system, along)
    shown = set_axis(ax, "x", names, along, scan[0], scan[1], CRITICAL_INCHES)  # in the scene's unit, as the page
    ax.set_xlabel(axis_label(names, along, width=60, shown=shown))
    critical_legend(fig, system, present, bool(gaps))
    ax.set_title(critical_title(ds, along, start is None, chosen), fontsize=10)
    return fig


def scanned_names(ds: xr.Dataset, system, along: str) -> xr.Dataset:
    """A one-coordinate Dataset naming the scanned parameter as an atlas's axis (long_name, units, display unit),
    for its axis label, ticks and texts."""
    attrs = scanned_attrs(ds, system, along, ds[f"{along}_stable_lower"])
    return xr.Dataset(coords={along: ((), 0.0, attrs)}, attrs=ds.attrs)


def free_axes(ds: xr.Dataset, along: str, sel: dict[str, float] | None) -> tuple[list[str], dict[str, float]]:
    """The axes of the file other than ``along`` left free by ``sel`` (at most one), and ``sel`` checked."""
    dims = [d for d in ds[f"{along}_stable_lower"].dims if d != "interval"]
    for k in sel or {}:
        if k not in dims:
            raise StabmapError(f"{given('sel', ..., k)}: not an axis of this file; its axes are: {', '.join(dims) or '(none)'}")
    chosen = dict(sel or {})
    free = [d for d in dims if d not in chosen]
    if len(free) > 1:
        raise StabmapError(f"this file has {len(free)} other axes ({', '.join(free)}); fix all but one with {given('sel', VALUE, 'NAME')}")
    return free, chosen


def critical_rows(ds: xr.Dataset, system, along: str, free: list[str], chosen: dict[str, float]) -> tuple[xr.Dataset, str | None]:
    """The file's boundaries, classes and stable intervals at ``chosen``, one row per value of the free axis (one
    row named ``row`` without one), and the name of the label at the scan's start (None in an older file)."""
    lab = system.label
    names = ["boundary_lower", "boundary_upper", f"{lab}_below", f"{lab}_above", f"{along}_stable_lower", f"{along}_stable_upper"]
    start = f"{lab}_at_scan_start" if f"{lab}_at_scan_start" in ds else None
    names += [g for g in ("undecided_lower", "undecided_upper") if g in ds]  # older files have no gaps
    picked = ds[names + ([start] if start else [])]
    if chosen:
        picked = picked.sel(chosen, method="nearest")
    return (picked.transpose(*free, ...) if free else picked.expand_dims(row=[0])), start


def critical_stretches(rows: xr.Dataset, system, along: str, start: str | None, scan: list[float]) -> tuple[list[tuple], list[tuple]]:
    """(row, x0, x1, class) of every stretch the file proves throughout, and of every undecided gap (its class proved
    at both its ends, the same there, not inside); the few-ulp brackets between stretches are left out. An older file
    (no ``start``) gives its stable intervals only."""
    return split_gaps(class_stretches(rows, system, along, start, scan), undecided_gaps(rows))


def undecided_gaps(rows: xr.Dataset) -> list[tuple[int, float, float]]:
    """(row, x0, x1) of every undecided gap: a stretch whose ends are proved to carry the same label but whose inside
    no proof settled; none in a file written before gaps were stored."""
    if "undecided_lower" not in rows:
        return []
    lo, hi = np.asarray(rows["undecided_lower"], dtype=float), np.asarray(rows["undecided_upper"], dtype=float)
    lo, hi = lo.reshape(lo.shape[0], -1), hi.reshape(hi.shape[0], -1)
    return [(r, float(a), float(b)) for r in range(lo.shape[0]) for a, b in zip(lo[r], hi[r], strict=True) if np.isfinite(a)]


def split_gaps(stretches: list[tuple], gaps: list[tuple[int, float, float]]) -> tuple[list[tuple], list[tuple]]:
    """``stretches`` (row, x0, x1, class) cut by the ``gaps`` (row, x0, x1): the pieces proved throughout, and the
    pieces inside a gap, with the class of the stretch they lie in."""
    proved, inside = [], []
    for r, x0, x1, c in stretches:
        pieces = [(x0, x1)]
        for g_r, g0, g1 in gaps:
            if g_r == r:
                inside += [(r, max(a, g0), min(b, g1), c) for a, b in pieces if min(b, g1) > max(a, g0)]
                pieces = [p for a, b in pieces for p in ((a, min(b, g0)), (max(a, g1), b)) if p[1] > p[0]]
        proved += [(r, a, b, c) for a, b in pieces]
    return proved, inside


def class_stretches(rows: xr.Dataset, system, along: str, start: str | None, scan: list[float]) -> list[tuple]:
    """(row, x0, x1, class) between the file's located changes, gaps included."""
    b_lo, b_hi = np.asarray(rows["boundary_lower"]), np.asarray(rows["boundary_upper"])
    above = np.asarray(rows[f"{system.label}_above"])
    s_lo, s_hi = np.asarray(rows[f"{along}_stable_lower"]), np.asarray(rows[f"{along}_stable_upper"])
    stretches = []
    for r in range(b_lo.shape[0]):
        if start is None:
            stretches += [(r, lo, hi, system.stable_label) for lo, hi in zip(s_lo[r], s_hi[r], strict=True) if np.isfinite(lo)]
            continue
        ok = np.isfinite(b_lo[r])
        cuts = [scan[0], *[v for pair in zip(b_lo[r][ok], b_hi[r][ok], strict=True) for v in pair], scan[1]]
        classes = [int(np.asarray(rows[start])[r]), *above[r][ok].astype(int)]
        stretches += [(r, cuts[2 * i], cuts[2 * i + 1], c) for i, c in enumerate(classes)]
    return stretches


def draw_stretches(ax, stretches: list[tuple], edges: np.ndarray, system) -> list[int]:
    """Fill each stretch as a box between its row's cell ``edges``, in its class's colour; returns the classes drawn.

    One box per point and stretch: joining neighbouring points would draw boundaries (and shade regions) that
    were never computed wherever the classes change between points.
    """
    from matplotlib.collections import PolyCollection

    present = sorted({c for *_, c in stretches})
    for c in present:
        boxes = [[(x0, edges[r]), (x0, edges[r + 1]), (x1, edges[r + 1]), (x1, edges[r])] for r, x0, x1, cc in stretches if cc == c]
        hatch = HATCH_DEGENERATE if c < 0 and c != system.absent_label else None
        ax.add_collection(PolyCollection(boxes, facecolors=system_colour(c, system), edgecolors="none", hatch=hatch))
    return present


def draw_gaps(ax, gaps: list[tuple], edges: np.ndarray) -> None:
    """Dot the undecided gaps (row, x0, x1, class), drawn in their class's colour, as maps dot the cells proved at their
    node only: the class holds at the gap's ends, not proved inside."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    if gaps:
        boxes = np.array([[(x0, edges[r]), (x0, edges[r + 1]), (x1, edges[r + 1]), (x1, edges[r])] for r, x0, x1, _ in gaps])
        patch = PathPatch(MplPath.make_compound_path_from_polys(boxes), facecolor="none", edgecolor="#00000066", linewidth=0,
                          hatch=HATCH_NODE_ONLY, zorder=2)
        patch.set_gid("undecided-gaps")
        ax.add_patch(patch)


def critical_legend(fig, system, present: list[int], gaps: bool = False) -> None:
    """The classes drawn, the undecided gaps (``gaps``: any drawn) and the located changes (dots), beside the plot."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = [class_patch(c, system) for c in present]
    if gaps:
        handles.append(Patch(facecolor="white", edgecolor="#00000066", lw=0, hatch=HATCH_NODE_ONLY,
                             label="undecided gap: proved at\nits ends, not inside"))
    handles.append(Line2D([], [], color="k", marker=".", ls="none", label=f"a change of {mathtext(system.label_symbol)},\nlocated"))
    fig.legend(handles=handles, loc="outside right upper", alignment="left", frameon=False, title=system.label_title,
               fontsize=9, title_fontsize=9)


def critical_title(ds: xr.Dataset, along: str, old: bool, chosen: dict[str, float]) -> str:
    """The file's title, what was scanned and how closely each change is located, and the values ``chosen``."""
    title = fill_title(ds.attrs.get("title", "stabmap critical values"), 70)
    title += f"\n{symbol(ds, along)} scanned, every change located to rtol {ds.attrs['critical_rtol']:g}"
    if old:
        title += " (stable intervals only: an older file)"
    if chosen:
        title += "; " + ", ".join(value_text(ds, k, float(ds[k].sel({k: v}, method="nearest"))) if k in ds.coords else f"{k} = {v:.4g}"
                                  for k, v in chosen.items())
    return title
