"""Modes followed along the spin axis: each point's roots, stored by ascending real part, reordered so that an index
keeps one mode from one spin rate to the next (docs/rates.md, "Modes followed along the spin axis").

Along a line of spin rates each root moves continuously, so between two neighbouring grid points a mode goes to the
root nearest where its last two values say it is heading.  Two orders are weighed at every step: the one that keeps
the order of the real parts (nothing crossed between the two points) and the one of the extrapolated values (the
modes whose slopes say they crossed).  Roots of different Krein type cross freely on the real axis (MacKay 1986;
Kirillov 2013, ch. 7), while roots of one type meet and leave it as a complex pair, so both happen in these spectra.
A crossing is followed only when the extrapolated order fits the new roots decisively better (CROSSING_GAIN); a
mode is ``followed`` only where both orders agree on its root and the proved enclosures of its root at both points
are disjoint from every other mode's.  Elsewhere the mode is ``ambiguous``: continued as said, never silently.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .outputs import FREQUENCY, FREQUENCY_RADIUS, MODE_TRACKING, ROOT_KIND

# A crossing is taken when the extrapolated order's squared misfit is below this share of the kept order's.
CROSSING_GAIN = 0.25
NONE, ASCENDING, FOLLOWED, AMBIGUOUS = (MODE_TRACKING.value(m) for m in ("none", "ascending", "followed", "ambiguous"))
_COMPLEX = 1  # root_kind of a proved non-real root: its conjugate shares its real part


def follow_modes(x: np.ndarray, freq: np.ndarray, radius: np.ndarray, kind: np.ndarray):
    """Reorder the roots of lines of points along one axis into modes.

    ``x`` (n,): the axis's values (a spin rate); ``freq``, ``radius`` (..., n, D) float and ``kind`` (..., n, D)
    int8: each point's roots by ascending real part, NaN (kind -1) padding last.  Returns (freq, radius, kind,
    tracking) of the same shapes, the last axis now the mode.  A line restarts in ascending order where its number
    of roots changes (a point not computed, say).
    """
    shape = freq.shape
    n, D = shape[-2], shape[-1]
    f = freq.reshape(-1, n, D)
    r = radius.reshape(-1, n, D)
    k = kind.reshape(-1, n, D)
    out_f, out_r, out_k = np.full_like(f, np.nan), np.full_like(r, np.nan), np.full_like(k, -1)
    flag = np.full(k.shape, NONE, dtype=np.int8)
    lines = np.arange(f.shape[0])[:, None]
    mode = np.arange(D)[None, :]
    before = None  # the modes' values at the previous point, and their enclosures' separation there
    for step in range(n):
        y, ry, ky = f[:, step], r[:, step], k[:, step]
        apart = _separated(y, ry, ky)
        count = np.sum(~np.isnan(y), axis=1)
        if before is None:
            pos = np.broadcast_to(mode, y.shape)
            restart = np.ones(y.shape[0], dtype=bool)
            state = np.where(np.isnan(y), NONE, ASCENDING)
        else:
            cur, prev, was_apart = before
            h = 0.0 if step < 2 else (x[step] - x[step - 1]) / (x[step - 1] - x[step - 2])
            pred = np.where(np.isnan(prev), cur, cur + (cur - prev) * h)
            restart = (np.sum(~np.isnan(cur), axis=1) != count) | (count == 0)
            pos_kept, pos_ext = _positions(cur, y), _positions(pred, y)
            cost_kept, cost_ext = _misfit(pred, y, pos_kept), _misfit(pred, y, pos_ext)
            cross = cost_ext < CROSSING_GAIN * cost_kept
            pos = np.where(cross[:, None], pos_ext, pos_kept)
            agree = (y[lines, pos_kept] == y[lines, pos_ext]) | np.isnan(y[lines, pos_kept])
            sure = agree & was_apart & apart[lines, pos]
            state = np.where(sure, FOLLOWED, AMBIGUOUS)
            pos = np.where(restart[:, None], mode, pos)
            state = np.where(restart[:, None], ASCENDING, state)
            state = np.where(np.isnan(y[lines, pos]), NONE, state)
        out_f[:, step], out_r[:, step], out_k[:, step] = y[lines, pos], ry[lines, pos], ky[lines, pos]
        flag[:, step] = state
        now = out_f[:, step]
        last = np.full_like(now, np.nan) if before is None else np.where(restart[:, None], np.nan, before[0])  # by the old order
        before = (now, last, apart[lines, pos])
    return (out_f.reshape(shape), out_r.reshape(shape), out_k.reshape(shape), flag.reshape(shape))


def follow_atlas(ds: xr.Dataset, along: str) -> xr.Dataset:
    """``ds`` with its modes followed along the grid axis ``along`` (lazy where ``ds`` is: one line of the axis a
    block, whatever the chunks it was computed in)."""
    names = [FREQUENCY.name, FREQUENCY_RADIUS.name, ROOT_KIND.name, MODE_TRACKING.name]
    parts = [ds[name] for name in names[:3]]
    if any(p.chunks is not None for p in parts):
        parts = [p.chunk({along: -1, "mode": -1}) for p in parts]
    core = [along, "mode"]
    out = xr.apply_ufunc(
        lambda f, r, k: follow_modes(np.asarray(ds[along], dtype=float), f, r, k),
        *parts,
        input_core_dims=[core] * 3,
        output_core_dims=[core] * 4,
        dask="parallelized",
        output_dtypes=[ds[name].dtype for name in names],
    )
    done = ds.copy()
    for name, value in zip(names, out, strict=True):
        done[name] = value.transpose(*ds[name].dims).assign_attrs(ds[name].attrs)
        done[name].encoding = ds[name].encoding
    return done


def _positions(values: np.ndarray, y: np.ndarray) -> np.ndarray:
    """For each mode (its value in ``values``), the index of the root of ``y`` (ascending, NaN last) that the mode's
    rank among ``values`` gives it: the j-th smallest value takes the j-th smallest root."""
    order = np.argsort(values, axis=1, kind="stable")  # NaN last, as in y
    pos = np.empty_like(order)
    np.put_along_axis(pos, order, np.arange(values.shape[1])[None, :], axis=1)
    return pos


def _misfit(pred: np.ndarray, y: np.ndarray, pos: np.ndarray) -> np.ndarray:
    """Sum over the modes of (predicted value - root given)^2, NaN pairs left out."""
    lines = np.arange(y.shape[0])[:, None]
    d = pred - y[lines, pos]
    return np.nansum(d * d, axis=1)


def _separated(y: np.ndarray, r: np.ndarray, kind: np.ndarray) -> np.ndarray:
    """Whether each root's proved interval of real parts [y - r, y + r] misses every other root's, its conjugate
    (a non-real root of the same real part) excepted."""
    lo, hi = (y - r)[:, :, None], (y + r)[:, :, None]
    meet = (lo <= (y + r)[:, None, :]) & ((y - r)[:, None, :] <= hi)
    partner = (y[:, :, None] == y[:, None, :]) & (kind[:, :, None] == _COMPLEX) & (kind[:, None, :] == _COMPLEX)
    D = y.shape[1]
    eye = np.eye(D, dtype=bool)[None]
    others = meet & ~eye & ~partner
    # a pair's two roots count once: a third root on the same real part still meets it
    twins = partner & ~eye
    crowded = twins.sum(axis=2) > 1
    return ~others.any(axis=2) & ~crowded & ~np.isnan(y)


__all__ = ["follow_modes", "follow_atlas", "CROSSING_GAIN", "NONE", "ASCENDING", "FOLLOWED", "AMBIGUOUS"]
