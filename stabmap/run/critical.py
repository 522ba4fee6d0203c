"""Critical values of one scanned parameter: the ends of the intervals where the system is stable.

``critical(scene, along)`` finds, for every point of the scene's other grid axes, the values of ``along``
(default: the system's ``default_axis``) where the system is stable, without a dense grid along ``along``.
"The label" is the system's ``System.label``, and "stable" its ``stable_label``:

1. **Scan.** The label is decided at every value of the ``along`` grid axis (the
   user's ``num`` sets where the search starts), for every point of the other axes.
2. **Proof between scan values.** Every scan step is a segment whose two ends
   have proved labels.  A box proof (``System.prove_boxes``) shows that the label is the
   same at every value of a segment; segments it cannot prove are halved (one
   batch of certified decisions and box proofs per step, in tasks through the
   run's runner: threads here or a dask cluster) and their halves tried again.
   A segment whose ends differ is a bracket of a change and is halved until
   hi - lo <= max(rtol * max(|lo|, |hi|), atol) / 4.  So a narrow stable window or unstable band between
   two scan values is found wherever a box proof fails around it: it makes
   two roots meet, which no box proof can hide.
3. **Gaps.** A segment with equal ends that is still unproved at that width,
   or once its point of the other axes has spent its budget of box proofs
   (BOX_BUDGET per scan step), or proves too few of them to pay (PAYS:
   clustered or exactly repeated roots defeat box proofs), is an *undecided
   gap*, and is listed.  A gap next to a bracket joins it
   (the bracket's width stays below the tolerance).
4. **Intervals.** The brackets and the proved segments between them
   partition the scan range outside the gaps; each maximal piece with the stable label
   is a stable interval, flagged where a gap lies inside it.

A system that
proves no boxes (``System.box_axes`` without ``along``) leaves every scan step
with equal ends as a gap, and says so: its changes are searched for only where
adjacent scan values differ (``POINTS_ONLY``; docs/critical.md).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from .. import systems
from ..errors import StabmapError, given, param
from ..store.dataset import CRITICAL_KIND, coordinates, global_attrs
from ..systems.base import SceneBase
from . import runner
from .atlas import decide_boxes, decide_grid, decide_points
from .chunks import check_chunk_points
from .progress import wanted

DEFAULT_RTOL = 1e-10
MIN_RTOL = 1e-15  # a few ulps: bisection in float64 cannot go finer anyway
ATOL_FACTOR = 1e-6  # default atol = ATOL_FACTOR * rtol * max |scan value|, for boundaries at or near 0
MAX_ITERATIONS = 2200  # bisection of float64 reaches adjacent floats long before (about 2100 halvings worst case)

# Box proofs that one point of the other axes may spend on segments with equal ends: BOX_BUDGET per scan step,
# plus BOX_BUDGET_BOUNDARIES for the segments next to its boundaries (each needs a few hundred: docs/critical.md)
BOX_BUDGET, BOX_BUDGET_BOUNDARIES = 4, 2048
# A point whose box proofs of one halving step prove less than PAYS of its segments, when they are at least
# PAYS_MIN and a quarter of its scan steps, stops halving: a stretch whose structure defeats the proofs (identical
# cavities' clustered roots) would only double its cost at every step.  (A search for a narrow window halves one
# or two segments a step, and a coarse scan's first steps are few: both go on.)
PAYS, PAYS_MIN = 0.25, 32

GUARANTEE = (
    "Every change of {label} in the scan range is reported: between its boundaries, {label} is proved the same at "
    "every value of the scanned parameter, except inside the undecided gaps listed (undecided_lower, undecided_upper), "
    "and each boundary lies inside its bracket, whose two ends have proved, different {label}."
)
POINTS_ONLY = (
    "This system proves {label} at points only: every scan step whose ends have equal {label} is an undecided gap, "
    "and a feature narrower than the scan spacing (an interval wholly between two adjacent scan values, or an even "
    "number of changes within one scan step) is found only if a bisection midpoint lands on it. Everything that is "
    "reported is {proved}: every located boundary lies inside its bracket, whose two ends have {certified}, "
    "different {label}."
)


@dataclass
class _Brackets:
    """Intervals (lo, hi] of the scanned parameter, each with the labels proved at its two ends."""

    owner: np.ndarray  # int64: flat index into the other axes
    lo: np.ndarray
    hi: np.ndarray
    label_lo: np.ndarray  # int16
    label_hi: np.ndarray

    def take(self, idx) -> _Brackets:
        return _Brackets(self.owner[idx], self.lo[idx], self.hi[idx], self.label_lo[idx], self.label_hi[idx])

    @staticmethod
    def concat(parts: list[_Brackets]) -> _Brackets:
        return _Brackets(*(np.concatenate([getattr(p, f) for p in parts]) for f in ("owner", "lo", "hi", "label_lo", "label_hi")))

    def __len__(self) -> int:
        return self.lo.size


@dataclass
class _Counts:
    """What the run cost, for the Dataset's attributes and history."""

    scan_points: int = 0
    bisection_points: int = 0
    box_proofs: int = 0
    boxes_proved: int = 0
    iterations: int = 0
    provenance: dict = field(default_factory=dict)  # flag value -> points it decided

    def decided(self, system, results: dict) -> None:
        if system.provenance is None:
            return
        values, n = np.unique(results[system.provenance], return_counts=True)
        for v, c in zip(values.tolist(), n.tolist(), strict=True):
            self.provenance[v] = self.provenance.get(v, 0) + c


