"""Derived quantities of an atlas: auxiliary coordinates that are functions of the grid axes (a projectile's S_g,
the half height an aspect-ratio axis moves, the spin an S_g axis moves).

They are not decided point by point but computed from the scene and the grid (docs/projectile.md), so a query can
show them at a grid point and, where one rises or falls monotonically along a single scanned axis, take a value of
it in place of that axis: ``S_g=2`` becomes the spin rate at which S_g = 2, found by linear interpolation between
neighbouring grid values (the answer then says which axis and which value were used).  Where the quantity depends
on several axes, or turns back along its axis, no single grid value answers, and the request is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from ..errors import StabmapError
from . import shown
from .blocks import compute


def names(ds: xr.Dataset, axes: list[str]) -> list[str]:
    """The derived quantities of an atlas whose grid axes are ``axes``: coordinates over some of them, no axis itself."""
    return [str(k) for k, c in ds.coords.items()
            if k not in axes and c.ndim >= 1 and set(c.dims) <= set(axes) and np.issubdtype(c.dtype, np.number)]


def at_point(ds: xr.Dataset, axes: list[str], point: dict[str, int]) -> dict[str, float]:
    """Every derived quantity at one grid point (``point``: the index of each grid axis)."""
    found = [ds[k].isel({d: point[d] for d in ds[k].dims}) for k in names(ds, axes)]
    return {str(v.name): float(v) for v in compute(*found)}


@dataclass(frozen=True)
class Inverted:
    """A value of a derived quantity turned into a value of the one grid axis it is monotone along."""

    name: str  # the derived quantity asked, e.g. S_g
    requested: float  # its value asked
    axis: str  # the grid axis it moves along
    value: float  # that axis's value where the quantity equals ``requested`` (linear between grid values)
    edge: bool = False  # outside the quantity's range on the grid: the nearest edge was used

    def describe(self, ds: xr.Dataset | None) -> str:
        edge = " (outside the scan: nearest edge)" if self.edge else " (linear between neighbouring grid values)"
        return (f"{self.name} = {shown.axis_value(ds, self.name, self.requested)} -> {self.axis} = "
                f"{shown.axis_value(ds, self.axis, self.value)}, where {self.name} = {self.requested:g} along {self.axis}{edge}")


def along(ds: xr.Dataset, name: str) -> tuple[str, np.ndarray, np.ndarray]:
    """The grid axis a derived quantity is monotone along: (axis, the axis's grid values, the quantity's values there).

    A StabmapError naming the quantity where it depends on more than one axis or is not strictly monotone.
    """
    c = ds[name]
    if c.ndim != 1:
        raise StabmapError(f"{name} depends on {' and '.join(map(str, c.dims))}, so a value of it is no single grid point; "
                           f"give the grid axes instead ({', '.join(map(str, c.dims))})")
    axis = str(c.dims[0])
    x = np.asarray(ds[axis].values, dtype=np.float64)
    y = np.asarray(compute(c)[0].values, dtype=np.float64)
    step = np.diff(y)
    if y.size > 1 and not ((step > 0).all() or (step < 0).all()):
        raise StabmapError(f"{name} is not monotone along {axis} on this grid, so a value of it may lie at several {axis}; "
                           f"give {axis} instead")
    return axis, x, y


def invert(ds: xr.Dataset, name: str, value: float, *, nearest_edge: bool = False) -> Inverted:
    """The value of the grid axis where the derived quantity ``name`` equals ``value`` (linear between grid values).

    Outside the range the grid gives the quantity, a StabmapError naming the range and ``--nearest-edge``, unless
    ``nearest_edge`` (then the axis's end where the quantity is nearest).
    """
    axis, x, y = along(ds, name)
    if y.size == 1:
        return Inverted(name, value, axis, float(x[0]), edge=value != y[0])
    order = np.argsort(y)
    lo, hi = float(y[order[0]]), float(y[order[-1]])
    if not within(value, lo, hi):
        if not nearest_edge:
            raise StabmapError(
                f"{name} = {value:g} lies outside this atlas: along its {x.size} grid values of {axis}, {name} runs from "
                f"{lo:.8g} to {hi:.8g}{shown.header_units(shown.stored_units(ds, name))}; give a value inside, or "
                "--nearest-edge (Python: nearest_edge=True) for the nearest end of the scan")
        return Inverted(name, value, axis, float(x[order[0]] if value < lo else x[order[-1]]), edge=True)
    return Inverted(name, value, axis, float(np.interp(value, y[order], x[order])))


def within(value: float, lo: float, hi: float) -> bool:
    """``lo <= value <= hi``, up to the 8 significant digits the text prints (a value copied from it is inside)."""
    slack = 1e-7 * max(abs(lo), abs(hi))
    return lo - slack <= value <= hi + slack


def as_axis(ds: xr.Dataset, name: str) -> xr.Dataset:
    """``ds`` with the derived quantity ``name`` as the index of the grid axis it is monotone along (for a plot
    against S_g, say: ``as_axis(ds, "S_g")`` then has the dimension S_g where it had omega); the axis's values stay
    a coordinate. A StabmapError, as :func:`along`, where ``name`` is not monotone along one axis."""
    known = names(ds, [str(d) for d in ds.dims])
    if name not in known:
        raise StabmapError(f"{name!r} is no derived quantity of this atlas; those it has: {', '.join(known) or '(none)'}")
    axis, _, _ = along(ds, name)
    return ds.swap_dims({axis: name})
