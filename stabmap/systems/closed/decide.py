"""Everything an atlas point or a ``solve`` call reports about a configuration: one function for both.

``decide`` takes a batch of configurations of one family (same n, same loops) and returns the outputs as plain
arrays: existence, angles, forces, energy, the residual of the general equations, index and nullity of the
constrained Hessian, the stability class and the rotation index.  Absent points get NaN and fill values.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import equations

# Values of the stability class (the atlases' label): negative values are "no class" in every figure.
STABLE, UNSTABLE, DEGENERATE, ABSENT = 0, 1, -1, -2
NO_COUNT = -1  # index and nullity where nothing exists
NO_TURNS = -128  # rotation index where nothing exists or a joint is folded back


@dataclass(frozen=True)
class Decided:
    """Per-point outputs of a batch of P configurations of n bodies and L loops."""

    exists: np.ndarray  # (P,) bool
    theta: np.ndarray  # (P, n) [rad]
    forces: np.ndarray  # (P, L, 2) [N], (R_y, R_z)
    energy: np.ndarray  # (P,) [J]
    residual: np.ndarray  # (P,) scaled
    index: np.ndarray  # (P,) int16
    nullity: np.ndarray  # (P,) int16
    stability: np.ndarray  # (P,) int8: STABLE, UNSTABLE, DEGENERATE, ABSENT
    rotation_index: np.ndarray  # (P,) int8
    eigenvalues: np.ndarray  # (P, d): reduced Hessian in units of c1^2/h, NaN pads


def stability_class(exists: np.ndarray, index: np.ndarray, nullity: np.ndarray) -> np.ndarray:
    """stable only where the index and the nullity are both 0; any nullity is degenerate, whatever the index."""
    out = np.where(nullity > 0, DEGENERATE, np.where(index > 0, UNSTABLE, STABLE))
    return np.where(exists, out, ABSENT).astype(np.int8)


def decide(theta, forces, exists, lengths, loop_of, c1sq, h) -> Decided:
    """The outputs at configurations ``theta`` (P, n) with loop ``forces`` (P, L, 2) where ``exists`` (P,)."""
    theta = np.asarray(theta, dtype=float)
    lengths = np.asarray(lengths, dtype=float)
    P, n = theta.shape
    c1sq = np.broadcast_to(np.asarray(c1sq, dtype=float), (P,))
    h = np.broadcast_to(np.asarray(h, dtype=float), (P,))
    exists = np.asarray(exists, dtype=bool)
    energy = np.full(P, np.nan)
    residual = np.full(P, np.nan)
    index = np.full(P, NO_COUNT, dtype=np.int16)
    nullity = np.full(P, NO_COUNT, dtype=np.int16)
    turns = np.full(P, NO_TURNS, dtype=np.int8)
    eig = np.full((P, n - 1), np.nan)  # at most n - 1 tangent directions (the rotation is always out)
    at = np.flatnonzero(exists)
    if at.size:
        args = (theta[at], lengths[at], forces[at], loop_of, c1sq[at], h[at])
        energy[at] = equations.energy(theta[at], c1sq[at], h[at])
        residual[at] = equations.residuals(*args)
        inertia = equations.inertia(*args)
        index[at], nullity[at] = inertia.index, inertia.nullity
        eig[at, : inertia.eigenvalues.shape[1]] = inertia.eigenvalues
        turns[at] = equations.rotation_index(theta[at])
    return Decided(exists, theta, forces, energy, residual, index, nullity, stability_class(exists, index, nullity), turns, eig)
