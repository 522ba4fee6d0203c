"""Numba kernels of stabmap: plain arrays in, plain arrays out.

Nothing here imports stabmap, xarray, dask or matplotlib; the labelled layer
(`stabmap`) owns scenes, grids and files.  Coefficient order is ascending powers
of lambda everywhere (as ``numpy.polynomial``).  This folder is installed as
``stabmap.kernels`` (PyPI has an unrelated top-level ``kernels`` package); its
modules import each other relatively, so they work under either name.

``layout`` names the columns of the parameter arrays (``body[k, layout.OMEGA]``), the slots of the state arrays
and the fields of the block workspaces (namedtuples: ``ws.state``, ``ws.pws.beta``); the labelled layer fills the
arrays by the same names (docs/speed.md, "Named layouts, at no cost").
"""

from .block import allatonce_block, box_block, charpoly_block, count_block, decide_block, linearise_block, nodes_box_block
from .rates import RATE_ALL_ROOTS, RATE_FAILED, RATE_PAIRS, rate_block
from .roots import NONREAL, REAL, ROOTS_FAILED, UNSEPARATED, roots_block
from .status import DECIDED_ALLATONCE, DECIDED_DISKS, DECIDED_FLOAT, DECIDED_INCLUSION, DECIDED_INERTIA, UNDECIDED, ZERO_POLYNOMIAL

__all__ = [
    "allatonce_block",
    "DECIDED_ALLATONCE",
    "box_block",
    "charpoly_block",
    "count_block",
    "decide_block",
    "linearise_block",
    "nodes_box_block",
    "rate_block",
    "RATE_ALL_ROOTS",
    "RATE_FAILED",
    "RATE_PAIRS",
    "roots_block",
    "NONREAL",
    "REAL",
    "ROOTS_FAILED",
    "UNSEPARATED",
    "DECIDED_DISKS",
    "DECIDED_FLOAT",
    "DECIDED_INERTIA",
    "DECIDED_INCLUSION",
    "UNDECIDED",
    "ZERO_POLYNOMIAL",
]
