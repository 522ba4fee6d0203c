"""Where a run's time went: its tasks' seconds by stage, the writing and the wall clock, and the atlas's attributes
that keep them (``stabmap info`` prints them; docs/speed.md, "Where the time went").

The work is timed inside each task by stage (``stabmap.systems.stages``: ``labels``, the cells' box proofs
``cells``, and the stages a system declares, ``rates`` for gyroscopes) and summed over the tasks, so on several
threads or workers it is CPU-seconds of work, more than the wall time.  ``write`` (checkpoint and file) and
``wall`` are seconds of the process that runs the atlas.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator
from typing import TYPE_CHECKING

from ..systems.stages import CELLS, LABELS

if TYPE_CHECKING:
    from .runner import Runner

WRITE, WALL = "write", "wall"
PREFIX = "stabmap_seconds_"  # stabmap_seconds_labels, ..._write, ..._wall: float seconds
THREADS = "stabmap_run_threads"  # the threads the work ran on (the most a cluster had during the run)
TIMED = "stabmap_run_timed"  # what the seconds cover, said in words
WHOLE = "the whole run"
RESUMED = "the resumed run and the interrupted run's saved chunks"
RESUMED_ONLY = "only the resumed part of a resumed run (the interrupted run's checkpoint holds no times)"


def work_stages(system) -> tuple[str, ...]:
    """The stages a run of ``system`` times its work in."""
    return (LABELS, CELLS, *system.stages)


def columns(system) -> tuple[str, ...]:
    """Every number a run of ``system`` records: its work stages, the writing and the wall clock."""
    return (*work_stages(system), WRITE, WALL)


class Costs:
    """The seconds of one run, taken as they accrue: ``run``'s tasks by stage, the writing timed in ``writing``, and
    the wall clock since ``t0`` (a ``perf_counter`` reading; default: now)."""

    def __init__(self, run: Runner, names: tuple[str, ...], t0: float | None = None):
        self.run, self.names = run, names
        self.spent = dict.fromkeys(names, 0.0)  # everything taken so far
        self._taken: dict[str, float] = {}  # the runner's seconds already taken
        self._write = 0.0
        self._writing: float | None = None  # when the writing under way started, or was last taken
        self._mark = time.perf_counter() if t0 is None else t0

    @contextlib.contextmanager
    def writing(self) -> Iterator[None]:
        """Count the time inside as writing (a ``take`` inside counts it up to then)."""
        self._writing = time.perf_counter()
        try:
            yield
        finally:
            self._write += time.perf_counter() - self._writing
            self._writing = None

    def take(self) -> dict[str, float]:
        """The seconds accrued since the last ``take``, by name: a checkpoint keeps them with the chunk it saves
        next, so that a resumed run adds what the interrupted one spent."""
        out = dict.fromkeys(self.names, 0.0)
        for k, v in self.run.seconds.items():
            if k not in out:
                raise ValueError(f"a task timed the stage {k!r}, which its system does not declare (System.stages)")
            out[k] = v - self._taken.get(k, 0.0)
        self._taken = dict(self.run.seconds)
        now = time.perf_counter()
        if self._writing is not None:
            self._write, self._writing = self._write + now - self._writing, now
        out[WRITE], out[WALL] = self._write, now - self._mark
        self._write, self._mark = 0.0, now
        for k, v in out.items():
            self.spent[k] += v
        return out


def added(*parts: dict[str, float]) -> dict[str, float]:
    """The seconds of several parts of a run, name by name."""
    out: dict[str, float] = {}
    for part in parts:
        for k, v in part.items():
            out[k] = out.get(k, 0.0) + v
    return out


def attrs(seconds: dict[str, float], threads: int, timed: str = WHOLE) -> dict:
    """The global attributes that keep ``seconds`` (netCDF-safe: numbers and a string)."""
    out: dict = {PREFIX + k: round(float(v), 6) for k, v in seconds.items()}
    return {**out, THREADS: int(threads), TIMED: timed}


def from_attrs(attrs: dict) -> dict[str, float]:
    """The seconds an atlas's attributes keep, by name; empty for an atlas written before they were kept."""
    return {k[len(PREFIX):]: float(v) for k, v in attrs.items() if k.startswith(PREFIX)}


def work(seconds: dict[str, float]) -> float:
    """The work of ``seconds``: every stage but the writing and the wall clock."""
    return sum(v for k, v in seconds.items() if k not in (WRITE, WALL))


def note(system, scene, seconds: dict[str, float]) -> str | None:
    """One line for a run whose optional stage (``System.stages``) cost more than its labels (and their cells'
    proofs): what it took and the scene key that skips it (``System.skip_stage``).  None otherwise."""
    labels = seconds.get(LABELS, 0.0) + seconds.get(CELLS, 0.0)
    named = "labels and cells" if seconds.get(CELLS, 0.0) > 0 else "labels"  # as stabmap info names them
    for name in system.stages:
        spent, skip = seconds.get(name, 0.0), system.skip_stage(scene, name)
        if spent > labels and skip is not None:
            what, how = skip
            return f"note: {what} took {spent:.1f} s of {work(seconds):.1f} s of work ({named} {labels:.1f} s); {how}"
    return None


__all__ = ["RESUMED", "RESUMED_ONLY", "WALL", "WHOLE", "WRITE", "Costs", "added", "attrs", "columns", "from_attrs", "note", "work",
           "work_stages"]
