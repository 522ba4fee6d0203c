"""Questions asked of a saved atlas (docs/query.md).

- :func:`label_at`: the label at the grid point nearest to a point.
- :func:`stable_fraction`: the fraction of stable grid points in a slice.
- :func:`boundaries`: where the label changes along one axis, bracketed by neighbouring grid values.
- :func:`smallest_stable`: the smallest stable grid value of one axis, for each value of another.
- :func:`summary`: counts that describe a whole atlas.

**Selections.** The keyword arguments of ``stable_fraction``, ``boundaries`` and
``smallest_stable`` select a slice, one keyword per grid axis:

- a number fixes the axis at its *nearest grid value* (the results say which value was used);
- a pair ``(lo, hi)`` or ``slice(lo, hi)`` keeps the grid values ``lo <= v <= hi`` (either end may be
  ``None``: unbounded; the two ends may come in either order);
- an axis not named is kept whole.

**What the answers are.** Every answer is about grid points, never about values between them. A boundary is
known only to lie between two neighbouring grid values with different labels; ``stabmap critical`` (stabmap.critical)
locates such ends to 1e-10 with proof (docs/critical.md). In an adaptive atlas (``stabmap atlas --refine``) some
points were not computed but inferred from their grid cell's corners (``decided_by`` = inferred_from_cell_corners);
every answer counts or flags them.

**Any size.** Every question also takes a lazily opened atlas (``open_atlas(path, lazy=True)``, as ``stabmap
query`` opens it) and reads it chunk by chunk (:mod:`stabmap.read.blocks`): memory stays bounded by a few chunks,
whatever the size of the atlas, and the answers are those of the atlas in memory.

``stabmap.read.report.render`` turns any answer into the text, CSV or JSON that ``stabmap query`` prints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from .. import systems
from ..errors import StabmapError, given, param
from ..scene.units import common_unit, in_si, looks_like_rate
from ..scene.values import is_plain_number
from ..store.dataset import is_critical
from ..store.variables import INFERRED
from . import derived, shown
from .blocks import changes, compute, first_true

CRITICAL_HINT = "'stabmap critical SCENE --along {along}' locates the ends to 1e-10 (docs/critical.md)"


@dataclass(frozen=True)
class Label:
    """Every variable of an atlas at the grid point nearest to a requested point.

    ``values`` holds each variable by name (a flag variable as its meaning), in the system's order; they are
    also attributes: ``label.n_complex_pairs``, ``label.stability``, ...
    """

    requested: dict[str, float]
    grid_point: dict[str, float]
    values: dict[str, object]
    outside: tuple[str, ...]  # axes on which the request lies outside the grid
    provenance: str | None = None  # the name of the variable that says how the point was decided
    derived: dict[str, float] = field(default_factory=dict)  # derived quantities (S_g, ...) at the grid point
    via: dict[str, str] = field(default_factory=dict)  # axes a derived quantity gave: how (stabmap.read.derived)

    def __getattr__(self, name: str):
        values = self.__dict__.get("values", {})
        if name in values:
            return values[name]
        raise AttributeError(name)

    @property
    def inferred(self) -> bool:
        """True when the point was not computed (adaptive atlas: inferred from its grid cell's corners)."""
        return self.provenance is not None and self.values[self.provenance] == INFERRED


@dataclass(frozen=True)
class AxisSelection:
    """How one grid axis entered a query: the request and the grid values actually used."""

    name: str
    units: str
    requested: float | tuple[float | None, float | None] | None  # a number, a range (lo, hi), or None: whole axis
    values: tuple[float, ...]  # the grid values used, in grid order
    outside: bool = False  # a number outside the grid's range: the nearest end was used (only asked for: nearest_edge)
    display_units: str = ""  # a spin-rate axis's display unit (rpm, Hz): the text shows it first, SI beside
    via: str = ""  # the request came as a derived quantity (S_g = 2): how it became a value of this axis

    @property
    def fixed(self) -> bool:
        """True when a number fixed the axis at one grid value."""
        return self.requested is not None and not isinstance(self.requested, tuple)

    @property
    def bounds(self) -> tuple[float, float]:
        """The smallest and largest grid value used."""
        return min(self.values), max(self.values)

    def describe(self) -> str:
        """One line of text, e.g. ``K_1 = 3 -> nearest grid value 3.0150754 N m rad-1``; a spin rate in its display
        unit first (``omega = 12000 rpm (1256.6371 rad s-1) -> ...``)."""
        units, disp = self.units, self.display_units
        req = self.requested
        via = f"{self.via}; " if self.via else ""
        if req is not None and not isinstance(req, tuple):  # fixed (a local name, so the type checker narrows it)
            note = " (outside the scan: nearest edge, as asked)" if self.outside else ""
            asked = f"{via}{self.name}" if self.via else f"{self.name} = {shown.value_text(req, units, disp, 6)}"
            return f"{asked} -> nearest grid value {shown.value_text(self.values[0], units, disp)}{note}"
        lo, hi = self.bounds
        n = len(self.values)
        span = f"{n} grid value{'s' if n != 1 else ''}, {shown.span_text(lo, hi, units, disp)}"
        if req is None:
            return f"{self.name}: all {span}"
        a, b = req
        ends = f"[{'-inf' if a is None else shown.number(_shown(a, disp), 6)}, {'inf' if b is None else shown.number(_shown(b, disp), 6)}]"
        return f"{via}{self.name} in {ends}{' ' + disp if disp else ''}: {span}"


def _shown(value: float, display: str) -> float:
    return shown.in_display(value, display) if display else value


@dataclass(frozen=True)
class StableFraction:
    """The stable fraction of a slice of an atlas, with what was counted and where."""

    fraction: float  # stable / points
    stable: int  # the label is the system's stable_label
    points: int  # grid points in the slice
    unstable: int  # another label >= 0
    degenerate: int  # a negative label other than the system's absent/undecided_label
    inferred: int  # points not computed (decided_by = inferred_from_cell_corners), stable or not
    inferred_stable: int  # of those, how many carry the label stable
    axes: dict[str, AxisSelection]  # every grid axis of the atlas, in order
    absent: int | None = None  # points with nothing to decide (the system's absent_label); None: the system has none
    undecided: int | None = None  # points whose class was not proved (the system's undecided_label); None: it has none

    @property
    def selected(self) -> dict[str, float | tuple[float, float]]:
        """The grid coordinates used: one value for a fixed axis, (smallest, largest) grid value otherwise."""
        return {k: a.values[0] if a.fixed else a.bounds for k, a in self.axes.items()}

    def __repr__(self) -> str:
        # Short: the axes hold every grid value used (thousands of numbers); ``.axes`` still has them.
        where = ", ".join(a.describe() for a in self.axes.values())
        return f"StableFraction({self.fraction:.6g}: {self.stable} of {self.points} points stable; {where})"

    @property
    def computed_fraction(self) -> float:
        """The stable fraction among the computed (not inferred) points only; NaN if none was computed."""
        computed = self.points - self.inferred
        return (self.stable - self.inferred_stable) / computed if computed else float("nan")


# ---------------------------------------------------------------------------------------------------------------
# selection


def grid_axes(ds: xr.Dataset) -> list[str]:
    """The grid axes of an atlas; a clear error for a critical-values Dataset or anything else."""
    if is_critical(ds):
        raise StabmapError(
            "this Dataset holds critical values (stabmap critical), not an atlas; its intervals are in "
            f"{ds.attrs.get('critical_along', 'ALONG')}_stable_lower/upper ('stabmap info FILE' lists them)"
        )
    system = systems.of_atlas(ds.attrs)
    missing = [v for v in (system.label, system.provenance) if v is not None and v not in ds]
    if missing:
        raise StabmapError(f"this Dataset is not a stabmap atlas (no {'/'.join(missing)}); open one with stabmap.open_atlas")
    return list(ds[system.label].dims)


def _inferred(ds: xr.Dataset, system) -> xr.DataArray:
    """Where points were not computed but inferred from their grid cell's corners (adaptive atlases), on the grid."""
    flags = system.variable(system.provenance) if system.provenance is not None else None
    if flags is None or INFERRED not in flags.meanings:
        return xr.zeros_like(ds[system.label], dtype=bool)
    return ds[system.provenance] == flags.value(INFERRED)


def _not_an_axis(ds: xr.Dataset, name: str, dims: list[str], what: str | None = None) -> StabmapError:
    """``name`` is no grid axis of ``ds``; ``what`` says where it was given (default: the name itself)."""
    axes = ", ".join(dims) or "(none)"
    what = repr(name) if what is None else what
    if name in ds.coords and ds[name].ndim == 0:
        units = ds[name].attrs.get("units", "")
        return StabmapError(f"{what} is fixed at {float(ds[name]):g} {units} in this atlas, not a grid axis; its axes are: {axes}")
    return StabmapError(f"{what} is not an axis of this atlas; its axes are: {axes}")


def _number(name: str, value, units: str = "") -> float:
    if isinstance(value, str) and not is_plain_number(value) and looks_like_rate(value):
        value = in_si(name, value, units)  # a spin rate may carry its unit: "14000 rpm"
    try:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, str, np.integer, np.floating)):
            raise ValueError
        value = float(value)
    except ValueError:
        raise StabmapError(f"{name}={value!r}: give a number (the nearest grid value is used) or a range (lo, hi)") from None
    if math.isnan(value):
        raise StabmapError(f"{name}=nan: give a number (the nearest grid value is used) or a range (lo, hi)")
    return value


