"""Values as a reader gave them: a spin-rate axis in its display unit (rpm, Hz), with the stored SI value beside it.

An atlas stores every spin rate in rad/s; a scene that wrote an axis in rpm or Hz leaves that unit on the axis's
coordinate as ``display_units`` (stabmap.scene.grid).  The text of ``stabmap query``, ``stabmap critical`` and
``stabmap info`` echoes such an axis in that unit first, so an engineer who typed rpm reads rpm, and the SI value
the atlas holds follows in brackets: ``12000 rpm (1256.6371 rad s-1)``.  CSV and JSON stay in SI (with the
display unit named beside), as the variables are.
"""

from __future__ import annotations

import functools

import xarray as xr

from ..scene import units as spin_units
from ..scene.units import unit_suffix


def display_unit(ds: xr.Dataset | None, name: str) -> str:
    """The unit ``name`` is shown in, "rpm" or "Hz", or "" (its stored units): the ``display_units`` of its
    coordinate, else (critical values keep no coordinate of the scanned axis) that of the stored scene's axis."""
    if ds is None:
        return ""
    if name in ds.variables and ds[name].attrs.get("display_units"):
        return str(ds[name].attrs["display_units"])
    return _scene_units(ds).get(name, "")


def _scene_units(ds: xr.Dataset) -> dict[str, str]:
    """``{axis: display unit}`` of the scene stored in ``ds`` (none if there is none, or it does not read)."""
    text = ds.attrs.get("scene")
    return dict(_units_of_scene(str(text))) if text else {}


@functools.lru_cache(maxsize=8)
def _units_of_scene(text: str) -> tuple[tuple[str, str], ...]:
    from .. import systems
    from ..errors import StabmapError

    try:
        scene = systems.loads_scene(text, "the stored scene")
    except (StabmapError, OSError, ValueError):
        return ()
    return tuple((a.name, a.display_units) for a in getattr(scene, "grid", ()) if getattr(a, "display_units", ""))


def stored_units(ds: xr.Dataset | None, name: str) -> str:
    """The CF units of ``name`` ("" when none or dimensionless)."""
    if ds is None or name not in ds.variables:
        return ""
    return unit_suffix(ds[name].attrs.get("units")).strip()


def in_display(value: float, unit: str) -> float:
    """An SI spin rate (rad/s) in ``unit`` (rpm or Hz)."""
    return value / spin_units.factor(unit)


def number(value: float, digits: int = 8) -> str:
    return f"{value:.{digits}g}"


def value_text(value: float, units: str, display: str = "", digits: int = 8) -> str:
    """``12000 rpm (1256.6371 rad s-1)`` with a display unit, else ``1256.6371 rad s-1`` (``units`` the stored ones)."""
    si = f"{number(value, digits)}{unit_suffix(units)}"
    if not display:
        return si
    return f"{number(in_display(value, display), digits)} {display} ({si})"


def axis_value(ds: xr.Dataset | None, name: str, value: float, digits: int = 8) -> str:
    """One value of an atlas's axis or variable ``name`` with its units, a spin rate in its display unit first."""
    return value_text(value, stored_units(ds, name), display_unit(ds, name), digits)


def span_text(lo: float, hi: float, units: str, display: str = "", digits: int = 8, sep: str = " .. ") -> str:
    """``8000 .. 20000 rpm (837.75804 .. 2094.3951 rad s-1)``, or ``1 .. 150 rad s-1`` (``sep`` between the ends)."""
    si = f"{number(lo, digits)}{sep}{number(hi, digits)}{unit_suffix(units)}"
    if not display:
        return si
    return f"{number(in_display(lo, display), digits)}{sep}{number(in_display(hi, display), digits)} {display} ({si})"


def header_units(units: str, display: str = "") -> str:
    """A table column's unit in brackets: `` [rpm (rad s-1)]``, `` [rad s-1]`` or ``""``."""
    units = unit_suffix(units).strip()
    if display:
        return f" [{display} ({units})]" if units else f" [{display}]"
    return f" [{units}]" if units else ""


def cell(value: float, display: str = "", digits: int = 8) -> str:
    """A table cell: ``12000 (1256.6371)`` under a header ``[rpm (rad s-1)]``, else the number."""
    if display:
        return f"{number(in_display(value, display), digits)} ({number(value, digits)})"
    return number(value, digits)
