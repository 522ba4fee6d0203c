"""Which variables of an atlas a figure of values can draw (float variables on the grid's axes), why another one
cannot, and how its values are coloured: the scale, the norm and the words for a value.

A flag variable or the label is a class, drawn by the class map; a variable the atlas does not store is named
with the scene key that left it out, read from the scene the atlas stores.
"""

from __future__ import annotations

import dataclasses
import math
import re
import textwrap

import numpy as np
import xarray as xr

from ... import systems
from ...errors import StabmapError, given, param
from ..blocks import ValueStats
from .labels import units_text


def drawable(ds: xr.Dataset, system) -> list[str]:
    """The variables a figure of values can draw: floats on exactly the label's axes, not flags."""
    dims = set(ds[system.label].dims)
    return [str(name) for name, v in ds.data_vars.items()
            if set(v.dims) == dims and np.issubdtype(v.dtype, np.floating) and "flag_values" not in v.attrs]


def check_variable(ds: xr.Dataset, var: str) -> xr.DataArray:
    """The float variable ``var`` of ``ds``, or a StabmapError naming ``var`` (as the caller spells it), what the
    atlas holds and the fix."""
    system = systems.of_atlas(ds.attrs)
    names = drawable(ds, system)
    choose = (f"variables to draw: {', '.join(names)}" if names
              else f"this atlas holds no float variable to draw; draw its classes without {param('var')}")
    if not isinstance(var, str) or not var:
        raise StabmapError(f"{given('var', var)}: give the name of a variable; {choose}")
    if var in ds.data_vars and var in names:
        return ds[var]
    if var in ds.data_vars:
        da = ds[var]
        if var == system.label or "flag_values" in da.attrs or not np.issubdtype(da.dtype, np.floating):
            what = "the atlas's label" if var == system.label else "a flag variable" if "flag_values" in da.attrs else f"a {da.dtype} variable"
            raise StabmapError(f"{given('var', var)}: {what}, classes rather than values; draw the class map without "
                               f"{param('var')} (or, from Python, ds.{var}.stabmap.plot()); {choose}")
        extra = [d for d in da.dims if d not in ds[system.label].dims]
        raise StabmapError(f"{given('var', var)}: it has the axis {', '.join(extra) or '(none)'} beside the grid's, which a figure "
                           f"does not draw; {choose}")
    if var in ds.coords:
        raise StabmapError(f"{given('var', var)}: a coordinate (an axis or a fixed parameter), not a variable; {choose}")
    if any(v.name == var for v in system.atlas_variables):
        why = turned_off(ds, system, var)
        raise StabmapError(f"{given('var', var)}: the atlas has no {var}" + (f": {why}" if why else "") + f"; {choose}")
    raise StabmapError(f"{given('var', var)}: not a variable of this atlas; {choose}")


def turned_off(ds: xr.Dataset, system, var: str) -> str:
    """Why the atlas lacks the system's output ``var``: the key of its stored scene that left it out and the fix
    ("it was computed with growth_rate = false; rerun without it"), or "" when no single key says."""
    try:
        scene = systems.loads_scene(str(ds.attrs["scene"]), "the atlas's scene")
    except (KeyError, StabmapError):
        return ""
    for f in dataclasses.fields(scene):  # every system's scene is a dataclass
        value = getattr(scene, f.name)
        if not isinstance(value, bool):
            continue
        try:
            other = dataclasses.replace(scene, **{f.name: not value})
        except (StabmapError, TypeError, ValueError):  # a flag the scene cannot take the other way (or not as an argument)
            continue
        if any(v.name == var for v in system.outputs(other)):
            fix = "rerun without it" if f.default is (not value) else f"rerun with {f.name} = {str(not value).lower()}"
            return f"it was computed with {f.name} = {str(value).lower()}; {fix}"
    return ""


def colour_scale(stats: ValueStats) -> str:
    """"log" where every finite value at points of other labels than the stable one is > 0 (growth rates, times),
    so that the stable points' exact 0 or infinity is drawn as stable; else "linear"."""
    return "log" if stats.unstable_min > 0 else "linear"


def colour_norm(stats: ValueStats, scale: str):
    """The norm of the colour scale over the values it shows; None when it shows none."""
    from matplotlib.colors import LogNorm, Normalize

    lo = stats.positive_min if scale == "log" else stats.finite_min
    hi = stats.finite_max
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return None
    if hi <= lo:  # one value: a scale around it, so that its colour is the middle one
        lo, hi = (lo / 2, hi * 2) if scale == "log" else (lo - max(abs(lo), 1.0) / 2, hi + max(abs(hi), 1.0) / 2)
    return LogNorm(lo, hi) if scale == "log" else Normalize(lo, hi)


def short_name(da: xr.DataArray) -> str:
    """A variable's name in words: 'growth_rate' -> 'growth rate'; spelt as its long_name begins where that is the
    same name ('efolding_time', long_name 'e-folding time of ...' -> 'e-folding time')."""
    name, long = str(da.name), str(da.attrs.get("long_name", ""))
    letters = re.sub(r"[^a-z0-9]", "", name.lower())
    for m in re.finditer(r"\b", long):
        if re.sub(r"[^a-z0-9]", "", long[: m.start()].lower()) == letters:
            return long[: m.start()].strip()
    return name.replace("_", " ")


def number(value: float) -> str:
    """A value as a figure writes it: 0, 5.89, 1.2e-05, ∞."""
    if math.isinf(value):
        return "\u221e" if value > 0 else "\u2212\u221e"
    return f"{value:.3g}".replace("-", "\u2212")


def values_text(da: xr.DataArray, low: float, high: float) -> str:
    """'growth rate 0', 'growth rate −3.2 to −0.1': values of the variable ``da`` in a range."""
    return f"{short_name(da)} {number(low)}" + ("" if low == high else f" to {number(high)}")


def value_label(da: xr.DataArray, width: int) -> str:
    """A colour bar's or y axis's label: the variable's long_name (λ written as such) and units, in lines of ``width``."""
    name = re.sub(r"\bIm lambda\b", "Im\u00a0\u03bb", str(da.attrs.get("long_name", da.name)))  # never broken apart
    name = re.sub(r"\blambda\b", "\u03bb", name)
    units = units_text(str(da.attrs.get("units", "")))
    text = textwrap.fill(name, width, break_on_hyphens=False)
    return text + (f" [{units}]" if units else "")
