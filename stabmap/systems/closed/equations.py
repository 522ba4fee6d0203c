"""The planar equilibrium equations of a closed chain and what they say about a configuration.

Everything here works on a batch of P configurations of n bodies at once (numpy, no loops over points):

- ``theta`` (P, n): axis angles [rad], e_k = (-sin theta_k, cos theta_k) in the (y, z) plane;
- ``lengths`` (P, n): h_k [m];
- ``forces`` (P, L, 2): the joint force (R_y, R_z) [N] of each of the L closing loops;
- ``loop_of`` (n,): the loop each body belongs to (0 for a plain chain; the hinge has two loops).

The energy is U = (c1^2/h) sum_k (1 - cos(theta_k - theta_{k-1})) (indices cyclic, joint k between bodies
k-1 and k), the constraints are the closures sum_{k in loop} h_k e_k = 0, and the forces are their Lagrange
multipliers: the equilibrium equations (22) and (24) of the paper (docs/closed.md) are the stationarity
conditions of U - sum_loops R . (closure).  Stability in the plane is a strict minimum of U on closed
configurations, decided by the Hessian of that Lagrangian on the tangent space of the constraints modulo the
rotation of the whole chain (proved in ``proofs``; everything here is floating point).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import space

# The tolerances of ``inertia``, a floating-point estimate that labels nothing: the labels are proved in
# ``proofs``; ``inertia`` gives the eigenvalues that ``solve`` reports for information.
# Relative size below which a singular value of the (normalised) closure Jacobian counts as zero: the
# constraints have lost rank (a loop folded onto a line).
RANK_TOL = 1e-10
# Relative size below which an eigenvalue of the reduced Hessian (in units of c1^2/h) counts as zero.
NULL_TOL = 1e-12


def wrap(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped into (-pi, pi]."""
    out = np.mod(angle + np.pi, 2 * np.pi) - np.pi
    return np.where(out == -np.pi, np.pi, out)


def joint_angles(theta: np.ndarray) -> np.ndarray:
    """Angle of each joint, theta_k - theta_{k-1} wrapped into (-pi, pi]: joint 1 joins body n to body 1."""
    return wrap(theta - np.roll(theta, 1, axis=-1))


def energy(theta: np.ndarray, c1sq, h, c2sq=None, phi=None) -> np.ndarray:
    """U [J] of each configuration: (c1^2/h) sum (1 - cos(theta_k - theta_{k-1})) without twist; with the bodies
    turned by phi_k about their axes (Q_k = Rx(theta_k) Rz(phi_k)), each joint adds
    (c2^2/2h)(1 + cos(theta_k - theta_(k-1)))(1 - cos(phi_k - phi_(k-1))) (docs/closed.md, section 1b)."""
    d = theta - np.roll(theta, 1, axis=-1)
    out = np.asarray(c1sq) / np.asarray(h) * np.sum(1.0 - np.cos(d), axis=-1)
    if phi is not None:
        f = phi - np.roll(phi, 1, axis=-1)
        out = out + np.asarray(c2sq) / (2 * np.asarray(h)) * np.sum((1.0 + np.cos(d)) * (1.0 - np.cos(f)), axis=-1)
    return out


def twist_residual(theta, phi, lengths, force_x, c1sq, c2sq, h) -> np.ndarray:
    """The scaled residual of the spatial equilibrium equations of configurations Q_k = Rx(theta_k) Rz(phi_k)
    with one loop and a closing force R_x normal to the plane (the twisted rings): every component of the
    gradient of U - R . closure (``space.spatial``, units of c1^2/h) divided by 2 + h_k |R| h / c1^2."""
    out = np.empty(len(theta))
    for p, (th, ph, hk, fx, c1, c2, hh) in enumerate(zip(theta, phi, lengths, force_x, np.broadcast_to(c1sq, len(theta)),
                                                          np.broadcast_to(c2sq, len(theta)), np.broadcast_to(h, len(theta)), strict=True)):
        quats = [space.body_frame(np.cos(a / 2), np.sin(a / 2), np.cos(b / 2), np.sin(b / 2)) for a, b in zip(th, ph, strict=True)]
        rho = (fx * hh / c1, 0.0, 0.0)
        _, g, _, _ = space.spatial(quats, list(hk), rho, c2 / c1, hessian=False)
        out[p] = np.max(np.abs(g).reshape(-1, 3).max(-1) / (2.0 + hk * abs(rho[0])))
    return out


