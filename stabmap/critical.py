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

import datetime as _dt
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
import xarray as xr

from . import __version__
from .atlas import FORMAT_VERSION, REFERENCES
from .atlas import compute as compute_atlas
from .decide import BY_EXACT, decide
from .errors import StabmapError
from .parameters import parse_name
from .points import point_arrays
from .scene import Scene, fixed_values
from .variables import N_COMPLEX_PAIRS

KIND = "critical"  # global attribute stabmap_kind of every critical-values Dataset
DEFAULT_RTOL = 1e-10
MIN_RTOL = 1e-15  # a few ulps: bisection in float64 cannot go finer anyway
ATOL_FACTOR = 1e-6  # default atol = ATOL_FACTOR * rtol * max |scan value|, for boundaries at or near 0
MAX_ITERATIONS = 2200  # bisection of float64 reaches adjacent floats long before (about 2100 halvings worst case)
CHUNK_POINTS = 8192
PAD_NC = -2  # n_complex_pairs_below/above where a point has fewer boundaries than the boundary dimension

# Values of the <along>_stable_lower_kind / _upper_kind flag variables.
END_NONE, END_BOUNDARY, END_SCAN = -1, 0, 1

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
    """What the run cost, for the Dataset's attributes and the CLI's summary line."""

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
    axis = scene.grid[names.index(along)]
    if len(axis.values) < 2:
        raise StabmapError(f"grid axis {along!r} has 1 value; critical values need a scan of at least 2 values (set num)")
    return names.index(along)


def check_rtol(rtol) -> float:
    """Validate the relative tolerance of located ends."""
    if isinstance(rtol, bool) or not isinstance(rtol, (int, float, np.floating)) or not math.isfinite(rtol):
        raise StabmapError(f"rtol must be a number, got {rtol!r}")
    if not MIN_RTOL <= rtol < 1:
        raise StabmapError(f"rtol must be >= {MIN_RTOL:g} (float64 resolution) and < 1, got {rtol!r}; the default is {DEFAULT_RTOL:g}")
    return float(rtol)


