"""The shares of a map's area that its cells prove stable or unstable, or to hold a change, for figure titles.

A grid point's share of the grid depends on the grid (a log axis crowds points at its low end); a cell's share of
the area does not. Cells are weighted by their size from the axis's cell edges, the same edges as the atlas's
bounds variables (``stabmap.store.dataset.edges``; docs/cells.md), read chunk by chunk like every other pass over
a lazy atlas (:mod:`stabmap.read.blocks`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..store.variables import CELL

_WHOLE, _CHANGE, _NOT_PROVED = CELL.value("whole_cell"), CELL.value("contains_change"), CELL.value("not_proved")


@dataclass(frozen=True)
class AreaShares:
    """Shares of the area drawn (each in [0, 1], together 1).

    ``stable`` and ``unstable``: whole cells proved stable or unstable (any other class, such as degenerate,
    is ``other``); ``change``: cells proved to hold a boundary, so neither; ``undecided``: cells whose label is
    proved at the grid point only, or not even there (``node_only``, ``not_proved``). ``inferred``: how many grid
    points are ``not_proved`` (a count, not a share).
    """

    stable: float
    unstable: float
    other: float
    change: float
    undecided: float
    inferred: int = 0

    @property
    def whole(self) -> float:
        """The share whose label is proved over the whole cell, whatever the class."""
        return self.stable + self.unstable + self.other

    @staticmethod
    def mean(shares: list[AreaShares]) -> AreaShares:
        """The shares of several maps of equal area together (the panels of one figure); their inferred points summed."""
        stable, unstable, other, change, undecided = (float(np.mean([getattr(s, k) for s in shares]))
                                                      for k in ("stable", "unstable", "other", "change", "undecided"))
        return AreaShares(stable, unstable, other, change, undecided, inferred=sum(s.inferred for s in shares))


def area_shares(labels, cells, wy: np.ndarray, wx: np.ndarray, stable: int | None) -> list[AreaShares]:
    """The :class:`AreaShares` of each of several maps of one size, shape (ny, nx) each (numpy or dask: the panels
    of a figure), computed in one pass.

    Parameters
    ----------
    labels, cells : sequences of arrays, shape (ny, nx)
        Each map's label and its ``cell`` flag.
    wy, wx : arrays of float, shape (ny,) and (nx,)
        The cells' sizes along y and x (ones along an axis of one value).
    stable : int or None
        The label of a stable point (None: a system without stability, whose whole cells are all ``other``
        or ``unstable``).
    """
    import dask.array as da

    from .blocks import as_dask, compute

    sums: list = []  # dask arrays, one per map and mask
    for label, cell in zip(labels, cells, strict=True):
        label = as_dask(label)
        cell = as_dask(cell).rechunk(label.chunks)
        wxd = da.from_array(np.asarray(wx, dtype=float), chunks=(label.chunks[1],))[None, :]
        whole = cell == _WHOLE
        is_stable = (label == stable) if stable is not None else da.zeros(label.shape, dtype=bool, chunks=label.chunks)
        masks = (whole & is_stable, whole & (label >= 0) & ~is_stable, whole & (label < 0), cell == _CHANGE)
        sums.extend(da.where(m, wxd, 0.0).sum(axis=1) for m in masks)  # per row: no (ny, nx) array of weights
        sums.append((cell == _NOT_PROVED).sum())
    rows = compute(*sums)
    total = float(np.sum(wy)) * float(np.sum(wx))
    out = []
    for p in range(len(labels)):
        stable_, unstable, other, change = (float(np.dot(wy, rows[5 * p + k])) / total for k in range(4))
        undecided = max(0.0, 1.0 - (stable_ + unstable + other + change))
        out.append(AreaShares(stable_, unstable, other, change, undecided, inferred=int(rows[5 * p + 4])))
    return out
