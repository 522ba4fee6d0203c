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