def critical(
    scene: Scene,
    along: str = "omega",
    *,
    rtol: float = DEFAULT_RTOL,
    atol: float | None = None,
    workers: int | None = None,
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
        (default 1e-10; at least 1e-15).
    atol : float, optional
        Absolute floor of the bracket width, which only matters for a boundary
        at or very near 0, where a relative width cannot be reached. Default:
        1e-6 * rtol * max |scan value|.
    workers : int, optional
        Threads (default: all cores).
    progress : bool, optional
        Progress bar on stderr for a scan over two seconds (default: when stderr is a terminal).

    Returns
    -------
    xarray.Dataset
        Dimensions: the other grid axes, ``interval`` and ``boundary``. The
        layout is in docs/critical.md; ``stabmap_kind = "critical"``.
    """
    index = check_along(scene, along)
    rtol = check_rtol(rtol)
    workers = workers or os.cpu_count() or 1
    if workers < 1:
        raise StabmapError(f"workers must be >= 1, got {workers}")
    scan = np.sort(scene.grid[index].array)
    if atol is None:
        atol = ATOL_FACTOR * rtol * float(np.abs(scan).max())
    if not (math.isfinite(atol) and atol >= 0):
        raise StabmapError(f"atol must be a finite number >= 0, got {atol!r}")
    others = tuple(a for d, a in enumerate(scene.grid) if d != index)
    counts = _Counts()
    t0 = time.perf_counter()
    nc = _scan(scene, index, workers, progress, counts)
    brackets = _initial_brackets(nc, scan)
    with ThreadPoolExecutor(max_workers=workers) as pool:
        brackets = _bisect(scene, along, others, brackets, rtol, atol, pool, workers, counts)
    ds = _dataset(scene, along, others, scan, nc, brackets, rtol, atol, counts)
    ds.attrs["history"] += f" in {time.perf_counter() - t0:.1f} s"
    return ds


def _scan(scene: Scene, index: int, workers: int, progress: bool | None, counts: _Counts) -> np.ndarray:
    """N_c on the whole grid, as (other axes..., along) with the along values increasing."""
    atlas = compute_atlas(scene, workers=workers, progress=progress)
    nc = np.moveaxis(atlas[N_COMPLEX_PAIRS].values, index, -1)
    if scene.grid[index].values[0] > scene.grid[index].values[-1]:
        nc = nc[..., ::-1]
    counts.scan_points = nc.size
    counts.exact += int((atlas["decided_by"].values == BY_EXACT).sum())
    return np.ascontiguousarray(nc)


def _initial_brackets(nc: np.ndarray, scan: np.ndarray) -> _Brackets:
    """Every pair of adjacent scan values whose N_c differ."""
    flat = nc.reshape(-1, scan.size)
    owner, step = np.nonzero(flat[:, 1:] != flat[:, :-1])
    return _Brackets(owner.astype(np.int64), scan[step], scan[step + 1], flat[owner, step], flat[owner, step + 1])


def _converged(b: _Brackets, rtol: float, atol: float) -> np.ndarray:
    width = b.hi - b.lo
    mid = b.lo + 0.5 * width
    # No float strictly inside: the bracket is two adjacent doubles and cannot shrink.
    no_room = (mid <= b.lo) | (mid >= b.hi)
    return (width <= np.maximum(rtol * np.maximum(np.abs(b.lo), np.abs(b.hi)), atol)) | no_room


def _bisect(scene, along, others, brackets: _Brackets, rtol, atol, pool, workers, counts: _Counts) -> _Brackets:
    """Halve every bracket until converged; returns all final brackets."""
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
        nc_mid = _decide_parallel(scene, values, mid.size, pool, workers, counts)
        counts.iterations += 1
        active = _halve(active, mid, nc_mid)
    else:  # pragma: no cover - float64 bisection always reaches adjacent doubles first
        raise RuntimeError("bisection did not converge")
    return _Brackets.concat(done)


def _halve(b: _Brackets, mid: np.ndarray, nc_mid: np.ndarray) -> _Brackets:
    """Keep the half (or both halves) whose ends still differ."""
    left = nc_mid != b.nc_lo  # a change in (lo, mid]
    right = nc_mid != b.nc_hi  # a change in (mid, hi]
    lower = _Brackets(b.owner[left], b.lo[left], mid[left], b.nc_lo[left], nc_mid[left])
    upper = _Brackets(b.owner[right], mid[right], b.hi[right], nc_mid[right], b.nc_hi[right])
    return _Brackets.concat([lower, upper])


def _decide_parallel(scene, values: dict, npts: int, pool, workers: int, counts: _Counts) -> np.ndarray:
    """N_c of the points ``values`` (1-d arrays), decided in chunks on the thread pool."""
    size = max(512, min(CHUNK_POINTS, -(-npts // (2 * workers))))
    starts = range(0, npts, size)
    futures = [pool.submit(decide, point_arrays(scene, {k: v[a : a + size] for k, v in values.items()})) for a in starts]
    nc = np.empty(npts, dtype=np.int16)
    for a, f in zip(starts, futures):
        part, by = f.result()
        nc[a : a + size] = part
        counts.exact += int((by == BY_EXACT).sum())
    counts.bisection_points += npts
    return nc


@dataclass
class _Table:
    """Per-point results padded along the interval and boundary dimensions."""

    n_intervals: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    lower_outer: np.ndarray
    upper_outer: np.ndarray
    lower_kind: np.ndarray
    upper_kind: np.ndarray
    n_boundaries: np.ndarray
    b_lower: np.ndarray
    b_upper: np.ndarray
    nc_below: np.ndarray
    nc_above: np.ndarray


def _table(nc: np.ndarray, scan: np.ndarray, b: _Brackets) -> _Table:
    """Stable intervals and boundaries of every point of the other axes."""
    flat = nc.reshape(-1, scan.size)
    npoints = flat.shape[0]
    b = b.take(np.lexsort((b.lo, b.owner)))
    n_bound = np.bincount(b.owner, minlength=npoints).astype(np.int16)
    starts = np.concatenate([[0], np.cumsum(n_bound)])
    # Pieces between brackets carry one N_c each (the scan start's, then each bracket's upper end's).
    pieces = [_pieces(flat[p, 0], scan, b.take(slice(starts[p], starts[p + 1]))) for p in range(npoints)]
    n_int = np.array([len(p) for p in pieces], dtype=np.int16)
    ni, nb = max(1, int(n_int.max(initial=0))), max(1, int(n_bound.max(initial=0)))
    t = _Table(
        n_int, *(np.full((npoints, ni), np.nan) for _ in range(4)), *(np.full((npoints, ni), END_NONE, np.int8) for _ in range(2)),
        n_bound, *(np.full((npoints, nb), np.nan) for _ in range(2)), *(np.full((npoints, nb), PAD_NC, np.int16) for _ in range(2)),
    )
    for p, intervals in enumerate(pieces):
        for i, row in enumerate(intervals):
            t.lower[p, i], t.upper[p, i], t.lower_outer[p, i], t.upper_outer[p, i], t.lower_kind[p, i], t.upper_kind[p, i] = row
    slot = np.arange(len(b)) - starts[b.owner]
    t.b_lower[b.owner, slot], t.b_upper[b.owner, slot] = b.lo, b.hi
    t.nc_below[b.owner, slot], t.nc_above[b.owner, slot] = b.nc_lo, b.nc_hi
    return t


def _pieces(nc_start: int, scan: np.ndarray, b: _Brackets) -> list[tuple]:
    """Stable intervals of one point: (inner lower, inner upper, outer lower, outer upper, lower kind, upper kind)."""
    k = len(b)
    if k and not np.array_equal(b.nc_hi[:-1], b.nc_lo[1:]):  # pragma: no cover - the brackets partition the scan
        raise AssertionError("brackets do not chain")
    out = []
    for i in range(k + 1):
        value = nc_start if i == 0 else b.nc_hi[i - 1]
        if value != 0:
            continue
        lower = (scan[0], np.nan, END_SCAN) if i == 0 else (b.hi[i - 1], b.lo[i - 1], END_BOUNDARY)
        upper = (scan[-1], np.nan, END_SCAN) if i == k else (b.lo[i], b.hi[i], END_BOUNDARY)
        out.append((lower[0], upper[0], lower[1], upper[1], lower[2], upper[2]))
    return out


def _dataset(scene, along, others, scan, nc, brackets, rtol, atol, counts: _Counts) -> xr.Dataset:
    info = parse_name(along, scene.n, scene.support)
    dims = tuple(a.name for a in others)
    shape = tuple(len(a.values) for a in others)
    t = _table(nc, scan, brackets)
    iv, bd = dims + ("interval",), dims + ("boundary",)

    def pad(a):
        return a.reshape(shape + a.shape[1:])

    def along_attrs(long_name, comment):
        return {"long_name": f"{long_name} ({info.long_name})", "units": info.units, "comment": comment}

    ends = {"flag_values": np.array([END_NONE, END_BOUNDARY, END_SCAN], np.int8), "flag_meanings": "no_interval located_boundary scan_range_end"}
    data = {
        "n_stable_intervals": (dims, pad(t.n_intervals), {"long_name": "number of stable intervals in the scan range", "units": "1"}),
        f"{along}_stable_lower": (iv, pad(t.lower), along_attrs("lower end of a stable interval, proved stable", "inner bound: stable at this value and up to the upper end (assuming no feature narrower than the scan spacing); NaN pads")),
        f"{along}_stable_upper": (iv, pad(t.upper), along_attrs("upper end of a stable interval, proved stable", "inner bound; NaN pads")),
        f"{along}_stable_lower_outer": (iv, pad(t.lower_outer), along_attrs("value just below the stable interval with N_c proved nonzero", "outer bound: the boundary lies in (lower_outer, lower]; NaN where the interval starts at the scan range end")),
        f"{along}_stable_upper_outer": (iv, pad(t.upper_outer), along_attrs("value just above the stable interval with N_c proved nonzero", "outer bound: the boundary lies in [upper, upper_outer); NaN where the interval ends at the scan range end")),
        f"{along}_stable_lower_kind": (iv, pad(t.lower_kind), {"long_name": "what bounds the stable interval from below", **ends}),
        f"{along}_stable_upper_kind": (iv, pad(t.upper_kind), {"long_name": "what bounds the stable interval from above", **ends}),
        "n_boundaries": (dims, pad(t.n_boundaries), {"long_name": "number of located changes of n_complex_pairs in the scan range", "units": "1"}),
        f"{along}_boundary_lower": (bd, pad(t.b_lower), along_attrs("lower end of the bracket of a change of n_complex_pairs", "n_complex_pairs_below holds here (proved); NaN pads")),
        f"{along}_boundary_upper": (bd, pad(t.b_upper), along_attrs("upper end of the bracket of a change of n_complex_pairs", "n_complex_pairs_above holds here (proved); a change lies in (lower, upper]; NaN pads")),
        "n_complex_pairs_below": (bd, pad(t.nc_below), {"long_name": "n_complex_pairs at the lower end of the bracket", "units": "1", "comment": f"-1: p identically zero; {PAD_NC}: padding (no boundary)"}),
        "n_complex_pairs_above": (bd, pad(t.nc_above), {"long_name": "n_complex_pairs at the upper end of the bracket", "units": "1", "comment": f"-1: p identically zero; {PAD_NC}: padding (no boundary)"}),
    }
    return xr.Dataset(data, coords=_coords(scene, others), attrs=_attrs(scene, along, scan, rtol, atol, counts))


def _coords(scene: Scene, others) -> dict:
    coords = {}
    for axis in others:
        name = parse_name(axis.name, scene.n, scene.support)
        coords[axis.name] = (axis.name, axis.array, {"units": name.units, "long_name": name.long_name, "scale": axis.scale})
    for key, value in fixed_values(scene).items():
        name = parse_name(key, scene.n, scene.support)
        coords[key] = ((), np.float64(value), {"units": name.units, "long_name": name.long_name})
    return coords


def _attrs(scene, along, scan, rtol, atol, counts: _Counts) -> dict:
    now = _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat()
    return {
        "Conventions": "CF-1.10",
        "title": scene.title or "stabmap critical values",
        "source": f"stabmap {__version__}",
        "history": f"{now} critical values of {along} computed by stabmap {__version__}: {counts.scan_points} scan points, "
        f"{counts.bisection_points} bisection points in {counts.iterations} steps",
        "references": REFERENCES,
        "stabmap_format_version": FORMAT_VERSION,
        "stabmap_kind": KIND,
        "support": scene.support,
        "n_bodies": scene.n,
        "polynomial_degree_bound": scene.degree,
        "along": along,
        "along_units": parse_name(along, scene.n, scene.support).units,
        "rtol": rtol,
        "atol": atol,
        "tolerance": "every bracket has hi - lo <= max(rtol * max(|lo|, |hi|), atol), or hi and lo are adjacent doubles",
        "scan_size": np.int64(scan.size),
        "scan_min": float(scan[0]),
        "scan_max": float(scan[-1]),
        "scan_max_spacing": float(np.diff(scan).max()),
        "assumption": ASSUMPTION,
        "n_scan_points": np.int64(counts.scan_points),
        "n_bisection_points": np.int64(counts.bisection_points),
        "n_decided_exactly": np.int64(counts.exact),
        "scene": scene.to_toml(),
    }