def check_along(scene: SceneBase, along: str | None) -> tuple[int, str]:
    """Index and name of the grid axis ``along`` (None: the system's ``default_axis``); a StabmapError naming the
    axes if it is not one."""
    names = [a.name for a in scene.grid]
    default = along is None
    along = systems.of(scene).default_axis if along is None else along
    if along not in names:
        have = ", ".join(names) if names else "none (the scene has no [grid])"
        # without along, say which default was taken, and how to choose another
        what = (f"{param('along')} not given, so the {scene.system} system's default axis {along!r}" if default
                else given("along", along))
        try:
            scene.parameter(along)
        except StabmapError as exc:  # not a name this scene could scan at all: say that, not "add it to [grid]"
            raise StabmapError(f"{what}: {exc}; its grid axes are: {have}") from None
        raise StabmapError(
            f"{what}: not a grid axis of this scene; its grid axes are: {have}. "
            f"Add {along} = {{ start = ..., stop = ..., num = ... }} under [grid] to scan it"
            + (f", or give {param('along')} one of them" if default and names else "")
        )
    if len(scene.grid[names.index(along)].values) < 2:
        raise StabmapError(f"{given('along', along)}: grid axis {along!r} has 1 value; critical values need a scan of at "
                           "least 2 values (set num)")
    return names.index(along), along


def check_rtol(rtol) -> float:
    """Validate the relative tolerance of located ends."""
    ok = not isinstance(rtol, bool) and isinstance(rtol, (int, float, np.floating)) and math.isfinite(rtol)
    if not ok or not MIN_RTOL <= rtol < 1:
        raise StabmapError(
            f"{given('rtol', rtol)}: must be between {MIN_RTOL:g} (float64 resolution) and 1 (excluded); the default "
            f"is {DEFAULT_RTOL:g}"
        )
    return float(rtol)


