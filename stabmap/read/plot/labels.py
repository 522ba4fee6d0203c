"""Text of the label's and the axes' names: symbols (``m_2`` -> $m_{2}$), units in mathtext (``rad s-1`` ->
rad s⁻¹), axis labels from a coordinate's ``long_name``, and the ticks of log axes and of spin rates shown in rpm
or Hz."""

from __future__ import annotations

import math
import re
import textwrap

import numpy as np
import xarray as xr

from ... import systems
from ...scene import units
from ...scene.units import factor as unit_factor


def mathtext(symbol: str) -> str:
    """A symbol with its subscript in mathtext, 'N_c' -> 'N$_c$', for legends."""
    base, _, sub = symbol.partition("_")
    return base if not sub else f"{base}$_{sub}$" if len(sub) == 1 else f"{base}$_{{{sub}}}$"


def units_text(units: str) -> str:
    """CF units as text: 'rad s-1' -> 'rad s⁻¹' (mathtext), '1' -> ''; spaces do not break lines."""
    if units in ("", "1"):
        return ""
    words = []
    for w in units.split():
        m = re.fullmatch(r"([A-Za-z]+)(-?\d+)", w)
        words.append(f"{m.group(1)}$^{{{m.group(2)}}}$" if m else w)
    return "\u00a0".join(words)


def symbol(ds: xr.Dataset, name: str) -> str:
    """'omega' -> '$\\omega$', 'm_2' -> '$m_{2}$' (the system's ``symbols``); other names are returned as they are."""
    symbols = systems.of_atlas(ds.attrs).symbols
    if name in symbols:  # a whole name with its own symbol: omega, c1sq -> c_1^2
        return f"${symbols[name]}$"
    m = re.fullmatch(r"([A-Za-z]+)(?:_(\d+|[a-z]))?", name)  # m_2, and components such as c_x
    if not m or m.group(1) not in symbols:
        return name
    base, k = symbols[m.group(1)], m.group(2)
    return f"${base}_{{{k}}}$" if k else f"${base}$"


def axis_label(ds: xr.Dataset, dim: str, width: int = 60, shown: str = "") -> str:
    """'common spin rate ω [rad s⁻¹]': the coordinate's long_name (parentheses dropped, as the system writes it in
    a figure: ``System.figure_text``), symbol and units (``shown``: the units its tick labels are shown in, see
    :func:`display_ticks`)."""
    attrs = ds[dim].attrs
    name = re.sub(r"\s*\([^)]*\)", "", attrs.get("long_name", ""))
    name = systems.of_atlas(ds.attrs).figure_text(name, units_text).strip()
    sym = symbol(ds, dim)
    if not name:
        text = sym
    elif sym == dim:
        text = f"{name} ({dim})"
    else:
        text = f"{name} {sym}"
    units = shown or units_text(str(attrs.get("units", "")))
    if units:
        text += f" [{units}]"
    return textwrap.fill(text, width, break_long_words=False, break_on_hyphens=False)


def display_ticks(ds: xr.Dataset, dim: str, axis, nbins: int | str = "auto") -> str:
    """Tick labels of a spin-rate axis in its ``display_units`` (rpm, Hz), at round values of that unit (at most
    ``nbins`` intervals; on a log axis, as ``log_ticks`` places them in that unit); the data stay in rad/s.  Returns
    the unit shown, or "" (no display unit)."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, MaxNLocator

    unit = str(ds[dim].attrs.get("display_units", ""))
    if not unit:
        return ""
    k = units.factor(unit)
    if axis.get_scale() == "log":
        lo, hi = sorted(axis.get_view_interval())
        log_ticks(axis, lo, hi, k)
        return unit

    class Scaled(MaxNLocator):
        def tick_values(self, vmin, vmax):
            return super().tick_values(vmin / k, vmax / k) * k

    if not isinstance(axis.get_major_locator(), FixedLocator):  # ticks at listed values stay there
        axis.set_major_locator(Scaled(nbins=nbins, steps=[1, 2, 2.5, 5, 10]))
    axis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v / k:g}"))
    return unit


def value_text(ds: xr.Dataset, dim: str, value: float) -> str:
    """'$m_{2}$ = 1 kg': the coordinate ``dim`` at ``value``, with its symbol and units; a spin rate the scene gave in
    rpm or Hz (``display_units``) in that unit first, the stored unit beside it: '$\\omega$ = 1000 rpm (104.7 rad s⁻¹)'."""
    units = units_text(str(ds[dim].attrs.get("units", "")))
    stored = f"{value:.4g}" + (f" {units}" if units else "")
    shown = str(ds[dim].attrs.get("display_units", ""))
    if shown:
        return f"{symbol(ds, dim)} = {value / unit_factor(shown):.4g} {shown} ({stored})"
    return f"{symbol(ds, dim)} = {stored}"


def log_axis(ds: xr.Dataset, dim: str) -> bool:
    """True when ``dim`` is drawn on a log scale: its grid says so and every value is positive."""
    return ds[dim].attrs.get("scale") == "log" and bool(np.all(np.asarray(ds[dim]) > 0))


def log_ticks(axis, lo: float, hi: float, k: float = 1.0) -> None:
    """Label a log axis between its decades too: at 2 and 5 times a power of ten over up to three decades, at 3
    over up to one (unlabelled minor ticks at every integer multiple); numbers as ``0.2``, ``50``, or, on an axis
    that reaches below 10⁻³ or to 10⁴, all as powers of ten (``2×10⁻⁵``).  ``k``: the data's unit per shown unit
    (a spin axis shown in rpm: ticks at round numbers of rpm, labelled in rpm)."""
    from matplotlib.ticker import FuncFormatter, LogLocator

    class Scaled(LogLocator):
        def tick_values(self, vmin, vmax):
            return super().tick_values(vmin / k, vmax / k) * k

    lo, hi = lo / k, hi / k
    decades = math.log10(hi / lo) if lo > 0 and hi > lo else 0.0
    labelled = (2, 3, 5) if decades <= 1.2 else (2, 5) if decades <= 3.5 else ()

    plain = 1e-3 <= lo and hi < 1e4  # one style an axis: "1000" beside "10⁴" would read as two scales

    def text(v: float, _pos=None) -> str:
        v = v / k
        e = math.floor(math.log10(v) + 1e-9)
        mantissa = round(v / 10.0**e, 6)
        if plain:
            return f"{v:g}"
        return f"$10^{{{e}}}$" if mantissa == 1 else f"${mantissa:g}\\times10^{{{e}}}$"

    def minor(v: float, pos=None) -> str:
        e = math.floor(math.log10(v / k) + 1e-9)
        return text(v) if round(v / k / 10.0**e, 6) in labelled else ""

    axis.set_major_locator(Scaled(base=10))
    axis.set_minor_locator(Scaled(base=10, subs=tuple(range(2, 10))))
    axis.set_major_formatter(FuncFormatter(text))
    axis.set_minor_formatter(FuncFormatter(minor))
    axis.set_tick_params(which="minor", labelsize=8)
