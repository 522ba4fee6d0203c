"""The scenes many test modules scan, typed once (tests/conftest.py serves them as fixtures).

- Maievskii's top: one dry top on a fixed point, stable (all roots real, N_c = 0) exactly when
  C^2 w^2 >= 4 (A + m c^2) m c g, else N_c = 1.  ``maievskii_stable`` decides that in exact rationals on the
  binary values of the numbers, so a test that uses it never compares stabmap with itself.
- Two tops: a liquid-filled top carrying a dry one on an elastic joint; its grid crosses stability boundaries.
"""

from __future__ import annotations

import copy
from fractions import Fraction

M, A, C, G = 1.0, 0.02, 0.03, 9.81
TOP = {"m": M, "A": A, "C": C, "c": 0.1}  # Maievskii's top, one [[bodies]] table


def maievskii_w2(c: float, m: float = M) -> Fraction:
    """The squared critical spin rate 4 (A + m c^2) m c g / C^2, exact on the binary values."""
    a, cc, g, c, m = (Fraction(float(v)) for v in (A, C, G, c, m))
    return 4 * (a + m * c * c) * m * c * g / (cc * cc)


def maievskii_stable(omega: float, c: float, m: float = M) -> bool:
    return Fraction(float(omega)) ** 2 >= maievskii_w2(c, m)


def top_system(grid: dict | None = None, **scene) -> dict:
    """Maievskii's top as a plain scene dict (``from_dict``), with ``grid`` and other top-level keys."""
    system = {"support": "fixed", "g": G, "bodies": [dict(TOP)], **scene}
    if grid is not None:
        system["grid"] = copy.deepcopy(grid)
    return system


def top_toml(grid: str, head: str = "") -> str:
    """Maievskii's top as a scene file: ``head`` (top-level lines) before the body, ``grid`` the [grid] lines."""
    return f'{head}support = "fixed"\ng = 9.81\n\n[[bodies]]\nm = 1.0\nA = 0.02\nC = 0.03\nc = 0.10\n\n[grid]\n{grid}'


def two_tops(**changes) -> dict:
    """The two tops at one point (no grid): body 1 with one liquid mode, K_1 = 20; ``changes`` top-level keys."""
    return {
        "support": "fixed", "g": 9.81, "omega": 50.0, "joints": [20.0],
        "bodies": [
            {"m": 1.0, "A": 0.02, "C": 0.03, "c": 0.10, "s": 0.25, "fluid": {"E": [1e-3], "kappa": [1.31]}},
            {"m": 0.5, "A": 0.01, "C": 0.015, "c": 0.08},
        ],
        **changes,
    }


# The two tops on a small grid, body 2 spinning at its own 45 rad/s (tests/test_atlas.py).
TWO_TOPS = """
title = "two tops, small grid"
support = "fixed"
g = 9.81
omega = 50.0
joints = [20.0]

[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25
fluid = { E = [1e-3], kappa = [1.31] }

[[bodies]]
m = 0.5
A = 0.01
C = 0.015
c = 0.08
omega = 45.0

[grid]
omega = { start = 1.0, stop = 150.0, num = 9 }
m_2 = { start = 0.1, stop = 5.0, num = 7, scale = "log" }
"""
