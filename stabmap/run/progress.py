"""One self-overwriting progress line on stderr, shown only once a run has taken a while."""

from __future__ import annotations

import sys
import time


def wanted(progress: bool | None) -> bool:
    """A run's ``progress`` option: None means "when stderr is a terminal"."""
    return sys.stderr.isatty() if progress is None else progress


class ProgressLine:
    """Shows ``text`` at most every ``dt`` seconds, from ``minimum`` seconds after the start.

    Short runs print nothing, so scripted use and tests stay quiet.
    """

    def __init__(self, enabled: bool, minimum: float = 2.0, dt: float = 0.5):
        self.enabled, self.minimum, self.dt = enabled, minimum, dt
        self.t0 = time.perf_counter()
        self.last = 0.0
        self.shown = False

    @property
    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def show(self, text: str, force: bool = False) -> None:
        now = self.elapsed
        if not self.enabled or (not force and (now < self.minimum or now - self.last < self.dt)):
            return
        self.last, self.shown = now, True
        sys.stderr.write(f"\r{text}   ")
        sys.stderr.flush()

    def close(self) -> None:
        if self.shown:
            sys.stderr.write("\n")
            sys.stderr.flush()
