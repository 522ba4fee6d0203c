"""``ds.stabmap``: the questions of :mod:`stabmap.read.query` as methods of an atlas Dataset, for notebooks.

``import stabmap`` registers the accessor as soon as xarray is imported (xarray's
``register_dataset_accessor``; the Dataset is not subclassed, so every xarray
operation keeps working and returns plain Datasets):

>>> import stabmap
>>> ds = stabmap.open_atlas("atlas.nc")
>>> ds.stabmap.label_at(omega=42.5, K_1=3)
>>> ds.stabmap.stable_fraction(K_1=(0, 10))
>>> ds.stabmap.boundaries("omega", K_1=3).to_dataframe()
>>> ds.stabmap.smallest_stable("omega", over="K_1").smallest_stable.plot()
>>> ds.stabmap.plot("map.png", sel={"K_1": 3})

Each method calls the function of the same name with the Dataset as its first argument, so the two always
give the same answer.  This module imports nothing of stabmap at load time: it is loaded while xarray
itself is being imported.
"""

from __future__ import annotations

from pathlib import Path

import xarray as xr


@xr.register_dataset_accessor("stabmap")
class StabmapAccessor:
    """Questions asked of a stabmap atlas: ``ds.stabmap.<question>(...)`` (see :mod:`stabmap.read.query`)."""

    def __init__(self, ds: xr.Dataset) -> None:
        self._ds = ds

    def label_at(self, **point: float):
        """Every variable at the grid point nearest to ``point``: :func:`stabmap.label_at`."""
        from .query import label_at

        return label_at(self._ds, **point)

    def stable_fraction(self, **sel):
        """The fraction of stable grid points in a slice: :func:`stabmap.stable_fraction`."""
        from .query import stable_fraction

        return stable_fraction(self._ds, **sel)

    def boundaries(self, along: str, /, **sel) -> xr.Dataset:
        """Every change of the label along one axis: :func:`stabmap.boundaries`."""
        from .query import boundaries

        return boundaries(self._ds, along, **sel)

    def smallest_stable(self, along: str = "omega", over: str | None = None, **sel) -> xr.Dataset:
        """The smallest stable grid value of ``along``: :func:`stabmap.smallest_stable`."""
        from .query import smallest_stable

        return smallest_stable(self._ds, along, over, **sel)

    def roots(self, **point: float):
        """Every characteristic root at ``point``, recomputed from the atlas's scene: :func:`stabmap.roots`."""
        from .roots import roots

        return roots(self._ds, **point)

    def summary(self) -> dict:
        """Counts that describe the whole atlas: :func:`stabmap.summary`."""
        from .summary import summary

        return summary(self._ds)

    def plot(self, path: str | Path, **kw) -> Path:
        """Draw the atlas to a PNG or PDF file: :func:`stabmap.plot_atlas` (``x=``, ``y=``, ``sel=``, ...).

        A critical-values Dataset (``stabmap.critical``) is drawn by :func:`stabmap.plot_critical`.
        """
        from .plot import plot_atlas, plot_critical

        if self._ds.attrs.get("stabmap_kind") == "critical values":
            return plot_critical(self._ds, path, **kw)
        return plot_atlas(self._ds, path, **kw)
