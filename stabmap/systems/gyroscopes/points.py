"""Turn a scene and a block of its grid into the kernels' plain per-point arrays."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import liquid, topology
from .parameters import BODY_COLUMNS, SCANNABLE_CAVITY, parse_name
from .scene import Scene


@dataclass
class PointArrays:
    """Arguments of ``kernels.count_block`` for npts points (layout: kernels/charpoly.py).

    Bodies are in the kernels' regular numbering (``topology.kernel_layout``).
    Without ``parent`` and ``at`` the bodies form a chain: parent[k] = k - 1 and
    at[:, k] = s of body k - 1.
    """

    body: np.ndarray  # (npts, n, 6)
    joint: np.ndarray  # (npts, n): the joint of body k with its parent; a chain: K_0, K_1..K_{n-1}
    g: np.ndarray  # (npts,)
    E: np.ndarray  # (npts, n, Lmax)
    kappa: np.ndarray  # (npts, n, Lmax)
    nmodes: np.ndarray  # (n,) int64
    free: bool
    parent: np.ndarray | None = None  # (n,) int64: parent[0] = -1, 0 <= parent[k] < k
    at: np.ndarray | None = None  # (npts, n): position of each joint on the parent's axis

    def __post_init__(self):
        npts, n = self.body.shape[:2]
        if self.parent is None:
            self.parent = np.arange(-1, n - 1, dtype=np.int64)
        if self.at is None:
            self.at = chain_positions(self.body)
        if self.parent.shape != (n,) or self.at.shape != (npts, n):
            raise ValueError(f"parent must have shape ({n},) and at ({npts}, {n})")

    def kernel_args(self):
        return self.body, self.joint, self.g, self.E, self.kappa, self.nmodes, self.free, self.parent, self.at


def chain_positions(body: np.ndarray) -> np.ndarray:
    """Joint positions ``at`` (..., n) of a chain from the bodies' s: at_k = s_{k-1}, at_0 = 0."""
    at = np.zeros(body.shape[:-1])
    at[..., 1:] = body[..., :-1, 4]
    return at


def base_arrays(scene: Scene):
    """Parameter arrays of the scene with no grid axis applied (body, joint, g, E, kappa), in scene order."""
    n = scene.n
    body = np.empty((n, 6))
    for k, b in enumerate(scene.bodies):
        omega = b.omega if b.omega is not None else scene.omega
        body[k] = (b.m, b.A, b.C, b.c, b.s, 0.0 if omega is None else omega)
    joint = np.array((scene.K_0,) + scene.joint_stiffness(), dtype=np.float64)
    lmax = max(1, int(scene.nmodes.max()))
    E = np.zeros((n, lmax))
    kappa = np.ones((n, lmax))
    for k, b in enumerate(scene.bodies):
        E[k, : len(b.E)] = b.E
        kappa[k, : len(b.kappa)] = b.kappa
    return body, joint, float(scene.g), E, kappa


