"""The grid of a scan: one axis per scanned parameter, read from a scene's ``[grid]`` table.

An axis is named exactly like the parameter it scans (the name becomes the
Dataset dimension) and holds its values, distinct and increasing (given
decreasing, ``start = 40, stop = 1``, they are the same axis, stored increasing).  In TOML it is
``name = { start = .., stop = .., num = .., scale = "linear" | "log" }`` or
``name = { values = [...] }``.  An axis given as a list of values is **discrete**: a set of separate cases, so a
grid cell does not span it (its CF bounds are the value itself) and cells are proved in the other axes only;
``discrete = true`` makes a start/stop/num axis discrete too, ``discrete = false`` makes a list continuous.
Which names exist and what values they may take
is the system's (``parameter``, a function of the name).  A spin-rate axis may be
given in rpm or Hz (``start = "5000 rpm"``, one unit for the whole axis): its
values are stored in rad/s and the unit is kept as the axis's ``display_units``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..errors import StabmapError
from . import units
from .values import Parameter, check_value, no_unknown

SCALES = ("linear", "log", "values")
# An axis's values are held in memory as Python floats (the scene) and as the atlas's coordinate and its bounds, about
# 60 bytes a value, and each is checked: a million take 60 MB and a second or two, and a finer single axis is a job for
# ``stabmap critical`` (docs/critical.md), which locates its boundaries to 1e-10.
MAX_AXIS_VALUES = 1_000_000
_AXIS_KEYS = {"start", "stop", "num", "scale", "values", "display_units", "discrete"}
_NUMBER = Parameter("", "", "")  # any finite number: the limits are the system's (check_axes)


@dataclass(frozen=True)
class Axis:
    """One scanned parameter: its name (the Dataset dimension) and its values, distinct and increasing."""

    name: str
    values: tuple[float, ...]
    scale: str = "linear"  # "linear" | "log" | "values" (listed explicitly)
    display_units: str = ""  # a spin rate's unit for display, "rpm" or "Hz"; "": the stored unit (values are SI)
    # separate cases rather than samples of a continuum: cells do not span the axis (None: scale == "values")
    discrete: bool | None = None

    def __post_init__(self):
        where = f"grid.{self.name}"
        if isinstance(self.values, (str, bytes)) or not hasattr(self.values, "__len__") or not len(self.values):
            raise StabmapError(f"{where}.values must be a non-empty list of numbers")
        object.__setattr__(self, "values", tuple(check_value(f"{where}.values[{i + 1}]", v, _NUMBER) for i, v in enumerate(self.values)))
        if self.scale not in SCALES:
            raise StabmapError(f'{where}.scale must be "linear", "log" or "values", got {self.scale!r}')
        diffs = np.diff(self.values)
        if len(self.values) > 1 and not (np.all(diffs > 0) or np.all(diffs < 0)):
            raise StabmapError(f"{where}: values must be distinct and sorted (increasing or decreasing)")
        if len(self.values) > 1 and diffs[0] < 0:
            # start > stop (or a decreasing list) is the same axis: stored increasing, as every reader of an atlas
            # takes it (a cell spans a node and the next one up; plots and searches go upward)
            object.__setattr__(self, "values", self.values[::-1])
        if self.scale == "log" and min(self.values) <= 0:
            raise StabmapError(f'{where}: scale = "log" needs values > 0, got {min(self.values)}')
        object.__setattr__(self, "display_units", units.check_display(f"{where}.display_units", self.display_units))
        if self.discrete is None:
            object.__setattr__(self, "discrete", self.scale == "values")
        elif not isinstance(self.discrete, bool):
            raise StabmapError(f"{where}.discrete must be true or false, got {self.discrete!r}")

    @property
    def continuous(self) -> bool:
        """Whether grid cells span the axis: a scanned (not discrete) axis of more than one value."""
        return len(self.values) > 1 and not self.discrete

    @property
    def array(self) -> np.ndarray:
        return np.asarray(self.values, dtype=np.float64)

    def to_dict(self) -> dict:
        """The TOML table of the axis: start/stop/num where that gives these very values, else the values."""
        n = len(self.values)
        if self.scale in ("linear", "log") and n > 2:
            spaced = np.geomspace if self.scale == "log" else np.linspace
            if np.array_equal(spaced(self.values[0], self.values[-1], n), self.array):
                return {"start": self.values[0], "stop": self.values[-1], "num": n, "scale": self.scale, **self._display(),
                        **({"discrete": True} if self.discrete else {})}
        return {"values": list(self.values), "scale": self.scale, **self._display(), **({} if self.discrete else {"discrete": False})}

    def _display(self) -> dict:
        return {"display_units": self.display_units} if self.display_units else {}


def check_axes(axes: tuple[Axis, ...], parameter: Callable[[str], Parameter]) -> None:
    """Every axis names a parameter (``parameter`` raises for other names) and holds values it may take."""
    names = [a.name for a in axes]
    for a in axes:
        if names.count(a.name) > 1:
            raise StabmapError(f"grid axis {a.name!r} is given twice; give each axis once")
        info = parameter(a.name)
        for i, v in enumerate(a.values):
            check_value(f"grid.{a.name}.values[{i + 1}]", v, info)
        if a.display_units and info.units != units.SPIN:
            raise StabmapError(f"grid.{a.name}.display_units: only a spin-rate axis [rad s-1] has display units; "
                               f"{a.name} is in [{info.units}], remove display_units")


def parse_axes(raw, parameter: Callable[[str], Parameter]) -> tuple[Axis, ...]:
    """The axes of a ``[grid]`` table; errors name the key (``grid.omega.num``) and the fix."""
    if not isinstance(raw, dict):
        raise StabmapError(f"grid must be a table of axes, got {raw!r}")
    axes = []
    for name, spec in raw.items():
        info = parameter(name)
        where = f"grid.{name}"
        no_unknown(spec, _AXIS_KEYS, where)
        if "values" in spec:
            extra = set(spec) - {"values", "scale", "display_units", "discrete"}
            if extra:
                raise StabmapError(f"{where}: give either values or start/stop/num, not both (remove {sorted(extra)[0]!r})")
            values = spec["values"]
            if not isinstance(values, list) or not values:
                raise StabmapError(f"{where}.values must be a non-empty list of numbers")
            converted = [units.in_si(f"{where}.values[{i + 1}]", v, info.units) for i, v in enumerate(values)]
            unit = units.common_unit(f"{where}.values", values)
            values = converted
            axes.append(Axis(name, tuple(values), spec.get("scale", "values"), _display(spec, unit), spec.get("discrete", True)))
            continue
        for key in ("start", "stop", "num"):
            if key not in spec:
                raise StabmapError(f"{where}.{key} is missing (or give values = [...])")
        num = spec["num"]
        if isinstance(num, bool) or not isinstance(num, int) or num < 1:
            raise StabmapError(f"{where}.num must be a whole number >= 1, got {num!r}")
        if num > MAX_AXIS_VALUES:
            raise StabmapError(f"{where}.num = {num:,}: an axis holds at most {MAX_AXIS_VALUES:,} values; give a smaller num "
                               "(to locate a boundary finely along one axis, use 'stabmap critical', docs/critical.md)")
        start = check_value(f"{where}.start", spec["start"], info)
        stop = check_value(f"{where}.stop", spec["stop"], info)
        unit = units.common_unit(where, [spec["start"], spec["stop"]])
        if num == 1 and stop != start:
            raise StabmapError(f"{where}: num = 1 gives the one value start = {start:g} and would ignore stop = {stop:g}; "
                               f"give num >= 2, or values = [{start:g}]")
        scale = spec.get("scale", "linear")
        start, stop = min(start, stop), max(start, stop)  # descending: the same axis (Axis), and the very same values
        if scale == "linear":
            values = np.linspace(start, stop, num)
        elif scale == "log":
            if start <= 0 or stop <= 0:
                raise StabmapError(f'{where}: scale = "log" needs start > 0 and stop > 0, got {start} and {stop}')
            values = np.geomspace(start, stop, num)
        else:
            raise StabmapError(f'{where}.scale must be "linear" or "log", got {scale!r}')
        axes.append(Axis(name, tuple(float(v) for v in values), scale, _display(spec, unit), spec.get("discrete", False)))
    return tuple(axes)


def _display(spec: dict, unit: str | None) -> str:
    """The display unit of an axis: ``display_units`` if given, else the unit its values were written in."""
    return spec.get("display_units", unit if unit in units.DISPLAY else "")


def resample(scene, **nums: int):
    """The scene with the named grid axes resampled to ``nums[name]`` points over the same range and scale."""
    unknown = set(nums) - {a.name for a in scene.grid}
    if unknown:
        raise StabmapError(f"resample: {sorted(unknown)[0]!r} is not a grid axis of this scene")
    axes = []
    for a in scene.grid:
        if a.name in nums:
            lo, hi = a.values[0], a.values[-1]
            values = np.geomspace(lo, hi, nums[a.name]) if a.scale == "log" else np.linspace(lo, hi, nums[a.name])
            a = replace(a, values=tuple(float(v) for v in values))
        axes.append(a)
    return replace(scene, grid=tuple(axes))
