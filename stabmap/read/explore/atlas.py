"""The page of an atlas: the map of two axes coloured as the PNG maps are, with the class boundaries, a slider for
each further axis, and on hover the point's parameters, label and class, what decided it and what its cell
proves.

The map is drawn in blocks no smaller than a pixel of the page's map (600 x 450), each block one byte (two past 256
states) naming its state (:mod:`.states`); the blocks' geometry is computed in the browser from the grid's edges,
so a frame costs one byte a block plus its boundary segments. A page holds every slider setting up to its size
bound (``max_mb``): beyond it the sliders keep evenly spaced values, and the page and ``notes`` say which.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from ... import systems
from ...errors import StabmapError
from ...store.variables import CELL
from ..plot.captions import fixed_caption
from ..plot.palette import BOUNDARY, CLASS_EDGE, system_colour
from . import widgets
from .frames import MAP_PIXELS, Frame, map_grid, read_frame
from .page import MAX_MB, Page, budget
from .plan import PagePlan, plan_page, thin
from .states import Legend, lighter, point_bits, state_text
from .text import axis_title, escape, plain, span_texts, value_text

# The index of a block under the pointer -> its text: position along x and y, the other axes' values, its state.
DESCRIBE_JS = """
function describe(i) {
  const k = frame_index(sliders, radix);
  const row = Math.floor(i / nbx), col = i % nbx;
  return [xtext[col], ytext[row], where[k], texts[STATE]].filter(t => t).join("\\n");
}
"""


@dataclass(frozen=True)
class BlockGlyph:
    """How the blocks are drawn and read back: the glyph's ``field``, the JavaScript expressions of block i's
    state, of the block under the pointer in a tooltip and in the hover callback's hits, and the frame swap."""

    field: str
    state: str
    tooltip_index: str
    hits: str
    swap: str


# One image when the blocks are equal in the axes' scales: drawn as one, no seams between blocks, light to pan.
IMAGE = BlockGlyph("img", "blocks.data.img[0][i]", "special_vars.image_index.flat_index",
                   "(cb_data.index.image_indices || []).map(h => h.flat_index)", "blocks.data = {img: [states[k]]};")
