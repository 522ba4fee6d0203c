"""Closed chains of elastic joints from Python: one equilibrium of a named family, or every one a search finds.

>>> from stabmap import closed
>>> eq = closed.solve("figure-eight-6", [1, 6, 1, 1, 6, 1])
>>> eq.exists, eq.stability, eq.planar_stability, eq.forces, eq.index, eq.nullity   # stability in space and in the plane
>>> closed.solve("ring", [1.0] * 12, twist=1, c2sq=2.0).stability                    # Michell: "unstable"
>>> closed.search([1, 2, 1.5, 1.2, 0.7])        # every isolated planar equilibrium found, sorted by energy

The model, the families and the method of ``search`` are in docs/closed.md; atlases of a family over its
length ratio, c1^2, c2^2, n, j and the twist are scenes with ``system = "closed"`` (``stabmap atlas``).
"""

from __future__ import annotations

from .systems.closed.families import FAMILIES, SHAPES
from .systems.closed.search import search
from .systems.closed.solve import Equilibrium, solve

__all__ = ["FAMILIES", "SHAPES", "Equilibrium", "search", "solve"]
