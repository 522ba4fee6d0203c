"""Boxes of parameter points for the box kernels: enclosures that hold every point of a box.

A box moves some grid axes over closed intervals and fixes the others.  Three ways to hand it to the kernels,
the narrowest first (docs/certification.md, section 6):

- **spin-scaled** (``kernels.nodes_box_block``): every body spins at one rate omega that the box moves, not
  through 0.  With lambda = omega mu, p(omega mu; omega) = omega^D p_1(mu; u), u = 1 / omega^2, p_1 the
  polynomial at unit spin with the stiffness (joints and gravity) times u: the same real roots.  Each row of
  P is affine in u, so p_1 is a polynomial of degree <= n in u, enclosed at n + 1 nodes.
- **one mechanical axis** (``kernels.nodes_box_block``): the box moves one axis whose kernel inputs are copies
  of its value (a mass, inertia, length, stiffness or g).  Every row of P is a polynomial of degree <= 2 in it
  (M = diag(A) + J^T diag(m) J, J linear in lengths), so p has degree <= 2n: 2n + 1 nodes.  Not a mass of a
  free system (it divides by the total mass).
- **plain** (``kernels.box_block``): the hull of the corners' inputs, as intervals.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .parameters import parse_name
from .points import PointArrays, point_arrays
from .scene import Scene

ROUNDING = 2.0**-52  # relative bound of one rounding, with a factor 2 of margin
TINY = 2.0**-1074


@dataclass
class BoxArrays:
    """Boxes for ``kernels.box_block``: midpoints (``mid``) and radii of body, joint, g and at.

    Every point of box p lies within ``rbody[p]``, ``rjoint[p]``, ``rg[p]`` and ``rat[p]`` of ``mid``'s point p,
    slot by slot; E and kappa are the same at every point of the box.
    """

    mid: PointArrays
    rbody: np.ndarray  # (npts, n, 6)
    rjoint: np.ndarray  # (npts, n)
    rg: np.ndarray  # (npts,)
    rat: np.ndarray  # (npts, n)

    def take(self, rows: np.ndarray) -> BoxArrays:
        m = self.mid
        mid = PointArrays(body=m.body[rows], joint=m.joint[rows], g=m.g[rows], E=m.E[rows], kappa=m.kappa[rows],
                          nmodes=m.nmodes, free=m.free, parent=m.parent, at=m.at[rows])
        return BoxArrays(mid, self.rbody[rows], self.rjoint[rows], self.rg[rows], self.rat[rows])

    def kernel_args(self):
        m = self.mid
        return (m.body, self.rbody, m.joint, self.rjoint, m.g, self.rg, m.E, m.kappa, m.nmodes, m.free, m.parent, m.at, self.rat)


@dataclass
class NodeBoxes:
    """Boxes for ``kernels.nodes_box_block``: the kernel inputs at N nodes t of each box's main parameter.

    ``body``, ``joint``, ``g``, ``at`` and their radii have a node axis after the box axis; t (npts, N) holds the
    nodes, distinct and decreasing, inside [t_lo, t_hi].
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

    def kernel_args(self):
        return (self.body, self.rbody, self.joint, self.rjoint, self.g, self.rg, self.E, self.kappa, self.nmodes, self.free,
                self.parent, self.at, self.rat, self.t, self.t_lo, self.t_hi)


def box_axes(scene: Scene) -> set[str]:
    """The grid axes along which a box can be enclosed: all but those whose kernel inputs are not monotone in them.

    Every kernel input is then a copy of one scanned value, or that value minus a constant (a cavity's tail),
    so the inputs at a box's two corners bound the inputs at every point of it.  Not enclosed: a cavity's size
    or density (the modes depend on them), and a column (m, A, C, c) of a body whose cavity's liquid stabmap
    adds (liquid_in_body = false: the frozen liquid moves the centre of mass with them).
    """
    out = set()
    for axis in scene.grid:
        name = parse_name(axis.name, scene.n, scene.support)
        if name.kind == "cavity":
            continue
        if name.kind in ("body", "every_body") and name.symbol != "omega":
            bodies = [scene.bodies[name.index - 1]] if name.kind == "body" else scene.bodies
            if any(b.cavity is not None and b.cavity.geometric and not b.cavity.liquid_in_body for b in bodies):
                continue
        out.add(axis.name)
    return out


