"""Reading an atlas in chunks: the few passes over its labels that ``info``, ``query`` and ``plot`` need.

Every function here takes plain arrays, numpy or dask (a lazily opened atlas, ``open_atlas(path, lazy=True)``),
and runs over them one chunk at a time (dask's synchronous scheduler), so the memory they use is bounded by a few
chunks, whatever the size of the atlas. Their results are small: counts, one value per line or per pixel block,
or the positions of the label's changes (as many as there are boundaries).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import dask
import dask.array as da
import numpy as np


def compute(*objects):
    """``objects`` (dask, xarray or numpy) computed together, one chunk in memory at a time; numpy passes through.

    Objects that read the same variable share its reads: each chunk is read once for all of them.
    """
    with dask.config.set(scheduler="synchronous"):
        return dask.compute(*objects)


def as_dask(a) -> da.Array:
    """A dask array of ``a``: itself if it is one, else one chunk of it (the same code runs on both)."""
    return a if isinstance(a, da.Array) else da.from_array(np.asarray(a), chunks=-1)


# ---------------------------------------------------------------------------------------------------- along lines
def changes(values, flags) -> tuple[tuple[np.ndarray, ...], np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Every change of ``values`` between neighbours along the last axis, in C order.

    Parameters
    ----------
    values : array of int, shape (..., n)
        A label, the axis searched last.
    flags : array of bool, same shape
        A per-point flag carried along (e.g. "inferred").

    Returns
    -------
    position, below, above, flag_below, flag_above
        ``position``: one index array per axis of the change's lower point (its upper point is one further along
        the last axis); the labels and flags at the two points.
    """
    v = as_dask(values)
    f = as_dask(flags).rechunk(v.chunks)
    starts = [np.concatenate([[0], np.cumsum(c)[:-1]]) for c in v.chunks]
    vs, fs = v.to_delayed(), f.to_delayed()
    parts = []
    for block in np.ndindex(*v.numblocks):  # each chunk with the last point of the one before it along the line
        offset = tuple(int(s[b]) for s, b in zip(starts, block, strict=True))
        before = block[:-1] + (block[-1] - 1,) if block and block[-1] > 0 else None
        parts.append(dask.delayed(_block_changes)(vs[block], fs[block], before and vs[before], before and fs[before], offset))
    found = compute(*parts)
    if not found:
        return tuple(np.zeros(0, dtype=np.intp) for _ in range(v.ndim)), *(np.zeros(0, dtype=a.dtype) for a in (v, v, f, f))
    position = tuple(np.concatenate([p[0][k] for p in found]) for k in range(v.ndim))
    order = np.lexsort(position[::-1])  # C order: the first axis slowest
    position = tuple(p[order] for p in position)
    rest = [np.concatenate([p[k] for p in found])[order] for k in range(1, 5)]
    return position, *rest


def _block_changes(v, f, v_before, f_before, offset):
    """The changes along the last axis inside one chunk, and between it and the chunk before (``*_before``)."""
    if v_before is not None:
        v = np.concatenate([v_before[..., -1:], v], axis=-1)
        f = np.concatenate([f_before[..., -1:], f], axis=-1)
        offset = offset[:-1] + (offset[-1] - 1,)
    where = np.nonzero(v[..., 1:] != v[..., :-1])
    above = where[:-1] + (where[-1] + 1,)
    return tuple(w + o for w, o in zip(where, offset, strict=True)), v[where], v[above], f[where], f[above]


@dataclass(frozen=True)
class FirstTrue:
    """Per line (all axes but the last) of a mask: where it is first True, and what lies there and just before."""

    has: np.ndarray  # bool: the line holds a True
    first: np.ndarray  # index of the first True (0 where none)
    true_to_end: np.ndarray  # bool: True from ``first`` to the end of the line
    value_before: np.ndarray  # values[first - 1]; ``fill`` where first == 0 or nothing is True
    flag_at: np.ndarray  # flags[first] (False where nothing is True)
    flag_before: np.ndarray  # flags[first - 1] (False where there is no such point)


