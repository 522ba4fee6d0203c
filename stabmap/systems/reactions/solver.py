"""Reactions of n point nodes by the least-norm rule (seed 004, docs/reactions.md), vectorised over loads and layouts.

A rigid body is held by n ideal point nodes (forces only). The reactions R_i on the body balance the load,

    sum_i R_i + F = 0,        sum_i x_i x R_i + M = 0        (M about the origin of the node positions x_i),

and a released node k carries no force along e_k (e_k . R_k = 0). Among all reactions that do, the nodes take the
one with the least sum_i |R_i|^2: what n equal, isotropic, stiff springs carry. That is the minimum-norm solution
of an underdetermined linear system, computed here by a singular value decomposition of a well-scaled form of it:

- moments are taken about the nodes' centroid and lengths measured in their RMS distance from it, so that every
  column of the balance matrix has entries of order one and its singular values compare as numbers;
- a released node's reaction is written in an orthonormal basis of the directions it still carries, so the
  releases are kept exactly and the least norm is unchanged (the basis is orthonormal);
- singular values below ``RANK_RTOL`` times the largest count as zero (the layout cannot resist that load
  pattern: collinear nodes cannot take a moment about their line, releases may free the body); the load is
  *compatible* when its part outside the balance matrix's range is below ``BALANCE_RTOL`` of the load, and
  then the reactions are unique; otherwise there are none, and they are reported as NaN, never "solved".

Everything works on stacks: ``nodes`` of shape (..., n, 3) and loads of shape (..., 3) broadcast against each
other, and each distinct layout is factored once (a grid over load axes only costs one SVD).
"""

from __future__ import annotations

from dataclasses import dataclass
from numbers import Integral

import numpy as np

from ...errors import StabmapError

RANK_RTOL = 1e-10  # singular values of the scaled balance matrix below this times the largest count as zero
BALANCE_RTOL = 1e-12  # a load whose part outside the range exceeds this times the load is incompatible
TIE_RTOL = 1e-9  # nodes within this relative distance of the largest |R_i| all carry it (ties on symmetric layouts)
BALANCE_ROWS = 6


@dataclass(frozen=True)
class Reactions:
    """The reactions of one load (``solve``).

    Attributes
    ----------
    R : ndarray of shape (n, 3) or None
        Reactions on the body at the nodes [force units of F]; None when no reactions balance the load.
    rank : int
        Rank of the whole linear constraint system: the six balance equations and one row per release.
    compatible : bool
        True when reactions balance the load (then R is unique by the least-norm rule).
    max_norm : float
        The largest |R_i| (NaN when incompatible).
    critical_node : int or None
        The node carrying ``max_norm`` (0-based; the lowest-numbered one when several carry it to ``TIE_RTOL``).
    n_critical : int
        How many nodes carry ``max_norm`` to within ``TIE_RTOL`` (0 when incompatible).
    norms : ndarray of shape (n,)
        |R_i| (NaN when incompatible).
    free_motions : int
        Rigid motions of the body the nodes do not stop (6 minus the rank of the balance equations on the
        reactions the releases allow): 0 for a body held fully, 1 for collinear nodes (rotation about the line).
    residual : float
        (|sum R + F| + |sum l x R + M_c| / ell) / s: the balance achieved, relative to the load scale
        s = sqrt(|F|^2 + |M_c|^2 / ell^2), M_c the moment about the nodes' centroid and ell their RMS distance
        from it (NaN when incompatible).
    """

    R: np.ndarray | None
    rank: int
    compatible: bool
    max_norm: float
    critical_node: int | None
    n_critical: int
    norms: np.ndarray
    free_motions: int
    residual: float


@dataclass(frozen=True)
class Batch:
    """The reactions of a stack of problems (``solve_batch``): arrays over the broadcast shape S of the inputs.

    ``R`` has shape S + (n, 3) and ``norms`` S + (n,), NaN where incompatible; ``max_norm`` and ``residual``
    are NaN there, ``critical_node`` is -1 and ``n_critical`` 0. Other fields as in ``Reactions``.
    """

    R: np.ndarray
    rank: np.ndarray
    compatible: np.ndarray
    max_norm: np.ndarray
    critical_node: np.ndarray
    n_critical: np.ndarray
    norms: np.ndarray
    free_motions: np.ndarray
    residual: np.ndarray


