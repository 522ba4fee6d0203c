"""Boxes enclosed at nodes of the parameters along which p is a polynomial (``kernels.nodes_box_block``).

The degree bound behind every node count (docs/certification.md, section 6).  p = det P, and each entry of row
k of P is (lambda^2 M_kj - K_kj) Q_k plus, on the diagonal, terms in C_k, omega_k and the liquid (E, kappa fixed
on a box).  M = diag(A) + J^T diag(m) J with J linear in the lengths (c, s, a tree's at); K = S diag(K_a) S^T
minus g (m c + at times the mass beyond) on the diagonal.  So each entry is a polynomial of degree <= 1 in a mass
(not a free system's: it divides by the total mass), an inertia, a stiffness or g, and <= 2 in a length; a product
such as m g c has degree 1 in each of its factors.  The bound is per variable: an axis that sets one column of
every body (``c``) still gives degree <= 2 per entry.  Every term of det P takes one entry from each of the n rows,
so p has degree <= n in a parameter of degree <= 1 per entry, and <= 2n in a length, whatever the others are.
A parameter that moves one row of P alone (A_k and C_k: row k of P = diag(Q) Phi T) or one rank-one term of it (a
joint's K_a: K = S diag(K_a) S^T, so P moves by t (Q o s_a)(s_a^T T)) gives degree <= 1: det(P_0 + t e f^T) =
det P_0 + t f^T adj(P_0) e.  In the spin-scaled model (every body at one rate omega, u = 1 / omega^2) u multiplies
K alone, so each entry is affine in u: degree <= n in u.  ``degree`` gives the bound of each axis;
tests/test_boxes.py checks each in exact arithmetic.

Hence the node counts:

- **spin-scaled**: u at n + 1 nodes, the other parameters within their radii at every node;
- **one mechanical axis**: degree + 1 nodes (2n + 1 in a length, n + 1 in a mass or g, 2 in one body's A or C or
  one joint's K), the inputs exact at each;
- **spin and one mechanical axis**: the tensor grid of (n + 1) nodes in u times those of the axis;
- **two mechanical axes**: the tensor grid of both axes' nodes.

p is then of degree < N1 in the first parameter and < N2 in the second, so its tensor interpolant through the
grid is p itself, and ``boxcount.over_grid`` encloses every value the count needs over the whole box.  A node is
exact only if every input that moves is the axis value itself (``copies``): an input formed from it with a
rounding (A less a cavity's tail) is not a polynomial in it, and such boxes take the plain enclosure.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...kernels import layout
from .parameters import parse_name
from .points import PointArrays, point_arrays
from .scene import Scene


@dataclass
class NodeBoxes:
    """Boxes for ``kernels.nodes_box_block``: the kernel inputs at the N1 x N2 nodes (t[i], t2[j]) of each box.

    ``body``, ``joint``, ``g``, ``at`` and their radii have a node axis after the box axis, node i N2 + j; t (npts,
    N1) and t2 (npts, N2) hold the nodes, distinct and decreasing, inside [t_lo, t_hi] and [t2_lo, t2_hi].  A box
    along one parameter has N2 = 1 and t2 = t2_lo = t2_hi = 0.  ``spin``: t is u = 1 / omega^2 (spin-scaled), and
    ``joint``, ``g`` and their radii are those of u = 1, which the kernel multiplies by u_i at node (i, j) exactly.
    """

    body: np.ndarray
    rbody: np.ndarray
    joint: np.ndarray
    rjoint: np.ndarray
    g: np.ndarray
    rg: np.ndarray
    at: np.ndarray
    rat: np.ndarray
    E: np.ndarray
    kappa: np.ndarray
    nmodes: np.ndarray
    free: bool
    parent: np.ndarray
    t: np.ndarray
    t_lo: np.ndarray
    t_hi: np.ndarray
    t2: np.ndarray
    t2_lo: np.ndarray
    t2_hi: np.ndarray
    spin: bool = False
    axis1: np.ndarray | None = None  # the grid axis of t (per box: the spin axis that moves it, for ``spin``)
    axis2: np.ndarray | None = None  # the grid axis of t2 (None: a box along one parameter)

    def kernel_args(self):
        return (self.body, self.rbody, self.joint, self.rjoint, self.g, self.rg, self.E, self.kappa, self.nmodes, self.free,
                self.parent, self.at, self.rat, self.t, self.t_lo, self.t_hi, self.t2, self.t2_lo, self.t2_hi, self.spin)


def chebyshev(lo: np.ndarray, hi: np.ndarray, N: int) -> np.ndarray:
    """N Chebyshev nodes of each [lo, hi] (rows), decreasing, clamped inside (the kernel checks they are distinct)."""
    mid = 0.5 * lo + 0.5 * hi
    t = mid[:, None] + (hi - mid)[:, None] * np.cos(np.pi * (2 * np.arange(N) + 1) / (2 * N))[None, :]
    return np.clip(t, lo[:, None], hi[:, None])


def u_interval(w1: np.ndarray, w2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """[u_lo, u_hi] holding 1 / omega^2 for omega between w1 and w2 (one sign), rounded outward."""
    near, far = np.minimum(np.abs(w1), np.abs(w2)), np.maximum(np.abs(w1), np.abs(w2))
    return _outward(1.0 / (far * far), -np.inf, 3), _outward(1.0 / (near * near), np.inf, 3)


def _outward(x: np.ndarray, direction: float, steps: int = 2) -> np.ndarray:
    """x moved ``steps`` floats towards ``direction``, except exact zeros (which stay exact)."""
    for _ in range(steps):
        x = np.where(x != 0.0, np.nextafter(x, direction), x)
    return x


def _no_second(npts: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """t2, t2_lo, t2_hi of boxes along one parameter: one node at 0."""
    return np.zeros((npts, 1)), np.zeros(npts), np.zeros(npts)


def spin_scaled(box, w1: np.ndarray, w2: np.ndarray, names: np.ndarray | None = None) -> NodeBoxes:
    """The plain boxes ``box`` (``boxes.BoxArrays``) in the spin-scaled model: u = 1 / omega^2 at n + 1 nodes, the
    other parameters within their radii at every node.  omega runs between the corners' w1 and w2 (one sign).
    The stiffness is handed over at u = 1: the kernel forms its products with the nodes exactly (``spin``)."""
    m = box.mid
    u_lo, u_hi = u_interval(w1, w2)
    n = m.body.shape[1]
    u = chebyshev(u_lo, u_hi, n + 1)

    def at_nodes(x: np.ndarray) -> np.ndarray:
        return x[:, None].repeat(n + 1, axis=1)

    body, rbody = at_nodes(m.body), at_nodes(box.rbody)
    body[..., layout.OMEGA], rbody[..., layout.OMEGA] = 1.0, 0.0
    return NodeBoxes(body, rbody, at_nodes(m.joint), at_nodes(box.rjoint), at_nodes(m.g), at_nodes(box.rg), at_nodes(m.at),
                     at_nodes(box.rat), m.E, m.kappa, m.nmodes, m.free, m.parent, u, u_lo, u_hi, *_no_second(u.shape[0]), spin=True,
                     axis1=names)


LENGTHS = {"c", "s", "at"}  # entries of P quadratic in them (M = J^T diag(m) J, J linear in the lengths)
RANK_ONE = {"A", "C", "K"}  # one body's (one joint's): they move one row of P, or one rank-one term of it


def degree(scene: Scene, key: str) -> int:
    """A bound on the degree of p in the mechanical parameter ``key`` (module docstring): 2n in a length, 1 in one
    body's A or C or one joint's K, n in the others (a mass, g, or a column or joint set for all at once)."""
    name = parse_name(key, scene.n, scene.support)
    if name.symbol in LENGTHS:
        return 2 * scene.n
    if name.kind in ("body", "joint") and name.symbol in RANK_ONE:
        return 1
    return scene.n


def copies(pts: PointArrays, lo: PointArrays, hi: PointArrays, sel: np.ndarray, grid: dict[str, np.ndarray],
            ranges: dict[str, tuple[np.ndarray, np.ndarray]], spin: bool) -> np.ndarray:
    """Which boxes ``sel`` have every input that moves equal to one axis's value, at both corners and at every node.

    ``pts``: the inputs at the nodes, (sel, nodes) flattened; ``grid[axis]`` (sel, nodes) the axis's value at each.
    The spin column is left out where the spin-scaled model replaces it (``spin``).
    """
    nodes = next(iter(grid.values())).shape[1]
    ok = np.ones(sel.size, dtype=bool)
    for name in ("body", "joint", "g", "at"):
        x, a, b = getattr(pts, name), getattr(lo, name)[sel], getattr(hi, name)[sel]
        if name == "body" and spin:
            x, a, b = x[..., :5], a[..., :5], b[..., :5]
        x = x.reshape(sel.size, nodes, -1)
        low, high = np.minimum(a, b).reshape(sel.size, 1, -1), np.maximum(a, b).reshape(sel.size, 1, -1)
        each = (low == high) & (x == low)
        for axis, values in grid.items():
            t_lo, t_hi = (r[:, None, None] for r in ranges[axis])
            each |= (low == t_lo) & (high == t_hi) & (x == values[:, :, None])
        ok &= each.all(axis=(1, 2))
    return ok


def mechanical(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray], lo: PointArrays, hi: PointArrays,
               sel: np.ndarray, axes: tuple[str, ...], spin: bool = False, spin_names: np.ndarray | None = None
               ) -> tuple[np.ndarray, NodeBoxes | None]:
    """Node boxes of the boxes ``sel`` that move the mechanical ``axes`` (one or two) and nothing else but, with
    ``spin``, the one spin rate of every body: those among them whose moving inputs are copies (``copies``).

    ``degree(axis) + 1`` nodes per mechanical axis; with ``spin`` the first grid axis is u = 1 / omega^2 at n + 1
    nodes (module docstring); ``spin_names``: the spin axis each box of ``sel`` moves.  Returns the rows kept and
    their boxes (None if none is kept).
    """
    if sel.size == 0:
        return sel, None
    ranges = {a: (np.minimum(lower[a][sel], upper[a][sel]), np.maximum(lower[a][sel], upper[a][sel])) for a in axes}
    nodes = {a: chebyshev(*ranges[a], degree(scene, a) + 1) for a in axes}
    # the mechanical grid, the first axis slowest: node i N_b + j at (nodes[a][i], nodes[b][j])
    if len(axes) == 1:
        grid = nodes
    else:
        a, b = axes
        grid = {a: np.repeat(nodes[a], nodes[b].shape[1], axis=1), b: np.tile(nodes[b], (1, nodes[a].shape[1]))}
    count = grid[axes[0]].shape[1]
    values = {k: np.repeat(lower[k][sel], count) for k in lower}
    values.update({k: v.ravel() for k, v in grid.items()})
    pts = point_arrays(scene, values)
    keep = copies(pts, lo, hi, sel, grid, ranges, spin)
    if not keep.any():
        return sel[:0], None

    def by_node(x: np.ndarray) -> np.ndarray:
        return x.reshape((sel.size, count) + x.shape[1:])[keep]

    body, joint, g, at = by_node(pts.body), by_node(pts.joint), by_node(pts.g), by_node(pts.at)
    sel = sel[keep]
    E, kappa = lo.E[sel], lo.kappa[sel]
    if not spin:
        second = (nodes[axes[1]][keep], ranges[axes[1]][0][keep], ranges[axes[1]][1][keep]) if len(axes) == 2 else _no_second(sel.size)
        t, t_lo, t_hi = nodes[axes[0]][keep], ranges[axes[0]][0][keep], ranges[axes[0]][1][keep]
        rbody, rjoint, rg, rat = (np.zeros_like(x) for x in (body, joint, g, at))
        names = [np.full(sel.size, a, dtype=object) for a in axes]
        return sel, NodeBoxes(body, rbody, joint, rjoint, g, rg, at, rat, E, kappa, pts.nmodes, pts.free, pts.parent, t, t_lo, t_hi,
                              *second, axis1=names[0], axis2=names[1] if len(axes) == 2 else None)
    # spin-scaled: at node (u_i, t_j) the inputs at t_j with every spin 1 and the stiffness (joints, g) times u_i,
    # the product formed by the kernel (``spin``)
    u_lo, u_hi = u_interval(lo.body[sel, 0, layout.OMEGA], hi.body[sel, 0, layout.OMEGA])
    n = scene.n
    u = chebyshev(u_lo, u_hi, n + 1)

    def tensor(x: np.ndarray) -> np.ndarray:
        """(sel, count, ...) at the mechanical nodes -> (sel, (n + 1) count, ...), the u axis slowest."""
        return np.repeat(x[:, None], n + 1, axis=1).reshape((sel.size, (n + 1) * count) + x.shape[2:])

    body, joint, g, at = tensor(body), tensor(joint), tensor(g), tensor(at)
    body[..., layout.OMEGA] = 1.0
    (axis,) = axes
    zeros = [np.zeros_like(x) for x in (body, joint, g, at)]
    return sel, NodeBoxes(body, zeros[0], joint, zeros[1], g, zeros[2], at, zeros[3], E, kappa, pts.nmodes, pts.free,
                          pts.parent, u, u_lo, u_hi, nodes[axis][keep], ranges[axis][0][keep], ranges[axis][1][keep], spin=True,
                          axis1=None if spin_names is None else spin_names[keep], axis2=np.full(sel.size, axis, dtype=object))