def unenclosed(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """For each axis outside ``box_axes``: which boxes span it (their two corners differ there)."""
    allowed = box_axes(scene)
    return {key: np.asarray(lower[key]) != np.asarray(upper[key]) for key in lower if key not in allowed}


def _hull(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Midpoint and radius of a float ball holding [min(a, b), max(a, b)] widened by one ulp each side.

    The widening covers a value computed from the scanned one with one rounding (a cavity's tail subtracted
    from A): the real value at an interior point lies within an ulp of the rounded corners' hull.
    """
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    moved = lo != hi
    lo = np.where(moved, np.nextafter(lo, -np.inf), lo)
    hi = np.where(moved, np.nextafter(hi, np.inf), hi)
    mid = np.where(moved, 0.5 * lo + 0.5 * hi, lo)
    rad = np.where(moved, np.nextafter(np.maximum(hi - mid, mid - lo), np.inf), 0.0)
    return mid, rad


def _outward(x: np.ndarray, direction: float, steps: int = 2) -> np.ndarray:
    """x moved ``steps`` floats towards ``direction``, except exact zeros (which stay exact)."""
    for _ in range(steps):
        x = np.where(x != 0.0, np.nextafter(x, direction), x)
    return x


def _corners(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]) -> tuple[PointArrays, PointArrays]:
    """The kernel inputs at the two corners of the boxes; ValueError for a box that spans an axis outside box_axes."""
    if set(lower) != set(upper):
        raise ValueError("lower and upper must name the same axes")
    for key, spans in unenclosed(scene, lower, upper).items():
        if np.any(spans):
            raise ValueError(f"a box cannot be enclosed along {key!r} (box_axes)")
    lo, hi = point_arrays(scene, lower), point_arrays(scene, upper)
    if not (np.array_equal(lo.E, hi.E) and np.array_equal(lo.kappa, hi.kappa)):  # pragma: no cover - box_axes rules it out
        raise ValueError("the liquid modes differ across the box")
    return lo, hi


def _plain(lo: PointArrays, hi: PointArrays) -> BoxArrays:
    body, rbody = _hull(lo.body, hi.body)
    joint, rjoint = _hull(lo.joint, hi.joint)
    g, rg = _hull(lo.g, hi.g)
    at, rat = _hull(lo.at, hi.at)
    mid = PointArrays(body=body, joint=joint, g=g, E=lo.E, kappa=lo.kappa, nmodes=lo.nmodes, free=lo.free, parent=lo.parent, at=at)
    return BoxArrays(mid, rbody, rjoint, rg, rat)


def box_arrays(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]) -> BoxArrays:
    """The plain enclosure of boxes with corners ``lower`` and ``upper`` (grid-axis values, arrays that broadcast
    together).  Axes missing from both are fixed at the scene's values; an axis with lower == upper is a point.
    Raises ValueError for an axis outside ``box_axes`` whose two corners differ."""
    return _plain(*_corners(scene, lower, upper))


def _chebyshev(lo: np.ndarray, hi: np.ndarray, N: int) -> np.ndarray:
    """N Chebyshev nodes of each [lo, hi] (rows), decreasing, clamped inside (the kernel checks they are distinct)."""
    mid = 0.5 * lo + 0.5 * hi
    t = mid[:, None] + (hi - mid)[:, None] * np.cos(np.pi * (2 * np.arange(N) + 1) / (2 * N))[None, :]
    return np.clip(t, lo[:, None], hi[:, None])


def _times(x: np.ndarray, r: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A ball (midpoint, radius) holding (x +- r) u for floats u > 0 (broadcast); an exact zero stays exact."""
    m = x * u
    rad = np.abs(m) * ROUNDING + r * u * (1.0 + 2.0 * ROUNDING) + TINY
    return m, np.where((x == 0.0) & (r == 0.0), 0.0, rad)


def _spin_rows(lo: PointArrays, hi: PointArrays) -> np.ndarray:
    """Boxes that every body spins through at one rate omega, not through 0."""
    w_lo = np.minimum(lo.body[..., 5], hi.body[..., 5])
    w_hi = np.maximum(lo.body[..., 5], hi.body[..., 5])
    one_rate = np.all(w_lo == w_lo[:, :1], axis=1) & np.all(w_hi == w_hi[:, :1], axis=1)
    return np.flatnonzero(one_rate & (w_lo[:, 0] != w_hi[:, 0]) & ((w_lo[:, 0] > 0.0) | (w_hi[:, 0] < 0.0)))


def _spin_scaled(box: BoxArrays, w1: np.ndarray, w2: np.ndarray) -> NodeBoxes:
    """The plain boxes ``box`` in the spin-scaled model (module docstring): u = 1 / omega^2 at n + 1 nodes, the
    other parameters within their radii at every node.  omega runs between the corners' w1 and w2 (one sign)."""
    m = box.mid
    near, far = np.minimum(np.abs(w1), np.abs(w2)), np.maximum(np.abs(w1), np.abs(w2))
    u_lo, u_hi = _outward(1.0 / (far * far), -np.inf, 3), _outward(1.0 / (near * near), np.inf, 3)
    n = m.body.shape[1]
    u = _chebyshev(u_lo, u_hi, n + 1)

    def at_nodes(x: np.ndarray) -> np.ndarray:
        return x[:, None].repeat(n + 1, axis=1)

    body, rbody = at_nodes(m.body), at_nodes(box.rbody)
    body[..., 5], rbody[..., 5] = 1.0, 0.0
    joint, rjoint = _times(m.joint[:, None], box.rjoint[:, None], u[..., None])
    g, rg = _times(m.g[:, None], box.rg[:, None], u)
    return NodeBoxes(body, rbody, joint, rjoint, g, rg, at_nodes(m.at), at_nodes(box.rat), m.E, m.kappa, m.nmodes, m.free,
                     m.parent, u, u_lo, u_hi)


def _mechanical(scene: Scene, key: str) -> bool:
    """An axis whose inputs enter every row of P polynomially, with degree <= 2 (module docstring)."""
    name = parse_name(key, scene.n, scene.support)
    kinds = ("body", "every_body", "joint", "every_joint", "position", "global")
    return name.kind in kinds and name.symbol != "omega" and not (scene.free and name.symbol == "m")


def _one_axis(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray], lo: PointArrays, hi: PointArrays,
              rows: np.ndarray, axis: str) -> tuple[np.ndarray, NodeBoxes | None]:
    """The boxes among ``rows`` that move ``axis`` alone, with every moving input a copy of it: 2n + 1 nodes."""
    moves = {k: np.asarray(lower[k])[rows] != np.asarray(upper[k])[rows] for k in lower}
    sel = rows[moves[axis] & (sum(m.astype(int) for m in moves.values()) == 1)]
    t_lo = np.minimum(np.asarray(lower[axis])[sel], np.asarray(upper[axis])[sel])
    t_hi = np.maximum(np.asarray(lower[axis])[sel], np.asarray(upper[axis])[sel])
    if sel.size == 0:
        return sel, None
    # every input that moves must be the axis value itself at both corners (not, e.g., A minus a cavity's tail)
    copies = np.ones(sel.size, dtype=bool)
    for name in ("body", "joint", "g", "at"):
        a, b = getattr(lo, name)[sel], getattr(hi, name)[sel]
        shape = (-1,) + (1,) * (a.ndim - 1)
        low, high = np.minimum(a, b), np.maximum(a, b)
        ok = (low == high) | ((low == t_lo.reshape(shape)) & (high == t_hi.reshape(shape)))
        copies &= ok.reshape(sel.size, -1).all(axis=1)
    sel, t_lo, t_hi = sel[copies], t_lo[copies], t_hi[copies]
    if sel.size == 0:
        return sel, None
    N = 2 * scene.n + 1
    t = _chebyshev(t_lo, t_hi, N)
    values = {k: np.repeat(np.asarray(lower[k])[sel], N) for k in lower}
    values[axis] = t.ravel()
    pts = point_arrays(scene, values)

    def by_node(x: np.ndarray) -> np.ndarray:
        return x.reshape((sel.size, N) + x.shape[1:])

    arrays = [a for x in (pts.body, pts.joint, pts.g, pts.at) for a in (by_node(x), np.zeros_like(by_node(x)))]
    return sel, NodeBoxes(*arrays, lo.E[sel], lo.kappa[sel], pts.nmodes, pts.free, pts.parent, t, t_lo, t_hi)


def boxes(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]) -> list[tuple[np.ndarray, BoxArrays | NodeBoxes]]:
    """Every box with corners ``lower`` and ``upper`` in its narrowest enclosure (module docstring): (rows, boxes)
    pairs that together hold each box once.  Raises ValueError as ``box_arrays``."""
    lo, hi = _corners(scene, lower, upper)
    npts = lo.body.shape[0]
    plain = _plain(lo, hi)
    out = []
    spin = _spin_rows(lo, hi)
    if spin.size:
        out.append((spin, _spin_scaled(plain.take(spin), lo.body[spin, 0, 5], hi.body[spin, 0, 5])))
    rest = np.setdiff1d(np.arange(npts), spin)
    for axis in (k for k in lower if _mechanical(scene, k)):
        one, nodes = _one_axis(scene, lower, upper, lo, hi, rest, axis)
        if nodes is not None:
            out.append((one, nodes))
            rest = np.setdiff1d(rest, one)
    if rest.size:
        out.append((rest, plain.take(rest)))
    return out