def critical(
    scene: SceneBase,
    along: str | None = None,
    *,
    rtol: float = DEFAULT_RTOL,
    atol: float | None = None,
    client=None,
    workers: int | None = None,
    threads: int | None = None,
    progress: bool | None = None,
    chunk_points: int | None = None,
) -> xr.Dataset:
    """The intervals of ``along`` where the system is stable (its ``stable_label``), ends located to ``rtol``.

    Parameters
    ----------
    scene : a scene of any system
        Its grid: ``along`` must be one of its grid axes; its
        values are the scan (so ``num`` sets how fine a feature can be found),
        and the other grid axes are the dimensions of the result.
    along : str
        The scanned parameter, any grid axis name (default: the system's ``default_axis``).
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
    system = systems.of(scene)
    if system.stable_label is None:
        raise StabmapError(f"critical values are the ends of stable intervals; {system.name} atlases have no stability")
    index, along = check_along(scene, along)
    rtol = check_rtol(rtol)
    chunk_points = check_chunk_points(chunk_points)
    scan = np.sort(scene.grid[index].array)
    if atol is None:
        atol = ATOL_FACTOR * rtol * float(np.abs(scan).max())
    if not (math.isfinite(atol) and atol >= 0):
        raise StabmapError(f"{given('atol', atol)}: must be a finite number >= 0")
    others = tuple(a for d, a in enumerate(scene.grid) if d != index)
    counts = _Counts()
    t0 = time.perf_counter()
    labels = system.labels_only(scene)  # critical values need the label alone, not the system's other outputs
    with runner.start(client, workers=workers, threads=threads, announce=wanted(progress)) as run:
        label = _scan(run, labels, index, progress, chunk_points, counts)
        boxes = along in system.box_axes(labels)
        brackets, gaps = _search(run, labels, along, others, _steps(label, scan), boxes, rtol, atol, chunk_points, counts)
    brackets, gaps = _join(brackets, gaps, rtol, atol)
    ds = _dataset(system, scene, along, others, scan, label, brackets, gaps, _proved(system))
    ds.attrs.update(_attrs(system, along, scan, rtol, atol, counts, boxes))
    ds.attrs["history"] += _history(along, counts, time.perf_counter() - t0)
    return ds


def _scan(run, scene, index: int, progress, chunk_points, counts: _Counts) -> np.ndarray:
    """The label on the whole grid, as (other axes..., along) with the along values increasing."""
    system = systems.of(scene)
    arrays = decide_grid(run, scene, progress=progress, chunk_points=chunk_points, prove_cells=False)  # its own boxes follow
    label = np.moveaxis(arrays[system.label], index, -1)
    if scene.grid[index].values[0] > scene.grid[index].values[-1]:
        label = label[..., ::-1]
    counts.scan_points = label.size
    counts.decided(system, arrays)
    return np.ascontiguousarray(label)


def _steps(label: np.ndarray, scan: np.ndarray) -> _Brackets:
    """Every scan step of every point of the other axes, with the labels at its ends."""
    flat = label.reshape(-1, scan.size)
    owner, step = np.indices(flat[:, :-1].shape)
    owner, step = owner.ravel(), step.ravel()
    return _Brackets(owner.astype(np.int64), scan[step], scan[step + 1], flat[owner, step], flat[owner, step + 1])


def _converged(b: _Brackets, rtol: float, atol: float) -> np.ndarray:
    width = b.hi - b.lo
    mid = b.lo + 0.5 * width
    # No double strictly inside: lo and hi are neighbours and the bracket cannot shrink.
    no_room = (mid <= b.lo) | (mid >= b.hi)
    return (width <= np.maximum(rtol * np.maximum(np.abs(b.lo), np.abs(b.hi)), atol)) | no_room


def _search(run, scene, along, others, active: _Brackets, boxes: bool, rtol, atol, chunk_points, counts: _Counts):
    """Prove or halve every segment (one batch of tasks per step); returns (brackets of changes, undecided gaps).

    Segments are closed intervals of ``along`` (the other axes at one grid point, ``owner``) whose ends have
    proved labels.  A segment proved by a box proof is done; a segment whose ends differ is halved down to a
    quarter of the tolerance (a bracket); one whose ends agree is halved while it is wider than that and its
    owner has box proofs left that pay (BOX_BUDGET, PAYS), else it is a gap.  Without box proofs (``boxes`` False) the segments whose ends
    agree are gaps at once.
    """
    system = systems.of(scene)
    shape = tuple(len(a.values) for a in others)
    npoints = max(1, math.prod(shape))
    steps = np.bincount(active.owner, minlength=npoints)
    budget = BOX_BUDGET * steps + BOX_BUDGET_BOUNDARIES
    spent = np.zeros(npoints, dtype=np.int64)
    unpaid = np.zeros(npoints, dtype=bool)  # points whose box proofs failed broadly (PAYS)
    brackets, gaps = [], []
    for _ in range(MAX_ITERATIONS):
        same = np.flatnonzero(active.label_lo == active.label_hi)  # a segment whose ends differ has no one label to prove
        if boxes and same.size:
            tried = active.take(same)
            label, proved = decide_boxes(run, scene, *_corners(others, shape, along, tried), chunk_points=chunk_points)
            counts.box_proofs += same.size
            counts.boxes_proved += int(proved.sum())
            now = np.bincount(tried.owner, minlength=npoints)
            spent += now
            broad = now >= np.maximum(PAYS_MIN, steps // 4)
            unpaid |= broad & (np.bincount(tried.owner[proved], minlength=npoints) < PAYS * now)
            if np.any(proved & (label != tried.label_lo)):  # pragma: no cover - two proofs disagree
                raise AssertionError(f"a box proof of {system.label} contradicts the proofs at its ends")
            keep = np.ones(len(active), dtype=bool)
            keep[same[proved]] = False
            active = active.take(keep)
        differ = active.label_lo != active.label_hi
        small = _converged(active, rtol / 4, atol / 4)
        stop = small | ((spent >= budget) | unpaid)[active.owner] | (not boxes)
        brackets.append(active.take(differ & small))
        gaps.append(active.take(~differ & stop))
        active = active.take(~small & (differ | ~stop))
        if not len(active):
            break
        mid = active.lo + 0.5 * (active.hi - active.lo)
        results = decide_points(run, scene, {**_owners(others, shape, active.owner), along: mid}, chunk_points=chunk_points)
        counts.bisection_points += mid.size
        counts.decided(system, results)
        counts.iterations += 1
        label_mid = results[system.label]
        active = _Brackets.concat([
            _Brackets(active.owner, active.lo, mid, active.label_lo, label_mid),
            _Brackets(active.owner, mid, active.hi, label_mid, active.label_hi),
        ])
    else:  # pragma: no cover - float64 bisection always reaches neighbouring doubles first
        raise RuntimeError("bisection did not converge")
    return _Brackets.concat(brackets), _Brackets.concat(gaps)


def _owners(others, shape, owner: np.ndarray) -> dict[str, np.ndarray]:
    """The values of the other axes at the grid points ``owner`` (flat indices into them)."""
    idx = np.unravel_index(owner, shape) if shape else ()
    return {a.name: a.array[i] for a, i in zip(others, idx, strict=True)}


def _corners(others, shape, along, seg: _Brackets) -> tuple[dict, dict]:
    """The boxes of segments: the other axes at their owner's grid values, ``along`` from lo to hi."""
    fixed = _owners(others, shape, seg.owner)
    return {**fixed, along: seg.lo}, {**fixed, along: seg.hi}


