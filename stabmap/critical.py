"""Critical values of one scanned parameter: the ends of the intervals where the rotation is stable.

``critical(scene, along="omega")`` answers "how fast must it spin?" for every
point of the scene's other grid axes, without a dense grid along ``along``:

1. **Scan.** N_c is decided at every value of the ``along`` grid axis (the
   user's ``num`` sets the scan density), for every point of the other axes.
2. **Brackets.** Every pair of adjacent scan values with different N_c is a
   bracket: a change of N_c certainly lies between its ends.
3. **Bisection.** All brackets are halved together, one batch of certified
   decisions per step (in chunks on a thread pool; the kernels release the
   GIL), until hi - lo <= max(rtol * max(|lo|, |hi|), atol).  A midpoint whose
   N_c differs from both ends reveals two changes; the bracket is split in two
   and both are followed.
4. **Intervals.** The brackets and the scan values between them partition the
   scan range; each maximal piece with N_c = 0 is a stable interval.

Every N_c involved is a proof (``stabmap.decide``), so each located boundary
lies certainly inside its final bracket, and each stable interval's stored ends
are points proved stable (the *inner* bounds) next to points proved to have a
different N_c (the *outer* bounds).  What is assumed is only that nothing
happens between two scan values with equal N_c: see ``ASSUMPTION`` and
docs/critical.md.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import xarray as xr

from .atlas import compute as compute_atlas
from .atlas import coordinates, global_attrs
from .cluster import check_threads
from .decide import BY_EXACT, decide_values
from .errors import StabmapError
from .parameters import parse_name
from .scene import Scene
from .variables import DECIDED_BY, N_COMPLEX_PAIRS

KIND = "critical values"  # global attribute stabmap_kind of every critical-values Dataset
DEFAULT_RTOL = 1e-10
MIN_RTOL = 1e-15  # a few ulps: bisection in float64 cannot go finer anyway
ATOL_FACTOR = 1e-6  # default atol = ATOL_FACTOR * rtol * max |scan value|, for boundaries at or near 0
MAX_ITERATIONS = 2200  # bisection of float64 reaches adjacent floats long before (about 2100 halvings worst case)
PAD_NC = -2  # n_complex_pairs_below/above where a point has fewer boundaries than the boundary dimension

ASSUMPTION = (
    "Changes of n_complex_pairs are searched for only between adjacent scan values whose n_complex_pairs differ. "
    "Features narrower than the scan spacing are not found: a stable or unstable interval lying wholly between "
    "two adjacent scan values, or an even number of changes within one scan step, is invisible unless a "
    "bisection midpoint happens to land on it. Everything that is reported is proved: every located boundary "
    "lies inside its bracket, whose two ends have certified, different n_complex_pairs."
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
    exact: int = 0


def check_along(scene: Scene, along: str) -> int:
    """Index of the grid axis ``along``; a StabmapError naming the axes if it is not one."""
    names = [a.name for a in scene.grid]
    if along not in names:
        have = ", ".join(names) if names else "none (the scene has no [grid])"
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
    scene: Scene,
    along: str = "omega",
    *,
    rtol: float = DEFAULT_RTOL,
    atol: float | None = None,
    threads: int | None = None,
    progress: bool | None = None,
) -> xr.Dataset:
    """The intervals of ``along`` where the rotation is stable, ends located to ``rtol``.

    Parameters
    ----------
    scene : Scene
        Bodies, support and grid. ``along`` must be one of its grid axes; its
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
    threads : int, optional
        Threads (default: all cores).
    progress : bool, optional
        Progress bar on stderr for a scan over two seconds (default: when stderr is a terminal).

    Returns
    -------
    xarray.Dataset
        Dimensions: the other grid axes, ``interval`` and ``boundary``;
        ``stabmap_kind = "critical values"``. Layout: docs/critical.md.
    """
    index = check_along(scene, along)
    rtol = check_rtol(rtol)
    threads = check_threads(threads)
    scan = np.sort(scene.grid[index].array)
    if atol is None:
        atol = ATOL_FACTOR * rtol * float(np.abs(scan).max())
    if not (math.isfinite(atol) and atol >= 0):
        raise StabmapError(f"atol must be a finite number >= 0, got {atol!r}")
    others = tuple(a for d, a in enumerate(scene.grid) if d != index)
    counts = _Counts()
    t0 = time.perf_counter()
    nc = _scan(scene, index, threads, progress, counts)
    brackets = _bisect(scene, along, others, _initial_brackets(nc, scan), rtol, atol, threads, counts)
    ds = _dataset(scene, along, others, scan, nc, brackets)
    ds.attrs.update(_attrs(along, scan, rtol, atol, counts))
    ds.attrs["history"] += _history(along, counts, time.perf_counter() - t0)
    return ds


def _scan(scene: Scene, index: int, threads: int, progress: bool | None, counts: _Counts) -> np.ndarray:
    """N_c on the whole grid, as (other axes..., along) with the along values increasing."""
    atlas = compute_atlas(scene, threads=threads, progress=progress)
    nc = np.moveaxis(atlas[N_COMPLEX_PAIRS].values, index, -1)
    if scene.grid[index].values[0] > scene.grid[index].values[-1]:
        nc = nc[..., ::-1]
    counts.scan_points = nc.size
    counts.exact += int((atlas[DECIDED_BY].values == BY_EXACT).sum())
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


def _bisect(scene, along, others, brackets: _Brackets, rtol, atol, threads, counts: _Counts) -> _Brackets:
    """Halve every bracket until converged (one batched decision per step); returns all final brackets."""
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
        nc_mid, by = decide_values(scene, values, threads=threads)
        counts.bisection_points += mid.size
        counts.exact += int((by == BY_EXACT).sum())
        counts.iterations += 1
        active = _halve(active, mid, nc_mid)
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
    """Per-point results, padded along the interval and boundary dimensions (NaN, or PAD_NC for counts)."""

    n_intervals: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    lower_outer: np.ndarray
    upper_outer: np.ndarray
    b_lower: np.ndarray
    b_upper: np.ndarray
    nc_below: np.ndarray
    nc_above: np.ndarray


def _table(nc: np.ndarray, scan: np.ndarray, b: _Brackets) -> _Table:
    """Stable intervals and boundaries of every point of the other axes."""
    flat = nc.reshape(-1, scan.size)
    npoints = flat.shape[0]
    b = b.take(np.lexsort((b.lo, b.owner)))
    starts = np.concatenate([[0], np.cumsum(np.bincount(b.owner, minlength=npoints))])
    intervals = [_stable_intervals(flat[p, 0], scan, b.take(slice(starts[p], starts[p + 1]))) for p in range(npoints)]
    n_int = np.array([len(i) for i in intervals], dtype=np.int16)
    ni = max(1, int(n_int.max(initial=0)))
    nb = max(1, int(np.diff(starts).max(initial=0)))
    ends = np.full((4, npoints, ni), np.nan)
    for p, rows in enumerate(intervals):
        for i, row in enumerate(rows):
            ends[:, p, i] = row
    slot = np.arange(len(b)) - starts[b.owner]
    bounds = np.full((2, npoints, nb), np.nan)
    counts = np.full((2, npoints, nb), PAD_NC, dtype=np.int16)
    bounds[0, b.owner, slot], bounds[1, b.owner, slot] = b.lo, b.hi
    counts[0, b.owner, slot], counts[1, b.owner, slot] = b.nc_lo, b.nc_hi
    return _Table(n_int, *ends, *bounds, *counts)


def _stable_intervals(nc_start: int, scan: np.ndarray, b: _Brackets) -> list[tuple[float, float, float, float]]:
    """(lower, upper, lower_outer, upper_outer) of each stable interval of one point; NaN outer: scan end.

    The sorted brackets and the scan steps between them partition the scan
    range, so the N_c between bracket i-1 and bracket i is bracket i's lower-end N_c.
    """
    k = len(b)
    if k and not np.array_equal(b.nc_hi[:-1], b.nc_lo[1:]):  # pragma: no cover - guaranteed by construction
        raise AssertionError("brackets do not chain")
    out = []
    for i in range(k + 1):
        if (nc_start if i == 0 else b.nc_hi[i - 1]) != 0:
            continue
        lower, lower_outer = (scan[0], np.nan) if i == 0 else (b.hi[i - 1], b.lo[i - 1])
        upper, upper_outer = (scan[-1], np.nan) if i == k else (b.lo[i], b.hi[i])
        out.append((lower, upper, lower_outer, upper_outer))
    return out


def _dataset(scene, along, others, scan, nc, brackets) -> xr.Dataset:
    info = parse_name(along, scene.n, scene.support)
    dims = tuple(a.name for a in others)
    shape = tuple(len(a.values) for a in others)
    t = _table(nc, scan, brackets)
    iv, bd = dims + ("interval",), dims + ("boundary",)

    def grid(a):
        return a.reshape(shape + a.shape[1:])

    def along_attrs(long_name, comment):
        return {"long_name": f"{long_name} ({info.long_name})", "units": info.units, "comment": comment}

    def count_attrs(long_name):
        return {"long_name": long_name, "units": "1", "comment": f"-1: p vanishes identically; {PAD_NC}: fill (no boundary)"}

    data = {
        "n_stable_intervals": (dims, grid(t.n_intervals), {"long_name": "number of stable intervals in the scan range", "units": "1"}),
        f"{along}_stable_lower": (iv, grid(t.lower), along_attrs("lower end of a stable interval", "proved stable; NaN pads")),
        f"{along}_stable_upper": (iv, grid(t.upper), along_attrs("upper end of a stable interval", "proved stable; NaN pads")),
        f"{along}_stable_lower_outer": (iv, grid(t.lower_outer), along_attrs(
            "value just below a stable interval", "proved unstable; the boundary lies in (lower_outer, lower]; "
            "NaN where the interval starts at the scan range end (it may continue below)")),
        f"{along}_stable_upper_outer": (iv, grid(t.upper_outer), along_attrs(
            "value just above a stable interval", "proved unstable; the boundary lies in [upper, upper_outer); "
            "NaN where the interval ends at the scan range end (it may continue above)")),
        "boundary_lower": (bd, grid(t.b_lower), along_attrs("lower end of the bracket of a change of n_complex_pairs", "n_complex_pairs_below holds here, proved; NaN pads")),
        "boundary_upper": (bd, grid(t.b_upper), along_attrs("upper end of the bracket of a change of n_complex_pairs", "n_complex_pairs_above holds here, proved; a change lies in (lower, upper]; NaN pads")),
        "n_complex_pairs_below": (bd, grid(t.nc_below), count_attrs("n_complex_pairs at boundary_lower")),
        "n_complex_pairs_above": (bd, grid(t.nc_above), count_attrs("n_complex_pairs at boundary_upper")),
    }
    attrs = global_attrs(scene, "stabmap critical values")
    return xr.Dataset(data, coords=coordinates(scene, skip=(along,)), attrs=attrs)


def _attrs(along, scan, rtol, atol, counts: _Counts) -> dict:
    return {
        "stabmap_kind": KIND,
        "critical_along": along,
        "critical_rtol": rtol,
        "critical_atol": atol,
        "critical_scan_points": np.int64(scan.size),
        "critical_scan_range": np.array([scan[0], scan[-1]]),
        "critical_scan_max_step": float(np.diff(scan).max()),
        "critical_evaluated_points": np.int64(counts.scan_points + counts.bisection_points),
        "critical_bisection_steps": np.int64(counts.iterations),
        "critical_decided_exactly": np.int64(counts.exact),
        "comment": "Ends are located until hi - lo <= max(rtol * max(|lo|, |hi|), atol), or lo and hi are neighbouring "
        "doubles. " + ASSUMPTION,
    }


def _history(along, counts: _Counts, seconds: float) -> str:
    return (
        f"; critical values of {along}: {counts.scan_points} scan points and {counts.bisection_points} "
        f"bisection points ({counts.iterations} steps) in {seconds:.1f} s"
    )
