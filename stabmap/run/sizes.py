"""How big a run is before it starts: its points, its file and memory, and the time a probe predicts.

A grid's size is the product of its axes, so a few keys of a scene can ask for more than a disk or a machine holds
(a 40 000 x 40 000 scan is 1.6e9 points).  A run that cannot fit is refused here, before any work, in one line;
a large one says what it will cost before it starts (docs/own-scene.md, "What a scene refuses, and how big a grid may be").

The sizes are exact before compression: the bytes of every variable the system stores at a grid point (its dtypes,
``stabmap.store.dataset.empty_arrays``) times the points.  The file and the run's checkpoint are compressed (zlib,
Zarr's default codec), to about a quarter on the bundled examples, and both are on disk at the end of a run: so a
run is refused when the uncompressed size is more than the free space, which leaves them about a factor of two.
"""

from __future__ import annotations

import math
import shutil
from dataclasses import dataclass
from pathlib import Path

from .. import systems
from ..errors import StabmapError

ANNOUNCE_POINTS = 1_000_000  # from here a run says its size before it starts (a few minutes of work on two threads)
ANNOUNCE_SECONDS = 10.0  # ... and from here (the probe's estimate) on any grid


@dataclass(frozen=True)
class Size:
    """The grid's shape and the bytes its atlas stores a point, uncompressed."""

    shape: tuple[int, ...]
    bytes_per_point: int

    @property
    def points(self) -> int:
        return math.prod(self.shape)

    @property
    def nbytes(self) -> int:
        return self.points * self.bytes_per_point

    def text(self) -> str:
        """'1,600,000,000 points (40,000 x 40,000), file at most 35.2 GB (before compression)'."""
        shape = " \u00d7 ".join(f"{n:,}" for n in self.shape)
        return f"{self.points:,} points ({shape}), file at most {human(self.nbytes)} (before compression)"


def of(scene) -> Size:
    """The size of ``scene``'s atlas, from its system's variables (nothing is allocated)."""
    from ..store.dataset import empty_arrays

    one = empty_arrays(systems.of(scene), scene, (1,) * len(scene.shape))  # one point: its bytes, by variable
    return Size(tuple(scene.shape), sum(a.nbytes for a in one.values()))


def check_disk(size: Size, output: str | Path) -> None:
    """Refuse a grid whose atlas cannot fit on the disk of ``output`` (its directory's free space)."""
    where = Path(output).resolve().parent
    free = shutil.disk_usage(where).free
    if size.nbytes > free:
        raise StabmapError(
            f"the atlas of {size.points:,} points would take up to {human(size.nbytes)} before compression, and the run keeps "
            f"a checkpoint beside it, but {str(where)!r} has {human(free)} free; make the grid coarser (smaller num) "
            "or write to a disk with more room"
        )


def check_memory(size: Size, what: str = "an atlas in memory") -> None:
    """Refuse a grid whose atlas cannot be held in this machine's available memory (``compute``, ``--refine``)."""
    free = available_memory()
    if free is not None and size.nbytes > free:
        raise StabmapError(
            f"{what} of {size.points:,} points needs {human(size.nbytes)}, but {human(free)} of memory is available; "
            "make the grid coarser (smaller num), or write it to a file (compute_to_file, 'stabmap atlas' without --refine), "
            "which holds a few chunks at a time"
        )


def available_memory() -> int | None:
    """Bytes of memory available to a new allocation (psutil, which dask.distributed installs), or None if unknown."""
    try:
        import psutil  # type: ignore[import-untyped]
    except ImportError:
        return None
    return int(psutil.virtual_memory().available)


def estimate(size: Size, seconds_per_point: float, threads: int, points_timed: int) -> str:
    """'about 3.1 h on 2 threads (timed on 512 points)': the run's time at a probe's pace (``seconds_per_point`` of
    one thread)."""
    seconds = size.points * seconds_per_point / max(1, threads)
    return f"about {duration(seconds)} on {threads} thread{'s' if threads != 1 else ''} (timed on {points_timed:,} points)"


def worth_saying(size: Size, seconds: float | None = None) -> bool:
    """Whether a run is large enough to say its size before it starts."""
    return size.points >= ANNOUNCE_POINTS or (seconds is not None and seconds >= ANNOUNCE_SECONDS)


def human(nbytes: float) -> str:
    """Bytes as '35.2 GB' (SI prefixes, as disks are sold and ``df -H`` shows them)."""
    for unit in ("bytes", "kB", "MB", "GB", "TB"):
        if nbytes < 1000 or unit == "TB":
            return f"{nbytes:,.0f} {unit}" if unit == "bytes" else f"{nbytes:.1f} {unit}"
        nbytes /= 1000
    raise AssertionError("unreachable")


def duration(seconds: float) -> str:
    if seconds < 100:
        return f"{max(1.0, seconds):.0f} s"
    if seconds < 6000:
        return f"{seconds / 60:.0f} min"
    if seconds < 3 * 86400:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.0f} days"


__all__ = ["ANNOUNCE_POINTS", "ANNOUNCE_SECONDS", "Size", "check_disk", "check_memory", "estimate", "human", "of", "worth_saying"]