def first_true(mask, values, flags, fill) -> FirstTrue:
    """The first True of ``mask`` along its last axis, per line, with ``values`` and ``flags`` there and before.

    Two passes over the arrays (chunk by chunk): one finds the first True and the last False of every line,
    the second picks the values at and before it.
    """
    m, v, f = as_dask(mask), as_dask(values), as_dask(flags)
    n = m.shape[-1]
    index = da.arange(n, chunks=m.chunks[-1])
    has, first, last_false = compute(m.any(axis=-1), m.argmax(axis=-1), da.where(~m, index, -1).max(axis=-1))
    before = np.maximum(first - 1, 0)
    has_before = has & (first > 0)

    def at(i):  # True at index i[line] of every line, in the chunks of the mask (an outer product: chunks multiply)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", da.PerformanceWarning)
            return index == da.from_array(i[..., None], chunks=m.chunks[:-1] + (1,))

    lowest = np.iinfo(v.dtype).min if np.issubdtype(v.dtype, np.integer) else -np.inf
    value, flag_at, flag_before = compute(
        da.where(at(before), v, lowest).max(axis=-1), (f & at(first)).any(axis=-1), (f & at(before)).any(axis=-1)
    )
    return FirstTrue(
        has=has,
        first=first,
        true_to_end=has & (last_false < first),
        value_before=np.where(has_before, value, fill).astype(v.dtype),
        flag_at=has & flag_at,
        flag_before=has_before & flag_before,
    )


# --------------------------------------------------------------------------------------------------- pixel blocks
@dataclass(frozen=True)
class Blocks:
    """A 2-D label map reduced to blocks of ``factors`` = (rows, columns) points (the last ones may be smaller).

    ``low``/``high``: the smallest and largest label in each block (equal where every point of the block has one
    label); ``mixed_stability``: the block holds stable and not stable points; ``any_flag``: the bitwise OR of
    the flags (small non-negative integers, bit codes, or booleans) of the block's points, None without flags.
    ``counts``: how often each label occurs in the whole map, at full resolution. With factors (1, 1) the blocks are the points themselves.
    """

    factors: tuple[int, int]
    low: np.ndarray
    high: np.ndarray
    mixed_stability: np.ndarray
    any_flag: np.ndarray | None
    counts: dict[int, int]

    @property
    def mixed(self) -> np.ndarray:
        """Blocks holding more than one label."""
        return self.low != self.high

    @property
    def reduced(self) -> bool:
        return self.factors != (1, 1)


def block_factors(shape: tuple[int, int], pixels: tuple[int, int]) -> tuple[int, int]:
    """Points per block along each axis so that a map of ``shape`` has at most ``pixels`` blocks along each."""
    (ny, nx), (py, px) = shape, pixels
    return max(1, math.ceil(ny / max(1, py))), max(1, math.ceil(nx / max(1, px)))


def reduce_blocks(values, flags, stable: int | None, factors: tuple[int, int]) -> Blocks:
    """Reduce a 2-D map ``values`` (and its ``flags``, or None) to blocks of ``factors`` points, chunk by chunk.

    The map is padded at its far ends by repeating its last row and column (which adds no label to a block) and
    cut into dask chunks holding whole blocks; each chunk is reduced and its labels counted (padding left out)
    by one task, so every chunk is read once and dropped at once: one pass, a few chunks in memory. With
    factors (1, 1) the blocks are the points.
    """
    dtype = as_dask(values).dtype
    done = block_tasks([values, flags], factors, _reduce_block, stable=stable)
    low, high, mixed_stable, flagged = (np.block([[p[0][k] for p in row] for row in done]) for k in range(4))
    return Blocks((int(factors[0]), int(factors[1])), low.astype(dtype), high.astype(dtype), mixed_stable.astype(bool),
                  None if flags is None else flagged, _merge(counted for row in done for _, counted in row))


def block_tasks(arrays: list, factors: tuple[int, int], reduce, **options) -> list[list]:
    """``reduce(*chunks, valid, start, factors=..., **options)`` of every chunk of the 2-D ``arrays`` (one shape; an
    entry None is passed as None), as a grid of results (rows of chunks), one task a chunk.

    The arrays are padded at their far ends by repeating their last row and column (``valid``: the chunk's size
    without the padding; ``start``: its first point's index in the map) and cut into chunks holding whole blocks
    of ``factors``, the same for every array, so that each chunk is read once and dropped at once.
    """
    factors = (int(factors[0]), int(factors[1]))
    given = [None if a is None else as_dask(a) for a in arrays]
    first = next(a for a in given if a is not None)
    shape = first.shape
    pad = [(0, -n % k) for n, k in zip(shape, factors, strict=True)]
    if any(p for _, p in pad):
        given = [None if a is None else da.pad(a, pad, mode="edge") for a in given]
        first = next(a for a in given if a is not None)
    chunks = tuple(_multiple(c, k, n) for c, k, n in zip(first.chunksize, factors, first.shape, strict=True))
    given = [None if a is None else a.rechunk(chunks) for a in given]
    first = next(a for a in given if a is not None)
    starts = [np.concatenate([[0], np.cumsum(c)[:-1]]) for c in first.chunks]
    delayed = [None if a is None else a.to_delayed() for a in given]
    tasks = []
    for block in np.ndindex(*first.numblocks):
        valid = tuple(int(min(c[b], n - s[b])) for c, s, b, n in zip(first.chunks, starts, block, shape, strict=True))
        start = tuple(int(s[b]) for s, b in zip(starts, block, strict=True))
        parts = [None if d is None else d[block] for d in delayed]
        tasks.append(dask.delayed(reduce)(*parts, valid, start, factors=factors, **options))
    done = compute(*tasks)
    ncols = first.numblocks[1]
    return [list(done[r * ncols : (r + 1) * ncols]) for r in range(first.numblocks[0])]


