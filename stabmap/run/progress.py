"""One self-overwriting progress line on stderr, shown once a run has taken a while, or at once when kernels compile."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable


def wanted(progress: bool | None) -> bool:
    """A run's ``progress`` option: None means "when stderr is a terminal"."""
    return sys.stderr.isatty() if progress is None else progress


class ProgressLine:
    """Shows ``text`` at most every ``dt`` seconds, from ``minimum`` seconds after the start.

    Short runs print nothing, so scripted use and tests stay quiet.  While the line is open it also receives the
    kernels' compile notice (``stabmap.kernels.options.set_compile_notice``): the first run after an install or
    an upgrade compiles for tens of seconds, and the line says so at once, as ``note``, instead of staying silent.
    ``redraw`` (set by the owner) draws the owner's current line; without it the note is shown alone.
    """

    def __init__(self, enabled: bool, minimum: float = 2.0, dt: float = 0.5):
        self.enabled, self.minimum, self.dt = enabled, minimum, dt
        self.t0 = time.perf_counter()
        self.last = 0.0
        self.shown = False
        self.note: str | None = None  # "compiling kernels (once, ~20 s)" once that is what happens
        self.redraw: Callable[[], None] | None = None
        self._force = False
        self._notice = None
        if enabled:
            from ..kernels import options

            self._notice = (options.set_compile_notice(self._compiling),)

    def _compiling(self, text: str) -> None:
        """The compile notice (called from the thread that compiles): shown now, not after ``minimum``."""
        self.note, self._force = text, True
        if self.redraw is not None:
            self.redraw()
        else:
            self.show(text)

    @property
    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def show(self, text: str, force: bool = False) -> None:
        now = self.elapsed
        force = force or self._force
        if not self.enabled or (not force and (now < self.minimum or now - self.last < self.dt)):
            return
        self.last, self.shown, self._force = now, True, False
        sys.stderr.write(f"\r{text}   ")
        sys.stderr.flush()

    def say(self, text: str) -> None:
        """``text`` on a line of its own (below the progress line, if one is drawn), shown whatever the time."""
        if not self.enabled:
            return
        sys.stderr.write(("\n" if self.shown else "") + text + "\n")
        sys.stderr.flush()
        self.shown = False

    def close(self) -> None:
        if self._notice is not None:  # the notice goes back to whoever had it before this line
            from ..kernels import options

            options.set_compile_notice(self._notice[0])
            self._notice = None
        if self.shown:
            sys.stderr.write("\n")
            sys.stderr.flush()


class Rate:
    """Points per second of a run and the time it has left, from the points finished over the last WINDOW seconds.

    The clock starts at the first finished task, so the time spent loading kernels and timing the probe does not
    count as slow work; the window follows a cluster that gains or loses workers.  There is no rate (and so no
    time to go) until the finished tasks span ``MIN_SPAN`` seconds: tasks held up together (by compilation, say)
    and finishing at once measure nothing.
    """

    WINDOW = 30.0  # seconds of history the rate is measured over
    MIN_SPAN = 1.0  # seconds between the first and the last finished task before a rate is given

    def __init__(self, total: int, done: int = 0):
        self.total, self.done = total, done
        self._history: list[tuple[float, int]] = []

    def add(self, points: int) -> None:
        self.done += points
        now = time.perf_counter()
        self._history.append((now, self.done))
        while len(self._history) > 2 and now - self._history[1][0] > self.WINDOW:
            self._history.pop(0)

    def per_second(self) -> float | None:
        """Points per second, once two tasks have finished ``MIN_SPAN`` seconds apart or more (else None)."""
        if len(self._history) < 2 or self._history[-1][0] - self._history[0][0] < self.MIN_SPAN:
            return None
        (t0, d0), now = self._history[0], time.perf_counter()
        return (self.done - d0) / max(now - t0, 1e-9)

    def text(self, unit: str = "points") -> str:
        """'12,345/1,000,000 points (1.2 %)' and, once measured, the rate and the time to go."""
        line = f"{self.done:,}/{self.total:,} {unit} ({100 * self.done / max(1, self.total):.1f} %)"
        rate = self.per_second()
        if rate:
            line += f", {rate:,.0f} {unit}/s, about {_duration((self.total - self.done) / rate)} to go"
        return line


def _duration(seconds: float) -> str:
    if seconds < 100:
        return f"{seconds:.0f} s"
    if seconds < 6000:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
