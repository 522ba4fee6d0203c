"""Spin rates with a unit: ``"14000 rpm"``, ``"250 Hz"``, ``"1500 rad/s"`` -> rad/s.

A spin rate (every parameter whose units are ``rad s-1``) may be written as a string of a number and one of the
units of :data:`UNITS`; everything is stored and computed in SI, rad/s.  Hz means revolutions per second, so
omega = 2 pi f; rpm means revolutions per minute, omega = 2 pi n / 60.  A small table rather than ``pint``: three
units of one quantity need no unit registry.
"""

from __future__ import annotations

import math
import re

from ..errors import StabmapError

SPIN = "rad s-1"  # the CF units of every spin rate (``Parameter.units``)
# Accepted spelling (lower case) -> (the unit's name, rad/s per unit).
UNITS = {
    "rad/s": ("rad/s", 1.0),
    "rad s-1": ("rad/s", 1.0),
    "rpm": ("rpm", 2.0 * math.pi / 60.0),
    "hz": ("Hz", 2.0 * math.pi),
}
DISPLAY = ("rpm", "Hz")  # units an axis may be shown in (``display_units``); rad/s is the stored unit itself
ACCEPTED = "rad/s, rpm or Hz"
_TEXT = re.compile(r"^\s*(?P<number>[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?)\s*(?P<unit>(?:[A-Za-z].*?)?)\s*$")


def looks_like_rate(text: str) -> bool:
    """True when ``text`` is a number, optionally followed by a word (a unit, known or not)."""
    return _TEXT.match(text) is not None


def split(where: str, text: str) -> tuple[float, str | None]:
    """``"14000 rpm"`` -> ``(14000.0, "rpm")``; a bare number -> ``(number, None)``; else a StabmapError naming ``where``."""
    match = _TEXT.match(text)
    if not match:
        raise StabmapError(f"{where} = {text!r}: give a number, or a spin rate with its unit such as \"14000 rpm\" ({ACCEPTED})")
    number, unit = float(match["number"]), match["unit"]
    if not unit:
        return number, None
    known = UNITS.get(unit.lower())
    if known is None:
        raise StabmapError(f"{where} = {text!r}: unknown unit {unit!r}; a spin rate may be given in {ACCEPTED}, e.g. \"14000 rpm\"")
    return number, known[0]


def factor(unit: str) -> float:
    """rad/s per ``unit`` (a name of :data:`UNITS`: ``"rpm"``, ``"Hz"``, ``"rad/s"``)."""
    return UNITS[unit.lower()][1]


def in_si(where: str, value, units: str):
    """``value`` with a spin rate's unit converted to rad/s (a float); anything but a string with a unit is returned
    as it is.

    ``units`` are the CF units of the quantity (``Parameter.units`` or a coordinate's ``units``): a string with a
    unit is accepted for a spin rate (``rad s-1``) only.
    """
    if not isinstance(value, str):
        return value
    if units != SPIN:
        # Any unit on another quantity ("1.2 kg", "9.81 m/s2") is refused for what it is, a unit where none is read,
        # before the unit is looked up: "unknown unit 'kg'" would send the user to the spin units instead.
        match = _TEXT.match(value)
        if match and match["unit"]:
            shown = " (dimensionless)" if units == "1" else f" in {units}" if units else ""
            raise StabmapError(f"{where} = {value!r}: a unit is accepted for spin rates only ({ACCEPTED}); "
                               f"give {where} as a plain number{shown}")
        return value  # not a number with a unit: the caller's check says what it should be
    number, unit = split(where, value)
    if unit is None:  # a number written as a string is not a number: the caller's check says so
        return value
    return number * factor(unit)


def common_unit(where: str, values) -> str | None:
    """The one unit written in ``values`` (strings or numbers), None if none; mixed units (or a unit on some values and
    not on others) are a StabmapError naming ``where``.  A unit is not checked here: the caller's ``in_si`` says what
    the quantity accepts (a spin unit, or none at all)."""
    units = {_word(v) if isinstance(v, str) else None for v in values}
    if len(units) > 1:
        shown = ", ".join(sorted(u or "no unit" for u in units))
        raise StabmapError(f"{where}: mixed units ({shown}); give every value of one axis in the same unit ({ACCEPTED})")
    return units.pop() if units else None


def _word(text: str) -> str | None:
    """The unit written after the number in ``text`` (a known one by its name in :data:`UNITS`), None if none."""
    match = _TEXT.match(text)
    if not match or not match["unit"]:
        return None
    known = UNITS.get(match["unit"].lower())
    return known[0] if known else match["unit"]


def check_display(where: str, unit) -> str:
    """A display unit of a spin-rate axis: "" (rad/s), "rpm" or "Hz"; any other is a StabmapError naming ``where``."""
    if unit in ("", None):
        return ""
    if not isinstance(unit, str) or unit.lower() not in ("rpm", "hz", "rad/s", "rad s-1"):
        raise StabmapError(f"{where} = {unit!r}: a spin-rate axis is shown in rpm or Hz (or rad/s, the stored unit)")
    name = UNITS[unit.lower()][0]
    return "" if name == "rad/s" else name


def unit_suffix(units) -> str:
    """``" kg"`` after a number on the terminal; ``""`` for no units or the dimensionless CF ``"1"``."""
    units = str(units or "")
    return "" if units in ("", "1") else f" {units}"
