"""Every isolated planar equilibrium of a plain closed chain that a multi-start Newton method finds.

The method (docs/closed.md, "search"):

1. **Starts.** ``starts`` configurations from a seeded generator: the ring of each winding w = 0 .. ceil(n/2) - 1
   (w = 0: no net turning, as a figure-eight) plus Gaussian noise of a width drawn from {0.3, 1, pi} [rad],
   pulled onto the closed configurations by Gauss-Newton steps on the closure (minimum-norm), the forces from
   the least-squares fit of the torque equations.
2. **Newton.** The n + 1 equations in theta_2..theta_n, R_y, R_z (theta_1 fixed: the rotation of the whole
   chain; the torque equation of body 1 follows from the others and the closure) are solved by MINPACK's
   hybrid method (``scipy.optimize.root``), then polished by plain Newton steps.
3. **Verification.** A solution is kept when its scaled residual (``equations.residuals``) is at most
   ``RESIDUAL`` = 1e-12 and the Jacobian of the equations is regular (reciprocal condition number above
   ``REGULAR`` = 1e-10): an isolated equilibrium with a unique force.  Folded states (every axis on one line)
   balance every force along that line, so the Jacobian is singular there; Newton also stops next to them
   with a nearly singular Jacobian and an arbitrary force along the line.  Solutions whose axes lie on one
   line to ``FOLDED`` (the closure's Jacobian nearly loses rank) are therefore not reported either.
4. **De-duplication.** Two solutions are the same shape when a rotation, a relabelling of the bodies that
   keeps the lengths (a cyclic shift, the reversed numbering) or a reflection maps one onto the other (joint
   angles equal to 1e-7).
5. **Proof.** Each shape kept is proved (``proofs.prove_equilibrium``): the Krawczyk operator on the general
   equations in ball arithmetic shows a unique equilibrium in a small box around it, and the inertia of the
   constrained Hessian over that box is proved in balls (``decided_by = "interval_newton"``): in the plane and,
   with the default ``model = "spatial"``, out of it (the planar shape is an equilibrium in space too: the
   reflection through its plane maps it onto itself), so each shape carries its class in space and in the plane.  A shape for which
   either fails is still listed, flagged: ``decided_by = "undecided"``, stability ``"undecided"`` (and
   ``exists = None`` when the Krawczyk test failed).

Nothing guarantees that every equilibrium is found: more ``starts`` find more of those with small basins.
Only planar equilibria are searched for: non-planar ones (which may branch off where a planar one loses
stability out of its plane) are not.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import root

from . import checks, equations, proofs, space_proofs
from .checks import can_close, positive
from .solve import Equilibrium, equilibrium, scalars

RESIDUAL = 1e-12
REGULAR = 1e-10
FOLDED = 1e-6  # closure rows this close to dependent: the axes lie on one line (to about 1e-6 rad)
SAME_ANGLES = 1e-7
NOISE = (0.3, 1.0, math.pi)
_FLOAT = proofs.Verdict(1, -1, -1, proofs.UNDECIDED)  # a candidate before its proof


def _system(x, h_k, rho_scale):
    """The equations F(x) and their Jacobian; x = (theta_2..theta_n, rho_y, rho_z), rho = R h / c1^2 [1/m]."""
    n = h_k.size
    theta = np.concatenate([[0.0], x[: n - 1]])
    ry, rz = x[n - 1] * rho_scale, x[n] * rho_scale
    s, c = np.sin(theta), np.cos(theta)
    nxt, prv = np.roll(theta, -1), np.roll(theta, 1)
    torque = np.sin(nxt - theta) - np.sin(theta - prv) - h_k * (rz * s + ry * c)
    total = h_k.sum()
    F = np.concatenate([torque[1:], [(h_k * s).sum() / total, (h_k * c).sum() / total]])
    J = np.zeros((n + 1, n + 1))
    cn, cp = np.cos(nxt - theta), np.cos(theta - prv)
    for k in range(1, n):
        row = k - 1
        for col, value in (((k + 1) % n, cn[k]), ((k - 1) % n, cp[k])):
            if col:
                J[row, col - 1] += value
        J[row, k - 1] += -cn[k] - cp[k] - h_k[k] * (rz * c[k] - ry * s[k])
        J[row, n - 1] = -h_k[k] * c[k] * rho_scale
        J[row, n] = -h_k[k] * s[k] * rho_scale
    J[n - 1, : n - 1] = h_k[1:] * c[1:] / total
    J[n, : n - 1] = -h_k[1:] * s[1:] / total
    return F, J


def _close(theta: np.ndarray, h_k: np.ndarray, steps: int = 30) -> np.ndarray | None:
    """``theta`` pulled onto the closed configurations by minimum-norm Gauss-Newton steps (None: it did not close)."""
    total = h_k.sum()
    for _ in range(steps):
        gap = np.array([(h_k * np.sin(theta)).sum(), (h_k * np.cos(theta)).sum()]) / total
        if np.abs(gap).max() < 1e-14:
            return theta
        A = np.stack([h_k * np.cos(theta), -h_k * np.sin(theta)]) / total
        theta = theta - np.linalg.lstsq(A, gap, rcond=None)[0]
    return None


def _start(theta: np.ndarray, h_k: np.ndarray, rho_scale: float) -> np.ndarray:
    """Unknowns of a start: theta relative to theta_1, and the forces that best balance its torques."""
    theta = theta - theta[0]
    s, c = np.sin(theta), np.cos(theta)
    d = np.sin(np.roll(theta, -1) - theta) - np.sin(theta - np.roll(theta, 1))
    rho = np.linalg.lstsq(np.stack([h_k * c, h_k * s], axis=1), d, rcond=None)[0] / rho_scale
    return np.concatenate([theta[1:], rho])


def _newton(x: np.ndarray, h_k: np.ndarray, rho_scale: float) -> tuple[np.ndarray, np.ndarray] | None:
    sol = root(_system, x, args=(h_k, rho_scale), jac=True, method="hybr", options={"xtol": 1e-14})
    x = sol.x
    for _ in range(8):  # MINPACK stops at its own tolerance; Newton's quadratic steps take it to rounding
        F, J = _system(x, h_k, rho_scale)
        try:
            x = x - np.linalg.solve(J, F)
        except np.linalg.LinAlgError:
            return None
    F, J = _system(x, h_k, rho_scale)
    return (x, J) if np.all(np.isfinite(x)) else None


def _same(a: Equilibrium, b: Equilibrium) -> bool:
    """Whether a rotation, a relabelling that keeps the lengths, or a reflection maps ``b`` onto ``a``."""
    if abs(a.energy - b.energy) > 1e-9 * max(1.0, abs(a.energy)):
        return False
    h_a, h_b = np.asarray(a.lengths), np.asarray(b.lengths)
    target = a.joint_angles
    for theta, h in ((b.theta, h_b), (np.pi + b.theta[::-1], h_b[::-1])):  # as numbered, and numbered backwards
        for mirror in (1.0, -1.0):
            for shift in range(h.size):
                hs = np.roll(h, shift)
                if np.abs(hs - h_a).max() > 1e-12 * h_a.max():
                    continue
                d = equations.joint_angles(mirror * np.roll(theta, shift))
                if np.abs(equations.wrap(d - target)).max() < SAME_ANGLES:
                    return True
    return False


def search(lengths, *, c1sq: float = 1.0, c2sq: float | None = None, h: float | None = None, starts: int | None = None, seed: int = 0,
           model: str = "spatial") -> list[Equilibrium]:
    """Every isolated planar equilibrium of the plain closed chain with ``lengths`` that the multi-start finds,
    with its stability in space (``model = "spatial"``, the default; ``c2sq`` defaults to c1sq) and in the plane.

    Parameters
    ----------
    lengths : sequence of float
        h_1..h_n [m], n >= 4 (three bodies are rigid: only their triangle), positive and closable.
    c1sq, c2sq, h, model
        As for ``solve``.
    starts : int, optional
        Number of starts (default 60 n).
    seed : int
        Seed of the starts: the same call gives the same list.

    Returns
    -------
    list of Equilibrium
        ``shape = "found"``, each verified (residual <= 1e-12, regular Jacobian) and distinct modulo rotation,
        relabelling and reflection, sorted by energy; each proved (``decided_by = "interval_newton"``) or
        flagged ``"undecided"``.  Method and limits: the module docstring.
    """
    h_k = np.array([positive(f"lengths[{k + 1}]", v) for k, v in enumerate(lengths)], dtype=float)
    if h_k.size < 3:
        from ...errors import StabmapError

        raise StabmapError(f"lengths: a closed chain needs at least 3 bodies, got {h_k.size}")
    can_close(h_k)
    c1sq, h, c2sq = scalars(h_k, c1sq, h, c2sq)
    gamma = space_proofs.gamma_of(c1sq, c2sq) if checks.model(model) else None
    n = h_k.size
    starts = 60 * n if starts is None else int(starts)
    rho_scale = 1.0 / h_k.mean()  # forces in units of c1^2 / (h mean h_k): unknowns of order one
    rng = np.random.default_rng(seed)
    k = np.arange(1, n + 1)
    found: list[Equilibrium] = []
    loop_of = np.zeros(n, dtype=np.int64)
    for _ in range(starts):
        w = rng.integers(0, max(1, math.ceil(n / 2)))
        theta = _close(2 * np.pi * w * k / n + rng.choice(NOISE) * rng.standard_normal(n), h_k)
        if theta is None:
            continue
        solved = _newton(_start(theta, h_k, rho_scale), h_k, rho_scale)
        if solved is None:
            continue
        x, J = solved
        if 1.0 / np.linalg.cond(J) < REGULAR:
            continue
        theta = equations.wrap(np.concatenate([[0.0], x[: n - 1]]))
        sv = np.linalg.svd(equations.constraint_rows(theta[None], h_k[None], loop_of)[0, :2], compute_uv=False)
        if sv[1] < FOLDED * sv[0]:
            continue
        forces = np.array([[x[n - 1], x[n]]]) * rho_scale * c1sq / h
        eq = equilibrium("found", h_k, theta, forces, _FLOAT, loop_of, c1sq, h)
        if eq.residual > RESIDUAL or any(_same(other, eq) for other in found):
            continue
        found.append(eq)
    proved = []
    for eq in found:  # each kept shape proved: Krawczyk on the general equations, then its inertia in balls
        verdict = proofs.prove_equilibrium(eq.theta, eq.forces * (h / c1sq), h_k, loop_of, gamma)
        proved.append(equilibrium("found", h_k, eq.theta, eq.forces, verdict, loop_of, c1sq, h, c2sq=c2sq, model=model))
    return sorted(proved, key=lambda e: (e.energy, e.index))
