"""Growth rates, e-folding times and mode frequencies of a block of points, with proved enclosures (docs/rates.md).

A growth rate alone needs the non-real roots only: ``rate_block`` encloses the N_c pairs the label has proved by
disjoint Newton disks, so clustered or repeated real roots never widen it.  Where that falls short it takes the
all-roots enclosure of ``roots_block`` (inclusion disks around every root), which is also what the frequencies
use.  Where either is wider than ``REL`` the point's exact rational polynomial is solved by FLINT/Arb instead
(``growth_rate_method`` = exact_arb_roots says where, and so how often).  Labels are taken as given: a point whose
N_c = 0 is proved has growth rate exactly 0, and no root of it is computed unless its frequencies are asked for.
"""

from __future__ import annotations

import flint
import numpy as np

from ...kernels import NONREAL, RATE_FAILED, RATE_PAIRS, REAL, rate_block, roots_block
from . import exact
from .decide import kernel_args
from .outputs import (
    EFOLDING_TIME,
    FREQUENCY,
    FREQUENCY_RADIUS,
    GROWTH_RATE,
    GROWTH_RATE_LOWER,
    GROWTH_RATE_METHOD,
    GROWTH_RATE_UPPER,
    MODE_TRACKING,
    ROOT_KIND,
)
from .points import PointArrays

REL = 1e-6  # a disk enclosure of the growth rate wider than this, relative, goes to exact arithmetic
ALL_REAL, DISKS, EXACT, NOT_COMPUTED, DEGENERATE, PAIRS = (
    GROWTH_RATE_METHOD.value(m) for m in ("all_roots_real", "inclusion_disks", "exact_arb_roots", "not_computed", "degenerate",
                                          "newton_pairs"))


def rates(points: PointArrays, nc: np.ndarray, growth: bool = True, frequencies: bool = False) -> dict[str, np.ndarray]:
    """The growth variables (``growth``) and the frequency variables (``frequencies``) of every point, flat.

    ``nc``: the points' proved N_c (-1: p identically zero).  Frequencies are computed at every point, the growth
    rate's roots only where N_c > 0.
    """
    nc = np.asarray(nc).reshape(-1)
    npts, D = nc.size, int((points.nmodes + 2).sum())
    lower, upper, best = (np.full(npts, np.nan) for _ in range(3))
    method = np.full(npts, NOT_COMPUTED, dtype=np.int8)
    method[nc < 0] = DEGENERATE
    method[nc == 0] = ALL_REAL
    lower[nc == 0] = upper[nc == 0] = best[nc == 0] = 0.0
    freq, radius = np.full((npts, D), np.nan), np.full((npts, D), np.nan)
    kind = np.full((npts, D), -1, dtype=np.int8)
    if growth and not frequencies:
        at = np.flatnonzero(nc > 0)
        if at.size:
            lower[at], upper[at], best[at], method[at] = growth_only(points, at, nc[at], D)
    todo = np.flatnonzero(nc >= 0) if frequencies else np.zeros(0, np.int64)
    if todo.size:
        z, r, k, rate, status = _roots(points.take(todo), D)
        unstable = nc[todo] > 0
        wide = (status != 0) | (unstable & _too_wide(rate))
        for i in np.flatnonzero(wide):
            z[i], r[i], k[i], rate[i] = exact_roots(points, todo[i], D)
        k[~unstable] = np.where(k[~unstable] >= 0, REAL, -1)  # N_c = 0 is proved: every root is real
        at = todo[unstable]
        lower[at], upper[at], best[at] = rate[unstable, 1], rate[unstable, 2], rate[unstable, 0]
        method[at] = np.where(wide[unstable], EXACT, DISKS)
        order = np.argsort(z.real, axis=1)  # NaN (padding) last
        freq[todo] = np.take_along_axis(z.real, order, 1)
        radius[todo] = np.take_along_axis(r, order, 1)
        kind[todo] = np.take_along_axis(k, order, 1)
    out = {}
    if growth:
        lo32, hi32 = outward_float32(lower, upper)
        lo32 = np.maximum(lo32, np.float32(0))  # |Im lambda| >= 0
        rate32 = np.clip(best.astype(np.float32), lo32, hi32)
        with np.errstate(divide="ignore"):
            efold = np.where(rate32 == 0, np.float32(np.inf), np.float32(1) / rate32).astype(np.float32)
        out.update({GROWTH_RATE.name: rate32, GROWTH_RATE_LOWER.name: lo32, GROWTH_RATE_UPPER.name: hi32,
                    EFOLDING_TIME.name: efold, GROWTH_RATE_METHOD.name: method})
    if frequencies:
        # numbered by ascending real part here; the finished atlas follows them along the spin axis (tracking.py)
        order = np.where(kind >= 0, MODE_TRACKING.value("ascending"), MODE_TRACKING.value("none")).astype(np.int8)
        out.update({FREQUENCY.name: freq, FREQUENCY_RADIUS.name: radius, ROOT_KIND.name: kind, MODE_TRACKING.name: order})
    return out