def _join(brackets: _Brackets, gaps: _Brackets, rtol: float, atol: float) -> tuple[_Brackets, _Brackets]:
    """Gaps that touch a bracket join it while it stays within the tolerance (a gap next to a bracket is at most a
    quarter of it wide, and may be one of a chain); touching gaps merge."""
    if len(gaps):
        keep = np.ones(len(gaps), dtype=bool)
        small = np.flatnonzero(_converged(gaps, rtol / 4, atol / 4))
        ends = {"lo": {(o, x): i for i, (o, x) in enumerate(zip(brackets.owner.tolist(), brackets.lo.tolist(), strict=True))},
                "hi": {(o, x): i for i, (o, x) in enumerate(zip(brackets.owner.tolist(), brackets.hi.tolist(), strict=True))}}
        changed = True
        while changed:  # a chain of gaps joins one by one, from the bracket outwards
            changed = False
            for g in small[keep[small]]:
                o = int(gaps.owner[g])
                for side, touch, new in (("lo", gaps.hi[g], gaps.lo[g]), ("hi", gaps.lo[g], gaps.hi[g])):
                    i = ends[side].get((o, float(touch)))
                    if i is None:
                        continue
                    grown = brackets.take([i])
                    getattr(grown, side)[0] = new
                    if _converged(grown, rtol, atol)[0]:
                        getattr(brackets, side)[i] = new
                        del ends[side][(o, float(touch))]
                        ends[side][(o, float(new))] = i
                        keep[g], changed = False, True
                        break
        gaps = gaps.take(keep)
        gaps = gaps.take(np.lexsort((gaps.lo, gaps.owner)))
    if len(gaps) > 1:
        # a run of gaps, each ending where the next starts, is one gap
        starts = np.ones(len(gaps), dtype=bool)
        starts[1:] = (gaps.owner[1:] != gaps.owner[:-1]) | (gaps.lo[1:] != gaps.hi[:-1])
        first = np.flatnonzero(starts)
        last = np.append(first[1:], len(gaps)) - 1
        gaps = _Brackets(gaps.owner[first], gaps.lo[first], gaps.hi[last], gaps.label_lo[first], gaps.label_hi[last])
    return brackets, gaps


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
    label_below: np.ndarray
    label_above: np.ndarray
    start: np.ndarray  # the label at the first scan value: with the boundaries, the label everywhere in the scan
    n_gaps: np.ndarray
    gap_lower: np.ndarray
    gap_upper: np.ndarray
    whole: np.ndarray  # int8 per stable interval: 1 proved stable throughout, 0 a gap lies inside, -1 pad