def point_arrays(scene: Scene, values: dict[str, np.ndarray]) -> PointArrays:
    """Per-point arrays for points given by grid-axis values (arrays broadcast together, C order)."""
    body0, joint0, g0, E0, kappa0 = base_arrays(scene)
    arrays = {name: np.asarray(v, dtype=np.float64) for name, v in values.items()}
    shape = np.broadcast_shapes(*(a.shape for a in arrays.values())) if arrays else ()
    npts = int(np.prod(shape, dtype=np.int64))
    body = np.broadcast_to(body0, shape + body0.shape).copy()
    joint = np.broadcast_to(joint0, shape + joint0.shape).copy()
    tree = scene.topology
    at = np.broadcast_to(np.asarray(tree.at if tree else np.zeros(scene.n), dtype=np.float64), shape + (scene.n,)).copy()
    g = np.full(shape, g0)
    own_omega = [b.omega is not None for b in scene.bodies]
    names = {key: parse_name(key, scene.n, scene.support) for key in arrays}
    # Axes common to every body or joint first, so that an axis of one body or joint (omega_2, C_2, K_1) wins there.
    common = {"omega", "every_body", "every_joint"}
    for key in sorted(arrays, key=lambda key: key not in common and names[key].kind not in common):
        value, name = arrays[key], names[key]
        if name.kind == "global" and name.symbol == "g":
            g[...] = value
        elif name.kind == "global":
            for k in range(scene.n):
                if not own_omega[k]:
                    body[..., k, 5] = value
        elif name.kind == "every_body":
            body[..., BODY_COLUMNS.index(name.symbol)] = value[..., None]
        elif name.kind == "every_joint":
            joint[..., 1:] = value[..., None]
        elif name.kind == "joint":
            joint[..., name.index] = value
        elif name.kind == "body":
            body[..., name.index - 1, BODY_COLUMNS.index(name.symbol)] = value
        elif name.kind == "position":
            at[..., name.index - 1] = value
    E = np.broadcast_to(E0, shape + E0.shape)
    kappa = np.broadcast_to(kappa0, shape + kappa0.shape)
    if any(b.cavity is not None for b in scene.bodies):
        E, kappa = E.copy(), kappa.copy()
        for k, b in enumerate(scene.bodies):
            if b.cavity is None:
                continue
            sizes = {}
            if b.cavity.geometric:
                sizes = {key: np.broadcast_to(arrays.get(f"{key}_{k + 1}", getattr(b.cavity, key)), shape) for key in SCANNABLE_CAVITY}
            # Modes after the explicit fluid modes; apply() also updates the body's columns in place.
            Ek, kappak = liquid.apply(b.cavity, body[..., k, :], sizes)
            first = len(b.E)
            E[..., k, first : first + Ek.shape[-1]] = Ek
            kappa[..., k, first : first + Ek.shape[-1]] = kappak
    if tree is None:
        at = chain_positions(body)
        order, parent = np.arange(scene.n), np.arange(-1, scene.n - 1, dtype=np.int64)
    else:
        order, parent = topology.kernel_layout(tree.parent)

    def kernel_order(x: np.ndarray) -> np.ndarray:
        """Bodies (axis 1) in the kernels' regular numbering: the scene's own unless it numbers a tree otherwise."""
        return x if np.array_equal(order, np.arange(scene.n)) else np.ascontiguousarray(x[:, order])

    return PointArrays(
        body=kernel_order(body.reshape(npts, scene.n, 6)),
        joint=kernel_order(joint.reshape(npts, scene.n)),
        g=g.reshape(npts),
        E=kernel_order(np.ascontiguousarray(E.reshape((npts,) + E0.shape))),
        kappa=kernel_order(np.ascontiguousarray(kappa.reshape((npts,) + kappa0.shape))),
        nmodes=scene.nmodes[order],
        free=scene.free,
        parent=parent,
        at=kernel_order(at.reshape(npts, scene.n)),
    )


@dataclass
class BoxArrays:
    """Boxes of parameter points for ``kernels.box_block``: midpoints (``mid``) and radii of body, joint, g and at.

    Every point of box p lies within ``rbody[p]``, ``rjoint[p]``, ``rg[p]`` and ``rat[p]`` of ``mid``'s point p,
    slot by slot; E and kappa are the same at every point of the box.
    """

    mid: PointArrays
    rbody: np.ndarray  # (npts, n, 6)
    rjoint: np.ndarray  # (npts, n)
    rg: np.ndarray  # (npts,)
    rat: np.ndarray  # (npts, n)
    # the spin-scaled boxes (``spin_scaled``): u = 1 / omega^2 in [u_lo, u_hi], the spin column 1; NaN elsewhere
    u_lo: np.ndarray  # (npts,)
    u_hi: np.ndarray  # (npts,)

    def take(self, rows: np.ndarray) -> BoxArrays:
        m = self.mid
        mid = PointArrays(body=m.body[rows], joint=m.joint[rows], g=m.g[rows], E=m.E[rows], kappa=m.kappa[rows],
                          nmodes=m.nmodes, free=m.free, parent=m.parent, at=m.at[rows])
        return BoxArrays(mid, *(getattr(self, f)[rows] for f in ("rbody", "rjoint", "rg", "rat", "u_lo", "u_hi")))

    def kernel_args(self):
        """Arguments of ``kernels.box_block``, and with u_lo and u_hi of ``kernels.spin_box_block``."""
        m = self.mid
        return (m.body, self.rbody, m.joint, self.rjoint, m.g, self.rg, m.E, m.kappa, m.nmodes, m.free, m.parent, m.at, self.rat)


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