def requested_value(name: str, value, units: str = "") -> float | tuple[float | None, float | None]:
    """A number, or a range (lo, hi) with lo <= hi (None: unbounded), from a user's value."""
    if isinstance(value, slice):
        if value.step is not None:
            raise StabmapError(f"{name}={value!r}: a range has no step; write {name}=({value.start}, {value.stop})")
        ends = (value.start, value.stop)
    elif isinstance(value, (tuple, list)):
        if len(value) != 2:
            raise StabmapError(f"{name}={value!r}: a range is a pair (lo, hi), e.g. {name}=(1.0, 2.5)")
        ends = tuple(value)
    else:
        return _number(name, value, units)
    lo, hi = (None if v is None else _number(name, v, units) for v in ends)
    if lo is not None and hi is not None and lo > hi:
        lo, hi = hi, lo
    return lo, hi


def select(ds: xr.Dataset, sel: dict, *, along: str | None = None, nearest_edge: bool = False) -> tuple[xr.Dataset, dict[str, AxisSelection]]:
    """The slice of ``ds`` that ``sel`` asks for, and how every grid axis was selected.

    Parameters
    ----------
    ds : xarray.Dataset
        An atlas.
    sel : dict
        ``{axis: number | (lo, hi) | slice(lo, hi)}`` (module docstring). A number removes the axis (it stays
        as a scalar coordinate holding the grid value used); a range keeps the grid values inside it. A derived
        quantity (``S_g``) monotone along one grid axis stands for that axis (:mod:`stabmap.read.derived`).
    along : str, optional
        An axis that must stay an axis (boundaries, smallest_stable): a number for it is an error.
    nearest_edge : bool
        A number outside the scanned range takes the nearest end of the scan; without it, that is an error.
    """
    dims = grid_axes(ds)
    index, axes = {}, {}
    for name, (requested, via, edge) in _on_axes(ds, sel, dims, nearest_edge).items():
        units = str(ds[name].attrs.get("units", ""))
        disp = shown.display_unit(ds, name)
        grid = np.asarray(ds[name].values, dtype=np.float64)
        if isinstance(requested, tuple):
            lo, hi = requested
            keep = np.ones(grid.size, dtype=bool)
            if lo is not None:
                keep &= grid >= lo
            if hi is not None:
                keep &= grid <= hi
            if not keep.any():
                raise StabmapError(
                    f"{name} in [{'-inf' if lo is None else f'{lo:g}'}, {'inf' if hi is None else f'{hi:g}'}] holds no grid "
                    f"value; the {grid.size} grid values of {name} run from {shown.span_text(grid.min(), grid.max(), units, disp, sep=' to ')}"
                )
            index[name] = _contiguous(np.flatnonzero(keep))
            axes[name] = AxisSelection(name, units, requested, tuple(float(v) for v in grid[keep]), display_units=disp, via=via)
        else:
            if name == along:
                raise StabmapError(
                    f"{name}={requested:g} would fix {name}, the axis searched along; give a range instead, "
                    f"e.g. {name}=({grid.min():g}, {grid.max():g}), or leave {name} out"
                )
            outside = not via and not derived.within(requested, float(grid.min()), float(grid.max()))
            if outside and not nearest_edge:
                raise outside_error(ds, name, requested, grid)
            i = int(ds.indexes[name].get_indexer([requested], method="nearest")[0])
            index[name] = i
            axes[name] = AxisSelection(name, units, requested, (float(grid[i]),), outside or edge,
                                       display_units=disp, via=via)
    for d in dims:
        if d not in axes:
            axes[d] = AxisSelection(d, str(ds[d].attrs.get("units", "")), None, tuple(float(v) for v in ds[d].values),
                                    display_units=shown.display_unit(ds, d))
    return (ds.isel(index) if index else ds), {d: axes[d] for d in dims}


