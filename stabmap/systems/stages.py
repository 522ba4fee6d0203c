"""Where a task's time goes: its seconds split by stage, measured where the work is done.

A task of a run (``stabmap.run.tasks.run_task``) times its work with ``timed``; inside, code that does an
optional part of the work wraps it in ``stage(NAME)`` (a system its growth rates, say, declared in
``System.stages``; the cells' box proofs ``CELLS``).  Time outside every named stage is ``LABELS``: deciding the
label.  Stages nest, each second counted once, in the innermost stage: growth rates computed inside a box proof
count as rates.

The seconds travel back with the task's result (a thread here or a dask worker in another process alike); this
module only keeps the clock of the task running on the current thread.  Outside a timed task ``stage`` does
nothing.  The cost is one ``perf_counter`` pair a ``stage``, never per point.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Iterator

LABELS = "labels"  # deciding the label: the work outside every named stage
CELLS = "cells"  # the cells' box proofs (stabmap.run.cells)

_local = threading.local()


class _Clock:
    """The seconds of one task by stage, and the stage running now."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}
        self.current = LABELS
        self.since = time.perf_counter()

    def switch(self, name: str) -> str:
        """Charge the time since the last switch to the running stage, start ``name``; returns the stage left."""
        now = time.perf_counter()
        self.seconds[self.current] = self.seconds.get(self.current, 0.0) + (now - self.since)
        left, self.current, self.since = self.current, name, now
        return left


@contextlib.contextmanager
def timed() -> Iterator[dict[str, float]]:
    """Time the work inside by stage: the dict yielded holds the seconds of each stage once the block is left."""
    clock, outer = _Clock(), getattr(_local, "clock", None)
    _local.clock = clock
    try:
        yield clock.seconds
    finally:
        clock.switch(LABELS)
        _local.clock = outer


@contextlib.contextmanager
def stage(name: str) -> Iterator[None]:
    """Charge the time inside to the stage ``name`` of the task timed on this thread (none: nothing is timed)."""
    clock = getattr(_local, "clock", None)
    if clock is None:
        yield
        return
    left = clock.switch(name)
    try:
        yield
    finally:
        clock.switch(left)


__all__ = ["CELLS", "LABELS", "stage", "timed"]
