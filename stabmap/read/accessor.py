"""``ds.stabmap``: the questions of :mod:`stabmap.read.query` as methods of an atlas Dataset, for notebooks.

``import stabmap`` registers the accessor as soon as xarray is imported (xarray's
``register_dataset_accessor``; the Dataset is not subclassed, so every xarray
operation keeps working and returns plain Datasets):

>>> import stabmap
>>> ds = stabmap.open_atlas("atlas.nc")                  # here an atlas of gyroscopes
>>> ds.stabmap.label_at(omega=42.5, K_1=3)
>>> ds.stabmap.stable_fraction(K_1=(0, 10))
>>> ds.stabmap.boundaries("omega", K_1=3).to_dataframe()
>>> ds.stabmap.smallest_stable("omega", over="K_1").smallest_stable.plot()
>>> ds.stabmap.plot("map.png", sel={"K_1": 3})
>>> ds.stabmap.explore()                                   # the interactive page, inline in Jupyter
>>> stabmap.open_atlas("critical.nc").stabmap.to_dataframe()    # one row per stable interval
>>> ds.stability.sel(K_1=3).stabmap.plot()            # xarray's own plot, in stabmap's colours
>>> ds.n_complex_pairs.sel(K_1=3).plot(**ds.stabmap.style())

Each method calls the function of the same name with the Dataset as its first argument, so the two always
give the same answer. A DataArray's ``.stabmap`` draws one class variable with xarray in stabmap's colours
(:mod:`stabmap.read.style`).  This module imports nothing of stabmap at load time: it is loaded while xarray
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

    def label_at(self, *, nearest_edge: bool = False, **point):
        """Every variable at the grid point nearest to ``point``: :func:`stabmap.label_at`."""
        from .query import label_at

        return label_at(self._ds, nearest_edge=nearest_edge, **point)

    def stable_fraction(self, **sel):
        """The fraction of stable grid points in a slice: :func:`stabmap.stable_fraction`."""
        from .query import stable_fraction

        return stable_fraction(self._ds, **sel)

    def boundaries(self, along: str | None = None, /, **sel) -> xr.Dataset:
        """Every change of the label along one axis (default: the system's ``default_axis``): :func:`stabmap.boundaries`."""
        from .query import boundaries

        return boundaries(self._ds, along, **sel)

    def smallest_stable(self, along: str | None = None, over: str | None = None, **sel) -> xr.Dataset:
        """The smallest stable grid value of ``along`` (default: the system's ``default_axis``): :func:`stabmap.smallest_stable`."""
        from .query import smallest_stable

        return smallest_stable(self._ds, along, over, **sel)

    def roots(self, **point: float):
        """Every characteristic root at ``point``, recomputed from the atlas's scene: :func:`stabmap.roots`."""
        from .roots import roots

        return roots(self._ds, **point)

    def summary(self) -> dict:
        """Counts that describe the whole atlas, or a critical-values file's intervals per line: :func:`stabmap.summary`."""
        from .summary import summary

        return summary(self._ds)

    def to_dataframe(self):
        """One row per stable interval of a critical-values file: :func:`stabmap.read.table.intervals_frame`."""
        from .table import intervals_frame

        return intervals_frame(self._ds)

    def plot(self, path: str | Path, **kw) -> Path:
        """Draw the atlas to a PNG or PDF file: :func:`stabmap.plot_atlas` (``x=``, ``y=``, ``sel=``, ...).

        A critical-values Dataset (``stabmap.critical``) is drawn by :func:`stabmap.plot_critical`.
        """
        from ..store.dataset import is_critical  # not at the top: this module loads while xarray does
        from .plot import plot_atlas, plot_critical

        if is_critical(self._ds):
            return plot_critical(self._ds, path, **kw)
        return plot_atlas(self._ds, path, **kw)

    def explore(self, **kw):
        """The interactive page of this atlas or critical-values file, shown inline in Jupyter (a bokeh page in an
        iframe, scripts inlined): :func:`stabmap.read.explore.explore` (``x=``, ``y=``, ``sel=``, ``max_mb=``).
        ``.save("atlas.html")`` writes it to a file; ``.layout`` is the bokeh layout, for ``bokeh.io.show``."""
        from .explore import explore

        return explore(self._ds, **kw)

    def style(self, name: str | None = None) -> dict:
        """Arguments of xarray's ``plot`` that draw the class variable ``name`` (default: the label, e.g.
        ``n_complex_pairs``) in stabmap's colours: ``ds.stability.plot(**ds.stabmap.style("stability"))``
        (:func:`stabmap.read.style.style`)."""
        from .. import systems
        from ..errors import StabmapError
        from .style import style

        system = systems.of_atlas(self._ds.attrs)
        name = name or system.label
        if name not in self._ds.data_vars:
            classes = [str(v) for v in self._ds.data_vars if v == system.label or "flag_meanings" in self._ds[v].attrs]
            raise StabmapError(f"style({name!r}): no such variable in this atlas; its class variables are: {', '.join(classes)}")
        return style(self._ds[name], system)


@xr.register_dataarray_accessor("stabmap")
class StabmapArrayAccessor:
    """One class variable of an atlas drawn by xarray in stabmap's colours: ``ds.stability.stabmap.plot()``."""

    def __init__(self, da: xr.DataArray) -> None:
        self._da = da

    def style(self) -> dict:
        """``cmap``, ``norm`` and ``cbar_kwargs`` for xarray's ``plot``: :func:`stabmap.read.style.style`."""
        from .style import style

        return style(self._da)

    def plot(self, **kwargs):
        """``da.plot.pcolormesh(**kwargs)`` in stabmap's colours, with a colour bar naming the classes
        (:func:`stabmap.read.style.plot`)."""
        from .style import plot

        return plot(self._da, **kwargs)