def outside_error(ds: xr.Dataset, name: str, value: float, grid: np.ndarray) -> StabmapError:
    """A number outside an axis's scan: one line with the value, the scan and the option that takes the nearest edge."""
    units, disp = str(ds[name].attrs.get("units", "")), shown.display_unit(ds, name)
    return StabmapError(
        f"{name} = {shown.value_text(value, units, disp, 6)} lies outside the scan of {name}, "
        f"{shown.span_text(float(grid.min()), float(grid.max()), units, disp)}; give a value inside it, or --nearest-edge "
        "(Python: nearest_edge=True) to use the nearest end of the scan"
    )


def _on_axes(ds: xr.Dataset, sel: dict, dims: list[str], nearest_edge: bool) -> dict[str, tuple]:
    """``sel`` with every entry on a grid axis: ``{axis: (number or (lo, hi), how a derived quantity gave it or "",
    whether that quantity lay outside its range on the grid and gave the nearest edge)}``."""
    out: dict[str, tuple] = {}
    made_by: dict[str, str] = {}
    extra = derived.names(ds, dims)
    for name, value in sel.items():
        units = str(ds[name].attrs.get("units", "")) if name in ds.variables else ""
        edge = False
        if name in dims:
            axis, requested, via = name, requested_value(name, value, units), ""
        elif name in extra:
            requested = requested_value(name, value, units)
            if isinstance(requested, tuple):  # a range of the quantity: the range of the axis between its ends
                axis = derived.along(ds, name)[0]
                ends = [None if e is None else derived.invert(ds, name, e, nearest_edge=True).value for e in requested]
                if _falls(ds, name):  # a falling quantity: its low end is the axis's high end
                    ends = ends[::-1]
                shown_ends = ", ".join("-inf" if e is None and i == 0 else "inf" if e is None else f"{e:g}" for i, e in enumerate(requested))
                via = f"{name} in [{shown_ends}] -> {axis} (linear between grid values)"
                requested = (ends[0], ends[1])
            else:
                inv = derived.invert(ds, name, requested, nearest_edge=nearest_edge)
                axis, requested, via, edge = inv.axis, inv.value, inv.describe(ds), inv.edge
        else:
            raise _not_an_axis(ds, name, dims)
        if axis in out:
            first = made_by.get(axis, axis)
            raise StabmapError(f"{name} and {first} both set {axis}; give one of them")
        out[axis] = (requested, via, edge)
        made_by[axis] = name
    return out


