"""Critical values of one scanned parameter: the ends of the intervals where the rotation is stable.

``critical(scene, along="omega")`` answers "how fast must it spin?" for every
point of the scene's other grid axes, without a dense grid along ``along``:

1. **Scan.** N_c is decided at every value of the ``along`` grid axis (the
   user's ``num`` sets the scan density), for every point of the other axes.
2. **Brackets.** Every pair of adjacent scan values with different N_c is a
   bracket: a change of N_c certainly lies between its ends.
3. **Bisection.** All brackets are halved together, one batch of certified
   decisions per step (in tasks through the run's runner: threads here or a
   dask cluster), until hi - lo <= max(rtol * max(|lo|, |hi|), atol).  A midpoint whose
   N_c differs from both ends reveals two changes; the bracket is split in two
   and both are followed.
4. **Intervals.** The brackets and the scan values between them partition the
   scan range; each maximal piece with N_c = 0 is a stable interval.

N_c stands for the system's label (``System.label``; for gyroscopes the number
of complex root pairs), and "stable" for its ``stable_label``.  Every label
involved is a proof (``System.evaluate``), so each located boundary
lies certainly inside its final bracket, and each stable interval's stored ends
are points proved stable (the *inner* bounds) next to points proved to have a
different N_c (the *outer* bounds).  What is assumed is only that nothing
happens between two scan values with equal N_c: see ``ASSUMPTION`` and
docs/critical.md.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from .. import systems
from ..errors import StabmapError
from ..store.dataset import coordinates, global_attrs
from ..systems.base import SceneBase
from . import runner
from .atlas import decide_grid, decide_points
from .chunks import check_chunk_points
from .progress import wanted

KIND = "critical values"  # global attribute stabmap_kind of every critical-values Dataset
DEFAULT_RTOL = 1e-10
MIN_RTOL = 1e-15  # a few ulps: bisection in float64 cannot go finer anyway
ATOL_FACTOR = 1e-6  # default atol = ATOL_FACTOR * rtol * max |scan value|, for boundaries at or near 0
MAX_ITERATIONS = 2200  # bisection of float64 reaches adjacent floats long before (about 2100 halvings worst case)

ASSUMPTION = (
    "Changes of {label} are searched for only between adjacent scan values whose {label} differ. "
    "Features narrower than the scan spacing are not found: a stable or unstable interval lying wholly between "
    "two adjacent scan values, or an even number of changes within one scan step, is invisible unless a "
    "bisection midpoint happens to land on it. Everything that is reported is {proved}: every located boundary "
    "lies inside its bracket, whose two ends have {certified}, different {label}."
)


@dataclass
class _Brackets:
    """Intervals (lo, hi] of the scanned parameter, each with certified, different N_c at its two ends."""

    owner: np.ndarray  # int64: flat index into the other axes
    lo: np.ndarray
    hi: np.ndarray
    nc_lo: np.ndarray  # int16
    nc_hi: np.ndarray

    def take(self, idx) -> _Brackets:
        return _Brackets(self.owner[idx], self.lo[idx], self.hi[idx], self.nc_lo[idx], self.nc_hi[idx])

    @staticmethod
    def concat(parts: list[_Brackets]) -> _Brackets:
        return _Brackets(*(np.concatenate([getattr(p, f) for p in parts]) for f in ("owner", "lo", "hi", "nc_lo", "nc_hi")))

    def __len__(self) -> int:
        return self.lo.size


@dataclass
class _Counts:
    """What the run cost, for the Dataset's attributes and history."""

    scan_points: int = 0
    bisection_points: int = 0
    iterations: int = 0
    provenance: dict = field(default_factory=dict)  # flag value -> points it decided

    def decided(self, system, results: dict) -> None:
        if system.provenance is None:
            return
        values, n = np.unique(results[system.provenance], return_counts=True)
        for v, c in zip(values.tolist(), n.tolist()):
            self.provenance[v] = self.provenance.get(v, 0) + c


def check_along(scene: SceneBase, along: str) -> int:
    """Index of the grid axis ``along``; a StabmapError naming the axes if it is not one."""
    names = [a.name for a in scene.grid]
    if along not in names:
        have = ", ".join(names) if names else "none (the scene has no [grid])"
        try:
            scene.parameter(along)
        except StabmapError as exc:  # not a name this scene could scan at all: say that, not "add it to [grid]"
            raise StabmapError(f"--along {along}: {exc}; its grid axes are: {have}") from None
        raise StabmapError(
            f"--along {along}: not a grid axis of this scene; its grid axes are: {have}. "
            f"Add {along} = {{ start = ..., stop = ..., num = ... }} under [grid] to scan it"
        )
    if len(scene.grid[names.index(along)].values) < 2:
        raise StabmapError(f"grid axis {along!r} has 1 value; critical values need a scan of at least 2 values (set num)")
    return names.index(along)


