"""Reactions of statically indeterminate joints by the least-norm rule (seed 004; docs/reactions.md).

>>> from stabmap.reactions import solve
>>> r = solve([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], F=[0, 0, -100.0], M=[0, 0, 0])
>>> r.R[:, 2], r.rank, r.compatible
(array([25., 25., 25., 25.]), 6, True)

The solver lives with the atlas system that scans it (``stabmap.systems.reactions.solver``); this module is its
public name.
"""

from __future__ import annotations

from .systems.reactions.solver import (
    DECIDED_BY,
    ERROR_RTOL,
    Batch,
    Reactions,
    closed_form,
    solve,
    solve_batch,
)

__all__ = ["DECIDED_BY", "ERROR_RTOL", "Batch", "Reactions", "closed_form", "solve", "solve_batch"]