def _falls(ds: xr.Dataset, name: str) -> bool:
    _, _, y = derived.along(ds, name)
    return bool(y.size > 1 and y[-1] < y[0])


def _contiguous(index: np.ndarray) -> np.ndarray | slice:
    """A run of consecutive indices as a slice (a lazy atlas then reads only that part of each chunk)."""
    if index.size and index[-1] - index[0] == index.size - 1:
        return slice(int(index[0]), int(index[-1]) + 1)
    return index


def fixed_names(axes: dict[str, AxisSelection]) -> str:
    """The axes a number fixed, space-separated (a netCDF-safe string attribute)."""
    return " ".join(a.name for a in axes.values() if a.fixed)


def selection_text(axes: dict[str, AxisSelection]) -> str:
    """The fixed and ranged axes, one description each, joined by '; ' (a netCDF-safe string attribute)."""
    return "; ".join(a.describe() for a in axes.values() if a.requested is not None)


# ---------------------------------------------------------------------------------------------------------------
# the questions


def label_at(ds: xr.Dataset, /, *, nearest_edge: bool = False, **point: float) -> Label:
    """Label of the grid point nearest to ``point`` (one value per grid axis).

    A derived quantity monotone along one grid axis (a projectile's ``S_g``) may stand for that axis. A value
    outside the scan is an error unless ``nearest_edge`` (then the nearest end of the scan is used, and said).
    """
    dims = grid_axes(ds)
    extra = derived.names(ds, dims)
    unknown = [k for k in point if k not in dims and k not in extra]
    if unknown:
        raise _not_an_axis(ds, unknown[0], dims)
    for k, v in point.items():
        if isinstance(v, (tuple, list, slice)):
            raise StabmapError(f"{k}={v!r}: the label is asked at one point; a range belongs to stable_fraction, boundaries or smallest_stable "
                "(stabmap query --fraction, --boundaries AXIS, --smallest-stable)")
    asked = _on_axes(ds, point, dims, nearest_edge)
    missing = [d for d in dims if d not in asked]
    if missing:
        raise StabmapError(f"give a value for every axis; missing: {', '.join(missing)} (e.g. {missing[0]}={float(ds[missing[0]][0]):g})")
    at = {k: float(v) for k, (v, _, _) in asked.items()}
    outside = tuple(d for d in dims if not derived.within(at[d], float(ds[d].min()), float(ds[d].max())))
    if outside and not nearest_edge:
        raise outside_error(ds, outside[0], at[outside[0]], np.asarray(ds[outside[0]].values, dtype=np.float64))
    outside += tuple(d for d, (_, _, edge) in asked.items() if edge and d not in outside)
    index = {d: int(ds.indexes[d].get_indexer([at[d]], method="nearest")[0]) for d in dims}
    sel = ds.isel(index) if dims else ds
    system = systems.of_atlas(ds.attrs)
    sel, = compute(sel)  # one point of every variable: a lazy atlas reads one chunk of each
    values: dict[str, object] = {}
    for var in system.atlas_variables:
        if var.name in sel:
            x = sel[var.name].values
            if var.flags:  # a flag variable on a dimension of its own (root_kind, say): one meaning per entry
                values[var.name] = var.meaning(int(x)) if x.ndim == 0 else [var.meaning(int(e)) for e in x.ravel()]
            else:
                values[var.name] = x.item() if x.ndim == 0 else x
    return Label(
        requested=at,
        grid_point={d: float(sel[d]) for d in dims},
        values=values,
        outside=outside,
        provenance=system.provenance if system.provenance in values else None,
        derived={k: float(sel[k]) for k in extra},
        via={k: via for k, (_, via, _) in asked.items() if via},
    )