def _table(label: np.ndarray, scan: np.ndarray, b: _Brackets, gaps: _Brackets, stable: int, fill: int) -> _Table:
    """Stable intervals, boundaries and undecided gaps of every point of the other axes."""
    flat = label.reshape(-1, scan.size)
    npoints = flat.shape[0]
    gaps = gaps.take(np.lexsort((gaps.lo, gaps.owner)))
    gstarts = np.concatenate([[0], np.cumsum(np.bincount(gaps.owner, minlength=npoints))])
    ng = max(1, int(np.diff(gstarts).max(initial=0)))
    gslot = np.arange(len(gaps)) - gstarts[gaps.owner]
    gap_ends = np.full((2, npoints, ng), np.nan)
    gap_ends[0, gaps.owner, gslot], gap_ends[1, gaps.owner, gslot] = gaps.lo, gaps.hi
    b = b.take(np.lexsort((b.lo, b.owner)))
    starts = np.concatenate([[0], np.cumsum(np.bincount(b.owner, minlength=npoints))])
    intervals = [_stable_intervals(flat[p, 0], scan, b.take(slice(starts[p], starts[p + 1])), stable) for p in range(npoints)]
    n_int = np.array([len(i) for i in intervals], dtype=np.int16)
    ni = max(1, int(n_int.max(initial=0)))
    nb = max(1, int(np.diff(starts).max(initial=0)))
    ends = np.full((4, npoints, ni), np.nan)
    whole = np.full((npoints, ni), -1, dtype=np.int8)
    for p, rows in enumerate(intervals):
        g = gaps.take(slice(gstarts[p], gstarts[p + 1]))
        for i, row in enumerate(rows):
            ends[:, p, i] = row
            whole[p, i] = not np.any((g.hi > row[0]) & (g.lo < row[1]))
    slot = np.arange(len(b)) - starts[b.owner]
    bounds = np.full((2, npoints, nb), np.nan)
    counts = np.full((2, npoints, nb), fill, dtype=label.dtype)
    bounds[0, b.owner, slot], bounds[1, b.owner, slot] = b.lo, b.hi
    counts[0, b.owner, slot], counts[1, b.owner, slot] = b.label_lo, b.label_hi
    n_gaps = np.diff(gstarts).astype(np.int32)
    return _Table(n_intervals=n_int, lower=ends[0], upper=ends[1], lower_outer=ends[2], upper_outer=ends[3],
                  b_lower=bounds[0], b_upper=bounds[1], label_below=counts[0], label_above=counts[1], start=flat[:, 0].copy(),
                  n_gaps=n_gaps, gap_lower=gap_ends[0], gap_upper=gap_ends[1], whole=whole)


def _stable_intervals(label_start: int, scan: np.ndarray, b: _Brackets, stable: int) -> list[tuple[float, float, float, float]]:
    """(lower, upper, lower_outer, upper_outer) of each stable interval of one point; NaN outer: scan end.

    The sorted brackets and the scan steps between them partition the scan
    range, so the label between bracket i-1 and bracket i is bracket i's lower-end label.
    """
    k = len(b)
    if k and not np.array_equal(b.label_hi[:-1], b.label_lo[1:]):  # pragma: no cover - guaranteed by construction
        raise AssertionError("brackets do not chain")
    out = []
    for i in range(k + 1):
        if (label_start if i == 0 else b.label_hi[i - 1]) != stable:
            continue
        lower, lower_outer = (scan[0], np.nan) if i == 0 else (b.hi[i - 1], b.lo[i - 1])
        upper, upper_outer = (scan[-1], np.nan) if i == k else (b.lo[i], b.hi[i])
        out.append((lower, upper, lower_outer, upper_outer))
    return out


def _proved(system) -> str:
    """How the labels were decided, for the texts: "proved", or "decided" for a system whose labels are not proofs."""
    return "proved" if system.proves_labels else "decided"