def check_rtol(rtol) -> float:
    """Validate the relative tolerance of located ends."""
    ok = not isinstance(rtol, bool) and isinstance(rtol, (int, float, np.floating)) and math.isfinite(rtol)
    if not ok or not MIN_RTOL <= rtol < 1:
        raise StabmapError(
            f"rtol must be between {MIN_RTOL:g} (float64 resolution) and 1 (excluded), got {rtol!r}; the default is {DEFAULT_RTOL:g}"
        )
    return float(rtol)


def critical(
    scene: SceneBase,
    along: str = "omega",
    *,
    rtol: float = DEFAULT_RTOL,
    atol: float | None = None,
    client=None,
    workers: int | None = None,
    threads: int | None = None,
    progress: bool | None = None,
    chunk_points: int | None = None,
) -> xr.Dataset:
    """The intervals of ``along`` where the rotation is stable, ends located to ``rtol``.

    Parameters
    ----------
    scene : a scene of any system
        Its grid: ``along`` must be one of its grid axes; its
        values are the scan (so ``num`` sets how fine a feature can be found),
        and the other grid axes are the dimensions of the result.
    along : str
        The scanned parameter, any grid axis name (default ``"omega"``).
    rtol : float
        Located ends satisfy hi - lo <= max(rtol * max(|lo|, |hi|), atol)
        (default 1e-10; between 1e-15 and 1).
    atol : float, optional
        Absolute floor of the bracket width. It only matters for a boundary at
        or very near 0, where a relative width cannot be reached. Default:
        1e-6 * rtol * max |scan value|.
    client, workers, threads, progress, chunk_points
        As for ``compute_atlas``: the scan and every bisection step run in tasks of about half a second on
        threads here (default), a cluster (``client``) or a local cluster of ``workers`` processes.

    Returns
    -------
    xarray.Dataset
        Dimensions: the other grid axes, ``interval`` and ``boundary``;
        ``stabmap_kind = "critical values"``. Layout: docs/critical.md.
    """
    index = check_along(scene, along)
    rtol = check_rtol(rtol)
    chunk_points = check_chunk_points(chunk_points)
    system = systems.of(scene)
    if system.stable_label is None:
        raise StabmapError(f"critical values are the ends of stable intervals; {system.name} atlases have no stability")
    scan = np.sort(scene.grid[index].array)
    if atol is None:
        atol = ATOL_FACTOR * rtol * float(np.abs(scan).max())
    if not (math.isfinite(atol) and atol >= 0):
        raise StabmapError(f"atol must be a finite number >= 0, got {atol!r}")
    others = tuple(a for d, a in enumerate(scene.grid) if d != index)
    counts = _Counts()
    t0 = time.perf_counter()
    with runner.start(client, workers=workers, threads=threads, announce=wanted(progress)) as run:
        nc = _scan(run, scene, index, progress, chunk_points, counts)
        brackets = _bisect(run, scene, along, others, _initial_brackets(nc, scan), rtol, atol, chunk_points, counts)
    ds = _dataset(system, scene, along, others, scan, nc, brackets, _proved(system))
    ds.attrs.update(_attrs(system, along, scan, rtol, atol, counts))
    ds.attrs["history"] += _history(along, counts, time.perf_counter() - t0)
    return ds


def _scan(run, scene, index: int, progress, chunk_points, counts: _Counts) -> np.ndarray:
    """The label on the whole grid, as (other axes..., along) with the along values increasing."""
    system = systems.of(scene)
    arrays = decide_grid(run, scene, progress=progress, chunk_points=chunk_points)
    nc = np.moveaxis(arrays[system.label], index, -1)
    if scene.grid[index].values[0] > scene.grid[index].values[-1]:
        nc = nc[..., ::-1]
    counts.scan_points = nc.size
    counts.decided(system, arrays)
    return np.ascontiguousarray(nc)


def _initial_brackets(nc: np.ndarray, scan: np.ndarray) -> _Brackets:
    """Every pair of adjacent scan values whose N_c differ."""
    flat = nc.reshape(-1, scan.size)
    owner, step = np.nonzero(flat[:, 1:] != flat[:, :-1])
    return _Brackets(owner.astype(np.int64), scan[step], scan[step + 1], flat[owner, step], flat[owner, step + 1])


def _converged(b: _Brackets, rtol: float, atol: float) -> np.ndarray:
    width = b.hi - b.lo
    mid = b.lo + 0.5 * width
    # No double strictly inside: lo and hi are neighbours and the bracket cannot shrink.
    no_room = (mid <= b.lo) | (mid >= b.hi)
    return (width <= np.maximum(rtol * np.maximum(np.abs(b.lo), np.abs(b.hi)), atol)) | no_room


