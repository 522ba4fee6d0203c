"""One equilibrium of a named family at given lengths: ``solve`` (the closed forms), and what an equilibrium holds."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import StabmapError
from . import checks, equations, proofs, space_proofs
from .decide import ABSENT, DEGENERATE, STABLE, UNDECIDED, UNSTABLE, decide
from .families import twist_form
from .outputs import DECIDED_BY

_CLASS = {STABLE: "stable", UNSTABLE: "unstable", DEGENERATE: "degenerate", ABSENT: "absent", UNDECIDED: "undecided"}


@dataclass(frozen=True, eq=False)
class Equilibrium:
    """An equilibrium of a closed chain (or the report that a family has none at these lengths), its stability
    in space and in its plane.

    Attributes
    ----------
    shape : str
        The family (``"ring"``, ``"figure-eight-4"``, ...) or ``"found"`` for one found by ``search``.
    lengths : tuple of float
        h_1..h_n [m]; body k runs from joint O_k to O_{k+1}, O_{n+1} = O_1.
    c1sq, c2sq, h : float
        Bending and torsional stiffness c1^2, c2^2 [N m^2] and the step h [m] of the elastic moment (default
        min h_k).
    exists : bool or None
        False: the family has no equilibrium at these lengths (then the arrays are NaN and the counts -1); None:
        not proved either way (``decided_by = "undecided"``; the arrays hold the floating-point closed form).
    theta : ndarray (n,)
        Axis angles [rad] (floating point): the axis of body k is e_k = (-sin theta_k, cos theta_k) in the
        (y, z) plane.
    forces : ndarray (L, 2)
        The joint force (R_y, R_z) [N] of each closing loop (one loop but for the hinge), floating point.
    force_x : ndarray (L,)
        The force's component normal to the plane [N]: 0 but for a twisted ring.
    phi : ndarray (n,)
        Each body's turn about its own axis [rad] (its frame is Rx(theta_k) Rz(phi_k)): 0 but for a twisted ring.
    loops : tuple of tuple of int
        The 1-based bodies of each loop, in the order of ``forces``.
    energy : float
        Elastic energy U [J].
    residual : float
        Largest scaled residual of the equilibrium equations (docs/closed.md).
    index, nullity : int
        Negative and zero eigenvalues of the Hessian on the closed configurations modulo the rotations and the
        common spin, in space (``model = "planar"``: in the plane); a folded loop adds its lost closure rank to
        the nullity.  Stable only when both are 0.  Proved (``decided_by``); -1 where absent or undecided.
    planar_index, planar_nullity : int
        The same for motions in the plane only (the in-plane block; a twisted ring: bending in its plane).
    rotation_index : int or None
        Turning number of the chain (ring: j, figure-eight: 0, hinge: -1); None where absent or folded.
    eigenvalues : ndarray
        Of the reduced planar Hessian, in units of c1^2/h: floating point, for information (the index and
        nullity are the proved ones).
    decided_by : str
        How existence, index and nullity were proved: ``"ball_arithmetic"``, ``"exact_rational_arithmetic"``,
        ``"exact_structure"``, ``"interval_newton"``; or ``"undecided"``: nothing is proved and the stability
        is ``"undecided"`` (docs/closed.md, section 5).
    """

    shape: str
    lengths: tuple[float, ...]
    c1sq: float
    h: float
    exists: bool | None
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
    decided_by: str = "undecided"
    c2sq: float | None = None
    twist: int = 0
    model: str = "spatial"
    planar_index: int = -1
    planar_nullity: int = -1
    force_x: np.ndarray = field(default=None, repr=False)
    phi: np.ndarray = field(default=None, repr=False)

    @property
    def n(self) -> int:
        return len(self.lengths)

    @property
    def proved(self) -> bool:
        """Whether existence, index and nullity are proved (``decided_by`` is not ``"undecided"``)."""
        return self.decided_by != "undecided"

    @property
    def stability(self) -> str:
        """In space (``model = "planar"``: in the plane): "stable", "unstable", "degenerate" (nullity > 0),
        "absent", or "undecided" (nothing proved)."""
        return self._class(self.index, self.nullity, self.proved)

    @property
    def planar_stability(self) -> str:
        """Against motions in the plane only, as ``stability``."""
        return self._class(self.planar_index, self.planar_nullity, self.exists is False or self.planar_index >= 0)

    def _class(self, index: int, nullity: int, proved: bool) -> str:
        if not proved:
            return _CLASS[UNDECIDED]
        if not self.exists:
            return _CLASS[ABSENT]
        return _CLASS[DEGENERATE if nullity > 0 else UNSTABLE if index > 0 else STABLE]

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
        if self.exists is False:
            return f"Equilibrium({self.shape}, lengths={list(self.lengths)}: absent, {self.decided_by})"
        return (
            f"Equilibrium({self.shape}, {self.stability}{' in space' if self.model == 'spatial' else ' in the plane'}, "
            f"index={self.index}, nullity={self.nullity}, planar: {self.planar_stability}, "
            f"rotation_index={self.rotation_index}, U={self.energy:.6g} J, residual={self.residual:.1e}, {self.decided_by})"
        )


def scalars(lengths: np.ndarray, c1sq, h, c2sq=None) -> tuple[float, float, float]:
    c1sq = checks.positive("c1sq", c1sq)
    h = float(lengths.min()) if h is None else checks.positive("h", h)
    c2sq = c1sq if c2sq is None else checks.positive("c2sq", c2sq)
    return c1sq, h, c2sq


def equilibrium(shape: str, lengths, theta, forces, verdict: proofs.Verdict, loop_of, c1sq: float, h: float, j=None, *,
                c2sq: float | None = None, model: str = "spatial", twist: int = 0, phi=None, force_x=None) -> Equilibrium:
    """The Equilibrium of one configuration with its ``verdict`` (``proofs``), decided like an atlas point."""
    lengths = np.asarray(lengths, dtype=float)
    n = lengths.size
    c2sq = c1sq if c2sq is None else c2sq
    d = decide(np.asarray(theta, dtype=float).reshape(1, n), np.asarray(forces, dtype=float)[None], proofs.Verdicts.of([verdict]),
               lengths[None], loop_of, c1sq, h, eigenvalues=True, c2sq=c2sq,
               phi=None if phi is None else np.asarray(phi, dtype=float).reshape(1, n), force_x=force_x)
    loops = tuple(tuple(int(k) + 1 for k in np.flatnonzero(loop_of == l)) for l in range(int(loop_of.max()) + 1))
    turns = int(d.rotation_index[0])
    exists = {1: True, 0: False, -1: None}[int(d.exists[0])]
    return Equilibrium(
        shape=shape, lengths=tuple(lengths.tolist()), c1sq=c1sq, h=h, exists=exists, theta=d.theta[0],
        forces=d.forces[0], loops=loops, energy=float(d.energy[0]), residual=float(d.residual[0]),
        index=int(d.index[0]), nullity=int(d.nullity[0]), rotation_index=None if turns == -128 or exists is False else turns,
        eigenvalues=d.eigenvalues[0][~np.isnan(d.eigenvalues[0])], j=j, decided_by=DECIDED_BY.meaning(int(d.decided_by[0])),
        c2sq=c2sq, twist=twist, model=model, planar_index=int(d.planar_index[0]), planar_nullity=int(d.planar_nullity[0]),
        force_x=d.force_x[0], phi=d.phi[0],
    )


def solve(shape: str, lengths, *, c1sq: float = 1.0, c2sq: float | None = None, h: float | None = None, j: int = 1, twist: int = 0,
          model: str = "spatial") -> Equilibrium:
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
    c2sq : float, optional
        Torsional stiffness c2^2 [N m^2] (default c1^2, the one value where the paper's law (11) has an
        energy); the labels in space depend on c2^2/c1^2.
    h : float, optional
        Step of the discrete curvature [m] (default: min h_k, as the paper).
    j : int
        The ring's winding, 1 <= j < n/2 (other families: leave it at 1).
    twist : int
        The ring's twist m, 0 <= m < n/2: its bodies' frames turn m times about their axes around the ring
        (phi_k = 2 pi m k/n); equal lengths only.  Other families: leave it at 0.
    model : str
        "spatial" (default): stability against every motion; "planar": the chain confined to its plane.

    Returns
    -------
    Equilibrium
        ``exists = False`` where the family has no equilibrium at these lengths.  Existence, index and nullity
        are proved at the exact binary values of the lengths and of c2^2/c1^2 (``decided_by``), or the
        stability is "undecided".

    Raises
    ------
    StabmapError
        For input that cannot describe a closed chain of this family (one line naming the parameter).
    """
    fam = checks.family(shape)
    h_k = checks.lengths(fam, lengths)
    c1sq, h, c2sq = scalars(h_k, c1sq, h, c2sq)
    spatial = checks.model(model)
    n = h_k.size
    if fam.name == "ring":
        j = checks.winding(j, n)
        twist = checks.twist(twist, n, equal=bool((h_k == h_k[0]).all()), spatial=spatial)
    elif not (isinstance(j, (int, np.integer)) and not isinstance(j, bool) and j == 1):
        raise StabmapError(f"j = {j!r}: the winding j applies to shape = 'ring' only; leave it out for {fam.name!r}")
    elif not (isinstance(twist, (int, np.integer)) and not isinstance(twist, bool) and twist == 0):
        raise StabmapError(f"twist = {twist!r}: a twisted equilibrium is a ring's; leave twist out for {fam.name!r}")
    guess = None
    if fam.pattern is not None:  # lengths off the pattern by rounding: the Krawczyk operator starts from the closed form

        def guess():
            theta, forces, _ = fam.closed_form(h_k[None], c1sq, h, j, exists=[True])
            return theta[0], forces[0] * (h / c1sq)

    gamma = space_proofs.gamma_of(c1sq, c2sq) if spatial else None
    verdict = space_proofs.prove_lengths(fam, j, twist, tuple(h_k.tolist()), gamma, guess)
    theta, forces, _ = fam.closed_form(h_k[None], c1sq, h, j, exists=[verdict.exists != 0])
    phi, force_x = twist_form(h_k[None], c1sq, c2sq, h, j, twist)
    return equilibrium(fam.name, h_k, theta[0], forces[0], verdict, fam.loop_of(n), c1sq, h, j if fam.name == "ring" else None,
                       c2sq=c2sq, model=model, twist=twist, phi=phi[0], force_x=force_x)