def _dataset(system, scene, along, others, scan, labels, brackets, gaps, proved: str = "proved") -> xr.Dataset:
    info = system.parameter(scene, along)
    label = system.variable(system.label)
    dims = tuple(a.name for a in others)
    shape = tuple(len(a.values) for a in others)
    t = _table(labels, scan, brackets, gaps, system.stable_label, label.fill)
    iv, bd, gp = dims + ("interval",), dims + ("boundary",), dims + ("gap",)
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
        "boundary_lower": (bd, grid(t.b_lower), along_attrs(
            f"lower end of the bracket of a change of {lab}", f"{lab}_below holds here, {proved}; NaN pads")),
        "boundary_upper": (bd, grid(t.b_upper), along_attrs(
            f"upper end of the bracket of a change of {lab}", f"{lab}_above holds here, {proved}; a change lies in (lower, upper]; NaN pads")),
        f"{lab}_below": (bd, grid(t.label_below), count_attrs(f"{lab} at boundary_lower")),
        f"{lab}_above": (bd, grid(t.label_above), count_attrs(f"{lab} at boundary_upper")),
        f"{along}_stable_whole": (iv, grid(t.whole), {
            "long_name": "stable at every value of the interval", "units": "1",
            "flag_values": np.array([-1, 0, 1], dtype=np.int8), "flag_meanings": "pad gap_inside proved_throughout",
            "comment": f"proved_throughout: {proved} stable at every value from lower to upper; gap_inside: {proved} "
                       "stable at its ends and at the scan values, undecided inside the gaps that overlap it"}),
        "n_undecided": (dims, grid(t.n_gaps), {"long_name": "number of undecided gaps in the scan range", "units": "1",
                                               "comment": f"0: {lab} is {proved} at every value of the scan range outside the boundaries' brackets"}),
        "undecided_lower": (gp, grid(t.gap_lower), along_attrs(
            "lower end of an undecided gap", f"{lab} is {proved} at both ends of a gap and the same there; inside, no proof was found; NaN pads")),
        "undecided_upper": (gp, grid(t.gap_upper), along_attrs("upper end of an undecided gap", "NaN pads")),
        f"{lab}_at_scan_start": (dims, grid(t.start), {"long_name": f"{lab} at the first scan value", "units": label.units or "1",
                                                       "comment": f"{proved}; it holds up to boundary_lower of the first boundary, "
                                                                  f"then {lab}_above of each boundary up to the next"}),
    }
    attrs = global_attrs(system, scene, "stabmap critical values")
    return xr.Dataset(data, coords=coordinates(system, scene, skip=(along,)), attrs=attrs)


def _attrs(system, along, scan, rtol, atol, counts: _Counts, boxes: bool) -> dict:
    attrs = {
        "stabmap_kind": CRITICAL_KIND,
        "critical_along": along,
        "critical_rtol": rtol,
        "critical_atol": atol,
        "critical_scan_points": np.int64(scan.size),
        "critical_scan_range": np.array([scan[0], scan[-1]]),
        "critical_scan_max_step": float(np.diff(scan).max()),
        "critical_evaluated_points": np.int64(counts.scan_points + counts.bisection_points),
        "critical_bisection_steps": np.int64(counts.iterations),
        "critical_box_proofs": np.int64(counts.box_proofs),
        "critical_boxes_proved": np.int64(counts.boxes_proved),
        "comment": "Ends are located until hi - lo <= max(rtol * max(|lo|, |hi|), atol), or lo and hi are neighbouring "
        "doubles. " + (GUARANTEE if boxes else POINTS_ONLY).format(
            label=system.label, proved=_proved(system), certified="certified" if system.proves_labels else "decided"),
    }
    if system.provenance is not None:
        flags = system.variable(system.provenance)
        attrs[f"critical_{flags.name}"] = "; ".join(f"{m}: {counts.provenance.get(v, 0)}" for v, m in flags.flags)
    return attrs


def _history(along, counts: _Counts, seconds: float) -> str:
    return (
        f"; critical values of {along}: {counts.scan_points} scan points, {counts.bisection_points} "
        f"bisection points ({counts.iterations} steps) and {counts.box_proofs} box proofs "
        f"({counts.boxes_proved} proved) in {seconds:.1f} s"
    )
