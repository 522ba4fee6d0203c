"""The page of an atlas: the map of two axes coloured as the PNG maps are, with the class boundaries, a slider for
each further axis, and on hover the point's parameters, label and class, what decided it and what its cell
proves.

The map is drawn in blocks no smaller than a pixel of the page's map (600 x 450) on the cells the atlas proves
its labels on (its ``*_bounds``: nothing is coloured beyond the scan); blocks of one colour are merged into
rectangles, one quad each, so that no seam shows inside a region. On hover, the block under the pointer is found
from its coordinates, and its state (:mod:`.states`: one byte per block, two past 256 states) names its text.
A page holds every slider setting that fits its size bound (``max_mb``), measured on the page itself: beyond it
the sliders keep evenly spaced values, and the page and ``notes`` say which.
"""

from __future__ import annotations

import zlib

import numpy as np
import xarray as xr

from ... import systems
from ...errors import StabmapError
from ...store.variables import CELL
from ..blocks import compute
from ..plot.captions import fixed_caption
from ..plot.layout import SINGLE_WIDTH, panel_points
from ..plot.marks import CHANGE_INK, change_text, hidden_cell_axes
from ..plot.palette import BOUNDARY, CLASS_EDGE, system_colour
from ..plot.ticks import axis_ticks
from ..summary import summary
from . import widgets
from .frames import EAGER_POINTS, MAP_PIXELS, Frame, map_grid, read_frame
from .page import MAX_MB, Page, budget, fitted
from .plan import PagePlan, plan_page
from .states import Legend, point_bits, state_text
from .text import axis_title, escape, plain, span_texts, value_text

# The block under the pointer (data coordinates x, y) -> its text: its values along x and y, the other axes' values,
# its state. Tables shared by the tooltip and the readout live in data sources, so the page holds them once.
DESCRIBE_JS = """
function locate(e, v) {
  const n = e.length - 1, up = e[n] >= e[0];
  let lo = 0, hi = n;
  while (hi - lo > 1) { const m = (lo + hi) >> 1; if ((v >= e[m]) === up) lo = m; else hi = m; }
  return lo;
}
function describe(x, y) {
  const k = frame_index(sliders, radix);
  const xe = tables.xe.data.v, ye = tables.ye.data.v, nbx = xe.length - 1;
  const col = locate(xe, x), row = ye.length > 2 ? locate(ye, y) : 0;
  const s = current.data.state[row * nbx + col];
  return [tables.xtext.data.v[col], tables.ytext.data.v[row], tables.where.data.v[k], tables.texts.data.v[s]].filter(t => t).join("\\n");
}
"""
# A rectangle's edges from its block columns [c0, c1) and rows [r0, r1); the right and top edges inside the map are
# pulled in by a millionth of a block, so that a pointer on the edge between two rectangles hovers the one it belongs to (edges are
# inclusive in bokeh's hit test), and the same one that locate() names.
RECT_EDGES_JS = {
    "left": "const e = xe.data.v; return Array.from(this.data.c0, c => e[c]);",
    "right": "const e = xe.data.v; return Array.from(this.data.c1, c => c == e.length - 1 ? e[c] : e[c] - 1e-6 * (e[c] - e[c - 1]));",
    "bottom": "const e = ye.data.v; return Array.from(this.data.r0, r => e[r]);",
    "top": "const e = ye.data.v; return Array.from(this.data.r1, r => r == e.length - 1 ? e[r] : e[r] - 1e-6 * (e[r] - e[r - 1]));",
}


