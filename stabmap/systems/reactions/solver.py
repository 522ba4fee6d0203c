"""Reactions of n point nodes by the least-norm rule (seed 004, docs/reactions.md), vectorised over loads and layouts.

A rigid body is held by n ideal point nodes (forces only). The reactions R_i on the body balance the load,

    sum_i R_i + F = 0,        sum_i x_i x R_i + M = 0        (M about the origin of the node positions x_i),

and a released node k carries no force along e_k (e_k . R_k = 0). Among all reactions that do, the nodes take the
one with the least sum_i |R_i|^2: what n equal, isotropic, stiff springs carry. That is the minimum-norm solution
of an underdetermined linear system. The inputs are binary floats, so the system and its solution are exact
rationals, and every label (rank, compatibility, the critical node and its ties) is a statement about them,
proved at every point in one of two ways (``decided_by``):

- ``float_with_bound``: ``floats`` solves a well-scaled form of the system in floating point (moments about
  the nodes' centroid, lengths in a power of two near their RMS distance from it), proves that the exact system
  has full row rank (so every load is compatible), and bounds the distance delta from the float reactions to
  the exact ones. The point is decided when the largest |R_i| exceeds every other by more than the bound
  allows, and the bound is at most ``ERROR_RTOL`` of it;
- ``exact_rational``: otherwise (rank-deficient layouts, ties, near-ties, loads too small for the bound),
  ``exact`` solves the point in rational arithmetic, factoring each distinct layout once. The reported R is
  the exact one rounded to floats, and ties are exact equalities.

Everything works on stacks: ``nodes`` of shape (..., n, 3) and loads of shape (..., 3) broadcast against each
other, and each distinct layout is factored once (a grid over load axes only costs one factorisation).
"""

from __future__ import annotations

from dataclasses import dataclass
from numbers import Integral

import numpy as np

from ...errors import StabmapError
from . import exact, floats

ERROR_RTOL = 1e-10  # a float point is kept only when its proved error |R - R*| is at most this times R_max
BALANCE_ROWS = 6
DECIDED_BY = ("float_with_bound", "exact_rational")  # the flag values 0 and 1 of decided_by


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
        The node carrying ``max_norm`` (0-based; the lowest-numbered one when several carry exactly as much).
    n_critical : int
        How many nodes carry exactly ``max_norm`` (0 when incompatible).
    norms : ndarray of shape (n,)
        |R_i| (NaN when incompatible).
    free_motions : int
        Rigid motions of the body the nodes do not stop (6 minus the rank of the balance equations on the
        reactions the releases allow): 0 for a body held fully, 1 for collinear nodes (rotation about the line).
    residual : float
        (|sum R + F| + |sum l x R + M_c| / ell) / s: the balance achieved, relative to the load scale
        s = sqrt(|F|^2 + |M_c|^2 / ell^2), M_c the moment about the nodes' centroid and ell their RMS distance
        from it (NaN when incompatible).
    decided_by : str
        How the labels were proved: ``"float_with_bound"`` (R within ``ERROR_RTOL`` of R_max of the exact
        reactions) or ``"exact_rational"`` (R the exact reactions rounded). Module docstring.
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
    decided_by: str