def _multiple(chunk: int, k: int, n: int) -> int:
    """A chunk length near ``chunk`` that holds whole blocks of ``k`` (at most the axis, ``n``)."""
    return min(n, max(k, round(chunk / k) * k))


def _reduce_block(v: np.ndarray, f: np.ndarray | None, valid: tuple[int, int], start: tuple[int, int], *, stable,
                  factors) -> tuple[np.ndarray, tuple]:
    """One chunk's blocks (low, high, mixed stability, any flag), and the counts of its labels but for padding."""
    fy, fx = factors
    ny, nx = v.shape[0] // fy, v.shape[1] // fx
    cells = v.reshape(ny, fy, nx, fx)
    out = np.empty((4, ny, nx), dtype=np.int32)
    out[0] = cells.min(axis=(1, 3))
    out[1] = cells.max(axis=(1, 3))
    if stable is None:
        out[2] = 0
    else:
        is_stable = cells == stable
        out[2] = is_stable.any(axis=(1, 3)) & ~is_stable.all(axis=(1, 3))
    out[3] = 0 if f is None else np.bitwise_or.reduce(np.bitwise_or.reduce(f.reshape(ny, fy, nx, fx).astype(np.int32), axis=3), axis=1)
    return out, np.unique(v[: valid[0], : valid[1]], return_counts=True)


def counts(values) -> dict[int, int]:
    """How often each value occurs, chunk by chunk (``dask.array.unique`` would first ravel the array, which for
    a transposed map gathers whole rows across chunks)."""
    return _merge(compute(*_block_counts(values)))


def _block_counts(values) -> list:
    """One delayed ``(values, counts)`` per chunk of ``values``."""
    v = as_dask(values)
    return [dask.delayed(np.unique)(block, return_counts=True) for block in v.to_delayed().ravel()]


def _merge(parts) -> dict[int, int]:
    out: dict[int, int] = {}
    for labels, n in parts:
        for u, c in zip(labels, n, strict=True):
            out[int(u)] = out.get(int(u), 0) + int(c)
    return dict(sorted(out.items()))


# ---------------------------------------------------------------------------------------------- float variables
SCALES = ("linear", "log")  # what a colour scale of a float variable shows: finite values, or finite values > 0


@dataclass(frozen=True)
class ValueStats:
    """A float map's numbers at full resolution (:func:`reduce_values`).

    ``points`` and ``nan`` (points without a value); per scale of :data:`SCALES`, ``off[scale]``: the points of the
    stable label whose value that scale cannot show (not NaN: an exact rate 0 on a log scale, an infinite e-folding
    time), and ``off_range[scale]`` the least and largest of those values; ``unstable_min``: the least finite value
    at a point of any other label (+inf: none); ``positive_min``: the least finite value > 0 (+inf: none);
    ``finite_min``, ``finite_max`` (±inf: none) and ``argmax``, the (row, column) of the largest finite value
    (None: no finite value).
    """

    points: int
    nan: int
    off: dict[str, int]
    off_range: dict[str, tuple[float, float]]
    unstable_min: float
    positive_min: float
    finite_min: float
    finite_max: float
    argmax: tuple[int, int] | None


@dataclass(frozen=True)
class ValueBlocks:
    """A float map reduced to blocks of ``factors`` = (rows, columns) points, beside its label (:func:`reduce_values`).

    Per scale of :data:`SCALES`, ``top[scale]``: the largest value of each block that the scale shows (NaN: none);
    ``off[scale]``: the block holds a point of the stable label whose value the scale cannot show. ``state``: 1
    where every point of the block has the stable label, 2 where some do and some do not, 0 where none does (the
    states :func:`stabmap.read.plot.geometry.block_classes` gives the class map's blocks). ``lower``, ``upper``:
    the least lower bound and the largest upper bound in each block (NaN: none; None: no bounds were given).
    """

    factors: tuple[int, int]
    top: dict[str, np.ndarray]
    off: dict[str, np.ndarray]
    state: np.ndarray
    lower: np.ndarray | None
    upper: np.ndarray | None
    stats: ValueStats

    @property
    def reduced(self) -> bool:
        return self.factors != (1, 1)


