"""Suite-wide collection rules, and the scenes and atlases many modules share (tests/scenes.py)."""

from __future__ import annotations

import pytest


@pytest.hookimpl(trylast=True)  # after ``-m`` and ``-k`` have deselected what they deselect
def pytest_collection_modifyitems(config, items):
    """A document whose slow variant runs needs no fast variant: the slow one runs every block of the fast one, in
    the same order (tests/test_docs.py).  The fast loop (``-m "not slow"``) keeps the fast variant."""
    slow = {item.callspec.id for item in items if getattr(item, "originalname", "") == "test_doc_runs_with_its_slow_blocks"}
    covered = [item for item in items if getattr(item, "originalname", "") == "test_doc_runs" and item.callspec.id in slow]
    if covered:
        config.hook.pytest_deselected(items=covered)
        items[:] = [item for item in items if item not in covered]
    items[:] = slow_first(items, int(getattr(config, "workerinput", {}).get("workercount", 1)))


def slow_first(items: list, workers: int) -> list:
    """``items`` in the order that lets ``workers`` pytest-xdist workers (``--dist worksteal``) end together.

    Worksteal hands each worker one contiguous share of the list (the first ``len // workers`` to the first, and so
    on) and later moves tests from the end of the longest queue to an idle worker.  A minutes-long test left at the
    end of a share would run last, alone, while the other worker waits (three minutes of a 22-minute suite when
    docs/paper-cases.md's commands did).  So each share starts with its part of the tests marked slow, dealt out in
    turn, and ends with quick tests that stealing can balance.  The set of tests is unchanged; only their order.
    """
    if workers <= 1:
        return items
    slow = [item for item in items if item.get_closest_marker("slow")]
    quick = [item for item in items if not item.get_closest_marker("slow")]
    out, left = [], len(items)
    for w in range(workers):
        size = left // (workers - w)  # what worksteal sends this worker first
        share = slow[w::workers]
        take = max(0, size - len(share))
        out += share + quick[:take]
        quick = quick[take:]
        left -= len(share) + take
    return out + quick


# ------------------------------------------------------------------------------------------- shared scenes
# The scenes are typed in tests/scenes.py (a module can import them at import time, for parametrize); here are the
# objects built from them once per session.


@pytest.fixture(scope="session")
def two_tops_scene():
    import stabmap
    from scenes import TWO_TOPS

    return stabmap.loads_scene(TWO_TOPS)


@pytest.fixture(scope="session")
def two_tops_atlas(two_tops_scene):
    """The two tops' atlas, computed once for every module that reads it (read only: tests copy before changing)."""
    import stabmap

    return stabmap.compute_atlas(two_tops_scene, threads=2, chunk_points=10, progress=False)

