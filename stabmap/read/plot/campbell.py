"""The Campbell diagram of an atlas with frequencies (``frequencies = true``): every mode's frequency against the
spin rate, the spin-rate lines and the critical speeds where modes cross them, and the growth rate beneath.

In rotordynamics a Campbell diagram plots the natural frequencies against the spin speed; a mode's frequency
meeting a multiple of the spin speed is a *critical speed*, where an excitation at that multiple (an unbalance at
1x) is resonant (Campbell 1924; Genta 2005, ch. 4).  Here the frequencies are Re lambda of the characteristic roots
(solutions ~ exp(i lambda t), non-spinning frame): lambda < 0 is a forward (prograde) whirl, lambda > 0 a backward
one, and the unbalance of a spin omega excites lambda = -omega.  A complex pair is an unstable stretch: its two
roots share their real part, and the panel below gives its growth rate with the proved enclosure.

Modes are those of the atlas (``mode_tracking``, :mod:`stabmap.systems.gyroscopes.tracking`): a link between two
grid points whose continuation is not proved is drawn dotted, never as a solid line.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ... import systems
from ...errors import StabmapError, param
from .captions import captioned_figure, fill_title
from .labels import axis_label, display_ticks, log_ticks, symbol, value_text
from .layout import free_to_draw, nearest
from .palette import STABLE_COLOUR

FORWARD, BACKWARD, PAIR, UNSEPARATED = "#0072B2", "#009E73", "#D55E00", "#999999"
SPIN_LINE = "#555555"
ORDERS = (1, 2)  # multiples of the spin rate drawn where a mode crosses them (forward 1x always); more would crowd
FOLLOWED, AMBIGUOUS = 1, 2  # mode_tracking's flags (the atlas's own flag_meanings are checked on reading)
REAL, COMPLEX, NOT_SEPARATED = 0, 1, 2  # root_kind's


def campbell_figure(ds: xr.Dataset, *, x: str | None = None, sel: dict[str, float] | None = None):
    """Draw the Campbell diagram of ``ds`` into a new Figure (nothing saved): frequencies against ``x`` (default: the
    spin axis the modes were followed along), other axes fixed by ``sel`` (nearest grid value) or at their first
    value, which the title says.  Raises StabmapError for an atlas without frequencies, naming the scene key."""
    line, along, notes = campbell_line(ds, x=x, sel=sel)
    return draw_campbell(ds, line, along, notes, critical_speeds(line, along))


def draw_campbell(ds: xr.Dataset, line: xr.Dataset, along: str, notes: list[str], crossings: list[tuple[int, float, float]]):
    """The figure of ``campbell_figure`` from the line it read (``campbell_line``) and its ``critical_speeds``."""
    rates = "growth_rate" in line
    fig = captioned_figure(ds, (8.4, 6.4 if rates else 4.6))
    if rates:
        top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[3, 1.2])
    else:
        top, bottom = fig.subplots(), None
    drawn = draw_modes(top, line, along)
    spin_lines(top, line, along, crossings)
    unstable = shade_unstable(top, line, along, systems.of_atlas(ds.attrs))
    if bottom is not None:
        draw_growth(bottom, line, along)
        bottom.set_xlabel(axis_label(ds, along, shown=display_ticks(ds, along, bottom.xaxis)))
    else:
        top.set_xlabel(axis_label(ds, along, shown=display_ticks(ds, along, top.xaxis)))
    shown = display_ticks(ds, along, top.yaxis)  # frequencies in the spin axis's unit: rad/s, rpm or Hz
    top.set_ylabel(f"frequency Re \u03bb [{shown or 'rad s$^{-1}$'}]")
    top.set_xlim(float(line[along][0]), float(line[along][-1]))
    legend(fig, drawn, unstable, bool(crossings), rates)
    top.set_title(campbell_title(ds, line, along, crossings, notes), fontsize=9)
    return fig


def campbell_line(ds: xr.Dataset, *, x: str | None, sel: dict[str, float] | None) -> tuple[xr.Dataset, str, list[str]]:
    """The variables the diagram needs along its spin axis, loaded, every other axis fixed; the axis; notes on the
    axes fixed."""
    if "frequency" not in ds or "mode" not in ds["frequency"].dims:
        raise StabmapError(f"{param('campbell')}: this atlas holds no mode frequencies; compute it with "
                           "frequencies = true in the scene (docs/rates.md)")
    dims = [d for d in ds["frequency"].dims if d != "mode"]
    along = x or ds["mode"].attrs.get("followed_along")
    if along is None:
        raise StabmapError(f"{param('campbell')} draws frequencies against a spin rate, and no spin rate is scanned in "
                           f"this atlas; name the axis to draw them against with {param('x')} (one of {', '.join(dims)})")
    chosen = dict(sel or {})
    free = free_to_draw(ds, dims, chosen, {"x": along})
    fixed, notes = nearest(ds, chosen)
    rest = [d for d in free if d != along]
    for d in rest:  # as on every map: further axes at their first value, and the figure says so
        fixed[d] = (0, float(ds[d][0]))
    if rest:
        notes.append(f"{', '.join(rest)} fixed at the first grid value (fix {'them' if len(rest) > 1 else 'it'} with {param('sel')})")
    label = systems.of_atlas(ds.attrs).label
    names = [v for v in ("frequency", "frequency_radius", "root_kind", "mode_tracking", label, "growth_rate",
                         "growth_rate_lower", "growth_rate_upper") if v in ds]
    line = ds[names].isel({d: i for d, (i, _) in fixed.items()}).transpose(along, ...).load()
    return line, along, notes


def _polylines(xs: np.ndarray, ys: np.ndarray, keep: np.ndarray) -> list[np.ndarray]:
    """The links (xs[j], ys[j]) -> (xs[j+1], ys[j+1]) where ``keep[j]``, joined into one polyline a run: few paths,
    so that a page's SVG stays small."""
    return [np.stack([xs[a : b + 1], ys[a : b + 1]], -1) for a, b in _runs(keep)]


