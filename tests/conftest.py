"""Suite-wide collection rules."""

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
