"""The one place that sets numba options for every kernel.

Compiled kernels are cached on disk by default, so only the first run after
an install or upgrade pays the compilation (about 20 s); later processes load
them in well under a second.  A stale cache is the classic source of confusing
failures: numba checks only the timestamp of the file that defines a function,
not of the modules it calls.  So the cache lives in a directory named after a
digest of every kernel source file and the numba and numpy versions; any
change to any of them starts a fresh cache.

Environment:
  STABMAP_NUMBA_CACHE=0   no on-disk cache (compile in every process)
  STABMAP_CACHE_DIR=DIR   cache root (default: $XDG_CACHE_HOME/stabmap or ~/.cache/stabmap)
  NUMBA_CACHE_DIR=DIR     numba's own setting wins if given

fastmath stays off always: the interval arithmetic relies on IEEE rounding of
every operation.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numba
import numpy

CACHE = os.environ.get("STABMAP_NUMBA_CACHE", "1").lower() not in {"0", "false", "no", "off"}


def _source_digest() -> str:
    h = hashlib.sha256(f"numba {numba.__version__} numpy {numpy.__version__}".encode())
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def cache_dir() -> Path:
    """Where compiled kernels of this exact source and toolchain are cached."""
    root = os.environ.get("STABMAP_CACHE_DIR")
    if not root:
        root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "stabmap"
    return Path(root) / f"kernels-{_source_digest()}"


_CACHE_DIR = str(cache_dir()) if CACHE and not os.environ.get("NUMBA_CACHE_DIR") else None


def kernel(func):
    """Compile ``func`` as a serial, GIL-free kernel (dask threads run them in parallel)."""
    if _CACHE_DIR is None:
        return numba.njit(nogil=True, cache=CACHE, fastmath=False, error_model="numpy")(func)
    # numba reads CACHE_DIR when the dispatcher is created; restore it so other libraries are unaffected.
    saved = numba.config.CACHE_DIR
    numba.config.CACHE_DIR = _CACHE_DIR
    try:
        return numba.njit(nogil=True, cache=True, fastmath=False, error_model="numpy")(func)
    finally:
        numba.config.CACHE_DIR = saved
