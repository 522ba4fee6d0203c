"""The Campbell diagram as a self-contained .html page: the figure as inline SVG, each mode's curve and the critical
speeds carrying a tooltip (an SVG ``<title>``: hover to read a mode's frequencies and kind), and the critical speeds
as a table.  No script and no server: any browser opens it, and its vector graphics zoom without blurring."""

from __future__ import annotations

import html
import io
import re

import numpy as np
import xarray as xr

from .campbell import COMPLEX, campbell_line, critical_speeds, draw_campbell


def campbell_page(ds: xr.Dataset, *, x: str | None = None, sel: dict[str, float] | None = None) -> str:
    """The page's text (HTML) for the Campbell diagram of ``ds`` (:func:`stabmap.read.plot.campbell.campbell_figure`)."""
    import matplotlib.pyplot as plt

    line, along, notes = campbell_line(ds, x=x, sel=sel)  # read once: the figure and the table share it
    crossings = critical_speeds(line, along)
    fig = draw_campbell(ds, line, along, notes, crossings)
    buf = io.StringIO()
    try:
        fig.savefig(buf, format="svg")
    finally:
        plt.close(fig)
    svg = buf.getvalue()
    svg = svg[svg.index("<svg"):]  # the XML prologue does not belong inside HTML
    unit, k = _unit(ds, along)
    tips = _mode_tips(line, unit, k)
    tips["critical-speeds"] = "critical speeds: " + "; ".join(
        f"{along} = {w / k:.5g} {unit} ({abs(o)}\u00d7 spin{', backward' if o > 0 else ''})" for o, w, _ in crossings)

    def titled(match: re.Match) -> str:
        gid = match.group(1)
        key = gid if gid in tips else re.sub(r"-(forward|backward|pair|unseparated)(-dotted)?$", "", gid)
        tip = tips.get(key)
        return match.group(0) + (f"\n   <title>{html.escape(tip)}</title>" if tip else "")

    svg = re.sub(r'<g id="((?:mode-\d+[\w-]*)|critical-speeds)"[^>]*>', titled, svg)
    rows = "".join(f"<tr><td>{abs(o)}\u00d7{' backward' if o > 0 else ''}</td><td>{w / k:.6g}</td><td>{f / k:.6g}</td></tr>"
                   for o, w, f in crossings)
    table = (f"<table><tr><th>spin multiple</th><th>{html.escape(along)} [{unit}]</th><th>frequency Re \u03bb [{unit}]</th></tr>"
             f"{rows}</table>") if crossings else "<p>No mode meets a drawn multiple of the spin rate on this line.</p>"
    title = html.escape(str(ds.attrs.get("title", "")) or "stabmap atlas")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>Campbell diagram: {title}</title>
<style>body{{font-family:sans-serif;margin:1em;max-width:80em}} svg{{width:100%;height:auto}}
table{{border-collapse:collapse}} td,th{{border:1px solid #bbb;padding:2px 8px;text-align:right}}</style></head>
<body><h1 style="font-size:1.2em">Campbell diagram: {title}</h1>
<p>Hover over a curve to read its mode; a dotted link is a continuation not proved (docs/rates.md).</p>
{svg}
<h2 style="font-size:1.05em">Critical speeds</h2>
<p>Where a real mode's frequency meets a multiple of the spin rate, interpolated linearly between grid points.</p>
{table}
</body></html>
"""


def _unit(ds: xr.Dataset, along: str) -> tuple[str, float]:
    """The unit the spin axis is shown in, and rad/s per that unit."""
    shown = str(ds[along].attrs.get("display_units", ""))
    if not shown:
        return "rad/s", 1.0
    from ...scene.units import factor

    return shown, factor(shown)


def _mode_tips(line: xr.Dataset, unit: str, k: float) -> dict[str, str]:
    """'mode-3' -> 'mode 3: Re lambda from a to b rpm; complex pair at 120 of 2000 points'."""
    f = np.asarray(line["frequency"], dtype=float)
    kind = np.asarray(line["root_kind"])
    tips = {}
    for m in range(f.shape[1]):
        y = f[:, m]
        if not np.isfinite(y).any():
            continue
        pairs = int(np.sum(kind[:, m] == COMPLEX))
        text = f"mode {m}: Re \u03bb from {np.nanmin(y) / k:.5g} to {np.nanmax(y) / k:.5g} {unit}"
        tips[f"mode-{m}"] = text + (f"; a complex pair at {pairs} of {y.size} points" if pairs else "; real throughout")
    return tips


__all__ = ["campbell_page"]
