"""The page of a critical-values file (``stabmap critical``): along x the scanned parameter, each stretch between
located changes in its class's colour (as the PNG draws it), against one other axis, a slider for each further
one; on hover a stretch's ends, its class and the values of the other axes."""

from __future__ import annotations

import numpy as np
import xarray as xr

from ... import systems
from ...errors import StabmapError, given
from ...scene.units import factor as unit_factor
from ..plot.captions import fixed_caption
from ..plot.critical import CRITICAL_INCHES, CRITICAL_INCHES_Y, critical_rows, critical_stretches, scanned_names
from ..plot.geometry import cell_edges
from ..plot.layout import nearest
from ..plot.palette import system_colour
from ..plot.ticks import axis_ticks
from . import widgets
from .page import MAX_MB, Page, budget, fitted
from .plan import PagePlan
from .states import lighter
from .text import axis_title, escape, name, plain, unit_plain, value_text

SHOW_JS = widgets.READOUT_JS + "const i = cb_data.index.indices;\nif (i.length) show(readout, quads.data.text[i[0]]);"


def critical_page(ds: xr.Dataset, *, y: str | None = None, sel: dict[str, float] | None = None, max_mb: float = MAX_MB,
                  progress=None) -> Page:
    """The interactive page of a critical-values Dataset: the stretches along the scanned axis against ``y`` (default:
    the first other axis not fixed by ``sel``), a slider for each further axis; ``max_mb`` bounds its size."""
    system = systems.of_atlas(ds.attrs)
    along = str(ds.attrs["critical_along"])
    dims = [str(d) for d in ds[f"{along}_stable_lower"].dims if d != "interval"]
    sel = dict(sel or {})
    for k in sel:
        if k not in dims:
            raise StabmapError(f"{given('sel', ..., k)}: not an axis of this file; its axes are: {', '.join(dims) or '(none)'}")
    free = [d for d in dims if d not in sel]
    if y is not None and y not in free:
        raise StabmapError(f"{given('y', y)}: not a free axis of this file; choose from {', '.join(free) or '(none)'}")
    y = y or (free[0] if free else None)
    rest = tuple(d for d in free if d != y)
    fixed, notes = nearest(ds, sel)
    plan = PagePlan(along, y, rest, {d: tuple(range(ds.sizes[d])) for d in rest}, fixed, tuple(notes))
    picked = ds.isel({k: i for k, (i, _) in fixed.items()})
    scan = [float(v) for v in ds.attrs["critical_scan_range"]]
    edges = cell_edges(np.asarray(ds[y], dtype=float), ds[y].attrs.get("scale")) if y else np.array([0.0, 1.0])
    names = scanned_names(ds, system, along)

    def read(at: dict[str, int]) -> tuple[dict, dict]:
        frame = picked.isel(at)
        rows, start = critical_rows(frame, system, along, [y] if y else [], {})
        stretches, gaps = critical_stretches(rows, system, along, start, scan)
        return stretch_columns(frame, system, along, y, edges, stretches, gaps, names, at), dot_columns(rows, y, edges)

    done: dict[tuple, tuple[dict, dict]] = {}

    def frame(at: dict[str, int], total: int) -> tuple[dict, dict]:
        key = tuple(sorted(at.items()))
        if key not in done:
            done[key] = read(at)
            if progress is not None:
                progress(len(done), total)
        return done[key]

    def make(plan: PagePlan) -> Page:
        frames = [frame(at, len(plan.frames)) for at in plan.frames]
        return Page(draw(ds, system, plan, edges, scan, names, frames), plain(ds.attrs.get("title", "") or "stabmap critical values"),
                    plan.notes)

    guess = budget(max_mb) // max(1, columns_bytes(frame(plan.frames[0], len(plan.frames))))
    return fitted(plan, dict(ds.sizes), max_mb, guess, make)


def stretch_columns(frame: xr.Dataset, system, along: str, y: str | None, edges: np.ndarray, stretches: list[tuple],
                    undecided: list[tuple], names: xr.Dataset, at: dict[str, int]) -> dict:
    """The stretches and the undecided gaps (``undecided``: row, x0, x1, the class at both ends) of one frame as quads:
    their box, colour (a gap's lighter) and hover text."""
    rows = [value_text(frame, y, float(v)) for v in np.asarray(frame[y])] if y else [""] * (len(edges) - 1)
    cols: dict[str, list] = {"left": [], "right": [], "bottom": [], "top": [], "cls": [], "colour": [], "text": []}
    unit = unit_plain(names, along).strip()
    display = str(names[along].attrs.get("display_units", ""))
    symbol = name(names, along)
    where = [value_text(frame, d, float(frame[d])) for d in at]
    label = plain(system.label_symbol)
    for (r, x0, x1, c), gap in [*((piece, False) for piece in stretches), *((piece, True) for piece in undecided)]:
        cols["left"].append(x0)
        cols["right"].append(x1)
        cols["bottom"].append(edges[r])
        cols["top"].append(edges[r + 1])
        cols["cls"].append(int(c))
        colour = system_colour(int(c), system)
        shown = f" ({x0 / unit_factor(display):.6g} to {x1 / unit_factor(display):.6g} {display})" if display else ""
        cols["colour"].append(lighter(colour) if gap else colour)
        head = (f"undecided gap: {label} = {c} ({system.class_name(int(c))}) at both ends, not proved inside" if gap
                else f"{label} = {c}: {system.class_name(int(c))}")
        cols["text"].append("\n".join(t for t in [head, f"{symbol} from {x0:.10g} to {x1:.10g} {unit}".rstrip() + shown, rows[r], *where] if t))
    return {k: np.asarray(v, dtype=float) if k in ("left", "right", "bottom", "top") else np.asarray(v, dtype=np.int16) if k == "cls" else v
            for k, v in cols.items()}


