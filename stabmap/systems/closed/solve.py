"""One equilibrium of a named family at given lengths: ``solve`` (the closed forms), and what an equilibrium holds."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import StabmapError
from . import checks, equations
from .decide import ABSENT, DEGENERATE, STABLE, UNSTABLE, decide

_CLASS = {STABLE: "stable", UNSTABLE: "unstable", DEGENERATE: "degenerate", ABSENT: "absent"}


@dataclass(frozen=True, eq=False)
class Equilibrium:
    """A planar equilibrium of a closed chain (or the report that a family has none at these lengths).

    Attributes
    ----------
    shape : str
        The family (``"ring"``, ``"figure-eight-4"``, ...) or ``"found"`` for one found by ``search``.
    lengths : tuple of float
        h_1..h_n [m]; body k runs from joint O_k to O_{k+1}, O_{n+1} = O_1.
    c1sq, h : float
        Bending stiffness c1^2 [N m^2] and the step h [m] of the elastic moment (default min h_k).
    exists : bool
        False: the family has no equilibrium at these lengths (then the arrays are NaN and the counts -1).
    theta : ndarray (n,)
        Axis angles [rad]: the axis of body k is e_k = (-sin theta_k, cos theta_k) in the (y, z) plane.
    forces : ndarray (L, 2)
        The joint force (R_y, R_z) [N] of each closing loop (one loop but for the hinge).
    loops : tuple of tuple of int
        The 1-based bodies of each loop, in the order of ``forces``.
    energy : float
        Elastic energy U [J].
    residual : float
        Largest scaled residual of the equilibrium equations (docs/closed.md).
    index, nullity : int
        Negative and zero eigenvalues of the Hessian on the closed configurations modulo rotation; a folded loop
        adds its lost closure rank to the nullity.  Stable only when both are 0.
    rotation_index : int or None
        Turning number of the chain (ring: j, figure-eight: 0, hinge: -1); None where absent or folded.
    eigenvalues : ndarray
        Of the reduced Hessian, in units of c1^2/h.
    """

    shape: str
    lengths: tuple[float, ...]
    c1sq: float
    h: float
    exists: bool
    theta: np.ndarray
    forces: np.ndarray
    loops: tuple[tuple[int, ...], ...]
    energy: float
    residual: float
    index: int
    nullity: int
    rotation_index: int | None
    eigenvalues: np.ndarray = field(repr=False)
    j: int | None = None

    @property
    def n(self) -> int:
        return len(self.lengths)

    @property
    def stability(self) -> str:
        """"stable", "unstable", "degenerate" (nullity > 0) or "absent"."""
        if not self.exists:
            return _CLASS[ABSENT]
        return _CLASS[DEGENERATE if self.nullity > 0 else UNSTABLE if self.index > 0 else STABLE]

    @property
    def stable(self) -> bool:
        return self.stability == "stable"

    @property
    def joint_angles(self) -> np.ndarray:
        """theta_k - theta_{k-1} wrapped into (-pi, pi] [rad]; joint 1 joins body n to body 1."""
        return equations.joint_angles(self.theta)

    @property
    def joints(self) -> np.ndarray:
        """(n + 1, 2): positions (y, z) [m] of O_1..O_{n+1}, O_1 at the origin."""
        return equations.joints(self.theta[None], np.asarray(self.lengths)[None])[0]

    def __repr__(self) -> str:
        if not self.exists:
            return f"Equilibrium({self.shape}, lengths={list(self.lengths)}: absent)"
        return (
            f"Equilibrium({self.shape}, {self.stability}, index={self.index}, nullity={self.nullity}, "
            f"rotation_index={self.rotation_index}, U={self.energy:.6g} J, residual={self.residual:.1e})"
        )


def _scalars(lengths: np.ndarray, c1sq, h) -> tuple[float, float]:
    c1sq = checks.positive("c1sq", c1sq)
    h = float(lengths.min()) if h is None else checks.positive("h", h)
    return c1sq, h


def equilibrium(shape: str, lengths, theta, forces, exists, loop_of, c1sq: float, h: float, j=None) -> Equilibrium:
    """The Equilibrium of one configuration, decided like an atlas point."""
    lengths = np.asarray(lengths, dtype=float)
    n = lengths.size
    d = decide(np.asarray(theta, dtype=float).reshape(1, n), np.asarray(forces, dtype=float)[None], [bool(exists)],
               lengths[None], loop_of, c1sq, h)
    loops = tuple(tuple(int(k) + 1 for k in np.flatnonzero(loop_of == l)) for l in range(int(loop_of.max()) + 1))
    turns = int(d.rotation_index[0])
    return Equilibrium(
        shape=shape, lengths=tuple(lengths.tolist()), c1sq=c1sq, h=h, exists=bool(d.exists[0]), theta=d.theta[0],
        forces=d.forces[0], loops=loops, energy=float(d.energy[0]), residual=float(d.residual[0]),
        index=int(d.index[0]), nullity=int(d.nullity[0]), rotation_index=None if turns == -128 or not d.exists[0] else turns,
        eigenvalues=d.eigenvalues[0][~np.isnan(d.eigenvalues[0])], j=j,
    )


def solve(shape: str, lengths, *, c1sq: float = 1.0, h: float | None = None, j: int = 1) -> Equilibrium:
    """The equilibrium of the family ``shape`` at ``lengths``, from its closed form (docs/closed.md).

    Parameters
    ----------
    shape : str
        ``"ring"`` (winding ``j``), ``"figure-eight-4"`` (lengths h1, h2, h1, h2), ``"figure-eight-6"``
        (h1, h2, h1, h1, h2, h1), ``"hinge"`` (h1, h1, h2, h1, h1, h2; loops {S1, S5, S6} and {S2, S3, S4}) or
        ``"hinge-straight"`` (same lengths, one plain loop).
    lengths : sequence of float
        h_1..h_n [m], positive, closable, in the family's pattern.
    c1sq : float
        Bending stiffness c1^2 [N m^2]; it and ``h`` scale the forces and the energy only.
    h : float, optional
        Step of the discrete curvature [m] (default: min h_k, as the paper).
    j : int
        The ring's winding, 1 <= j < n/2 (other families: leave it at 1).

    Returns
    -------
    Equilibrium
        ``exists = False`` where the family has no equilibrium at these lengths.

    Raises
    ------
    StabmapError
        For input that cannot describe a closed chain of this family (one line naming the parameter).
    """
    fam = checks.family(shape)
    h_k = checks.lengths(fam, lengths)
    c1sq, h = _scalars(h_k, c1sq, h)
    n = h_k.size
    if fam.name == "ring":
        j = checks.winding(j, n)
    elif not (isinstance(j, (int, np.integer)) and not isinstance(j, bool) and j == 1):
        raise StabmapError(f"j = {j!r}: the winding j applies to shape = 'ring' only; leave it out for {fam.name!r}")
    theta, forces, exists = fam.closed_form(h_k[None], c1sq, h, j)
    return equilibrium(fam.name, h_k, theta[0], forces[0], exists[0], fam.loop_of(n), c1sq, h, j if fam.name == "ring" else None)