def draw_modes(ax, line: xr.Dataset, along: str) -> dict[str, bool]:
    """Every mode as a curve, each link between two grid points coloured by what it is (forward or backward whirl,
    a complex pair, roots not separated from the axis) and dotted where its continuation is not proved."""
    from matplotlib.collections import LineCollection

    xs = np.asarray(line[along], dtype=float)
    f = np.asarray(line["frequency"], dtype=float)
    kind = np.asarray(line["root_kind"])
    track = np.asarray(line["mode_tracking"]) if "mode_tracking" in line else np.full(kind.shape, FOLLOWED)
    drawn = dict.fromkeys(("forward", "backward", "pair", "unseparated", "ambiguous"), False)
    for m in range(f.shape[1]):
        y, k = f[:, m], kind[:, m]
        both = np.isfinite(y[:-1]) & np.isfinite(y[1:])
        pair = both & ((k[:-1] == COMPLEX) | (k[1:] == COMPLEX))
        loose = both & ~pair & ((k[:-1] == NOT_SEPARATED) | (k[1:] == NOT_SEPARATED))
        real = both & ~pair & ~loose
        mid = (y[:-1] + y[1:]) / 2
        unsure = track[1:, m] == AMBIGUOUS
        for mask, colour, width, key in ((real & (mid < 0), FORWARD, 1.3, "forward"), (real & (mid >= 0), BACKWARD, 1.3, "backward"),
                                         (pair, PAIR, 2.6, "pair"), (loose, UNSEPARATED, 1.3, "unseparated")):
            for dotted in (False, True):
                part = mask & (unsure if dotted else ~unsure)
                if not part.any():
                    continue
                lines = LineCollection(_polylines(xs, y, part), colors=colour, linewidths=width,
                                       linestyles=(0, (1, 1.5)) if dotted else "solid", capstyle="round", zorder=3)
                lines.set_gid(f"mode-{m}-{key}" + ("-dotted" if dotted else ""))  # ids unique in an SVG page
                ax.add_collection(lines)
                drawn[key] = True
                drawn["ambiguous"] |= dotted
    finite = f[np.isfinite(f)]
    if finite.size:
        pad = 0.05 * max(float(np.ptp(finite)), 1e-12)
        ax.set_ylim(float(finite.min()) - pad, float(finite.max()) + pad)
    ax.axhline(0.0, color="#BBBBBB", lw=0.6, zorder=1)
    return drawn