def body_forces(forces: np.ndarray, loop_of: np.ndarray) -> np.ndarray:
    """(P, n, 2): the force of the loop of each body."""
    return forces[:, np.asarray(loop_of), :]


def residuals(theta, lengths, forces, loop_of, c1sq, h) -> np.ndarray:
    """The scaled residual of the equilibrium equations: max over every equation of each configuration.

    Equation (22) of body k, sin(theta_{k+1} - theta_k) - sin(theta_k - theta_{k-1}) = a_k (R_z sin theta_k +
    R_y cos theta_k) with a_k = h_k h / c1^2 and R the force of body k's loop, is divided by the size of its
    terms, 2 + a_k |R|; each loop's closure |sum h_k e_k| by its length sum h_k.  Both are then dimensionless.
    """
    theta, lengths = np.asarray(theta, dtype=float), np.asarray(lengths, dtype=float)
    loop_of = np.asarray(loop_of)
    R = body_forces(np.asarray(forces, dtype=float), loop_of)
    a = lengths * (np.asarray(h, dtype=float) / np.asarray(c1sq, dtype=float))[..., None]
    s, c = np.sin(theta), np.cos(theta)
    d = np.sin(np.roll(theta, -1, axis=-1) - theta) - np.sin(theta - np.roll(theta, 1, axis=-1))
    torque = np.abs(d - a * (R[..., 1] * s + R[..., 0] * c)) / (2.0 + a * np.hypot(R[..., 0], R[..., 1]))
    worst = torque.max(axis=-1)
    for loop in range(int(loop_of.max()) + 1):
        body = loop_of == loop
        hl = lengths[:, body]
        gap = np.hypot((hl * s[:, body]).sum(-1), (hl * c[:, body]).sum(-1)) / hl.sum(-1)
        worst = np.maximum(worst, gap)
    return worst


def hessian(theta, lengths, forces, loop_of, c1sq, h) -> np.ndarray:
    """(P, n, n): the Hessian of U - sum R . closure, in units of c1^2/h (so dimensionless).

    (c1^2/h) times the cyclic Laplacian with weights cos(theta_k - theta_{k-1}), plus
    diag(h_k (R_z cos theta_k - R_y sin theta_k)) with each body's loop force.
    """
    theta, lengths = np.asarray(theta, dtype=float), np.asarray(lengths, dtype=float)
    P, n = theta.shape
    w = np.cos(theta - np.roll(theta, 1, axis=-1))  # w[k]: joint k, between bodies k-1 and k
    H = np.zeros((P, n, n))
    k = np.arange(n)
    H[:, k, k] = w + np.roll(w, -1, axis=-1)
    H[:, k, (k - 1) % n] -= w
    H[:, (k - 1) % n, k] -= w
    R = body_forces(np.asarray(forces, dtype=float), np.asarray(loop_of))
    scale = (np.asarray(h, dtype=float) / np.asarray(c1sq, dtype=float))[..., None]
    H[:, k, k] += scale * lengths * (R[..., 1] * np.cos(theta) - R[..., 0] * np.sin(theta))
    return H


def constraint_rows(theta, lengths, loop_of) -> np.ndarray:
    """(P, 2L + 1, n): the closure Jacobian, each loop's rows divided by its length sum, and the rotation row.

    Rows 2l, 2l+1 are d/dtheta of (sum h sin theta, sum h cos theta) over loop l; the last row, all
    1/sqrt(n), spans the rotation of the whole chain, which every closure leaves closed.
    """
    theta, lengths = np.asarray(theta, dtype=float), np.asarray(lengths, dtype=float)
    loop_of = np.asarray(loop_of)
    P, n = theta.shape
    L = int(loop_of.max()) + 1
    A = np.zeros((P, 2 * L + 1, n))
    for loop in range(L):
        body = loop_of == loop
        hl = lengths * body / (lengths * body).sum(-1, keepdims=True)
        A[:, 2 * loop] = hl * np.cos(theta)
        A[:, 2 * loop + 1] = -hl * np.sin(theta)
    A[:, -1] = 1.0 / np.sqrt(n)
    return A