# ---------------------------------------------------------------------------------------------------- input checks
def check_nodes(nodes, where: str = "nodes") -> np.ndarray:
    """Node positions as a float array of shape (..., n, 3): finite, n >= 1, no two nodes at one point."""
    try:
        a = np.asarray(nodes, dtype=np.float64)
    except (TypeError, ValueError):
        raise StabmapError(f"{where} must be an (n, 3) array of node positions [x, y, z], got {nodes!r}") from None
    if a.ndim < 2 or a.shape[-1] != 3 or a.shape[-2] < 1:
        raise StabmapError(f"{where} must be an (n, 3) array of node positions [x, y, z] with n >= 1, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        i = np.argwhere(~np.isfinite(a))[0]
        raise StabmapError(f"{where}: node {int(i[-2])} has a non-finite coordinate ({a[tuple(i)]}); give finite numbers")
    n = a.shape[-2]
    flat = a.reshape(-1, n, 3)
    same = np.all(flat[:, :, None, :] == flat[:, None, :, :], axis=-1) & ~np.eye(n, dtype=bool)
    if same.any():
        p, i, j = np.argwhere(same)[0]
        raise StabmapError(
            f"{where}: nodes {int(i)} and {int(j)} are at the same point {flat[p, i].tolist()}; give each node "
            "its own position (one node carries any force, two at one point add nothing)"
        )
    return a


def check_vector(value, where: str) -> np.ndarray:
    """A load vector as a float array of shape (..., 3) with finite values."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise StabmapError(f"{where} must be a 3-vector [x, y, z] of numbers, got {value!r}") from None
    if a.ndim < 1 or a.shape[-1] != 3:
        raise StabmapError(f"{where} must be a 3-vector [x, y, z] (or an array of them, shape (..., 3)), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise StabmapError(f"{where} must be finite, got {a.tolist() if a.size <= 9 else 'non-finite values'}")
    return a


def check_releases(releases, n: int, where: str = "releases") -> tuple[tuple[int, np.ndarray], ...]:
    """``(node_index, direction)`` pairs: a 0-based index below n and a finite nonzero 3-vector, made unit."""
    if isinstance(releases, (str, bytes)) or not hasattr(releases, "__iter__"):
        raise StabmapError(f"{where} must be a sequence of (node_index, direction) pairs, got {releases!r}")
    out = []
    for k, pair in enumerate(releases):
        here = f"{where}[{k}]"
        if isinstance(pair, (str, bytes)) or not hasattr(pair, "__len__") or len(pair) != 2:
            raise StabmapError(f"{here} must be a pair (node_index, direction), e.g. (0, [1.0, 0.0, 0.0]); got {pair!r}")
        node, direction = pair
        if isinstance(node, bool) or not isinstance(node, Integral):
            raise StabmapError(f"{here}: the node index must be a whole number 0..{n - 1}, got {node!r}")
        if not 0 <= node < n:
            raise StabmapError(f"{here}: node {node} does not exist; the nodes are numbered 0..{n - 1}")
        e = check_vector(direction, f"{here} direction")
        if e.shape != (3,):
            raise StabmapError(f"{here} direction must be one 3-vector [x, y, z], got shape {e.shape}")
        length = float(np.linalg.norm(e))
        if length == 0.0:
            raise StabmapError(f"{here} direction is zero; give the direction along which node {node} carries no force, e.g. [1.0, 0.0, 0.0]")
        out.append((int(node), e / length))
    return tuple(out)


# ---------------------------------------------------------------------------------------------------- the solve
def carried_basis(n: int, releases) -> np.ndarray:
    """Block-diagonal (3n, m) matrix whose node-i block is an orthonormal basis of the directions node i carries.

    A node with releases carries the orthogonal complement of their span (found by SVD, so parallel or
    dependent release directions count once); a node released in three independent directions carries nothing.
    """
    blocks = []
    for i in range(n):
        dirs = np.array([e for k, e in releases if k == i]).reshape(-1, 3)
        if not len(dirs):
            blocks.append(np.eye(3))
            continue
        _, s, vt = np.linalg.svd(dirs, full_matrices=True)
        released = int(np.sum(s > RANK_RTOL))  # unit rows: an absolute tolerance is a relative one
        blocks.append(vt[released:].T)
    m = sum(b.shape[1] for b in blocks)
    Q = np.zeros((3 * n, m))
    col = 0
    for i, b in enumerate(blocks):
        Q[3 * i : 3 * i + 3, col : col + b.shape[1]] = b
        col += b.shape[1]
    return Q


def _skew(v: np.ndarray) -> np.ndarray:
    """[v]x of shape (..., 3, 3): [v]x r = v x r."""
    z = np.zeros(v.shape[:-1])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([np.stack([z, -w, y], -1), np.stack([w, z, -x], -1), np.stack([-y, x, z], -1)], -2)


def solve_batch(nodes, F, M, *, releases=()) -> Batch:
    """Least-norm reactions of a stack of problems; the inputs are checked (a StabmapError names the bad one).

    Parameters
    ----------
    nodes : array_like, shape (..., n, 3)
        Node positions [m], about the point that ``M`` is taken about.
    F, M : array_like, shape (..., 3)
        Main vector [N] and main moment [N m] of the load on the body (external and inertia forces).
    releases : sequence of (int, array_like)
        ``(node_index, direction)``: node ``node_index`` (0-based) carries no force along ``direction``.
        The same for every problem of the stack.

    Returns
    -------
    Batch
        Arrays over the broadcast shape of ``nodes[..., 0, 0]``, ``F[..., 0]`` and ``M[..., 0]``.
    """
    x = check_nodes(nodes)
    return least_norm(x, check_vector(F, "F"), check_vector(M, "M"), carried_basis(x.shape[-2], check_releases(releases, x.shape[-2])))


def least_norm(x: np.ndarray, F: np.ndarray, M: np.ndarray, Q: np.ndarray) -> Batch:
    """``solve_batch`` on checked float arrays, with the releases as ``carried_basis`` (no checks: the atlas's scene
    was checked once, and its grid cannot put two nodes at one point)."""
    n = x.shape[-2]
    released_rank = 3 * n - Q.shape[1]

    # The layout, factored once per distinct layout (the nodes' own batch shape L).
    centroid = x.mean(axis=-2)
    l = x - centroid[..., None, :]
    ell = np.sqrt(np.mean(np.sum(l * l, axis=-1), axis=-1))
    ell = np.where(ell > 0, ell, 1.0)  # one node: any length scale will do
    B = np.concatenate([np.broadcast_to(np.eye(3), l.shape[:-1] + (3, 3)), _skew(l / ell[..., None, None])], axis=-2)  # (L, n, 6, 3)
    A = np.moveaxis(B, -3, -2).reshape(l.shape[:-2] + (BALANCE_ROWS, 3 * n)) @ Q  # (L, 6, m)
    if A.shape[-1]:
        U, s, Vt = np.linalg.svd(A, full_matrices=False)
    else:  # every node released in every direction: nothing carried
        U, s, Vt = np.zeros(A.shape[:-1] + (0,)), np.zeros(A.shape[:-2] + (0,)), np.zeros(A.shape[:-2] + (0, 0))
    smax = s[..., :1] if s.shape[-1] else np.zeros(s.shape[:-1] + (1,))
    kept = (s > RANK_RTOL * smax) & (s > 0)
    balance_rank = kept.sum(axis=-1)

    # The load about the centroid, scaled like the matrix: b = -(F, M_c / ell).
    Mc = M - np.cross(centroid, F)
    b = -np.concatenate([np.broadcast_to(F, np.broadcast_shapes(F.shape, Mc.shape)), Mc / ell[..., None]], axis=-1)
    scale = np.linalg.norm(b, axis=-1)
    coef = np.einsum("...ij,...i->...j", U, b) * kept  # components of b along the kept left singular vectors
    outside = np.linalg.norm(b - np.einsum("...ij,...j->...i", U, coef), axis=-1)
    compatible = outside <= BALANCE_RTOL * scale
    inv = np.divide(1.0, s, out=np.zeros_like(s), where=kept)
    rho = np.einsum("...ji,...j->...i", Vt, coef * inv)
    # One step of iterative refinement on what the first solve left unbalanced (within the range, as the part
    # outside cannot be carried): it takes the rounding of the SVD's factors out of the balance.
    left = b - np.einsum("...ij,...j->...i", A, rho)
    rho = rho + np.einsum("...ji,...j->...i", Vt, np.einsum("...ij,...i->...j", U, left) * kept * inv)
    R = (rho @ Q.T).reshape(rho.shape[:-1] + (n, 3))

    # Balance as achieved, in the same scaled form (forces, and moments about the centroid over ell).
    l_b = np.broadcast_to(l, R.shape)
    force = np.sum(R, axis=-2) + F
    moment = (np.sum(np.cross(l_b, R), axis=-2) + Mc) / ell[..., None]
    residual = (np.linalg.norm(force, axis=-1) + np.linalg.norm(moment, axis=-1)) / np.where(scale > 0, scale, 1.0)

    norms = np.linalg.norm(R, axis=-1)
    shape = norms.shape[:-1]
    compatible = np.broadcast_to(compatible, shape)
    rmax = norms.max(axis=-1)
    tied = norms >= rmax[..., None] * (1.0 - TIE_RTOL)
    nan = np.where(compatible, 0.0, np.nan)
    return Batch(
        R=R + nan[..., None, None],
        rank=np.broadcast_to(balance_rank + released_rank, shape).astype(np.int16),
        compatible=compatible.copy(),
        max_norm=rmax + nan,
        critical_node=np.where(compatible, np.argmax(tied, axis=-1), -1).astype(np.int16),
        n_critical=np.where(compatible, tied.sum(axis=-1), 0).astype(np.int16),
        norms=norms + nan[..., None],
        free_motions=np.broadcast_to(BALANCE_ROWS - balance_rank, shape).astype(np.int16),
        residual=np.broadcast_to(residual, shape) + nan,
    )


def solve(nodes, F, M, *, releases=()) -> Reactions:
    """Reactions of n point nodes holding a rigid body, by the least sum of |R_i|^2 (docs/reactions.md).

    Parameters
    ----------
    nodes : array_like, shape (n, 3)
        Node positions [m].
    F : array_like, shape (3,)
        Main vector of the load on the body [N] (external and inertia forces).
    M : array_like, shape (3,)
        Main moment of the load about the origin of ``nodes`` [N m].
    releases : sequence of (int, array_like)
        ``(node_index, direction)`` pairs: node ``node_index`` (0-based) carries no force along ``direction``
        (a cylindrical hinge's axis, a sliding support's plane).

    Returns
    -------
    Reactions
        ``R`` (n, 3) with sum R + F = 0 and sum nodes x R + M = 0, least in sum |R_i|^2; None when no reactions
        balance the load (``compatible`` False: collinear nodes and a moment about their line, or releases that
        leave the body free to move that way). Also ``rank``, ``max_norm``, ``critical_node`` and more.

    Raises
    ------
    StabmapError
        Bad input: NaN, wrong shapes, a zero release direction, two nodes at one point; the message names it.

    Examples
    --------
    >>> plate = [[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]
    >>> solve(plate, [0, 0, -100.0], [0, 0, 0]).R[:, 2]          # a quarter of the weight each
    array([25., 25., 25., 25.])
    """
    for value, where, ndim in ((nodes, "nodes", 2), (F, "F", 1), (M, "M", 1)):
        want = "an (n, 3) array of node positions [x, y, z]" if ndim == 2 else "a 3-vector [x, y, z]"
        try:
            shape = np.shape(value)
        except ValueError:  # rows of different lengths
            raise StabmapError(f"{where} must be {want}, got {value!r}") from None
        if len(shape) != ndim:
            raise StabmapError(f"{where} must be {want}, got shape {shape} (solve_batch takes stacks)")
    out = solve_batch(nodes, F, M, releases=releases)
    ok = bool(out.compatible)
    return Reactions(
        R=out.R if ok else None,
        rank=int(out.rank),
        compatible=ok,
        max_norm=float(out.max_norm),
        critical_node=int(out.critical_node) if ok else None,
        n_critical=int(out.n_critical),
        norms=out.norms,
        free_motions=int(out.free_motions),
        residual=float(out.residual),
    )


def closed_form(nodes, F, M) -> np.ndarray:
    """The paper's closed form (6)-(9) about the centroid, no releases: R_i = -F/n + l_i x J^-1 M_c.

    J = sum(|l_i|^2 E - l_i l_i^T) is singular for collinear nodes; then this raises (use ``solve``). Kept as the
    formula of docs/reactions.md, and as a second way to the same numbers in the tests.
    """
    x = check_nodes(nodes)
    F, M = check_vector(F, "F"), check_vector(M, "M")
    c = x.mean(axis=0)
    l = x - c
    J = np.sum(l * l) * np.eye(3) - l.T @ l
    if np.linalg.cond(J) > 1.0 / RANK_RTOL:
        raise StabmapError("closed_form: the nodes are collinear (J is singular); use solve, the least-norm rule")
    y = np.linalg.solve(J, M - np.cross(c, F))
    return -F / len(x) + np.cross(l, y)


__all__ = ["BALANCE_RTOL", "RANK_RTOL", "TIE_RTOL", "Batch", "Reactions", "carried_basis", "check_nodes",
           "check_releases", "check_vector", "closed_form", "least_norm", "solve", "solve_batch"]
