"""The one place that sets numba options for every kernel.

``STABMAP_NUMBA_CACHE=1`` writes compiled kernels to numba's on-disk cache so
that later processes start fast; it is off by default because a stale cache
after an upgrade is a classic source of confusing failures.  fastmath stays off
always: the interval arithmetic relies on IEEE rounding of every operation.
"""

from __future__ import annotations

import os

import numba

CACHE = os.environ.get("STABMAP_NUMBA_CACHE", "0").lower() in {"1", "true", "yes", "on"}


def kernel(func):
    """Compile ``func`` as a serial, GIL-free kernel (dask threads run them in parallel)."""
    return numba.njit(nogil=True, cache=CACHE, fastmath=False, error_model="numpy")(func)
