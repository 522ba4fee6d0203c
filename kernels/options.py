"""The one place that sets numba options for every kernel.

Compiled kernels are cached on disk by default, so a process that finds them
there loads them in well under a second instead of compiling them (about 20 s
on 2 cores).  A stale cache is the classic source of confusing failures: numba
checks only the file that defines a function, not the modules it calls.  So
the cache lives in a directory named after a digest of every kernel source
file and the numba and numpy versions; any change to any of them starts a
fresh cache.

Installation fills the cache ahead of the first run (docs/speed.md, "First
run"): the build step of ``pip install .`` compiles the kernels that an atlas
calls (``precompile``) and ships numba's cache files in the package, under
``_cache/kernels-<digest>``.  The first kernel defined in a process copies
those files into its cache directory where that directory has no index for
them yet; numba then loads them like any cache entry, provided they were
built for the same sources, numba and numpy versions and CPU (numba keys its
entries by CPU and recompiles on a mismatch; a digest mismatch means nothing
is copied).

Environment:
  STABMAP_NUMBA_CACHE=0   no on-disk cache (compile in every process)
  STABMAP_CACHE_DIR=DIR   cache root (default: $XDG_CACHE_HOME/stabmap or ~/.cache/stabmap)
  NUMBA_CACHE_DIR=DIR     numba's own setting wins if given (no digest directory then)

A cache root that cannot be written turns the cache off (every process
compiles) rather than letting numba fall back to a ``__pycache__`` beside the
sources, which it checks file by file only.

fastmath stays off always: the interval arithmetic relies on IEEE rounding of
every operation.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import sys
import tempfile
import time
import warnings
from pathlib import Path

# The kernels run one block per core (threads or dask workers) and call BLAS on small matrices (the all-at-once
# certificate, the Newton disks of long chains): BLAS threads inside each call only oversubscribe the cores, which
# measured 2.5x the CPU time at 24 bodies (BENCHMARKS.md, "All eigenvalues at once").  One BLAS thread, as dask's
# Nanny sets for its workers; a value the user set wins, and it must be set before the BLAS library loads.
for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numba  # noqa: E402 -- after the BLAS threads are set
import numpy  # noqa: E402
from numba.core import event  # noqa: E402

CACHE = os.environ.get("STABMAP_NUMBA_CACHE", "1").lower() not in {"0", "false", "no", "off"}
COMPILE_SECONDS = 20  # a full compile of decide_block on the 2-core machine of BENCHMARKS.md, unloaded


def _source_digest() -> str:
    h = hashlib.sha256(f"numba {numba.__version__} numpy {numpy.__version__}".encode())
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


DIGEST = _source_digest()
SHIPPED = Path(__file__).parent / "_cache" / f"kernels-{DIGEST}"  # filled by the build step, if it ran


def cache_dir() -> Path:
    """Where compiled kernels of this exact source and toolchain are cached."""
    given = os.environ.get("STABMAP_CACHE_DIR")
    root = Path(given) if given else Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "stabmap"
    return root / f"kernels-{DIGEST}"


def _writable(path: Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except OSError:
        return False
    return True


def _our_cache_dir() -> str | None:
    """The cache directory to give numba, or None for numba's own NUMBA_CACHE_DIR or no cache."""
    if not CACHE or os.environ.get("NUMBA_CACHE_DIR"):
        return None
    path = cache_dir()
    if _writable(path):
        return str(path)
    warnings.warn(f"stabmap: cannot write the kernel cache {path}; kernels are compiled in every process "
                  "(set STABMAP_CACHE_DIR to a writable directory)", RuntimeWarning, stacklevel=3)
    return ""


_CACHE_DIR = _our_cache_dir()
_seeded = False


def seed(cache_path: str | os.PathLike | None, shipped: Path = SHIPPED) -> int:
    """Copy the cache files built at install time into numba's ``cache_path``; return how many.

    A function whose index (``*.nbi``) is already there is left alone: numba
    decides about it.  Data files go first and each index last, each through a
    temporary name and an atomic rename, so that processes starting together
    never read half a file.  Any failure leaves the rest to compilation.
    """
    if not cache_path or not shipped.is_dir():
        return 0
    target = Path(cache_path)
    copied = 0
    try:
        for index in sorted(shipped.glob("*.nbi")):
            if (target / index.name).exists():
                continue
            stem = index.name[: -len(".nbi")]
            for f in [*sorted(shipped.glob(f"{stem}.*.nbc")), index]:
                tmp = target / f".{f.name}.{os.getpid()}.tmp"
                shutil.copyfile(f, tmp)
                os.replace(tmp, target / f.name)
                copied += 1
    except OSError:
        pass
    return copied


def kernel(func):
    """Compile ``func`` as a serial, GIL-free kernel (dask threads run them in parallel)."""
    global _seeded
    options = {"nogil": True, "fastmath": False, "error_model": "numpy"}
    if _CACHE_DIR is None:
        dispatcher = numba.njit(cache=CACHE, **options)(func)
    elif not _CACHE_DIR:
        return numba.njit(cache=False, **options)(func)
    else:
        # numba reads CACHE_DIR when the dispatcher is created; restore it so other libraries are unaffected.
        saved = numba.config.CACHE_DIR
        numba.config.CACHE_DIR = _CACHE_DIR
        try:
            dispatcher = numba.njit(cache=True, **options)(func)
        finally:
            numba.config.CACHE_DIR = saved
    if CACHE and not _seeded:  # every kernel lives in this folder, so numba gives all one cache path
        _seeded = True
        seed(dispatcher.stats.cache_path)
    return dispatcher


# "compiling kernels (once, ~20 s)": said when a kernel of this package starts compiling (a cache miss).
def _print_notice(text: str) -> None:
    if sys.stderr is not None and sys.stderr.isatty():
        sys.stderr.write(text + "\n")
        sys.stderr.flush()


_notice = [_print_notice]


def set_compile_notice(callback):
    """Call ``callback(text)`` instead of printing (to stderr, if a terminal) when kernels start compiling.

    ``None`` silences it; returns the callback it replaces (to put back).  It is called at most once per process, from the thread
    that compiles (a dask worker thread, say), when the first kernel of this
    package misses the cache; compilation then holds numba's global lock.
    """
    previous, _notice[0] = _notice[0], callback
    return previous


class _CompileNotice(event.Listener):
    def __init__(self):
        self.depth, self.t0, self.told = 0, 0.0, False

    def on_start(self, ev):
        self.depth += 1
        if self.depth == 1 and not self.told and _ours(ev.data["dispatcher"]):
            self.told, self.t0 = True, time.perf_counter()
            if _notice[0] is not None:
                _notice[0](f"compiling kernels (once, ~{COMPILE_SECONDS} s)")

    def on_end(self, ev):
        self.depth -= 1


def _ours(dispatcher) -> bool:
    module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
    return module.rpartition(".")[0] == __name__.rpartition(".")[0]


event.register("numba:compile", _CompileNotice())
