"""Numba kernels of stabmap: plain arrays in, plain arrays out.

Nothing here imports stabmap, xarray, dask or matplotlib; the labelled layer
(`stabmap`) owns scenes, grids and files.  Coefficient order is ascending powers
of lambda everywhere (as ``numpy.polynomial``).
"""

# stabmap checks this marker at import: an unrelated PyPI package is also called
# ``kernels`` and would otherwise fail in obscure ways.
STABMAP_KERNELS = 1

from .block import charpoly_block, count_block  # noqa: E402
from .status import DECIDED_FLOAT, DECIDED_INCLUSION, DEGENERATE, UNDECIDED  # noqa: E402

__all__ = [
    "STABMAP_KERNELS",
    "charpoly_block",
    "count_block",
    "DECIDED_FLOAT",
    "DECIDED_INCLUSION",
    "UNDECIDED",
    "DEGENERATE",
]