def _bisect(run, scene, along, others, brackets: _Brackets, rtol, atol, chunk_points, counts: _Counts) -> _Brackets:
    """Halve every bracket until converged (one batch of tasks per step); returns all final brackets."""
    system = systems.of(scene)
    shape = tuple(len(a.values) for a in others)
    done = []
    active = brackets
    for _ in range(MAX_ITERATIONS):
        finished = _converged(active, rtol, atol)
        done.append(active.take(finished))
        active = active.take(~finished)
        if not len(active):
            break
        mid = active.lo + 0.5 * (active.hi - active.lo)
        idx = np.unravel_index(active.owner, shape) if shape else ()
        values = {a.name: a.array[i] for a, i in zip(others, idx)}
        values[along] = mid
        results = decide_points(run, scene, values, chunk_points=chunk_points)
        counts.bisection_points += mid.size
        counts.decided(system, results)
        counts.iterations += 1
        active = _halve(active, mid, results[system.label])
    else:  # pragma: no cover - float64 bisection always reaches neighbouring doubles first
        raise RuntimeError("bisection did not converge")
    return _Brackets.concat(done)


def _halve(b: _Brackets, mid: np.ndarray, nc_mid: np.ndarray) -> _Brackets:
    """Keep the half whose ends differ; keep both when the midpoint differs from both ends (two changes)."""
    left = nc_mid != b.nc_lo  # a change in (lo, mid]
    right = nc_mid != b.nc_hi  # a change in (mid, hi]
    lower = _Brackets(b.owner[left], b.lo[left], mid[left], b.nc_lo[left], nc_mid[left])
    upper = _Brackets(b.owner[right], mid[right], b.hi[right], nc_mid[right], b.nc_hi[right])
    return _Brackets.concat([lower, upper])


@dataclass
class _Table:
    """Per-point results, padded along the interval and boundary dimensions (NaN, or the label's fill value)."""

    n_intervals: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    lower_outer: np.ndarray
    upper_outer: np.ndarray
    b_lower: np.ndarray
    b_upper: np.ndarray
    nc_below: np.ndarray
    nc_above: np.ndarray
    start: np.ndarray  # the label at the first scan value: with the boundaries, the label everywhere in the scan


def _table(nc: np.ndarray, scan: np.ndarray, b: _Brackets, stable: int, fill: int) -> _Table:
    """Stable intervals and boundaries of every point of the other axes."""
    flat = nc.reshape(-1, scan.size)
    npoints = flat.shape[0]
    b = b.take(np.lexsort((b.lo, b.owner)))
    starts = np.concatenate([[0], np.cumsum(np.bincount(b.owner, minlength=npoints))])
    intervals = [_stable_intervals(flat[p, 0], scan, b.take(slice(starts[p], starts[p + 1])), stable) for p in range(npoints)]
    n_int = np.array([len(i) for i in intervals], dtype=np.int16)
    ni = max(1, int(n_int.max(initial=0)))
    nb = max(1, int(np.diff(starts).max(initial=0)))
    ends = np.full((4, npoints, ni), np.nan)
    for p, rows in enumerate(intervals):
        for i, row in enumerate(rows):
            ends[:, p, i] = row
    slot = np.arange(len(b)) - starts[b.owner]
    bounds = np.full((2, npoints, nb), np.nan)
    counts = np.full((2, npoints, nb), fill, dtype=nc.dtype)
    bounds[0, b.owner, slot], bounds[1, b.owner, slot] = b.lo, b.hi
    counts[0, b.owner, slot], counts[1, b.owner, slot] = b.nc_lo, b.nc_hi
    return _Table(n_int, *ends, *bounds, *counts, flat[:, 0].copy())


def _stable_intervals(nc_start: int, scan: np.ndarray, b: _Brackets, stable: int) -> list[tuple[float, float, float, float]]:
    """(lower, upper, lower_outer, upper_outer) of each stable interval of one point; NaN outer: scan end.

    The sorted brackets and the scan steps between them partition the scan
    range, so the N_c between bracket i-1 and bracket i is bracket i's lower-end N_c.
    """
    k = len(b)
    if k and not np.array_equal(b.nc_hi[:-1], b.nc_lo[1:]):  # pragma: no cover - guaranteed by construction
        raise AssertionError("brackets do not chain")
    out = []
    for i in range(k + 1):
        if (nc_start if i == 0 else b.nc_hi[i - 1]) != stable:
            continue
        lower, lower_outer = (scan[0], np.nan) if i == 0 else (b.hi[i - 1], b.lo[i - 1])
        upper, upper_outer = (scan[-1], np.nan) if i == k else (b.lo[i], b.hi[i])
        out.append((lower, upper, lower_outer, upper_outer))
    return out


