"""Boxes of parameter points for the box kernels: enclosures that hold every point of a box.

A box moves some grid axes over closed intervals and fixes the others.  Five ways to hand it to the kernels,
the narrowest first (docs/certification.md, section 6; the degree bounds in ``nodes``):

- **spin and one mechanical axis** (``kernels.nodes_box_block``): every body spins at the one rate omega of one
  grid axis, which the box moves, not through 0, and the box moves one more axis whose kernel inputs are copies
  of its value (a mass, inertia, length, stiffness or g).  With lambda = omega mu, p(omega mu; omega) =
  omega^D p_1(mu; u), u = 1 / omega^2, p_1 the polynomial at unit spin with the stiffness (joints and gravity)
  times u: the same real roots.  p_1 has degree <= n in u and at most ``nodes.degree`` in the axis (2n in a
  length, n in a mass or g, 1 in one body's A or C or one joint's K): the tensor grid of their nodes.
- **two mechanical axes**: the tensor grid of both axes' nodes.
- **spin-scaled**: the spin as above, other moving axes within their radii: n + 1 nodes in u.
- **one mechanical axis**: its degree + 1 nodes.  Not a mass of a free system (it divides by the total mass).
- **plain** (``kernels.box_block``): the hull of the corners' inputs, as intervals.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...kernels import layout
from .nodes import NodeBoxes, degree, mechanical, spin_scaled
from .parameters import parse_name
from .points import PointArrays, point_arrays
from .scene import Scene

__all__ = ["BoxArrays", "NodeBoxes", "box_arrays", "box_axes", "boxes", "unenclosed"]


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
        return BoxArrays(self.mid.take(rows), self.rbody[rows], self.rjoint[rows], self.rg[rows], self.rat[rows])

    def kernel_args(self):
        m = self.mid
        return (m.body, self.rbody, m.joint, self.rjoint, m.g, self.rg, m.E, m.kappa, m.nmodes, m.free, m.parent, m.at, self.rat)


def box_axes(scene: Scene) -> set[str]:
    """The grid axes along which a box can be enclosed: all but those whose kernel inputs are not monotone in them.

    Every kernel input is then a copy of one scanned value, or that value minus a constant (a cavity's tail), or
    rounded once from it (C = C/A times A, -M_alpha), so the inputs at a box's two corners bound the inputs at every
    point of it.  Not enclosed: a cavity's size
    or density (the modes depend on them), and a column (m, A, C, c) of a body whose cavity's liquid stabmap
    adds (liquid_in_body = false: the frozen liquid moves the centre of mass with them).
    """
    out = set()
    for axis in scene.grid:
        name = parse_name(axis.name, scene.n, scene.support)
        # An aspect ratio moves the modes, A = C / ratio takes two roundings with a cavity's tail, and S_g moving
        # M_alpha (hold.S_g = "omega") divides: nodes only.  C = ratio A (one rounding), -M_alpha (exact) and S_g
        # moving the spin (monotone; the corners widened by _spin_margin) are enclosed.
        if name.kind == "cavity" or name.symbol == "aspect" or (name.symbol == "C_over_A" and scene.hold.C_over_A == "C"):
            continue
        if name.symbol == "S_g" and (scene.hold.S_g != "M_alpha" or _spin_not_monotone(scene)):
            continue
        if name.kind in ("body", "every_body", "ratio") and name.symbol != "omega":
            bodies = [scene.bodies[name.index - 1]] if name.kind == "body" else scene.bodies
            if any(b.cavity is not None and b.cavity.geometric and not b.cavity.liquid_in_body for b in bodies):
                continue
        out.add(axis.name)
    return out


def _spin_not_monotone(scene: Scene) -> bool:
    """Whether a grid axis besides S_g moves body 1's A or C: omega = 2 sqrt(A M_alpha S_g) / C then falls along one
    axis of a box as it grows along S_g, and a box's corners no longer hold the spins inside it."""
    return bool({a.name for a in scene.grid} & {"A", "C", "A_1", "C_1", "C_over_A_1"})


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


def box_corners(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]) -> tuple[PointArrays, PointArrays]:
    """The kernel inputs at the two corners of the boxes; ValueError for a box that spans an axis outside box_axes."""
    if set(lower) != set(upper):
        raise ValueError("lower and upper must name the same axes")
    for key, spans in unenclosed(scene, lower, upper).items():
        if np.any(spans):
            raise ValueError(f"a box cannot be enclosed along {key!r} (box_axes)")
    lo, hi = point_arrays(scene, lower), point_arrays(scene, upper)
    _spin_margin(scene, lower, upper, lo, hi)
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
    return _plain(*box_corners(scene, lower, upper))


def spin_rows(scene: Scene, lo: PointArrays, hi: PointArrays, moves: dict[str, np.ndarray]) -> np.ndarray:
    """Boxes that every body spins through at one rate omega, not through 0: one spin axis moves, and every body's
    spin column with it (two spin axes over the same interval hold points where the bodies spin apart)."""
    spins = sum(moves[k].astype(int) for k in moves if is_spin(scene, k))
    w_lo = np.minimum(lo.body[..., layout.OMEGA], hi.body[..., layout.OMEGA])
    w_hi = np.maximum(lo.body[..., layout.OMEGA], hi.body[..., layout.OMEGA])
    one_rate = np.all(w_lo == w_lo[:, :1], axis=1) & np.all(w_hi == w_hi[:, :1], axis=1) & (spins == 1)
    return np.flatnonzero(one_rate & (w_lo[:, 0] != w_hi[:, 0]) & ((w_lo[:, 0] > 0.0) | (w_hi[:, 0] < 0.0)))


