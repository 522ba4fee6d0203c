"""stabmap's class colours for xarray's own plots: ``ds.stability.stabmap.plot()``.

xarray's ``DataArray.plot`` reads ``long_name``, ``standard_name`` and ``units`` from a variable's attributes and
nothing else: its colours come from its arguments, viridis by default. A class variable such as ``stability``
(0 unstable, 1 stable) is then a ramp with stable in yellow, the colour stabmap's maps give one complex pair.
No attribute written to the file changes that, so the colours are passed as arguments: :func:`style` builds them
(a discrete colormap, its norm and a colour bar naming the classes), from the same palette as
:func:`stabmap.read.plot.colour`, so a class has one colour in every figure.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .. import systems
from ..errors import StabmapError


def _flag_classes(da: xr.DataArray) -> list[tuple[int, str, str]]:
    """(value, colour, name) of each flag of a CF flag variable."""
    from .plot import ABSENT_COLOUR, DEGENERATE_COLOUR, STABLE_COLOUR, UNDECIDED_COLOUR, UNSTABLE_COLOUR, colour

    values = [int(v) for v in np.atleast_1d(da.attrs["flag_values"])]
    meanings = str(da.attrs["flag_meanings"]).split()
    if len(values) != len(meanings):
        raise StabmapError(f"{da.name}: {len(values)} flag_values but {len(meanings)} flag_meanings; "
                           "the variable's attributes are damaged")
    by_meaning = {"stable": STABLE_COLOUR, "unstable": UNSTABLE_COLOUR[0], "degenerate": DEGENERATE_COLOUR, "absent": ABSENT_COLOUR,
                  "undecided": UNDECIDED_COLOUR}
    if any(m in by_meaning for m in meanings):  # classes of stability: the colours of the maps
        return [(v, by_meaning.get(m, colour(i + 1, stable=None)), m) for i, (v, m) in enumerate(zip(values, meanings, strict=True))]
    return [(v, colour(i, stable=None), m.replace("_", " ")) for i, (v, m) in enumerate(zip(values, meanings, strict=True))]


def _label_system(da: xr.DataArray, system):
    """The system whose label ``da`` is (``system`` if given and its label), or None."""
    if system is not None:
        return system if da.name == system.label else None
    for name in systems.names():
        candidate = systems.get(name)
        if candidate.label == da.name:
            return candidate
    return None


def classes(da: xr.DataArray, system=None) -> list[tuple[int, str, str]]:
    """(value, colour, name) of each class of ``da``: every flag of a flag variable, or the label values present."""
    from .blocks import counts
    from .plot import colour

    if "flag_values" in da.attrs and "flag_meanings" in da.attrs:
        return _flag_classes(da)
    owner = _label_system(da, system)
    if owner is None:
        raise StabmapError(
            f"{da.name}: stabmap's colours are for class variables, the label or a flag variable (with flag_values and "
            f"flag_meanings); draw this one with xarray's own colours, ds.{da.name}.plot()")
    present = sorted(counts(da.data))
    stable, absent, undecided = owner.stable_label, owner.absent_label, owner.undecided_label
    return [(v, colour(v, stable, absent, undecided), owner.class_name(v)) for v in present]


def style(da: xr.DataArray, system=None) -> dict:
    """Keyword arguments of xarray's ``DataArray.plot`` (``pcolormesh``, ``imshow``) that draw the class variable ``da``
    in stabmap's colours, with a colour bar naming each class.

    Parameters
    ----------
    da : xarray.DataArray
        The atlas's label (``n_complex_pairs``; closed chains: ``stability``; reactions: ``critical_node``) or a
        CF flag variable (``stability``, ``decided_by``, ``cell``, ...).
    system : stabmap.systems.System, optional
        The atlas's system (``ds.stabmap.style`` passes it); by default the system whose label ``da`` is named.

    Returns
    -------
    dict
        ``cmap``, ``norm`` and ``cbar_kwargs`` (``ticks`` at the class values, ``format`` their names, ``label``).
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.ticker import FuncFormatter

    found = sorted(classes(da, system))  # a norm's bins rise; flags may be listed in any order
    if not found:
        raise StabmapError(f"{da.name}: no values to draw (an empty selection)")
    values = np.array([v for v, _, _ in found], dtype=float)
    # one bin a class, cut halfway between neighbouring values: classes need not be consecutive numbers
    cuts = np.concatenate([[values[0] - 0.5], (values[1:] + values[:-1]) / 2, [values[-1] + 0.5]])
    names = {v: n for v, _, n in found}
    return {
        "cmap": ListedColormap([c for _, c, _ in found], name=f"stabmap-{da.name}"),
        "norm": BoundaryNorm(cuts, len(found)),
        # the variable's name, not its long_name: that runs off the figure beside a colour bar
        "cbar_kwargs": {"ticks": values, "format": FuncFormatter(lambda x, _pos=None: names.get(int(round(x)), "")), "label": str(da.name)},
    }


def plot(da: xr.DataArray, system=None, **kwargs):
    """``da.plot.pcolormesh`` in stabmap's colours (:func:`style`); ``kwargs`` go to xarray (``x=``, ``col=``, ``ax=``,
    ...) and override the style."""
    if da.ndim < 2:
        raise StabmapError(f"{da.name} has {'one axis' if da.ndim == 1 else 'no axis'}; xarray's colour maps need two "
                           "(stabmap.plot_atlas draws a strip of one axis)")
    extra = [d for d in da.dims if d not in (kwargs.get("col"), kwargs.get("row"))]
    if len(extra) > 2:
        raise StabmapError(f"{da.name} has {len(extra)} axes ({', '.join(map(str, extra))}) beyond col= and row=; a map shows two: "
                           f"select the others, e.g. ds.{da.name}.sel({extra[-1]}=...).stabmap.plot(), or make panels of one, "
                           f"col={str(extra[-1])!r}")
    merged = style(da, system)
    merged.update(kwargs)
    return da.plot.pcolormesh(**merged)
