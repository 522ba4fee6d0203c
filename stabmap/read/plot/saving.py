"""Writing figures: a .png or .pdf name checked before anything is drawn, and an atomic write (a temporary file
renamed into place), so an error or Ctrl-C leaves no partial file."""

from __future__ import annotations

from pathlib import Path

import xarray as xr

from ...errors import StabmapError
from ...store.files import check_writable
from .atlas import atlas_figure
from .campbell import campbell_figure
from .critical import critical_figure
from .layout import DPI, MAX_PANELS
from .value_map import check_value_options, variable_figure


def check_figure_path(path: str | Path) -> Path:
    """A figure file that can be written: a .png or .pdf name in a writable directory."""
    path = check_writable(path)
    if path.suffix.lower() not in (".png", ".pdf"):
        raise StabmapError(f"plot file {str(path)!r}: use a .png or .pdf name")
    return path


def save_figure(fig, path: Path) -> Path:
    """Write the figure atomically (a temporary file renamed into place), then close it; a PNG at 150 dpi (the
    resolution the blocks of big maps are chosen for), a PDF's images at 300 dpi."""
    import matplotlib.pyplot as plt

    tmp = path.with_name(f".{path.name}.tmp{path.suffix}")
    try:
        fig.savefig(tmp, dpi=DPI if path.suffix.lower() == ".png" else 300)
        tmp.replace(path)
    finally:
        plt.close(fig)
        tmp.unlink(missing_ok=True)
    return path


def plot_atlas(
    ds: xr.Dataset,
    path: str | Path,
    *,
    x: str | None = None,
    y: str | None = None,
    sel: dict[str, float] | None = None,
    facet: str | None = None,
    max_panels: int = MAX_PANELS,
    var: str | None = None,
) -> Path:
    """Draw ``ds`` with :func:`atlas_figure`, or its float variable ``var`` (e.g. ``"growth_rate"``) with
    :func:`variable_figure`, and write it to ``path`` (.png or .pdf) atomically; returns the path.

    Every check runs before anything is written, so bad options leave no file.
    """
    path = check_figure_path(path)
    if var is not None:
        check_value_options(var, facet, max_panels != MAX_PANELS)
        return save_figure(variable_figure(ds, var, x=x, y=y, sel=sel), path)
    return save_figure(atlas_figure(ds, x=x, y=y, sel=sel, facet=facet, max_panels=max_panels), path)


def plot_critical(ds: xr.Dataset, path: str | Path, *, sel: dict[str, float] | None = None) -> Path:
    """Draw a critical-values Dataset to a file (:func:`critical_figure`): PNG or PDF, written atomically."""
    path = check_figure_path(path)
    return save_figure(critical_figure(ds, sel=sel), path)


def plot_campbell(ds: xr.Dataset, path: str | Path, *, x: str | None = None, sel: dict[str, float] | None = None) -> Path:
    """Draw the Campbell diagram of ``ds`` (:func:`campbell_figure`) to ``path``: a PNG or PDF, or an .html page with
    tooltips (:mod:`.campbell_page`), written atomically."""
    if Path(path).suffix.lower() in (".html", ".htm"):
        from ...store.files import write_text
        from .campbell_page import campbell_page

        return write_text(campbell_page(ds, x=x, sel=sel), check_writable(path))
    path = check_figure_path(path)
    return save_figure(campbell_figure(ds, x=x, sel=sel), path)