def atlas_page(ds: xr.Dataset, *, x: str | None = None, y: str | None = None, sel: dict[str, float] | None = None,
               max_mb: float = MAX_MB, progress=None) -> Page:
    """The interactive page of an atlas (lazy or in memory): nothing is computed, every frame is read once.

    Parameters
    ----------
    ds : xarray.Dataset
        An atlas (``stabmap.open_atlas(path, lazy=True)`` reads it chunk by chunk).
    x, y : str, optional
        The map's axes (default: the first two axes not fixed by ``sel``).
    sel : dict, optional
        Axes to fix, ``{name: value}`` (nearest grid value); every other axis gets a slider.
    max_mb : float
        Bound of the page's size [MB] (default 20): slider values beyond it are left out, evenly spaced ones kept.
    progress : callable, optional
        Called as ``progress(done, total)`` after each frame read.
    """
    system = systems.of_atlas(ds.attrs)
    if system.label not in ds:
        raise StabmapError(f"not a stabmap atlas: the Dataset has no {system.label!r} variable")
    dims = [str(d) for d in ds[system.label].dims]
    if not dims:
        raise StabmapError("this atlas has no axis to draw (a single point); use 'stabmap info' or 'stabmap query'")
    room = budget(max_mb)
    full = plan_page(ds, dims, x=x, y=y, sel=sel)
    fix = {k: i for k, (i, _) in full.fixed.items()}
    label = ds[system.label].isel(fix)
    bits = point_bits(ds, system)
    bits = None if bits is None else bits.isel(fix)
    if label.size <= EAGER_POINTS:  # every frame at once: a few MB, each chunk of the file read once, not once a frame
        label, bits = compute(label, bits)
    grid = map_grid(ds, full)
    legend = Legend(system, system.provenance in ds)
    frames: dict[tuple, Frame] = {}

    def read(at: dict[str, int], total: int) -> Frame:
        key = tuple(sorted(at.items()))
        if key not in frames:
            frames[key] = read_frame(label, bits, full, at, grid, legend)
            if progress is not None:
                progress(len(frames), total)
        return frames[key]

    first = read(full.frames[0], len(full.frames))  # a first guess of the frames that fit; the page is then measured

    def make(plan: PagePlan) -> Page:
        chosen = [read(at, len(plan.frames)) for at in plan.frames]
        return Page(draw(ds, system, plan, grid, legend, chosen), plain(ds.attrs.get("title", "") or "stabmap atlas"), plan.notes)

    return fitted(full, dict(ds.sizes), max_mb, room // max(1, frame_bytes(first)), make)


def frame_bytes(f: Frame) -> int:
    """A first guess of the bytes a frame adds to a page, as bokeh writes it: its block states, rectangles and
    boundary segments compressed, in base64, and about 1.5 kB of wrapping and title."""
    arrays = (f.keys.astype(np.uint16), f.rects.astype(np.uint16), f.stability, f.classes)
    return 1500 + sum(len(zlib.compress(np.ascontiguousarray(a).tobytes())) for a in arrays) * 4 // 3


def draw(ds: xr.Dataset, system, plan: PagePlan, grid, legend: Legend, chosen: list[Frame]) -> object:
    """The bokeh layout of an atlas page: title, map, sliders, readout, legend and caption."""
    from bokeh.layouts import column, row
    from bokeh.models import ColumnDataSource, CustomJS, CustomJSExpr, CustomJSHover, CustomJSTransform, HoverTool, LinearColorMapper, Range1d
    from bokeh.plotting import figure

    has_prov, has_cell = system.provenance in ds, CELL.name in ds
    states, table = np.unique(np.concatenate([f.keys.ravel() for f in chosen]), return_inverse=True)
    ids = np.split(table, np.cumsum([f.keys.size for f in chosen])[:-1])
    texts = [state_text(int(k), system, has_prov, has_cell) for k in states]
    palette = list(legend.colours)
    mapper = LinearColorMapper(palette=palette * (2 if len(palette) == 1 else 1), low=-0.5, high=len(palette) - 0.5)

    p = figure(name="map", frame_width=MAP_PIXELS[1], frame_height=MAP_PIXELS[0] if plan.y else 60,
               x_axis_type="log" if grid.log[0] else "linear", y_axis_type="log" if grid.log[1] else "linear",
               x_range=Range1d(float(grid.xe[0]), float(grid.xe[-1]), bounds="auto"),  # not panned past the scan
               y_range=Range1d(float(grid.ye[0]), float(grid.ye[-1]), bounds="auto"),
               tools="pan,wheel_zoom,box_zoom,reset,save", toolbar_location="right")
    inches = map_inches(plan)
    p.xaxis.axis_label = axis_title(ds, plan.x, widgets.set_ticks(p.xaxis, axis_ticks(ds, plan.x, grid.xe[0], grid.xe[-1], inches[1], "x")))
    if plan.y:
        p.yaxis.axis_label = axis_title(ds, plan.y, widgets.set_ticks(p.yaxis, axis_ticks(ds, plan.y, grid.ye[0], grid.ye[-1], inches[0], "y")))
    else:
        p.yaxis.visible = False
    p.grid.visible = False

    where = [where_text(ds, {**at, **{k: i for k, (i, _) in plan.fixed.items()}}) for at in plan.frames]
    # The tables every callback reads, each in a model: bokeh writes a model once, however many callbacks name it.
    tables = {name: ColumnDataSource({"v": values}) for name, values in (
        ("xe", grid.xe), ("ye", grid.ye), ("texts", texts), ("where", where), ("xtext", span_texts(ds, plan.x, grid.factors[1])),
        ("ytext", span_texts(ds, plan.y, grid.factors[0]) if plan.y else [""]))}
    rects = ColumnDataSource(rect_columns(chosen[0]))
    current = ColumnDataSource({"state": widgets.array(ids[0])})
    edges = {side: CustomJSExpr(args={"xe": tables["xe"], "ye": tables["ye"]}, code=code) for side, code in RECT_EDGES_JS.items()}
    # A fill id names a colour and a hatch: cells proved to hold a change keep their class colour under the hatch.
    hatch = CustomJSTransform(args={"h": legend.hatches}, v_func="return Array.from(xs, x => h[x] || ' ');")
    ink = CustomJSTransform(args={"c": legend.inks}, v_func="return Array.from(xs, x => c[x]);")
    blocks = p.quad(left={"expr": edges["left"]}, right={"expr": edges["right"]}, bottom={"expr": edges["bottom"]},
                    top={"expr": edges["top"]}, source=rects, fill_color={"field": "colour", "transform": mapper},
                    # outlined in their own colour: no seam of antialiased edges shows between rows of rectangles
                    line_color={"field": "colour", "transform": mapper}, line_width=1,
                    hatch_pattern={"field": "colour", "transform": hatch}, hatch_color={"field": "colour", "transform": ink},
                    hatch_scale=8, hatch_weight=1.2)
    lines = []
    for kind, colour in (("classes", CLASS_EDGE), ("stability", BOUNDARY)):
        seg = ColumnDataSource(segment_columns(getattr(chosen[0], kind)))
        p.segment(x0="x0", y0="y0", x1="x1", y1="y1", line_width="w", line_color=colour, source=seg, line_cap="square")
        lines.append(seg)

    controls = widgets.sliders(ds, plan.sliders, plan.positions)
    radix = [len(plan.positions[s]) for s in plan.sliders]
    head = summary(ds)["headline"]  # of the whole atlas: the title of a single map, else in the caption
    whole = not plan.sliders and not plan.fixed
    titles = [title_html(ds, system, plan, f, at, head if whole else None) for f, at in zip(chosen, plan.frames, strict=True)]
    readout = widgets.readout()
    title = widgets.title(titles)
    describe = {"sliders": controls, "radix": radix, "tables": tables, "current": current}
    js = widgets.FRAME_JS + DESCRIBE_JS
    tooltip = CustomJSHover(args=describe, code=js + "return describe(special_vars.x, special_vars.y);")
    hover = HoverTool(renderers=[blocks], tooltips='<div style="white-space: pre-line; max-width: 420px">@colour{custom}</div>',
                      formatters={"@colour": tooltip},
                      callback=CustomJS(args={**describe, "readout": readout}, code=js + widgets.READOUT_JS
                                        + "if (cb_data.index.indices.length) show(readout, describe(cb_data.geometry.x, cb_data.geometry.y));"))
    p.add_tools(hover)
    if controls:
        widgets.on_frame(controls, radix, """
rects.data = frames[k][0];
current.data = {state: frames[k][1]};
lines[0].data = frames[k][2];
lines[1].data = frames[k][3];
title.text = titles[k];
""", rects=rects, current=current, lines=lines, title=title, titles=titles,
                         frames=[[rect_columns(f), widgets.array(i), segment_columns(f.classes), segment_columns(f.stability)]
                                 for f, i in zip(chosen, ids, strict=True)])
    change = change_text(hidden_cell_axes(ds, system.label, (plan.x, plan.y)), ds, plain)
    side = widgets.legend(plain(system.label_title), legend_entries(system, chosen, change))
    return column(title, row(p, side), *controls, readout, widgets.caption(caption_lines(ds, plan, grid, None if whole else head)))


def map_inches(plan: PagePlan) -> tuple[float, float]:
    """The length (y, x) [inch] of the PNG's single map of these axes: the page's ticks are chosen as on it."""
    return tuple(v / 72 for v in panel_points(SINGLE_WIDTH, 1, 1, facets=False, strip=plan.y is None))  # type: ignore[return-value]


def rect_columns(f: Frame) -> dict[str, np.ndarray]:
    """A frame's rectangles of one colour as the columns of its quads: block columns c0..c1, rows r0..r1, colour."""
    r = f.rects
    return {"c0": r[:, 0].astype(np.uint16), "c1": r[:, 1].astype(np.uint16), "r0": r[:, 2].astype(np.uint16),
            "r1": r[:, 3].astype(np.uint16), "colour": r[:, 4].astype(np.uint8)}


def segment_columns(table: np.ndarray) -> dict[str, np.ndarray]:
    """Boundary segments (rows x0, y0, x1, y1, width) as the columns of a segment glyph."""
    return {k: np.ascontiguousarray(table[:, j]) for j, k in enumerate(("x0", "y0", "x1", "y1", "w"))}


def where_text(ds: xr.Dataset, at: dict[str, int]) -> str:
    """The values of the axes off the map at ``at`` (the sliders' setting and the axes fixed by ``sel``), one line each."""
    return "\n".join(value_text(ds, d, float(ds[d][i])) for d, i in at.items())


def title_html(ds: xr.Dataset, system, plan: PagePlan, f: Frame, at: dict[str, int], headline: str | None = None) -> str:
    """The title of one frame: the atlas's title, the ``headline`` of a page that shows the whole atlas in one map
    (:mod:`stabmap.read.headline`) or else the share of this map's grid points stable, the values of the sliders and
    of the axes fixed by ``sel``."""
    total = sum(f.counts.values())
    lines = [f"<b>{escape(plain(ds.attrs.get('title', '') or 'stabmap atlas'))}</b>"]
    if headline is not None:
        lines.append(escape(headline))
    elif system.stable_label is not None:
        share = 100 * f.counts.get(system.stable_label, 0) / max(1, total)
        lines.append(f"{share:.1f} % of the {total:,} grid points of this map {escape(system.stable_word)}")
    shown = [value_text(ds, d, float(ds[d][i])) for d, i in at.items()]
    shown += [value_text(ds, k, float(ds[k][i])) + ("" if np.isclose(v, float(ds[k][i])) else f" (nearest to {v:g})")
              for k, (i, v) in plan.fixed.items()]
    if shown:
        lines.append(escape(", ".join(shown)))
    return "<br>".join(lines)


def legend_entries(system, chosen: list[Frame], change: str = "") -> list[str]:
    """The legend: the classes drawn, then the lines and marks drawn, as the PNG legend names them (of the frames on
    the page only, not of those left out; ``change``: the words of the change hatch)."""
    present = sorted({v for f in chosen for v in f.counts})
    entries = [widgets.swatch(system_colour(v, system), system.class_name(v)) for v in present]
    drawn = frozenset().union(*(f.drawn for f in chosen))
    if "stability" in drawn:
        entries.append(widgets.swatch(BOUNDARY, "stability boundary", "line"))
    if "classes" in drawn:
        entries.append(widgets.swatch(CLASS_EDGE, f"{plain(system.label_symbol)} changes", "thin"))
    if "inferred" in drawn:
        entries.append(widgets.swatch("#888888", "inferred from cell corners (not computed)", "hatch"))
    if "node-only" in drawn:
        entries.append(widgets.swatch("#888888", "proved at the grid node, not over its cell", "dots"))
    if "change" in drawn:
        entries.append(widgets.swatch(CHANGE_INK[:7], change, "hatch"))
    if "mixed-stability" in drawn:
        entries.append(widgets.swatch(BOUNDARY, "block holding stable and unstable points"))
    if "mixed-classes" in drawn:
        entries.append(widgets.swatch(CLASS_EDGE, "block holding several other classes"))
    return entries


def caption_lines(ds: xr.Dataset, plan: PagePlan, grid, headline: str | None = None) -> list[str]:
    """The caption: the ``headline`` of the whole atlas when the maps show part of it (:mod:`stabmap.read.headline`;
    each map's title has its own share of stable points), the fixed parameters and caveats (as under the PNG maps),
    how blocks were drawn, the notes."""
    lines = [f"whole atlas: {headline}"] if headline else []
    lines.append(plain(fixed_caption(ds, 10_000)).replace("\u00a0", " "))
    fy, fx = grid.factors
    if (fy, fx) != (1, 1):
        lines.append(f"{ds.sizes[plan.x]:,}" + (f" × {ds.sizes[plan.y]:,}" if plan.y else "") + f" grid points drawn in blocks of {fx}"
                     + (f" × {fy}" if plan.y else "") + " (no block smaller than a pixel): a block shows its class where all its points "
                     "agree (hatched where a cell in it holds a change), black if it holds stable and unstable points, dark grey if "
                     "several other classes; hover names them.")
    lines += [f"note: {n}" for n in plan.notes]
    lines.append(widgets.how_to(bool(plan.sliders)))
    return lines