def stable_fraction(ds: xr.Dataset, /, *, nearest_edge: bool = False, **sel) -> StableFraction:
    """The fraction of stable grid points (the label equal to the system's ``stable_label``) in a slice of an atlas.

    Parameters
    ----------
    ds : xarray.Dataset
        An atlas.
    **sel
        ``axis=number`` fixes the axis at its nearest grid value, ``axis=(lo, hi)`` keeps a range of it; the
        fraction is taken over every grid point of what remains (module docstring).

    Returns
    -------
    StableFraction
        ``fraction`` with the counts behind it (stable, unstable, degenerate, points), how many points were
        inferred rather than computed, and ``axes``/``selected``: the grid values actually used.

    Examples
    --------
    >>> stable_fraction(ds, K_1=3)                  # a gyroscopes' atlas: every omega, K_1 nearest to 3
    >>> stable_fraction(ds, omega=(20, 60))         # 20 <= omega <= 60, every K_1
    """
    sub, axes = select(ds, sel, nearest_edge=nearest_edge)
    system = stable_system(ds, "the stable fraction")
    labels = sub[system.label].data
    inferred = _inferred(sub, system).data
    stable = labels == system.stable_label
    absent = labels == system.absent_label if system.absent_label is not None else np.zeros((), dtype=bool)
    undecided = labels == system.undecided_label if system.undecided_label is not None else np.zeros((), dtype=bool)
    # One pass over the slice, chunk by chunk: every count reads the same chunks.
    counts = compute(stable.sum(), (~stable & (labels >= 0)).sum(), ((labels < 0) & ~absent & ~undecided).sum(), inferred.sum(),
                     (inferred & stable).sum(), absent.sum(), undecided.sum())
    n_stable, unstable, degenerate, n_inferred, inferred_stable, n_absent, n_undecided = (int(c) for c in counts)
    points = int(labels.size)
    return StableFraction(
        fraction=n_stable / points,
        stable=n_stable,
        points=points,
        unstable=unstable,
        degenerate=degenerate,
        inferred=n_inferred,
        inferred_stable=inferred_stable,
        axes=axes,
        absent=n_absent if system.absent_label is not None else None,
        undecided=n_undecided if system.undecided_label is not None else None,
    )


def check_axis(ds: xr.Dataset, value, dims: list[str], name: str = "along") -> str:
    """The grid axis given to the parameter ``name``; for ``along``, None is the system's ``default_axis``."""
    if value is None and name == "along":
        value = systems.of_atlas(ds.attrs).default_axis
        if value not in dims:
            raise StabmapError(f"{param('along')} was not given and the default axis {value!r} of {ds.attrs.get('stabmap_system')} "
                               f"atlases is not a grid axis of this one; its axes are: {', '.join(dims)}; give "
                               f"{param('along')} one of them")
    if not isinstance(value, str) or value not in dims:
        raise _not_an_axis(ds, str(value), dims, given(name, value))
    return value


def stable_system(ds: xr.Dataset, question: str):
    """The atlas's system, if it has a notion of stability."""
    system = systems.of_atlas(ds.attrs)
    if system.stable_label is None:
        raise StabmapError(f"{question} needs stability; {system.name} atlases have none (ask about {system.label} instead)")
    return system