def critical_speeds(line: xr.Dataset, along: str) -> list[tuple[int, float, float]]:
    """(order, spin rate, frequency) where a real mode meets lambda = -order * spin (forward) or +order * spin
    (backward): each crossing of the grid's straight links, linearly interpolated, ascending in spin rate."""
    xs = np.asarray(line[along], dtype=float)
    f = np.asarray(line["frequency"], dtype=float)
    kind = np.asarray(line["root_kind"])
    out = []
    for order in ORDERS:
        for sign in (-1, 1):
            gap = f - sign * order * xs[:, None]
            real = (kind[:-1] == REAL) & (kind[1:] == REAL)
            flips = real & (np.sign(gap[:-1]) * np.sign(gap[1:]) < 0)
            for j, m in zip(*np.nonzero(flips), strict=True):
                t = gap[j, m] / (gap[j, m] - gap[j + 1, m])
                w = xs[j] + t * (xs[j + 1] - xs[j])
                out.append((sign * order, float(w), float(sign * order * w)))
    return sorted(out, key=lambda c: (abs(c[0]), c[1]))


def spin_lines(ax, line: xr.Dataset, along: str, crossings: list[tuple[int, float, float]]) -> None:
    """lambda = -omega (the 1x forward line an unbalance excites) always, other multiples where a mode crosses them,
    each labelled at its end; the critical speeds as open circles."""
    xs = np.asarray(line[along], dtype=float)
    lo, hi = ax.get_ylim()
    orders = {-1} | {o for o, _, _ in crossings}
    for o in sorted(orders, key=lambda v: (abs(v), v)):
        ys = o * xs
        inside = (ys >= lo) & (ys <= hi)
        if not inside.any():
            continue
        ax.plot(xs, ys, color=SPIN_LINE, lw=0.8, ls=(0, (5, 3)), zorder=2, gid=f"spin-line-{o}")
        j = np.flatnonzero(inside)[-1]  # where the line leaves the axes: steep and shallow lines are labelled apart
        ax.annotate(f"{abs(o)}\u00d7 spin" + (" (backward)" if o > 0 else ""), (xs[j], ys[j]), fontsize=7, color=SPIN_LINE,
                    xytext=(-2, 6 if o < 0 else -6), textcoords="offset points", ha="right", va="bottom" if o < 0 else "top",
                    bbox={"boxstyle": "square,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8}, zorder=5)
    ax.set_ylim(lo, hi)
    if crossings:
        ax.plot([w for _, w, _ in crossings], [y for _, _, y in crossings], "o", mfc="white", mec="black", ms=5, zorder=4,
                gid="critical-speeds")


def shade_unstable(ax, line: xr.Dataset, along: str, system) -> bool:
    """A light band over every stretch of grid points whose label is an unstable class (N_c > 0); whether there is
    one."""
    if system.label not in line or system.stable_label is None:
        return False
    xs = np.asarray(line[along], dtype=float)
    value = np.asarray(line[system.label])
    bad = (value >= 0) & (value != system.stable_label)
    edges = np.concatenate([[xs[0]], (xs[:-1] + xs[1:]) / 2, [xs[-1]]])
    for a, b in _runs(bad):
        ax.axvspan(edges[a], edges[b], color=PAIR, alpha=0.1, lw=0, zorder=0)
    return bool(bad.any())


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) of each run of True in ``mask``."""
    padded = np.concatenate([[False], mask, [False]]).astype(np.int8)
    d = np.diff(padded)
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1), strict=True))


def draw_growth(ax, line: xr.Dataset, along: str) -> None:
    """The growth rate against the spin rate on a log scale, its proved enclosure as a band, and the stretches where
    every root is proved real (rate exactly 0) in the stable colour."""
    xs = np.asarray(line[along], dtype=float)
    rate = np.asarray(line["growth_rate"], dtype=float)
    stable = rate == 0
    edges = np.concatenate([[xs[0]], (xs[:-1] + xs[1:]) / 2, [xs[-1]]])
    for a, b in _runs(stable):
        ax.axvspan(edges[a], edges[b], color=STABLE_COLOUR, alpha=0.35, lw=0, zorder=0)
    positive = np.where(rate > 0, rate, np.nan)
    if np.isfinite(positive).any():
        ax.set_yscale("log")
        if "growth_rate_lower" in line:
            lo = np.asarray(line["growth_rate_lower"], dtype=float)
            hi = np.asarray(line["growth_rate_upper"], dtype=float)
            ok = rate > 0
            ax.fill_between(xs, np.where(ok, np.maximum(lo, 1e-300), np.nan), np.where(ok, hi, np.nan), color=PAIR, alpha=0.3, lw=0)
        ax.plot(xs, positive, color=PAIR, lw=1.5, gid="growth-rate")
        log_ticks(ax.yaxis, float(np.nanmin(positive)), float(np.nanmax(positive)))
    else:
        ax.set_yticks([])
        ax.text(0.5, 0.5, "every root proved real along this line: growth rate 0", transform=ax.transAxes, ha="center",
                va="center", fontsize=8)
    ax.set_ylabel("growth rate\nmax |Im \u03bb| [s$^{-1}$]", fontsize=8)


def legend(fig, drawn: dict[str, bool], unstable: bool, crossings: bool, rates: bool) -> None:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles = []
    for key, colour, width, text in (("forward", FORWARD, 1.3, "real root, \u03bb < 0: forward whirl"),
                                     ("backward", BACKWARD, 1.3, "real root, \u03bb > 0: backward whirl"),
                                     ("pair", PAIR, 2.6, "complex pair (unstable): Re \u03bb"),
                                     ("unseparated", UNSEPARATED, 1.3, "root not separated from the real axis")):
        if drawn[key]:
            handles.append(Line2D([], [], color=colour, lw=width, label=text))
    if drawn["ambiguous"]:
        handles.append(Line2D([], [], color="#333333", lw=1.3, ls=(0, (1, 1.5)), label="continuation not proved\n(crossing, or enclosures meet)"))
    handles.append(Line2D([], [], color=SPIN_LINE, lw=0.8, ls=(0, (5, 3)), label="multiples of the spin rate"))
    if crossings:
        handles.append(Line2D([], [], ls="", marker="o", mfc="white", mec="black", label="critical speed"))
    if unstable:
        handles.append(Patch(color=PAIR, alpha=0.15, label="unstable: N$_c$ > 0"))
    if rates:
        handles.append(Patch(color=STABLE_COLOUR, alpha=0.5, label="stable: growth rate 0"))
    fig.legend(handles=handles, loc="outside right upper", fontsize=8, frameon=False)


def campbell_title(ds: xr.Dataset, line: xr.Dataset, along: str, crossings: list, notes: list[str]) -> str:
    """The scene's title, what is drawn, the axes fixed, and the 1x critical speeds."""
    modes = int(np.isfinite(np.asarray(line["frequency"], dtype=float)).any(axis=0).sum())
    parts = [str(ds.attrs.get("title", "")).strip(), f"Campbell diagram: the {modes} modes' frequencies against {symbol(ds, along)}"]
    fixed = [value_text(ds, d, float(line[d])) for d in line.coords if d not in line.dims and d in ds.dims]
    if fixed:
        parts[-1] += " at " + ", ".join(fixed)
    ones = [w for o, w, _ in crossings if o == -1]
    if ones:
        unit = str(ds[along].attrs.get("display_units", "")) or "rad/s"
        k = 1.0
        if ds[along].attrs.get("display_units"):
            from ...scene.units import factor

            k = factor(unit)
        shown = ", ".join(f"{w / k:.4g}" for w in ones[:6]) + (", ..." if len(ones) > 6 else "")
        parts.append(f"critical speeds (a forward mode at 1\u00d7 spin): {symbol(ds, along)} = {shown} {unit}")
    text = "\n".join(fill_title(p, 80) for p in parts if p)  # as wide as the diagram: the legend is beside it
    return text + "".join(f"\n{n}" for n in notes)


__all__ = ["campbell_figure", "campbell_line", "critical_speeds", "draw_campbell"]