@dataclass(frozen=True)
class Inertia:
    """Index and nullity of the constrained Hessian of each configuration, and what decided them.

    ``eigenvalues`` (P, d) are those of the reduced Hessian in units of c1^2/h, NaN where a point has fewer
    tangent directions (only where the constraints lost rank); ``rank_loss`` counts the closure rows lost.
    """

    index: np.ndarray
    nullity: np.ndarray
    rank_loss: np.ndarray
    eigenvalues: np.ndarray


def tangent_basis(A: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """An orthonormal basis of the null space of each A (P, m, n), and how many of the m rows were dependent."""
    _, sv, vt = np.linalg.svd(A, full_matrices=True)
    rank = (sv > RANK_TOL * sv[:, :1]).sum(-1)
    return [vt[p, r:].T for p, r in enumerate(rank)], A.shape[1] - rank


def inertia(theta, lengths, forces, loop_of, c1sq, h) -> Inertia:
    """Index (negative eigenvalues) and nullity (zero ones) of the Hessian on the closures' tangent space, in
    floating point with the tolerances above: an estimate, and its eigenvalues (the labels come from ``proofs``).

    The tangent space is that of every loop's closure with the rotation of the whole chain taken out (dimension
    n - 2L - 1).  Where a loop is folded onto a line its two closure rows become dependent: the closed
    configurations do not form a manifold there and no Hessian test decides stability, so every lost row is
    counted in the nullity (such a point is degenerate, never stable) and the Hessian is taken on the larger
    null space of the linearised constraints.
    """
    theta = np.asarray(theta, dtype=float)
    P = theta.shape[0]
    H = hessian(theta, lengths, forces, loop_of, c1sq, h)
    bases, lost = tangent_basis(constraint_rows(theta, lengths, loop_of))
    dims = np.array([b.shape[1] for b in bases])
    d = int(dims.max(initial=0))
    ev = np.full((P, d), np.nan)
    # Points whose tangent spaces have one dimension are reduced together (the usual case), the others alone.
    for size in np.unique(dims):
        pts = np.flatnonzero(dims == size)
        if size == 0:
            continue
        Z = np.stack([bases[p] for p in pts])
        Hr = np.einsum("pki,pkl,plj->pij", Z, H[pts], Z)
        ev[pts, :size] = np.linalg.eigvalsh(0.5 * (Hr + np.swapaxes(Hr, 1, 2)))
    tol = NULL_TOL * np.maximum(1.0, np.nanmax(np.abs(ev), axis=-1, initial=0.0))
    neg = (ev < -tol[:, None]).sum(-1)
    zero = (np.abs(ev) <= tol[:, None]).sum(-1)
    return Inertia(neg.astype(np.int16), (zero + lost).astype(np.int16), lost.astype(np.int16), ev)


def rotation_index(theta: np.ndarray) -> np.ndarray:
    """The turning number of the chain's tangent: sum of the joint angles / 2 pi (ring j: j; figure-eight: 0).

    Undefined where a joint is folded back (a joint angle of +-pi): -128 there.
    """
    d = joint_angles(theta)
    folded = np.any(np.abs(np.abs(d) - np.pi) < 1e-9, axis=-1)
    turns = np.rint(d.sum(-1) / (2 * np.pi)).astype(np.int16)
    return np.where(folded, np.int16(-128), turns).astype(np.int8)


def joints(theta: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """(P, n + 1, 2): positions (y, z) [m] of O_1..O_{n+1}, O_1 at the origin (O_{n+1} = O_1 when closed)."""
    theta, lengths = np.asarray(theta, dtype=float), np.asarray(lengths, dtype=float)
    steps = np.stack([-lengths * np.sin(theta), lengths * np.cos(theta)], axis=-1)
    return np.concatenate([np.zeros(steps.shape[:-2] + (1, 2)), np.cumsum(steps, axis=-2)], axis=-2)