def _lines(sub: xr.Dataset, along: str) -> tuple[list[str], np.ndarray, Any, Any]:
    """Other axes, the ascending grid of ``along``, and the label and the inferred flag as (other axes..., along).

    The two arrays are those of the Dataset, transposed: dask arrays (not read yet) for a lazy atlas.
    """
    system = systems.of_atlas(sub.attrs)
    if not sub.indexes[along].is_monotonic_increasing:
        sub = sub.sortby(along)
    others = [d for d in sub[system.label].dims if d != along]
    labels = sub[system.label].transpose(*others, along).data
    inferred = _inferred(sub, system).transpose(*others, along).data
    return others, np.asarray(sub[along].values, dtype=np.float64), labels, inferred


def _coord(sub: xr.Dataset, name: str, dim: str, values) -> tuple:
    return (dim, np.asarray(values), dict(sub[name].attrs))


def fixed_coords(sub: xr.Dataset, axes: dict[str, AxisSelection]) -> dict:
    """The grid axes a number fixed, as scalar coordinates holding the grid value used.

    The scene's fixed parameters (the atlas's other scalar coordinates) are left out, so that ``.to_dataframe()``
    of an answer has one column per thing that varies or was chosen; they stay in the atlas.
    """
    return {k: sub[k].variable for k, a in axes.items() if a.fixed}


def boundaries(ds: xr.Dataset, along: str | None = None, /, *, nearest_edge: bool = False, **sel) -> xr.Dataset:
    """Every change of the label along one axis, bracketed by the two neighbouring grid values.

    For every line along ``along`` (one per grid point of the other axes, or of the slice ``sel`` selects), each
    pair of neighbouring grid values with different labels is one boundary. The change lies somewhere between the
    two values, not at either: ``stabmap critical`` locates it to 1e-10 (docs/critical.md). Changes hidden
    between two grid values with equal labels (a thin band) are not seen.

    Parameters
    ----------
    ds : xarray.Dataset
        An atlas.
    along : str, optional
        The grid axis to search along (default: the system's ``default_axis``).
    **sel
        Selection of the other axes (number: nearest grid value; (lo, hi): a range); ``along`` itself may only
        take a range, which limits the search.

    Returns
    -------
    xarray.Dataset
        A tidy table, one entry per boundary along the dimension ``boundary`` (``.to_dataframe()`` gives a
        pandas table). Coordinates: the other axes' grid values of each boundary's line; axes fixed by
        ``sel`` are scalar coordinates (the scene's fixed parameters stay in the atlas). Variables:
        ``boundary_lower``/``boundary_upper`` (the bracketing grid values, lower < upper, in the units of ``along``),
        ``<label>_below``/``<label>_above`` (the label at them, e.g. ``n_complex_pairs_below``),
        ``inferred_below``/``inferred_above`` (True where that side was not computed but inferred from cell corners).
        Attributes: ``along``, ``n_lines``, ``n_lines_with_boundary``, ``selection`` and ``comment``.

    Examples
    --------
    >>> b = boundaries(ds, "omega", K_1=(0, 10))                    # a gyroscopes' atlas
    >>> b.to_dataframe()                                            # one row per boundary
    >>> b.where(b.n_complex_pairs_above == 0, drop=True)            # only the changes to stable
    """
    dims = grid_axes(ds)
    along = check_axis(ds, along, dims)
    sub, axes = select(ds, sel, along=along, nearest_edge=nearest_edge)
    others, x, labels, inferred = _lines(sub, along)
    lab = systems.of_atlas(ds.attrs).label
    shape = labels.shape[:-1]
    where, below, above, inferred_below, inferred_above = changes(labels, inferred)  # chunk by chunk
    position, k = where[:-1], where[-1]
    line = np.ravel_multi_index(position, shape) if others else np.zeros(k.size, dtype=np.intp)
    units = str(ds[along].attrs.get("units", ""))

    def var(values, long_name, **attrs):
        return ("boundary", values, {"long_name": long_name, **attrs})

    coords = {d: _coord(sub, d, "boundary", sub[d].values[p]) for d, p in zip(others, position, strict=True)}
    coords.update(fixed_coords(sub, axes))
    out = xr.Dataset(
        {
            "boundary_lower": var(x[k], f"{along} at the grid value below the change of {lab}", units=units),
            "boundary_upper": var(x[k + 1], f"{along} at the grid value above the change of {lab}", units=units),
            f"{lab}_below": var(below, f"{lab} at boundary_lower", units="1"),
            f"{lab}_above": var(above, f"{lab} at boundary_upper", units="1"),
            "inferred_below": var(inferred_below, "boundary_lower was not computed (inferred from its grid cell's corners)"),
            "inferred_above": var(inferred_above, "boundary_upper was not computed (inferred from its grid cell's corners)"),
        },
        coords=coords,
    )
    n_lines = int(np.prod(shape)) if others else 1
    # Only a stability boundary has a command that locates it more finely.
    located = f" {CRITICAL_HINT.format(along=along)}." if systems.of_atlas(ds.attrs).stable_label is not None else ""
    out.attrs = {
        "title": ds.attrs.get("title", ""),
        "stabmap_query": "boundaries",
        "label": lab,
        "label_symbol": systems.of_atlas(ds.attrs).label_symbol,
        "along": along,
        "along_units": units,
        "along_display_units": shown.display_unit(ds, along),
        "n_lines": n_lines,
        "n_lines_with_boundary": int(np.unique(line).size),
        "along_grid_values": int(x.size),
        "selection": selection_text(axes),
        "fixed_axes": fixed_names(axes),
        "located_by": located.strip(),
        "comment": (
            f"Each change of {lab} lies somewhere between boundary_lower and boundary_upper, two "
            f"neighbouring grid values of {along}; it is not located more finely. Changes hidden between two grid "
            f"values with equal {lab} are not seen.{located}"
        ),
    }
    return out


