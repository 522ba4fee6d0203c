"""A scannable parameter's units and limits, and the one check every number of a scene goes through."""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass

from ..errors import StabmapError
from .units import in_si


@dataclass(frozen=True)
class Parameter:
    """What a parameter name means: symbol, CF units, a long name (``{k}`` for the body or joint) and its limits."""

    symbol: str
    units: str
    long_name: str
    minimum: float | None = None  # None: any finite value
    strict: bool = False  # minimum excluded


def check_value(where: str, value, info: Parameter) -> float:
    """Return ``value`` as a float or raise a StabmapError naming ``where``; a spin rate may carry a unit ("14000 rpm")."""
    value = in_si(where, value, info.units)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        quoted = " (remove the quotes: TOML reads a quoted number as text)" if isinstance(value, str) and is_plain_number(value) else ""
        raise StabmapError(f"{where} must be a number, got {value!r}{quoted}")
    value = float(value)
    if not math.isfinite(value):
        raise StabmapError(f"{where} must be finite, got {value}")
    if info.minimum is not None:
        if info.strict and value <= info.minimum:
            raise StabmapError(f"{where} must be > {info.minimum:g}, got {value}")
        if not info.strict and value < info.minimum:
            raise StabmapError(f"{where} must be >= {info.minimum:g}, got {value}")
    return value


def is_plain_number(text: str) -> bool:
    """Whether ``text`` reads as a float ("9.81", "1e-3", "nan"), with no unit after it."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def did_you_mean(name: str, known) -> str:
    """"did you mean 'x'? " when a known name is close to ``name`` (a misspelling), else ""."""
    close = difflib.get_close_matches(name, list(known), n=1)
    return f"did you mean {close[0]!r}? " if close else ""


def no_unknown(table, allowed, where: str) -> None:
    """A TOML table with only ``allowed`` keys, or a StabmapError naming the first other one."""
    if not isinstance(table, dict):
        raise StabmapError(f"{where} must be a table, got {table!r}")
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise StabmapError(f"{where}: unknown key {unknown[0]!r}; {did_you_mean(unknown[0], allowed)}allowed keys are "
                           f"{', '.join(sorted(allowed))}")
