"""Interactive pages of atlases and critical values: one self-contained HTML file (bokeh, scripts inlined: no
server, no internet) or an inline view in Jupyter (``ds.stabmap.explore()``).

- :mod:`.plan`: which axis goes where (two on the map, a slider for each further one) and what fits the size bound;
- :mod:`.frames`: each slider setting's map read once and reduced to blocks no smaller than a pixel;
- :mod:`.states`: a block's state (labels, provenance, cell proofs, colour), packed into one integer;
- :mod:`.text`: mathtext as plain Unicode, the lines shown for grid values;
- :mod:`.widgets`: sliders, the frame-switching callback, readout, legend, caption;
- :mod:`.atlas`: the page of an atlas; :mod:`.critical`: the page of a critical-values file;
- :mod:`.page`: the page as a file (atomic write) or inline in a notebook.
"""

from __future__ import annotations

import xarray as xr

from ...store.dataset import is_critical
from .atlas import atlas_page
from .critical import critical_page
from .page import MAX_MB, Page, check_page_path


def explore(ds: xr.Dataset, **kw) -> Page:
    """The page of ``ds``: :func:`critical_page` for critical values, else :func:`atlas_page` (same options)."""
    return critical_page(ds, **kw) if is_critical(ds) else atlas_page(ds, **kw)


__all__ = ["MAX_MB", "Page", "atlas_page", "check_page_path", "critical_page", "explore"]