# Else one quad per block (an irregular list of values), its edges computed in the browser from the grid's edges and
# pulled in by a millionth of the block, so that a pointer on the common edge of two neighbours hovers one, not both.
QUADS = BlockGlyph("state", "blocks.data.state[i]", "special_vars.index", "cb_data.index.indices", "blocks.data = {state: states[k]};")
QUAD_EDGES_JS = {
    "left": "return Array.from(this.data.state, (_, i) => xe[i % nbx] + 1e-6 * (xe[i % nbx + 1] - xe[i % nbx]));",
    "right": "return Array.from(this.data.state, (_, i) => xe[i % nbx + 1] - 1e-6 * (xe[i % nbx + 1] - xe[i % nbx]));",
    "bottom": "return Array.from(this.data.state, (_, i) => { const r = Math.floor(i / nbx); return ye[r] + 1e-6 * (ye[r + 1] - ye[r]); });",
    "top": "return Array.from(this.data.state, (_, i) => { const r = Math.floor(i / nbx); return ye[r + 1] - 1e-6 * (ye[r + 1] - ye[r]); });",
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
    plan = plan_page(ds, dims, x=x, y=y, sel=sel)
    fix = {k: i for k, (i, _) in plan.fixed.items()}
    label = ds[system.label].isel(fix)
    bits = point_bits(ds, system)
    bits = None if bits is None else bits.isel(fix)
    grid = map_grid(ds, plan)
    legend = Legend(system, system.provenance in ds)

    frames: dict[tuple, Frame] = {}

    def read(at: dict[str, int]) -> Frame:
        key = tuple(sorted(at.items()))
        if key not in frames:
            frames[key] = read_frame(label, bits, plan, at, grid, legend)
            if progress is not None:
                progress(len(frames), len(plan.frames))
        return frames[key]

    first = read(plan.frames[0])
    plan = thin(plan, dict(ds.sizes), room // max(1, frame_bytes(first, 1)), f"the page's size bound, max_mb = {max_mb:g}; "
                "a value left out can be chosen with sel / --sel")
    chosen = [read(at) for at in plan.frames]
    states, table = np.unique(np.concatenate([f.keys.ravel() for f in chosen]), return_inverse=True)
    while sum(frame_bytes(f, 1 if len(states) <= 256 else 2) for f in chosen) > room and len(chosen) > 1:  # an estimate fell short
        plan = thin(plan, dict(ds.sizes), len(chosen) // 2, f"the page's size bound, max_mb = {max_mb:g}")
        chosen = [read(at) for at in plan.frames]
        states, table = np.unique(np.concatenate([f.keys.ravel() for f in chosen]), return_inverse=True)
    ids = np.split(table, np.cumsum([f.keys.size for f in chosen])[:-1])
    layout = draw(ds, system, plan, grid, legend, chosen, states, ids)
    data = sum(frame_bytes(f, 1 if len(states) <= 256 else 2) for f in chosen)
    return Page(layout, plain(ds.attrs.get("title", "") or "stabmap atlas"), plan.notes, data)


def frame_bytes(f: Frame, per_block: int) -> int:
    """Bytes a frame adds to a page: a state index per block, five float32 per boundary segment."""
    return per_block * f.keys.size + 20 * (len(f.stability) + len(f.classes))


def draw(ds: xr.Dataset, system, plan: PagePlan, grid, legend: Legend, chosen: list[Frame], states: np.ndarray, ids: list) -> object:
    """The bokeh layout of an atlas page: title, map, sliders, readout, legend and caption."""
    from bokeh.layouts import column, row
    from bokeh.models import ColumnDataSource, CustomJS, CustomJSHover, HoverTool, LinearColorMapper, Range1d
    from bokeh.plotting import figure

    has_prov, has_cell = system.provenance in ds, CELL.name in ds
    ny, nx = grid.shape
    texts = [state_text(int(k), system, has_prov, has_cell) for k in states]
    palette = [legend.colours[(int(k) >> 33) & 63] for k in states]
    mapper = LinearColorMapper(palette=palette * (2 if len(palette) == 1 else 1), low=-0.5, high=len(palette) - 0.5)

    p = figure(name="map", frame_width=MAP_PIXELS[1], frame_height=MAP_PIXELS[0] if plan.y else 60,
               x_axis_type="log" if grid.log[0] else "linear", y_axis_type="log" if grid.log[1] else "linear",
               x_range=Range1d(float(grid.xe[0]), float(grid.xe[-1]), bounds="auto"),  # not past the grid's ends
               y_range=Range1d(float(grid.ye[0]), float(grid.ye[-1]), bounds="auto"),
               tools="pan,wheel_zoom,box_zoom,reset,save", toolbar_location="right", output_backend="canvas")
    p.xaxis.axis_label = axis_title(ds, plan.x)
    if plan.y:
        p.yaxis.axis_label = axis_title(ds, plan.y)
    else:
        p.yaxis.visible = False
    p.grid.visible = False
    glyph, blocks = draw_blocks(p, grid, [widgets.array(i).reshape(grid.shape) for i in ids], mapper)
    lines = []
    for kind, colour in (("classes", CLASS_EDGE), ("stability", BOUNDARY)):
        seg = ColumnDataSource(segment_columns(getattr(chosen[0], kind)))
        p.segment(x0="x0", y0="y0", x1="x1", y1="y1", line_width="w", line_color=colour, source=seg, line_cap="square")
        lines.append(seg)

    controls = widgets.sliders(ds, plan.sliders, plan.positions)
    radix = [len(plan.positions[s]) for s in plan.sliders]
    where = [where_text(ds, plan, {**at, **{k: i for k, (i, _) in plan.fixed.items()}}) for at in plan.frames]
    titles = [title_html(ds, system, plan, f, at, grid) for f, at in zip(chosen, plan.frames, strict=True)]
    readout = widgets.readout()
    title = widgets.title(titles)
    describe = {"sliders": controls, "radix": radix, "nbx": nx, "blocks": blocks.data_source, "texts": texts, "where": where,
                "xtext": span_texts(ds, plan.x, grid.factors[1]), "ytext": span_texts(ds, plan.y, grid.factors[0]) if plan.y else [""]}
    js = widgets.FRAME_JS + DESCRIBE_JS.replace("STATE", glyph.state)
    tooltip = CustomJSHover(args=describe, code=js + f"return describe({glyph.tooltip_index});")
    hover = HoverTool(renderers=[blocks], tooltips=f'<div style="white-space: pre-line; max-width: 420px">@{glyph.field}{{custom}}</div>',
                      formatters={f"@{glyph.field}": tooltip},
                      callback=CustomJS(args={**describe, "readout": readout}, code=js + widgets.READOUT_JS
                                        + f"const i = {glyph.hits};\nif (i.length) show(readout, describe(i[0]));"))
    p.add_tools(hover)
    if controls:
        shape = grid.shape if glyph is IMAGE else (-1,)
        widgets.on_frame(controls, radix, glyph.swap + """
lines[0].data = segs[k][0];
lines[1].data = segs[k][1];
title.text = titles[k];
""", blocks=blocks.data_source, states=[widgets.array(i).reshape(shape) for i in ids], lines=lines, title=title, titles=titles,
                         segs=[[segment_columns(f.classes), segment_columns(f.stability)] for f in chosen])
    side = widgets.legend(plain(system.label_title), legend_entries(system, legend, chosen))
    return column(title, row(p, side), *controls, readout, widgets.caption(caption_lines(ds, plan, grid)))


def draw_blocks(p, grid, states: list[np.ndarray], mapper) -> tuple[BlockGlyph, Any]:
    """Draw the first frame's blocks (``states``: each frame's state indices, rows along y) as one image, or as a quad
    each where the blocks are not equal in the axes' scales; returns how they are read and the renderer."""
    from bokeh.models import ColumnDataSource, CustomJSExpr

    nx = grid.shape[1]
    if grid.image is not None:
        x, y, dw, dh = grid.image
        return IMAGE, p.image(image="img", x=x, y=y, dw=dw, dh=dh, color_mapper=mapper, source=ColumnDataSource({"img": [states[0]]}))
    edges = {side: CustomJSExpr(args={"xe": grid.xe, "ye": grid.ye, "nbx": nx}, code=code) for side, code in QUAD_EDGES_JS.items()}
    return QUADS, p.quad(left={"expr": edges["left"]}, right={"expr": edges["right"]}, bottom={"expr": edges["bottom"]},
                         top={"expr": edges["top"]}, source=ColumnDataSource({"state": states[0].ravel()}),
                         fill_color={"field": "state", "transform": mapper}, line_color=None)


def segment_columns(table: np.ndarray) -> dict[str, np.ndarray]:
    """Boundary segments (rows x0, y0, x1, y1, width) as the columns of a segment glyph."""
    return {k: np.ascontiguousarray(table[:, j]) for j, k in enumerate(("x0", "y0", "x1", "y1", "w"))}


def where_text(ds: xr.Dataset, plan: PagePlan, at: dict[str, int]) -> str:
    """The values of the axes off the map at ``at`` (the sliders' setting and the axes fixed by ``sel``), one line each."""
    return "\n".join(value_text(ds, d, float(ds[d][i])) for d, i in at.items())


def title_html(ds: xr.Dataset, system, plan: PagePlan, f: Frame, at: dict[str, int], grid) -> str:
    """The title of one frame: the atlas's title, the share of this map's grid points proved stable, the values of
    the sliders and of the axes fixed by ``sel``."""
    total = sum(f.counts.values())
    lines = [f"<b>{escape(plain(ds.attrs.get('title', '') or 'stabmap atlas'))}</b>"]
    if system.stable_label is not None:
        share = 100 * f.counts.get(system.stable_label, 0) / max(1, total)
        lines.append(f"{share:.1f} % of the {total:,} grid points of this map {escape(system.stable_word)}")
    shown = [value_text(ds, d, float(ds[d][i])) for d, i in at.items()]
    shown += [value_text(ds, k, float(ds[k][i])) + ("" if np.isclose(v, float(ds[k][i])) else f" (nearest to {v:g})")
              for k, (i, v) in plan.fixed.items()]
    if shown:
        lines.append(escape(", ".join(shown)))
    return "<br>".join(lines)


def legend_entries(system, legend: Legend, chosen: list[Frame]) -> list[str]:
    """The legend: the classes drawn, then the lines and marks drawn, as the PNG legend names them."""
    present = sorted({v for f in chosen for v in f.counts})
    entries = [widgets.swatch(system_colour(v, system), system.class_name(v)) for v in present]
    drawn = legend.drawn
    if "stability" in drawn:
        entries.append(widgets.swatch(BOUNDARY, "stability boundary", "line"))
    if "classes" in drawn:
        entries.append(widgets.swatch(CLASS_EDGE, f"{plain(system.label_symbol)} changes", "thin"))
    if "inferred" in drawn:
        entries.append(widgets.swatch(lighter("#888888"), "lighter: inferred from cell corners (not computed)"))
    if "node-only" in drawn:
        entries.append(widgets.swatch(lighter("#888888"), "lighter: proved at the grid node, not over its cell"))
    if "change" in drawn:
        entries.append(widgets.swatch(CLASS_EDGE, "cell proved to hold a change of label"))
    if "mixed-stability" in drawn:
        entries.append(widgets.swatch(BOUNDARY, "block holding stable and unstable points"))
    if "mixed-classes" in drawn:
        entries.append(widgets.swatch(CLASS_EDGE, "block holding several other classes"))
    return entries


def caption_lines(ds: xr.Dataset, plan: PagePlan, grid) -> list[str]:
    """The caption: the fixed parameters and caveats (as under the PNG maps), how blocks were drawn, the notes."""
    lines = [plain(fixed_caption(ds, 10_000)).replace("\u00a0", " ")]
    fy, fx = grid.factors
    if (fy, fx) != (1, 1):
        lines.append(f"{ds.sizes[plan.x]:,}" + (f" × {ds.sizes[plan.y]:,}" if plan.y else "") + f" grid points drawn in blocks of {fx}"
                     + (f" × {fy}" if plan.y else "") + " (no block smaller than a pixel): a block shows its class where all its points "
                     "agree, black if it holds stable and unstable points, dark grey if several other classes; hover names them.")
    lines += [f"note: {n}" for n in plan.notes]
    lines.append(widgets.how_to(bool(plan.sliders)))
    return lines