def reduce_values(values, labels, stable: int | None, factors: tuple[int, int], lower=None, upper=None) -> ValueBlocks:
    """Reduce a 2-D map of a float variable ``values`` (its label map ``labels`` beside it, and optionally bounds
    ``lower`` and ``upper`` of the values) to blocks of ``factors`` points, in one pass, chunk by chunk.

    A block keeps the largest value of its points (a map of growth rates shows the fastest growth in each block)
    and whether it holds a point of the stable label that a colour scale cannot show; the numbers of
    :class:`ValueStats` are counted over every point.
    """
    done = block_tasks([values, labels, lower, upper], factors, _reduce_values, stable=stable)

    def joined(pick) -> np.ndarray:
        return np.block([[pick(blocks) for blocks, _ in row] for row in done])

    top = {s: joined(lambda b, s=s: b["top"][s]) for s in SCALES}
    off = {s: joined(lambda b, s=s: b["off"][s]) for s in SCALES}
    low, high = (None if given is None else joined(lambda b, k=k: b[k]) for k, given in (("lower", lower), ("upper", upper)))
    parts = [stats for row in done for _, stats in row]
    best = max((p for p in parts if p["argmax"] is not None), key=lambda p: p["finite_max"], default=None)
    stats = ValueStats(
        points=sum(p["points"] for p in parts), nan=sum(p["nan"] for p in parts),
        off={s: sum(p["off"][s] for p in parts) for s in SCALES},
        off_range={s: (min(p["off_range"][s][0] for p in parts), max(p["off_range"][s][1] for p in parts)) for s in SCALES},
        unstable_min=min(p["unstable_min"] for p in parts), positive_min=min(p["positive_min"] for p in parts),
        finite_min=min(p["finite_min"] for p in parts), finite_max=-np.inf if best is None else best["finite_max"],
        argmax=None if best is None else best["argmax"],
    )
    return ValueBlocks((int(factors[0]), int(factors[1])), top, off, joined(lambda b: b["state"]), low, high, stats)


def _reduce_values(v, label, lower, upper, valid: tuple[int, int], start: tuple[int, int], *, stable, factors) -> tuple[dict, dict]:
    """One chunk's blocks (see :class:`ValueBlocks`) and its numbers (see :class:`ValueStats`) but for padding."""
    fy, fx = factors
    ny, nx = v.shape[0] // fy, v.shape[1] // fx
    v = np.asarray(v, dtype=np.float64)
    is_stable = np.zeros(v.shape, dtype=bool) if stable is None else np.asarray(label) == stable
    finite = np.isfinite(v)
    shown = {"linear": finite, "log": finite & (v > 0)}
    off = {s: is_stable & ~np.isnan(v) & ~shown[s] for s in SCALES}

    def per_block(a: np.ndarray, how) -> np.ndarray:
        return how(a.reshape(ny, fy, nx, fx), axis=(1, 3))

    def extreme(a: np.ndarray, keep: np.ndarray, how, empty: float) -> np.ndarray:
        """``how`` (np.max, np.min) of ``a`` where ``keep`` over each block; NaN where it keeps nothing."""
        out = per_block(np.where(keep, a, empty), how)
        return np.where(out == empty, np.nan, out)

    any_stable, all_stable = per_block(is_stable, np.any), per_block(is_stable, np.all)
    blocks = {
        "top": {s: extreme(v, shown[s], np.max, -np.inf) for s in SCALES},
        "off": {s: per_block(off[s], np.any) for s in SCALES},
        "state": np.where(any_stable & ~all_stable, 2, all_stable).astype(np.int8),
    }
    for key, bound, how, empty in (("lower", lower, np.min, np.inf), ("upper", upper, np.max, -np.inf)):
        if bound is not None:
            b = np.asarray(bound, dtype=np.float64)
            blocks[key] = extreme(b, ~np.isnan(b), how, empty)

    inside = (slice(0, valid[0]), slice(0, valid[1]))
    v, is_stable, finite = v[inside], is_stable[inside], finite[inside]
    f = np.where(finite, v, np.nan)

    def least(mask: np.ndarray) -> float:
        return float(v[mask].min()) if mask.any() else np.inf

    def largest(mask: np.ndarray) -> float:
        return float(v[mask].max()) if mask.any() else -np.inf

    stats = {
        "points": int(v.size), "nan": int(np.isnan(v).sum()),
        "off": {s: int(off[s][inside].sum()) for s in SCALES},
        "off_range": {s: (least(off[s][inside]), largest(off[s][inside])) for s in SCALES},
        "unstable_min": least(finite & ~is_stable), "positive_min": least(finite & (v > 0)), "finite_min": least(finite),
        "finite_max": -np.inf, "argmax": None,
    }
    if finite.any():
        row, col = np.unravel_index(int(np.nanargmax(f)), f.shape)
        stats["finite_max"], stats["argmax"] = float(f[row, col]), (int(row) + start[0], int(col) + start[1])
    return blocks, stats