def smallest_stable(ds: xr.Dataset, /, along: str | None = None, over: str | None = None, *, nearest_edge: bool = False,
                    **sel) -> xr.Dataset:
    """The smallest grid value of ``along`` at which the system is stable, for each value of ``over``.

    Parameters
    ----------
    ds : xarray.Dataset
        An atlas.
    along : str
        The axis searched, from its smallest grid value up (default: the system's ``default_axis``, e.g. the
        gyroscopes' spin rate).
    over : str, optional
        The axis that labels the answer. Every other axis must then be fixed by a number in ``sel``. Without
        ``over``, the answer has every axis that ``sel`` leaves (one value per grid point of them).
    **sel
        Selection (number: nearest grid value; (lo, hi): a range). A range of ``along`` limits the search,
        e.g. ``omega=(0, None)`` for the gyroscopes' smallest stable *positive* spin rate.

    Returns
    -------
    xarray.Dataset
        Labelled by ``over`` (or the remaining axes); axes fixed by ``sel`` are scalar coordinates. Variables:

        - ``smallest_stable``: the smallest stable grid value of ``along``; NaN where no grid value is stable;
        - ``unstable_below``: the grid value just below it, not stable; NaN where ``smallest_stable`` is the
          first grid value searched (stable from the start of the scan: the true threshold may lie lower) or
          where nothing is stable. [unstable_below, smallest_stable] brackets the threshold;
        - ``<label>_below`` (e.g. ``n_complex_pairs_below``): the label at ``unstable_below`` (its fill value where
          there is none);
        - ``stable_to_scan_end``: True where every grid value from ``smallest_stable`` to the end of the searched
          range is stable (False: an unstable band follows further up);
        - ``inferred``/``inferred_below``: True where that point was not computed but inferred from cell corners.

    Examples
    --------
    >>> s = smallest_stable(ds, "omega", over="K_1")  # a gyroscopes' atlas
    >>> s.smallest_stable.plot()                    # the smallest stable spin rate against K_1
    """
    dims = grid_axes(ds)
    along = check_axis(ds, along, dims)
    sub, axes = select(ds, sel, along=along, nearest_edge=nearest_edge)
    others, x, labels, inferred = _lines(sub, along)
    system = stable_system(ds, "smallest_stable")
    label = system.variable(system.label)
    if over is not None:
        if over == along:
            raise StabmapError(f"{given('over', over)} is the axis searched along; choose another axis for {param('over')}, e.g. "
                               f"{next((d for d in dims if d != along), 'another grid axis')}")
        over = check_axis(ds, over, dims, "over")
        if axes[over].fixed:
            raise StabmapError(f"{given('over', over)} is also fixed by {over}={axes[over].requested:g}; "
                               f"give {over} a range (lo, hi) or leave it out")
        extra = [d for d in others if d != over]
        if extra:
            example = ", ".join(f"{d}={float(ds[d][0]):g}" for d in extra)
            raise StabmapError(
                f"{given('over', over)}: fix the other axes as well ({example}, or any grid value), "
                f"or leave out {param('over')} to get one answer per point of every remaining axis"
            )
    found = first_true(labels == system.stable_label, labels, inferred, label.fill)  # two passes, chunk by chunk
    has, first = found.has, found.first
    below = np.maximum(first - 1, 0)
    has_below = has & (first > 0)
    units = str(ds[along].attrs.get("units", ""))

    def var(values, long_name, **attrs):
        return (others, values, {"long_name": long_name, **attrs})

    coords = {d: _coord(sub, d, d, sub[d].values) for d in others}
    coords.update(fixed_coords(sub, axes))
    out = xr.Dataset(
        {
            "smallest_stable": var(np.where(has, x[first], np.nan), f"smallest stable {along}", units=units),
            "unstable_below": var(np.where(has_below, x[below], np.nan), f"unstable {along} just below the smallest stable one", units=units),
            f"{label.name}_below": var(
                found.value_before, f"{label.name} at unstable_below", units="1",
                comment=f"{label.fill} where there is no unstable_below",
            ),
            "stable_to_scan_end": var(
                found.true_to_end, f"stable at every grid value of {along} from smallest_stable to the end of the searched range"
            ),
            "inferred": var(found.flag_at, "smallest_stable was not computed (inferred from its grid cell's corners)"),
            "inferred_below": var(found.flag_before, "unstable_below was not computed (inferred from its grid cell's corners)"),
        },
        coords=coords,
    )
    out.attrs = {
        "title": ds.attrs.get("title", ""),
        "stabmap_query": "smallest_stable",
        "label": label.name,
        "label_symbol": system.label_symbol,
        "label_fill": label.fill,
        "along": along,
        "along_units": units,
        "along_display_units": shown.display_unit(ds, along),
        "along_range": [float(x.min()), float(x.max())],
        "along_grid_values": int(x.size),
        "selection": selection_text(axes),
        "fixed_axes": fixed_names(axes),
        "comment": (
            f"smallest_stable is a grid value of {along} proved (or, where inferred is true, inferred) stable, and "
            f"unstable_below the grid value just below it; the threshold lies between them and is not located more "
            f"finely. Stability below unstable_below is not implied, nor above smallest_stable unless "
            f"stable_to_scan_end. {CRITICAL_HINT.format(along=along)}."
        ),
    }
    return out


