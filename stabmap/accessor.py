"""``ds.stabmap``: the questions of :mod:`stabmap.query` as methods of an atlas Dataset, for notebooks.

``import stabmap`` registers the accessor (xarray's ``register_dataset_accessor``; the Dataset is not
subclassed, so every xarray operation keeps working and returns plain Datasets):

>>> import stabmap
>>> ds = stabmap.open_atlas("atlas.nc")
>>> ds.stabmap.label_at(omega=42.5, K_1=3)
>>> ds.stabmap.stable_fraction(K_1=(0, 10))
>>> ds.stabmap.boundaries("omega", K_1=3).to_dataframe()
>>> ds.stabmap.smallest_stable("omega", over="K_1").smallest_stable.plot()
>>> ds.stabmap.plot("map.png", sel={"K_1": 3})

Each method calls the function of the same name with the Dataset as its first argument, so the two always
give the same answer; their docstrings are the functions'.
"""

from __future__ import annotations

from pathlib import Path

import xarray as xr

from . import query


@xr.register_dataset_accessor("stabmap")
class StabmapAccessor:
    """Questions asked of a stabmap atlas: ``ds.stabmap.<question>(...)`` (see :mod:`stabmap.query`)."""

    def __init__(self, ds: xr.Dataset) -> None:
        self._ds = ds

    def label_at(self, **point: float) -> query.Label:
        return query.label_at(self._ds, **point)

    def stable_fraction(self, **sel) -> query.StableFraction:
        return query.stable_fraction(self._ds, **sel)

    def boundaries(self, along: str, /, **sel) -> xr.Dataset:
        return query.boundaries(self._ds, along, **sel)

    def smallest_stable(self, along: str = "omega", over: str | None = None, **sel) -> xr.Dataset:
        return query.smallest_stable(self._ds, along, over, **sel)

    def summary(self) -> dict:
        return query.summary(self._ds)

    def plot(self, path: str | Path, **kw) -> Path:
        """Draw the atlas to a PNG or PDF file: :func:`stabmap.plot.plot_atlas` (``x=``, ``y=``, ``sel=``, ...).

        A critical-values Dataset (``stabmap.critical``) is drawn by :func:`stabmap.plot.plot_critical`.
        """
        from .plot import plot_atlas, plot_critical

        if self._ds.attrs.get("stabmap_kind") == "critical values":
            return plot_critical(self._ds, path, **kw)
        return plot_atlas(self._ds, path, **kw)


for _name in ("label_at", "stable_fraction", "boundaries", "smallest_stable", "summary"):
    getattr(StabmapAccessor, _name).__doc__ = getattr(query, _name).__doc__
del _name