@dataclass(frozen=True)
class Batch:
    """The reactions of a stack of problems (``solve_batch``): arrays over the broadcast shape S of the inputs.

    ``R`` has shape S + (n, 3) and ``norms`` S + (n,), NaN where incompatible; ``max_norm`` and ``residual``
    are NaN there, ``critical_node`` is -1 and ``n_critical`` 0. ``decided_by`` holds 0 (float_with_bound) or 1
    (exact_rational), the index in ``DECIDED_BY``. Other fields as in ``Reactions``.
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
    decided_by: np.ndarray


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
    """``(node_index, direction)`` pairs: a 0-based index below n and a finite nonzero 3-vector (as given, not
    normalised: the exact problem is the one with the given direction)."""
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
        if not 0 <= int(node) < n:
            raise StabmapError(f"{here}: node {node} does not exist; the nodes are numbered 0..{n - 1}")
        e = check_vector(direction, f"{here} direction")
        if e.shape != (3,):
            raise StabmapError(f"{here} direction must be one 3-vector [x, y, z], got shape {e.shape}")
        length = float(np.linalg.norm(e))
        if length == 0.0:
            raise StabmapError(f"{here} direction is zero; give the direction along which node {node} carries no force, e.g. [1.0, 0.0, 0.0]")
        out.append((int(node), e))
    return tuple(out)


# ---------------------------------------------------------------------------------------------------- the solve
def prepare_releases(n: int, releases) -> tuple[tuple[int, np.ndarray], ...]:
    """The independent release rows (``exact.release_rows``) of checked ``(node, direction)`` pairs
    (``check_releases``: directions as given); they define the exact problem."""
    return exact.release_rows(n, releases)


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
    n = x.shape[-2]
    return least_norm(x, check_vector(F, "F"), check_vector(M, "M"), prepare_releases(n, check_releases(releases, n)))


def least_norm(x: np.ndarray, F: np.ndarray, M: np.ndarray, releases) -> Batch:
    """``solve_batch`` on checked float arrays, with ``prepare_releases`` (no checks: the atlas's scene was
    checked once, and its grid cannot put two nodes at one point). Module docstring: how each label is proved."""
    n = x.shape[-2]
    L = x.shape[:-2]

    # Floats with a proved bound: which points they decide.
    layouts = floats.Layouts(x, releases)
    R, delta = layouts.solve(F, M)
    shape = R.shape[:-2]
    with np.errstate(invalid="ignore"):
        norms = np.linalg.norm(R, axis=-1)
        proved = floats.separated(norms, delta) & (delta <= ERROR_RTOL * norms.max(axis=-1))

    # Flat over the points while the exact ones are filled in.
    P = int(np.prod(shape, dtype=int))
    R = np.array(np.broadcast_to(R, shape + (n, 3))).reshape(P, n, 3)
    norms = np.array(np.broadcast_to(norms, shape + (n,))).reshape(P, n)
    compatible = np.ones(P, dtype=bool)
    critical = np.argmax(norms, axis=-1).astype(np.int16)
    n_critical = np.ones(P, dtype=np.int16)
    rank = np.full(P, BALANCE_ROWS + len(releases), dtype=np.int16)
    decided = np.zeros(P, dtype=np.int8)

    # The rest exactly, each distinct layout factored once.
    todo = np.flatnonzero(~np.broadcast_to(proved, shape).ravel())
    if todo.size:
        layout_of = np.broadcast_to(np.arange(int(np.prod(L, dtype=int))).reshape(L), shape).ravel()
        xs = x.reshape((-1, n, 3))
        Fs = np.broadcast_to(F, shape + (3,)).reshape(-1, 3)
        Ms = np.broadcast_to(M, shape + (3,)).reshape(-1, 3)
        factored: dict[int, exact.Layout] = {}
        for i in todo:
            j = int(layout_of[i])
            if j not in factored:
                factored[j] = exact.Layout(xs[j], releases)
            point = factored[j].solve(Fs[i], Ms[i])
            R[i], norms[i], compatible[i] = point.R, point.norms, point.compatible
            critical[i], n_critical[i], rank[i], decided[i] = point.critical_node, point.n_critical, factored[j].rank, 1
    R, norms = R.reshape(shape + (n, 3)), norms.reshape(shape + (n,))
    compatible, critical, n_critical, rank, decided = (a.reshape(shape) for a in (compatible, critical, n_critical, rank, decided))

    # Balance as achieved, relative to the load scale s (forces, moments about the centroid over ell).
    centroid = x.mean(axis=-2)
    l = x - centroid[..., None, :]
    ell = np.sqrt(np.mean(np.sum(l * l, axis=-1), axis=-1))
    ell = np.where(ell > 0, ell, 1.0)[..., None]  # one node: any length scale will do
    Mc = M - np.cross(centroid, F)
    scale = np.sqrt(np.sum(F * F, axis=-1) + np.sum(Mc * Mc, axis=-1) / ell[..., 0] ** 2)
    force = np.sum(R, axis=-2) + F
    moment = (np.sum(np.cross(np.broadcast_to(l, R.shape), R), axis=-2) + Mc) / ell
    residual = (np.linalg.norm(force, axis=-1) + np.linalg.norm(moment, axis=-1)) / np.where(scale > 0, scale, 1.0)

    with np.errstate(invalid="ignore"):
        top = np.take_along_axis(norms, np.maximum(critical, 0)[..., None].astype(np.intp), -1)[..., 0]
    return Batch(
        R=R,
        rank=rank,
        compatible=compatible,
        max_norm=np.where(compatible, top, np.nan),
        critical_node=np.where(compatible, critical, -1).astype(np.int16),
        n_critical=np.where(compatible, n_critical, 0).astype(np.int16),
        norms=norms,
        free_motions=(BALANCE_ROWS - (rank - len(releases))).astype(np.int16),
        residual=np.where(compatible, np.broadcast_to(residual, shape), np.nan),
        decided_by=decided,
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
        decided_by=DECIDED_BY[int(out.decided_by)],
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
    if np.linalg.cond(J) > 1e10:
        raise StabmapError("closed_form: the nodes are collinear (J is singular); use solve, the least-norm rule")
    y = np.linalg.solve(J, M - np.cross(c, F))
    return -F / len(x) + np.cross(l, y)


__all__ = ["DECIDED_BY", "ERROR_RTOL", "Batch", "Reactions", "check_nodes", "check_releases", "check_vector", "closed_form",
           "least_norm", "prepare_releases", "solve", "solve_batch"]