def _end(text: str) -> float | str | None:
    """One end of a selection: None (open), a number, or a number with a unit, kept as text: ``select`` converts it
    by the axis's units, so that a unit on an axis that takes none is refused for that (``units.in_si``) rather than
    as a spin unit it is not; anything else a ValueError."""
    if not text:
        return None
    if is_plain_number(text):
        return float(text)
    if not looks_like_rate(text):
        raise ValueError(text)
    return text


def parse_selection(items: list[str], *, ranges: bool = True, option: str = "") -> dict:
    """``NAME=VALUE`` (nearest grid value) and, with ``ranges``, ``NAME=LO:HI`` (LO: and :HI open) as a selection.

    The selections of the command line; errors name the item and ``option`` (e.g. ``--sel``).
    """
    out = {}
    prefix = f"{option} " if option else ""
    for item in items:
        key, sep, value = (part.strip() for part in item.partition("="))
        if not sep or not key:
            how = "NAME=VALUE (nearest grid value) or NAME=LO:HI (a range), e.g. omega=42.5 or K_1=0:10" if ranges else "NAME=VALUE, e.g. omega=42.5"
            raise StabmapError(f"{prefix}{item!r}: write {how}")
        if key in out:
            raise StabmapError(f"{key} is given twice; give each axis once")
        ends = value.split(":")
        if len(ends) > 2 or (len(ends) == 2 and not ranges):
            fix = f"a range is NAME=LO:HI, e.g. {key}=0:10" if ranges else f"give one value, e.g. {key}=42.5"
            raise StabmapError(f"{prefix}{item!r}: {fix}")
        try:
            numbers = [_end(e.strip()) for e in ends]
        except ValueError:
            what = "a number or a range LO:HI" if ranges else "a number"
            raise StabmapError(f"{prefix}{item!r}: {value!r} is not {what}; write e.g. {key}=42.5" + (f" or {key}=0:10" if ranges else "")
                               + f' (a spin rate may carry its unit: {key}="14000 rpm")') from None
        # A unit after a range is that of both ends: omega=5000:20000rpm (mixed units are an error).
        unit = common_unit(f"{prefix}{item!r}", [e for e in numbers if isinstance(e, str)])
        if unit is not None:
            numbers = [f"{e} {unit}" if isinstance(e, float) else e for e in numbers]
        if len(numbers) == 1 and numbers[0] is None:
            raise StabmapError(f"{prefix}{item!r}: no value; write e.g. {key}=42.5" + (f" or {key}=0:10" if ranges else ""))
        out[key] = numbers[0] if len(numbers) == 1 else tuple(numbers)
    return out