def dot_columns(rows: xr.Dataset, y: str | None, edges: np.ndarray) -> dict:
    """The located changes of one frame as dots at the middle of their brackets."""
    lo, hi = np.asarray(rows["boundary_lower"], dtype=float), np.asarray(rows["boundary_upper"], dtype=float)
    mid = (edges[:-1] + edges[1:]) / 2 if y else np.array([0.5])
    ys = np.broadcast_to(mid[:, None], lo.shape)
    ok = np.isfinite(lo)
    return {"x": (lo[ok] + hi[ok]) / 2, "y": ys[ok].astype(float)}


def columns_bytes(frame: tuple[dict, dict]) -> int:
    """Bytes a frame adds to the page: its floats and its texts."""
    quads, dots = frame
    return 8 * (4 * len(quads["left"]) + 2 * len(dots["x"])) + sum(len(t) + 8 for t in quads["text"]) + 10 * len(quads["colour"])


def draw(ds: xr.Dataset, system, plan: PagePlan, edges: np.ndarray, scan: list[float], names: xr.Dataset, frames: list) -> object:
    """The bokeh layout of a critical-values page."""
    from bokeh.layouts import column, row
    from bokeh.models import ColumnDataSource, CustomJS, HoverTool
    from bokeh.plotting import figure

    y = plan.y
    log_y = bool(y) and ds[y].attrs.get("scale") == "log"
    p = figure(name="map", frame_width=600, frame_height=450 if y else 80, x_range=(scan[0], scan[1]),
               y_range=(float(edges[0]), float(edges[-1])), y_axis_type="log" if log_y else "linear",
               tools="pan,wheel_zoom,box_zoom,reset,save", toolbar_location="right")
    shown = widgets.set_ticks(p.xaxis, axis_ticks(names, plan.x, scan[0], scan[1], CRITICAL_INCHES, "x"))  # as the PNG's
    p.xaxis.axis_label = axis_title(names, plan.x, shown)
    if y:
        p.yaxis.axis_label = axis_title(ds, y, widgets.set_ticks(p.yaxis, axis_ticks(ds, y, edges[0], edges[-1], CRITICAL_INCHES_Y, "y")))
    else:
        p.yaxis.visible = False
    p.grid.visible = False
    quads = ColumnDataSource(frames[0][0])
    dots = ColumnDataSource(frames[0][1])
    glyph = p.quad(left="left", right="right", bottom="bottom", top="top", fill_color="colour", line_color="colour",
                   line_width=1, source=quads)  # outlined in their own colour: no seams between rows
    p.scatter(x="x", y="y", size=4, color="black", source=dots)
    readout = widgets.readout()
    p.add_tools(HoverTool(renderers=[glyph], tooltips='<div style="white-space: pre-line; max-width: 420px">@text</div>',
                          callback=CustomJS(args={"readout": readout, "quads": quads}, code=SHOW_JS)))
    controls = widgets.sliders(ds, plan.sliders, plan.positions)
    radix = [len(plan.positions[s]) for s in plan.sliders]
    head = f"<b>{escape(plain(ds.attrs.get('title', '') or 'stabmap critical values'))}</b><br>" \
           f"{escape(name(names, plan.x))} scanned, every change located to rtol {ds.attrs['critical_rtol']:g}"
    fixed = {k: i for k, (i, _) in plan.fixed.items()}
    titles = [head + ("<br>" + escape(", ".join(value_text(ds, d, float(ds[d][i])) for d, i in {**at, **fixed}.items())) if at or fixed else "")
              for at in plan.frames]
    title = widgets.title(titles)
    if controls:
        widgets.on_frame(controls, radix, "quads.data = frames[k][0];\ndots.data = frames[k][1];\ntitle.text = titles[k];",
                         quads=quads, dots=dots, frames=[list(f) for f in frames], title=title, titles=titles)
    classes = sorted({int(c) for f in frames for c in f[0]["cls"]})
    entries = [widgets.swatch(system_colour(c, system), system.class_name(c)) for c in classes]
    if any(t.startswith("undecided gap") for f in frames for t in f[0]["text"]):
        entries.append(widgets.swatch(lighter("#888888"), "lighter: an undecided gap, its class proved at its ends, not inside"))
    entries.append('<div style="margin:3px 0">&#9679;&nbsp; a change of ' + escape(plain(system.label_symbol)) + ", located</div>")
    side = widgets.legend(plain(system.label_title), entries)
    lines = [plain(fixed_caption(ds, 10_000)).replace("\u00a0", " "), *(f"note: {n}" for n in plan.notes),
             widgets.how_to(bool(plan.sliders))]
    return column(title, row(p, side), *controls, readout, widgets.caption(lines))
