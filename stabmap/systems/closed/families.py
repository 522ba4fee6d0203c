"""The named equilibrium families of a closed chain and their closed forms (docs/closed.md, sections 1 and 2).

Each family fixes the number of bodies (the ring takes any n >= 3), which loops close, and which bodies share
which of two lengths: ``pattern`` gives 1 for a body of length h1 and 2 for one of length h2, and scenes scan
``ratio`` = h2/h1.  ``closed_form`` evaluates the family at a batch of length vectors: the axis angles, the loop
forces and where the family exists.  At the end of its range each two-length family folds onto a line (a
collinear state, an equilibrium for every force along that line): that end point is reported as existing, and
the constraints' lost rank makes it degenerate.  Everything here is floating point; ``proofs`` decides existence
exactly and evaluates the same closed forms in ball and rational arithmetic.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# The ring closes when |sum h_k exp(i theta_k)| is below this fraction of sum h_k (rounding leaves ~1e-16 n).
CLOSE_TOL = 1e-12
# Figure-eight of six bodies: it exists for a = h1/h2 up to this value (p = 1 there and the eight folds flat).
A_STAR_6 = (math.sqrt(2.0) - 1.0) / 2.0


@dataclass(frozen=True)
class Family:
    """One named family: its bodies, loops and length pattern (``None``: the ring, any n, lengths alternate)."""

    name: str
    title: str
    n: int | None
    pattern: tuple[int, ...] | None
    loops: tuple[tuple[int, ...], ...]  # 1-based bodies of each closing loop; forces[l] belongs to loops[l]
    ratio_range: str  # where it exists, as text

    def n_bodies(self, n: int | None = None) -> int:
        if self.n is not None:
            return self.n
        if n is None:
            raise TypeError(f"the family {self.name!r} takes any number of bodies: give n")
        return int(n)

    def loop_of(self, n: int | None = None) -> np.ndarray:
        """The loop (0-based) of each body."""
        out = np.zeros(self.n_bodies(n), dtype=np.int64)
        for l, bodies in enumerate(self.loops):
            out[[b - 1 for b in bodies]] = l
        return out

    def lengths(self, h1, ratio, n: int | None = None) -> np.ndarray:
        """(P, n) lengths of the pattern from h1 [m] and ratio = h2/h1 (ring: h1, h2, h1, h2, ...)."""
        h1 = np.atleast_1d(np.asarray(h1, dtype=float))
        h2 = h1 * np.atleast_1d(np.asarray(ratio, dtype=float))
        pattern = self.pattern if self.pattern is not None else tuple(1 + k % 2 for k in range(self.n_bodies(n)))
        h1, h2 = np.broadcast_arrays(h1, h2)
        return np.stack([h1 if p == 1 else h2 for p in pattern], axis=-1)

    def closed_form(self, lengths, c1sq, h, j=None, exists=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """theta (P, n) [rad], forces (P, L, 2) [N] as (R_y, R_z), exists (P,) at lengths (P, n); NaN where absent.

        In floating point: ``exists`` decided here is a float comparison, which ``proofs`` replaces by an exact
        one; pass ``exists`` (P,) to use that instead (the formulas stay finite up to and just past the ends).
        """
        lengths = np.atleast_2d(np.asarray(lengths, dtype=float))
        P = lengths.shape[0]
        c1sq = np.broadcast_to(np.asarray(c1sq, dtype=float), (P,))
        h = np.broadcast_to(np.asarray(h, dtype=float), (P,))
        theta, forces, float_exists = _FORMS[self.name](lengths, c1sq, h, j)
        exists = float_exists if exists is None else np.broadcast_to(np.asarray(exists, dtype=bool), (P,))
        theta = np.where(exists[:, None], theta, np.nan)
        forces = np.where(exists[:, None, None], forces, np.nan)
        return theta, forces, exists


def twist_form(lengths, c1sq, c2sq, h, j, m) -> tuple[np.ndarray, np.ndarray]:
    """phi (P, n) [rad] and the normal force R_x (P,) [N] of the ring of winding j and twist m (docs/closed.md,
    section 1b): phi_k = 2 pi m k/n, R_x = (c2^2/(h h_1)) sin(2 pi j/n) sin(2 pi m/n); zero without twist."""
    lengths = np.atleast_2d(np.asarray(lengths, dtype=float))
    P, n = lengths.shape
    phi = np.broadcast_to(2.0 * np.pi * float(m) * np.arange(1, n + 1) / n, (P, n)).copy()
    force = np.asarray(c2sq, dtype=float) / (np.asarray(h, dtype=float) * lengths[:, 0]) * np.sin(2 * np.pi * j / n) * np.sin(2 * np.pi * m / n)
    return phi, np.broadcast_to(force, (P,)).copy()


def _ring(lengths, c1sq, h, j):
    """(27): theta_k = 2 pi j k / n, R = 0; closes iff sum h_k exp(2 pi i j k / n) = 0."""
    P, n = lengths.shape
    theta = np.broadcast_to(2.0 * np.pi * np.asarray(j, dtype=float).reshape(-1, 1) * np.arange(1, n + 1) / n, (P, n))
    gap = np.abs((lengths * np.exp(1j * theta)).sum(-1))
    return theta.copy(), np.zeros((P, 1, 2)), gap <= CLOSE_TOL * lengths.sum(-1)


def _figure_eight_4(lengths, c1sq, h, j):
    """(33)-(34): theta = (-t, pi/2, pi + t, pi/2), sin t = h2/h1, R_y = 2/a_1; exists iff h2 <= h1."""
    h1, h2 = lengths[:, 0], lengths[:, 1]
    exists = h2 <= h1
    t = np.arcsin(np.minimum(h2 / h1, 1.0))
    half = np.full_like(t, np.pi / 2)
    theta = np.stack([-t, half, np.pi + t, half], axis=-1)
    a1 = h1 * h / c1sq
    forces = np.stack([2.0 / a1, np.zeros_like(a1)], axis=-1)[:, None, :]
    return theta, forces, exists


def _figure_eight_6(lengths, c1sq, h, j):
    """(35)-(44), corrected: a = h1/h2, p = 1 - 2a + sqrt(1 - 4a), sin^2 t = (p^2 - 1)/(p^2 - 4a^2),
    sin s = 2a sin t, cos s = p cos t, theta = (t, -s, t, pi - t, pi + s, pi - t), R_y = (2 - p - 2a) sin t / a_1;
    exists iff a <= (sqrt 2 - 1)/2."""
    h1, h2 = lengths[:, 0], lengths[:, 1]
    a = h1 / h2
    exists = a <= A_STAR_6
    with np.errstate(invalid="ignore", divide="ignore"):  # where absent: the values are discarded
        p = 1.0 - 2.0 * a + np.sqrt(np.maximum(1.0 - 4.0 * a, 0.0))
        sin2 = np.clip((p * p - 1.0) / (p * p - 4.0 * a * a), 0.0, 1.0)
    st, ct = np.sqrt(sin2), np.sqrt(1.0 - sin2)
    t = np.arctan2(st, ct)
    s = np.arctan2(2.0 * a * st, p * ct)
    theta = np.stack([t, -s, t, np.pi - t, np.pi + s, np.pi - t], axis=-1)
    a1 = h1 * h / c1sq
    forces = np.stack([(2.0 - p - 2.0 * a) * st / a1, np.zeros_like(a1)], axis=-1)[:, None, :]
    return theta, forces, exists


def _hinge(lengths, c1sq, h, j):
    """(51)-(52): loops {S1, S5, S6} and {S2, S3, S4}, theta = (-t, t, -pi/2, pi - t, pi + t, pi/2),
    sin t = h2/(2 h1), R_1y = -R_3y = (2 sin t + 1)/a_1; exists iff h2 <= 2 h1."""
    h1, h2 = lengths[:, 0], lengths[:, 2]
    exists = h2 <= 2.0 * h1
    st = np.minimum(h2 / (2.0 * h1), 1.0)
    t = np.arcsin(st)
    theta = np.stack([-t, t, np.full_like(t, -np.pi / 2), np.pi - t, np.pi + t, np.full_like(t, np.pi / 2)], axis=-1)
    ry = (2.0 * st + 1.0) / (h1 * h / c1sq)
    zero = np.zeros_like(ry)
    forces = np.stack([np.stack([ry, zero], -1), np.stack([-ry, zero], -1)], axis=1)
    return theta, forces, exists


def _hinge_straight(lengths, c1sq, h, j):
    """The closing remark: theta = (-t, -t, pi/2, pi + t, pi + t, pi/2), sin t = h2/(2 h1), one force R_y = 1/a_1
    (a plain closed chain: the four-body figure-eight with its long bodies split); exists iff h2 <= 2 h1."""
    h1, h2 = lengths[:, 0], lengths[:, 2]
    exists = h2 <= 2.0 * h1
    t = np.arcsin(np.minimum(h2 / (2.0 * h1), 1.0))
    half = np.full_like(t, np.pi / 2)
    theta = np.stack([-t, -t, half, np.pi + t, np.pi + t, half], axis=-1)
    a1 = h1 * h / c1sq
    forces = np.stack([1.0 / a1, np.zeros_like(a1)], axis=-1)[:, None, :]
    return theta, forces, exists


_FORMS = {
    "ring": _ring,
    "figure-eight-4": _figure_eight_4,
    "figure-eight-6": _figure_eight_6,
    "hinge": _hinge,
    "hinge-straight": _hinge_straight,
}

FAMILIES = {
    f.name: f
    for f in (
        Family("ring", "ring of winding j: theta_k = 2 pi j k / n, no force", None, None, (), "closes iff sum h_k exp(2 pi i j k/n) = 0"),
        Family("figure-eight-4", "figure-eight of four bodies (h1, h2, h1, h2)", 4, (1, 2, 1, 2), (), "ratio = h2/h1 <= 1"),
        Family("figure-eight-6", "figure-eight of six bodies crossing between joints (h1, h2, h1, h1, h2, h1)", 6,
               (1, 2, 1, 1, 2, 1), (), "ratio = h2/h1 >= 2/(sqrt 2 - 1) = 4.828..."),
        Family("hinge", "two loops sharing the joint O2 = O5 (h1, h1, h2, h1, h1, h2)", 6, (1, 1, 2, 1, 1, 2),
               ((1, 5, 6), (2, 3, 4)), "ratio = h2/h1 <= 2"),
        Family("hinge-straight", "the closing remark's plain chain through O2 twice (h1, h1, h2, h1, h1, h2)", 6,
               (1, 1, 2, 1, 1, 2), (), "ratio = h2/h1 <= 2"),
    )
}
SHAPES = tuple(FAMILIES)