def is_spin(scene: Scene, key: str) -> bool:
    """omega, omega_k, and S_g where it moves the spin (``ratios``)."""
    symbol = parse_name(key, scene.n, scene.support).symbol
    return symbol == "omega" or (symbol == "S_g" and scene.hold.S_g == "M_alpha")


SPIN_MARGIN = 4  # floats: omega = 2 sqrt(A M_alpha S_g) / C rounds four times, each by half a float at most


def _spin_margin(scene: Scene, lower: dict, upper: dict, lo: PointArrays, hi: PointArrays) -> None:
    """Widen the corners' spins outward where a box moves S_g: omega(S_g) is increasing, so the spins of the box lie
    between the exact spins of its corners, each within SPIN_MARGIN floats of the rounded one."""
    if "S_g" not in lower:
        return
    npts = lo.body.shape[0]
    moves = np.broadcast_to(np.asarray(lower["S_g"]) != np.asarray(upper["S_g"]), (npts,))[:, None]
    w_lo, w_hi = lo.body[..., layout.OMEGA], hi.body[..., layout.OMEGA]
    moving = moves & (w_lo != w_hi)
    a, b = np.minimum(w_lo, w_hi), np.maximum(w_lo, w_hi)
    for _ in range(SPIN_MARGIN):
        a, b = np.nextafter(a, -np.inf), np.nextafter(b, np.inf)
    lo.body[..., layout.OMEGA], hi.body[..., layout.OMEGA] = np.where(moving, a, w_lo), np.where(moving, b, w_hi)


def is_mechanical(scene: Scene, key: str) -> bool:
    """An axis whose inputs enter every row of P polynomially, with degree <= 2 (``nodes``)."""
    name = parse_name(key, scene.n, scene.support)
    kinds = ("body", "every_body", "joint", "every_joint", "position", "global")
    return name.kind in kinds and name.symbol != "omega" and not (scene.free and name.symbol == "m")


def boxes(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]) -> list[tuple[np.ndarray, BoxArrays | NodeBoxes]]:
    """Every box with corners ``lower`` and ``upper`` in its narrowest enclosure (module docstring): (rows, boxes)
    pairs that together hold each box once.  Raises ValueError as ``box_arrays``."""
    lo, hi = box_corners(scene, lower, upper)
    npts = lo.body.shape[0]
    lower = {k: np.broadcast_to(np.asarray(v, dtype=np.float64), (npts,)) for k, v in lower.items()}
    upper = {k: np.broadcast_to(np.asarray(v, dtype=np.float64), (npts,)) for k, v in upper.items()}
    moves = {k: lower[k] != upper[k] for k in lower}
    others = sum((m.astype(int) for k, m in moves.items() if not is_spin(scene, k)), np.zeros(npts, dtype=int))
    mech = [k for k in lower if is_mechanical(scene, k)]
    plain = _plain(lo, hi)
    out: list[tuple[np.ndarray, BoxArrays | NodeBoxes]] = []

    spin_names = np.full(npts, None, dtype=object)  # the spin axis a box moves
    for k in lower:
        if is_spin(scene, k):
            spin_names[moves[k]] = k

    def route(rows: np.ndarray, axes: tuple[str, ...], spin: bool) -> np.ndarray:
        """Hand the boxes among ``rows`` that move exactly ``axes`` (besides the spin) to the node path; the rest."""
        sel = rows[np.all([moves[a][rows] for a in axes], axis=0) & (others[rows] == len(axes))]
        kept, nodes = mechanical(scene, lower, upper, lo, hi, sel, axes, spin, spin_names[sel])
        if nodes is not None:
            out.append((kept, nodes))
        return np.setdiff1d(rows, kept)

    spin = spin_rows(scene, lo, hi, moves)
    rest = spin
    for axis in mech:
        rest = route(rest, (axis,), True)
    if rest.size:
        out.append((rest, spin_scaled(plain.take(rest), lo.body[rest, 0, layout.OMEGA], hi.body[rest, 0, layout.OMEGA], spin_names[rest])))
    rest = np.setdiff1d(np.arange(npts), spin)
    for axis in mech:
        rest = route(rest, (axis,), False)
    for i, a in enumerate(mech):
        for b in mech[i + 1 :]:
            rest = route(rest, (a, b), False)
    if rest.size:
        out.append((rest, plain.take(rest)))
    return out


def box_cost(scene: Scene) -> float:
    """A box proof along the scene's scanned axes, in point proofs: its enclosure's nodes (n + 1 along the spin,
    ``nodes.degree`` + 1 along a mechanical axis, their product for two axes; plain: 1), each dearer than a point by a factor
    that grows with n: the box kernel expands the determinant's 2^n minors in intervals at every node, where a
    point reuses its neighbour's work or proves without coefficients.  1 + n/3 + 2^n/64, fitted to
    scripts/bench_cells.py (a box of two bodies costs about 23 points, of six about 270, of eight about 1400)."""
    n = scene.n
    per_axis = [n + 1 if is_spin(scene, a.name) else degree(scene, a.name) + 1 if is_mechanical(scene, a.name) else 1
                for a in scene.grid if a.continuous]
    nodes = float(np.prod(per_axis)) if len(per_axis) <= 2 else 1.0
    return nodes * (1.0 + n / 3.0 + 2.0**n / 64.0)