def _proved(system) -> str:
    """How the labels were decided, for the texts: "proved", or "decided" for a system whose labels are not proofs."""
    return "proved" if system.proves_labels else "decided"


def _dataset(system, scene, along, others, scan, nc, brackets, proved: str = "proved") -> xr.Dataset:
    info = system.parameter(scene, along)
    label = system.variable(system.label)
    dims = tuple(a.name for a in others)
    shape = tuple(len(a.values) for a in others)
    t = _table(nc, scan, brackets, system.stable_label, label.fill)
    iv, bd = dims + ("interval",), dims + ("boundary",)
    lab = label.name

    def grid(a):
        return a.reshape(shape + a.shape[1:])

    def along_attrs(long_name, comment):
        return {"long_name": f"{long_name} ({info.long_name})", "units": info.units, "comment": comment}

    def count_attrs(long_name):
        return {"long_name": long_name, "units": label.units or "1", "comment": f"{label.fill}: fill (no boundary); otherwise as {lab}"}

    data = {
        "n_stable_intervals": (dims, grid(t.n_intervals), {"long_name": "number of stable intervals in the scan range", "units": "1"}),
        f"{along}_stable_lower": (iv, grid(t.lower), along_attrs("lower end of a stable interval", f"{proved} stable; NaN pads")),
        f"{along}_stable_upper": (iv, grid(t.upper), along_attrs("upper end of a stable interval", f"{proved} stable; NaN pads")),
        f"{along}_stable_lower_outer": (iv, grid(t.lower_outer), along_attrs(
            "value just below a stable interval", f"{proved} unstable; the boundary lies in (lower_outer, lower]; "
            "NaN where the interval starts at the scan range end (it may continue below)")),
        f"{along}_stable_upper_outer": (iv, grid(t.upper_outer), along_attrs(
            "value just above a stable interval", f"{proved} unstable; the boundary lies in [upper, upper_outer); "
            "NaN where the interval ends at the scan range end (it may continue above)")),
        "boundary_lower": (bd, grid(t.b_lower), along_attrs(f"lower end of the bracket of a change of {lab}", f"{lab}_below holds here, {proved}; NaN pads")),
        "boundary_upper": (bd, grid(t.b_upper), along_attrs(f"upper end of the bracket of a change of {lab}", f"{lab}_above holds here, {proved}; a change lies in (lower, upper]; NaN pads")),
        f"{lab}_below": (bd, grid(t.nc_below), count_attrs(f"{lab} at boundary_lower")),
        f"{lab}_above": (bd, grid(t.nc_above), count_attrs(f"{lab} at boundary_upper")),
        f"{lab}_at_scan_start": (dims, grid(t.start), {"long_name": f"{lab} at the first scan value", "units": label.units or "1",
                                                       "comment": f"{proved}; it holds up to boundary_lower of the first boundary, "
                                                                  f"then {lab}_above of each boundary up to the next"}),
    }
    attrs = global_attrs(system, scene, "stabmap critical values")
    return xr.Dataset(data, coords=coordinates(system, scene, skip=(along,)), attrs=attrs)


def _attrs(system, along, scan, rtol, atol, counts: _Counts) -> dict:
    attrs = {
        "stabmap_kind": KIND,
        "critical_along": along,
        "critical_rtol": rtol,
        "critical_atol": atol,
        "critical_scan_points": np.int64(scan.size),
        "critical_scan_range": np.array([scan[0], scan[-1]]),
        "critical_scan_max_step": float(np.diff(scan).max()),
        "critical_evaluated_points": np.int64(counts.scan_points + counts.bisection_points),
        "critical_bisection_steps": np.int64(counts.iterations),
        "comment": "Ends are located until hi - lo <= max(rtol * max(|lo|, |hi|), atol), or lo and hi are neighbouring "
        "doubles. " + ASSUMPTION.format(label=system.label, proved=_proved(system),
                                          certified="certified" if system.proves_labels else "decided"),
    }
    if system.provenance is not None:
        flags = system.variable(system.provenance)
        attrs[f"critical_{flags.name}"] = "; ".join(f"{m}: {counts.provenance.get(v, 0)}" for v, m in flags.flags)
    return attrs


def _history(along, counts: _Counts, seconds: float) -> str:
    return (
        f"; critical values of {along}: {counts.scan_points} scan points and {counts.bisection_points} "
        f"bisection points ({counts.iterations} steps) in {seconds:.1f} s"
    )
