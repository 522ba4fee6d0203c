"""A larger spare for the proofs between grid points (``stabmap.run.cells.SPARE``), for tests of what cells claim
on coarse grids, where the default spare tries few boxes: what is proved must hold whatever the spare."""

from __future__ import annotations

import contextlib

from stabmap.run import cells


@contextlib.contextmanager
def spare(value: float = 1.0):
    """``cells.SPARE`` set to ``value`` inside the block (in-process atlases: threads share the module)."""
    saved, cells.SPARE = cells.SPARE, value
    try:
        yield
    finally:
        cells.SPARE = saved
