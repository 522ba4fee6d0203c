"""Everything an atlas point or a ``solve`` call reports about a configuration: one function for both.

``decide`` takes a batch of configurations of one family (same n, same loops) with their verdicts (``proofs``:
existence, index and nullity, and how they were proved) and returns the outputs as plain arrays: existence,
angles, forces, energy, the residual of the general equations, index and nullity, the stability class and the
rotation index.  The class comes from the verdicts alone; the angles, forces, energy, residual and rotation
index are floating-point values of the closed form.  Absent points get NaN and fill values.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import equations
from .proofs import UNDECIDED as BY_NONE
from .proofs import Verdicts

# Values of the stability class (the atlases' label): negative values are "no class" in every figure.
STABLE, UNSTABLE, DEGENERATE, ABSENT, UNDECIDED = 0, 1, -1, -2, -3
NO_COUNT = -1  # index and nullity where nothing exists or nothing is proved
NO_TURNS = -128  # rotation index where nothing exists or a joint is folded back


@dataclass(frozen=True)
class Decided:
    """Per-point outputs of a batch of P configurations of n bodies and L loops."""

    exists: np.ndarray  # (P,) int8: 1 exists, 0 absent, -1 undecided
    theta: np.ndarray  # (P, n) [rad]
    forces: np.ndarray  # (P, L, 2) [N], (R_y, R_z)
    energy: np.ndarray  # (P,) [J]
    residual: np.ndarray  # (P,) scaled
    index: np.ndarray  # (P,) int16
    nullity: np.ndarray  # (P,) int16
    stability: np.ndarray  # (P,) int8: STABLE, UNSTABLE, DEGENERATE, ABSENT, UNDECIDED
    rotation_index: np.ndarray  # (P,) int8
    decided_by: np.ndarray  # (P,) int8: proofs.BY_*
    eigenvalues: np.ndarray  # (P, d): planar reduced Hessian in units of c1^2/h (floating point), NaN pads
    planar_index: np.ndarray  # (P,) int16: the in-plane block's counts
    planar_nullity: np.ndarray
    planar_stability: np.ndarray  # (P,) int8: the class in the plane
    phi: np.ndarray  # (P, n) [rad]: each body's turn about its own axis (twisted rings)
    force_x: np.ndarray  # (P, L) [N]: the closing force normal to the plane (twisted rings)


def stability_class(exists: np.ndarray, index: np.ndarray, nullity: np.ndarray, decided_by: np.ndarray) -> np.ndarray:
    """stable only where the index and the nullity are both 0; any nullity is degenerate, whatever the index;
    undecided wherever the verdict is not a proof."""
    out = np.where(nullity > 0, DEGENERATE, np.where(index > 0, UNSTABLE, STABLE))
    out = np.where(exists == 1, out, ABSENT)
    return np.where(decided_by == BY_NONE, UNDECIDED, out).astype(np.int8)


def decide(theta, forces, verdicts: Verdicts, lengths, loop_of, c1sq, h, eigenvalues: bool = False, c2sq=None, phi=None,
           force_x=None) -> Decided:
    """The outputs at configurations ``theta`` (P, n) with loop ``forces`` (P, L, 2) and their ``verdicts``.

    The floating-point values are kept wherever an equilibrium exists or its existence is undecided; with
    ``eigenvalues`` the reduced Hessian's eigenvalues are computed too (floating point, for information).
    A twisted ring also has ``phi`` (P, n), its bodies' turns about their axes, and ``force_x`` (P,), its normal
    force, with the torsional stiffness ``c2sq`` (default c1sq).
    """
    theta = np.asarray(theta, dtype=float)
    lengths = np.asarray(lengths, dtype=float)
    P, n = theta.shape
    c1sq = np.broadcast_to(np.asarray(c1sq, dtype=float), (P,))
    h = np.broadcast_to(np.asarray(h, dtype=float), (P,))
    exists = np.asarray(verdicts.exists, dtype=np.int8)
    energy = np.full(P, np.nan)
    residual = np.full(P, np.nan)
    turns = np.full(P, NO_TURNS, dtype=np.int8)
    eig = np.full((P, n - 1), np.nan)  # at most n - 1 tangent directions (the rotation is always out)
    at = np.flatnonzero(exists != 0)
    theta = np.where((exists != 0)[:, None], theta, np.nan)
    forces = np.where((exists != 0)[:, None, None], forces, np.nan)
    c2sq = c1sq if c2sq is None else np.broadcast_to(np.asarray(c2sq, dtype=float), (P,))
    twisted = phi is not None and np.any(phi != 0)
    phi = np.zeros((P, n)) if phi is None else np.where((exists != 0)[:, None], phi, np.nan)
    L = forces.shape[1]
    force_x = np.zeros((P, L)) if force_x is None else np.broadcast_to(np.asarray(force_x, dtype=float).reshape(P, -1), (P, L))
    force_x = np.where((exists != 0)[:, None], force_x, np.nan)
    if at.size:
        args = (theta[at], lengths[at], forces[at], loop_of, c1sq[at], h[at])
        energy[at] = equations.energy(theta[at], c1sq[at], h[at], c2sq[at], phi[at] if twisted else None)
        residual[at] = equations.residuals(*args)
        if twisted:
            residual[at] = np.maximum(residual[at], equations.twist_residual(theta[at], phi[at], lengths[at], force_x[at, 0],
                                                                              c1sq[at], c2sq[at], h[at]))
        turns[at] = equations.rotation_index(theta[at])
        if eigenvalues:
            ev = equations.inertia(*args).eigenvalues
            eig[at, : ev.shape[1]] = ev
    index = np.where(exists == 1, verdicts.index, NO_COUNT).astype(np.int16)
    nullity = np.where(exists == 1, verdicts.nullity, NO_COUNT).astype(np.int16)
    stability = stability_class(exists, index, nullity, verdicts.decided_by)
    planar_index = np.where(exists == 1, verdicts.planar_index, NO_COUNT).astype(np.int16)
    planar_nullity = np.where(exists == 1, verdicts.planar_nullity, NO_COUNT).astype(np.int16)
    planar_by = np.where(planar_index < 0, BY_NONE, 0)  # the planar counts are proved wherever they are known
    planar = np.where(exists == 1, stability_class(exists, planar_index, planar_nullity, planar_by), stability).astype(np.int8)
    return Decided(exists, theta, forces, energy, residual, index, nullity, stability, turns,
                   np.asarray(verdicts.decided_by, dtype=np.int8), eig, planar_index, planar_nullity, planar, phi, force_x)