def spin_scaled(lo: PointArrays, hi: PointArrays) -> tuple[np.ndarray, np.ndarray]:
    """(u_lo, u_hi) of the boxes that every body spins through at one rate omega, not through 0; NaN elsewhere.

    With lambda = omega mu, Phi(omega mu) = omega^2 Phi_1(mu) with Phi_1 the characteristic matrix at unit spin
    whose stiffness is K / omega^2 (docs/model.md: M, G, the liquid terms and the poles all scale with omega),
    and Q_k(omega mu) = omega^L_k Q_k^(1)(mu).  So p(omega mu; omega) = omega^D p_1(mu; u), u = 1 / omega^2,
    whose real roots (with multiplicity) are those of p: N_c is the same.  The interval of u is rounded outward,
    and the spin column of those rows of ``lo`` and ``hi`` (the corners' kernel inputs) is set to 1 in place.
    """
    w_lo = np.minimum(lo.body[..., 5], hi.body[..., 5])
    w_hi = np.maximum(lo.body[..., 5], hi.body[..., 5])
    one_rate = np.all(w_lo == w_lo[:, :1], axis=1) & np.all(w_hi == w_hi[:, :1], axis=1)
    rows = np.flatnonzero(one_rate & (w_lo[:, 0] != w_hi[:, 0]) & ((w_lo[:, 0] > 0.0) | (w_hi[:, 0] < 0.0)))
    u_lo, u_hi = np.full(w_lo.shape[0], np.nan), np.full(w_lo.shape[0], np.nan)
    near = np.minimum(np.abs(w_lo[rows, 0]), np.abs(w_hi[rows, 0]))
    far = np.maximum(np.abs(w_lo[rows, 0]), np.abs(w_hi[rows, 0]))
    u_lo[rows], u_hi[rows] = _outward(1.0 / (far * far), -np.inf, 3), _outward(1.0 / (near * near), np.inf, 3)
    lo.body[rows, :, 5] = hi.body[rows, :, 5] = 1.0
    return u_lo, u_hi


def box_arrays(scene: Scene, lower: dict[str, np.ndarray], upper: dict[str, np.ndarray]) -> BoxArrays:
    """Boxes with corners ``lower`` and ``upper`` (grid-axis values, arrays that broadcast together).

    Axes missing from both are fixed at the scene's values; an axis with lower == upper is a point.  Raises
    ValueError for an axis outside ``box_axes`` whose two corners differ.
    """
    if set(lower) != set(upper):
        raise ValueError("lower and upper must name the same axes")
    for key, spans in unenclosed(scene, lower, upper).items():
        if np.any(spans):
            raise ValueError(f"a box cannot be enclosed along {key!r} (box_axes)")
    lo, hi = point_arrays(scene, lower), point_arrays(scene, upper)
    if not (np.array_equal(lo.E, hi.E) and np.array_equal(lo.kappa, hi.kappa)):  # pragma: no cover - box_axes rules it out
        raise ValueError("the liquid modes differ across the box")
    u_lo, u_hi = spin_scaled(lo, hi)
    body, rbody = _hull(lo.body, hi.body)
    joint, rjoint = _hull(lo.joint, hi.joint)
    g, rg = _hull(lo.g, hi.g)
    at, rat = _hull(lo.at, hi.at)
    mid = PointArrays(body=body, joint=joint, g=g, E=lo.E, kappa=lo.kappa, nmodes=lo.nmodes, free=lo.free, parent=lo.parent, at=at)
    return BoxArrays(mid, rbody, rjoint, rg, rat, u_lo, u_hi)
