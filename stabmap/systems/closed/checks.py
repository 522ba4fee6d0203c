"""The checks every closed-chain input goes through, from Python (``stabmap.closed``) and from scene files alike.

Each failure is one StabmapError naming the parameter and the fix.  A family that has no equilibrium at valid
lengths is not an error: it is reported as ``exists = False``.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import StabmapError
from .families import FAMILIES, Family

PATTERN_RTOL = 1e-12  # lengths that a pattern says are equal may differ by rounding only


def family(shape) -> Family:
    if not isinstance(shape, str) or shape not in FAMILIES:
        raise StabmapError(f"family {shape!r} is not a closed-chain family; choose one of: {', '.join(FAMILIES)}")
    return FAMILIES[shape]


def positive(where: str, value) -> float:
    """A finite number > 0."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or not math.isfinite(value):
        raise StabmapError(f"{where} must be a finite number, got {value!r}")
    if value <= 0:
        raise StabmapError(f"{where} must be > 0, got {value!r}: give a positive value")
    return float(value)


def whole(where: str, value, minimum: int) -> int:
    """A whole number >= minimum (a float such as 6.0 from a grid counts)."""
    ok = not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating)) and math.isfinite(value)
    if not ok or float(value) != int(value):
        raise StabmapError(f"{where} must be a whole number, got {value!r}")
    if int(value) < minimum:
        raise StabmapError(f"{where} must be >= {minimum}, got {int(value)}")
    return int(value)


def body_count(fam: Family, n: int, where: str = "n") -> int:
    """The number of bodies, checked against the family."""
    if fam.n is None:
        return whole(where, n, 3)
    if n != fam.n:
        if fam.name.startswith("figure-eight") and n % 2:
            raise StabmapError(
                f"{where} = {n}: a figure-eight needs an even number of bodies (n = 2N, theta_(N+l) = pi - theta_l); "
                f"family {fam.name!r} has n = {fam.n}: give {fam.n} lengths"
            )
        raise StabmapError(f"{where} = {n}: family {fam.name!r} has n = {fam.n} bodies; give {fam.n} lengths (pattern {pattern_text(fam)})")
    return n


def winding(j, n: int, where: str = "j") -> int:
    """The ring's winding number: 1 <= j < n/2."""
    j = whole(where, j, 1)
    if not 2 * j < n:
        top = (n - 1) // 2
        raise StabmapError(
            f"{where} = {j} is out of range for a ring of n = {n} bodies: the winding must satisfy 1 <= j < n/2, "
            f"so j <= {top}" + (" (n = 3 and 4 allow j = 1 only)" if n <= 4 else "") + "; lower j or add bodies"
        )
    return j


MODELS = ("spatial", "planar")


def model(name) -> bool:
    """Whether the model ``name`` is the spatial one ("spatial" or "planar")."""
    if name not in MODELS:
        raise StabmapError(f"model = {name!r}: choose \"spatial\" (stability against every motion, the default) or \"planar\" "
                           "(the chain confined to its plane)")
    return name == "spatial"


def twist(m, n: int, where: str = "twist", equal: bool = True, spatial: bool = True) -> int:
    """The ring's twist: 0 <= m < n/2 (less than half a turn per joint); a twisted ring (m > 0) exists in space only
    (``spatial``) and with equal lengths only (``equal``: its closing force is normal to the plane and balances only
    equal bodies)."""
    m = whole(where, m, 0)
    if m and not spatial:
        raise StabmapError(f"{where} = {m} with model = \"planar\": a twisted ring is an equilibrium in space only; "
                           "remove twist or use model = \"spatial\"")
    if m and not equal:
        raise StabmapError(f"{where} = {m}: a twisted ring needs equal lengths (ratio = 1, or equal lengths = [...]); "
                           "unequal bodies do not balance its normal force. Set ratio = 1 or remove twist")
    if m and not 2 * m < n:
        raise StabmapError(f"{where} = {m} is out of range for a ring of n = {n} bodies: each joint twists by 2 pi m/n, which must "
                           f"stay below pi, so twist <= {(n - 1) // 2}; lower the twist or add bodies")
    return m


def pattern_text(fam: Family) -> str:
    return "(" + ", ".join(f"h{p}" for p in fam.pattern) + ")" if fam.pattern else "(h1, h2, h1, ...)"


def can_close(lengths: np.ndarray, where: str = "lengths") -> None:
    """A closed polygon exists iff the longest side is at most the sum of the others (equal: folded on a line)."""
    lengths = np.atleast_2d(lengths)
    longest = lengths.max(-1)
    rest = lengths.sum(-1) - longest
    bad = np.flatnonzero(longest > rest * (1 + PATTERN_RTOL))
    if bad.size:
        row = lengths[bad[0]]
        k = int(np.argmax(row))
        raise StabmapError(
            f"{where} cannot close: h_{k + 1} = {row[k]:g} is longer than all the others together ({rest[bad[0]]:g}); "
            "shorten it or lengthen the others (a closed chain needs every length <= the sum of the rest)"
        )


def lengths(fam: Family, values, where: str = "lengths") -> np.ndarray:
    """Explicit lengths h_1..h_n [m] for ``fam``: positive, closable, and in the family's pattern."""
    if isinstance(values, (str, bytes)) or not hasattr(values, "__len__"):
        raise StabmapError(f"{where} must be a list of lengths h_1..h_n [m], got {values!r}")
    out = np.array([positive(f"{where}[{k + 1}]", v) for k, v in enumerate(values)], dtype=float)
    body_count(fam, len(out), f"the number of {where}")
    can_close(out, where)
    if fam.pattern is not None:
        for kind in (1, 2):
            same = out[[k for k, p in enumerate(fam.pattern) if p == kind]]
            if np.ptp(same) > PATTERN_RTOL * same.max():
                raise StabmapError(
                    f"{where} = {out.tolist()} does not follow the pattern {pattern_text(fam)} of family {fam.name!r}: "
                    f"bodies marked h{kind} must have equal lengths (or choose another family)"
                )
    return out
