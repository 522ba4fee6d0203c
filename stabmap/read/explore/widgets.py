"""The bokeh pieces both pages share: a slider per further axis showing its values with units, the callback that
swaps a frame's data in when a slider moves, the readout that keeps the text of the last point hovered, the
legend and the caption. The only JavaScript is in the small callbacks here and in the pages' hover texts."""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..plot.ticks import Ticks
from .text import escape, plain, value_text

# The frame shown: the slider positions read as one mixed-radix number, the first slider turning slowest.
FRAME_JS = """
function frame_index(sliders, radix) {
  let k = 0;
  for (let j = 0; j < sliders.length; j++) k = k * radix[j] + Math.round(sliders[j].value);
  return k;
}
"""
# A hover text (plain lines) as the readout's HTML.
READOUT_JS = """
function show(readout, text) {
  const safe = text.replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;");
  readout.text = '<div style="white-space: pre-line">' + safe + '</div>';
}
"""
STYLE = {"font-size": "13px", "font-family": "sans-serif"}


def sliders(ds: xr.Dataset, dims: tuple[str, ...], positions: dict[str, tuple[int, ...]]) -> list:
    """One slider per axis of ``dims`` over the grid indices ``positions[dim]`` it shows, its value shown as
    'K₁ = 10 N m rad⁻¹' (``name="slider-<dim>"``); an axis with one position shown gets none."""
    from bokeh.models import CustomJSTickFormatter, Slider

    out = []
    for d in dims:
        idx = positions[d]
        labels = [value_text(ds, d, float(ds[d][i])) for i in idx]
        shown = CustomJSTickFormatter(args={"labels": labels}, code="return labels[Math.round(tick)] ?? ''")
        out.append(Slider(start=0, end=max(1, len(idx) - 1), step=1, value=0, name=f"slider-{d}", title="", width=520,
                          disabled=len(idx) == 1, format=shown))
    return out


def on_frame(controls: list, radix: list[int], code: str, **args) -> None:
    """Run ``code`` (with ``k``, the frame index, and ``args``) whenever a slider of ``controls`` moves."""
    from bokeh.models import CustomJS

    callback = CustomJS(args={"sliders": controls, "radix": radix, **args}, code=FRAME_JS + "const k = frame_index(sliders, radix);\n" + code)
    for s in controls:
        s.js_on_change("value", callback)


def readout():
    """The Div that keeps the text of the last point hovered (``name="readout"``)."""
    from bokeh.models import Div

    return Div(name="readout", width=520, styles=STYLE,
               text="<i>Move the mouse over the map: the point's parameters, its label and class, what decided it and what its cell "
                    "proves appear here and beside the pointer.</i>")


def swatch(colour: str, text: str, kind: str = "box") -> str:
    """One legend entry in HTML: a box of ``colour``, white hatched in ``colour`` (``kind="hatch"``, as the map
    hatches cells holding a change), white dotted (``kind="dots"``, cells proved at the node only), or a line
    (``kind="line"``, ``"thin"``)."""
    if kind in ("box", "hatch", "dots"):
        fill = {"box": colour, "hatch": f"repeating-linear-gradient(45deg, {colour} 0 1.2px, #FFFFFF 1.2px 5px)",
                "dots": f"radial-gradient({colour} 1px, #FFFFFF 1.2px) 0 0 / 4px 4px"}[kind]
        mark = f'<span style="display:inline-block;width:14px;height:14px;background:{fill};border:1px solid #888;vertical-align:middle"></span>'
    else:
        height = 3 if kind == "line" else 1
        mark = f'<span style="display:inline-block;width:18px;height:{height}px;background:{colour};vertical-align:middle"></span>'
    return f'<div style="margin:3px 0">{mark}&nbsp; {escape(text)}</div>'


def legend(title: str, entries: list[str]):
    """The legend beside the map (``name="legend"``)."""
    from bokeh.models import Div

    return Div(name="legend", width=250, styles=STYLE, text=f"<b>{escape(title)}</b>" + "".join(entries))


def caption(lines: list[str]):
    """The caption under the map: fixed parameters, caveats, notes (``name="caption"``)."""
    from bokeh.models import Div

    return Div(name="caption", width=880, styles={**STYLE, "font-size": "12px", "color": "#333"},
               text="<br>".join(escape(t) for t in lines if t))


def title(texts: list[str]):
    """The title over the map, one text per frame (``name="title"``); the frame callbacks set it."""
    from bokeh.models import Div

    return Div(name="title", width=880, styles={**STYLE, "font-size": "14px"}, text=texts[0])


def how_to(sliders: bool) -> str:
    """The caption's last line: how to move around the page."""
    return "Drag to pan, scroll to zoom (the tools at the right of the map)" + (", move the sliders to change the further axes." if sliders else ".")


def array(a) -> np.ndarray:
    """The smallest unsigned integer type that holds ``a`` (a page stores state indices, not labels)."""
    a = np.asarray(a)
    return a.astype(np.uint8 if a.max(initial=0) < 256 else np.uint16)


def set_ticks(axis, ticks: Ticks) -> str:
    """Put the PNG's ticks on a bokeh axis: its labelled ticks as major ticks with the PNG's texts, the others as
    minor ticks. Returns the unit the texts are in. Fixed ticks stay where they are when the map is zoomed."""
    from bokeh.models import FixedTicker

    axis.ticker = FixedTicker(ticks=[v for v, _ in ticks.labelled], minor_ticks=ticks.unlabelled)
    axis.major_label_overrides = {v: plain(t) for v, t in ticks.labelled}
    return ticks.shown