def growth_only(points: PointArrays, at: np.ndarray, nc: np.ndarray, D: int):
    """(lower, upper, estimate, method) of the growth rate at the points ``at`` (N_c = ``nc`` > 0, proved)."""
    rate = np.empty((at.size, 3))
    status = np.empty(at.size, np.int8)
    rate_block(*kernel_args(points.take(at)), nc.astype(np.int64), rate, status)
    method = np.where(status == RATE_PAIRS, PAIRS, DISKS).astype(np.int8)
    wide = (status == RATE_FAILED) | _too_wide(rate)
    for i in np.flatnonzero(wide):
        rate[i] = exact_roots(points, at[i], D)[3]
    method[wide] = EXACT
    return rate[:, 1], rate[:, 2], rate[:, 0], method


def _too_wide(rate: np.ndarray) -> np.ndarray:
    """Rows (estimate, lower, upper) whose enclosure of a nonzero rate proves no positive lower bound or is wider than
    ``REL``: those go to exact arithmetic."""
    return (rate[:, 1] <= 0.0) | (rate[:, 2] - rate[:, 1] > REL * rate[:, 2])


def not_computed(label: np.ndarray, proved: bool) -> dict[str, np.ndarray]:
    """The rate variables of points not evaluated one by one: 0 where N_c = 0 is ``proved``, flagged NaN elsewhere
    (inferred points; a box-proved node's NaN are then replaced by ``rates`` at the node: ``at_proved_nodes``).

    Each has the label's shape; the frequency variables come as the label's shape plus a last axis of 1, a fill that
    broadcasts over the ``mode`` dimension.
    """
    label = np.asarray(label)
    zero = (label == 0) if proved else np.zeros(label.shape, bool)
    rate = np.where(zero, np.float32(0), np.float32(np.nan)).astype(np.float32)
    method = np.where(zero, ALL_REAL, np.where(label < 0, DEGENERATE, NOT_COMPUTED)).astype(np.int8)
    efold = np.where(zero, np.float32(np.inf), np.float32(np.nan)).astype(np.float32)
    column = np.full(label.shape + (1,), np.nan)
    return {GROWTH_RATE.name: rate, GROWTH_RATE_LOWER.name: rate.copy(), GROWTH_RATE_UPPER.name: rate.copy(),
            EFOLDING_TIME.name: efold, GROWTH_RATE_METHOD.name: method,
            FREQUENCY.name: column, FREQUENCY_RADIUS.name: column.copy(), ROOT_KIND.name: np.full(label.shape + (1,), -1, np.int8),
            MODE_TRACKING.name: np.full(label.shape + (1,), -1, np.int8)}


def exact_roots(points: PointArrays, p: int, D: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Roots of point ``p`` from its exact polynomial (FLINT/Arb): (centres, radii, kinds, (estimate, lower, upper)).

    Arb isolates every root with certified error bounds and returns the real ones with an imaginary part that is
    exactly zero, the others with one that excludes zero; the bounds below are its endpoints rounded outward.
    """
    z, r = np.full(D, complex(np.nan, np.nan)), np.full(D, np.nan)
    k = np.full(D, -1, dtype=np.int8)
    rate = np.zeros(3)
    assert points.at is not None  # PointArrays fills it in __post_init__
    poly = exact.char_poly(points.body[p], points.joint[p], points.g[p], points.E[p], points.kappa[p], points.nmodes,
                           points.free, points.parent, points.at[p])
    if poly == 0:
        return z, r, k, np.full(3, np.nan)
    i = 0
    for root, mult in poly.numer().complex_roots():
        im = abs(root.imag)
        for _ in range(mult):
            z[i] = complex(float(root.real.mid()), float(root.imag.mid()))
            # the arb radii, and the rounding of its midpoints to the floats stored
            spill = (abs(root.real.mid()) + abs(root.imag.mid())) * flint.arb(2.0**-52)
            r[i] = up(flint.arb(root.real.rad()) + flint.arb(root.imag.rad()) + spill)
            k[i] = REAL if root.imag.is_zero() else NONREAL
            i += 1
        rate[0] = max(rate[0], float(im.mid()))
        rate[2] = max(rate[2], up(im))
        if not root.imag.is_zero():
            rate[1] = max(rate[1], max(0.0, down(im)))
    return z, r, k, rate


def up(x: flint.arb) -> float:
    """A float >= every point of the arb ball x."""
    return float(np.nextafter(float(x.upper()), np.inf))


def down(x: flint.arb) -> float:
    """A float <= every point of the arb ball x."""
    return float(np.nextafter(float(x.lower()), -np.inf))


def outward_float32(lower: np.ndarray, upper: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """float32 bounds that hold the float64 ones: each rounded away from the enclosed value where float32 rounds in."""
    lo, hi = lower.astype(np.float32), upper.astype(np.float32)
    lo = np.where(lo.astype(np.float64) > lower, np.nextafter(lo, np.float32(-np.inf)), lo)
    hi = np.where(hi.astype(np.float64) < upper, np.nextafter(hi, np.float32(np.inf)), hi)
    return lo, hi


def _roots(points: PointArrays, D: int):
    npts = points.body.shape[0]
    z = np.empty((npts, D), np.complex128)
    r = np.empty((npts, D))
    k = np.empty((npts, D), np.int8)
    rate = np.empty((npts, 3))
    status = np.empty(npts, np.int8)
    roots_block(*kernel_args(points), z, r, k, rate, status)
    return z, r, k, rate, status


__all__ = ["rates", "growth_only", "not_computed", "exact_roots", "up", "down", "outward_float32"]
