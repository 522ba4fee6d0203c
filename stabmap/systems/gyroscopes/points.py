"""Turn a scene and a block of its grid into the kernels' plain per-point arrays."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...kernels import layout
from . import liquid, ratios, topology
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
    # Given as None, these two are the chain's and filled in by __post_init__: never None afterwards.
    parent: np.ndarray = None  # (n,) int64: parent[0] = -1, 0 <= parent[k] < k
    at: np.ndarray = None  # (npts, n): position of each joint on the parent's axis

    def __post_init__(self):
        npts, n = self.body.shape[:2]
        if self.parent is None:
            self.parent = np.arange(-1, n - 1, dtype=np.int64)
        if self.at is None:
            self.at = chain_positions(self.body)
        if self.parent.shape != (n,) or self.at.shape != (npts, n):
            raise ValueError(f"parent must have shape ({n},) and at ({npts}, {n})")

    def kernel_args(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool, np.ndarray, np.ndarray]:
        return self.body, self.joint, self.g, self.E, self.kappa, self.nmodes, self.free, self.parent, self.at

    def take(self, rows: np.ndarray) -> PointArrays:
        """The points ``rows`` of this block, in that order (the per-point arrays indexed, the shared ones kept)."""
        return PointArrays(self.body[rows], self.joint[rows], self.g[rows], self.E[rows], self.kappa[rows], self.nmodes,
                           self.free, self.parent, self.at[rows])


def chain_positions(body: np.ndarray) -> np.ndarray:
    """Joint positions ``at`` (..., n) of a chain from the bodies' s: at_k = s_{k-1}, at_0 = 0."""
    at = np.zeros(body.shape[:-1])
    at[..., 1:] = body[..., :-1, layout.S]
    return at


def base_arrays(scene: Scene):
    """Parameter arrays of the scene with no grid axis applied (body, joint, g, E, kappa), in scene order."""
    n = scene.n
    body = np.empty((n, 6))
    for k, b in enumerate(scene.bodies):
        omega = b.omega if b.omega is not None else scene.omega
        body[k] = (b.m, b.A, b.C, b.c, b.s, 0.0 if omega is None else omega)
    # M_alpha overturns body 1 about the fixed point at its centre of mass: -M_alpha at (1, 1) of the stiffness,
    # where a base stiffness K_0 would go (the scene refuses the two together); the negation is exact.
    base = scene.K_0 if scene.M_alpha is None else -scene.M_alpha
    joint = np.array((base,) + scene.joint_stiffness(), dtype=np.float64)
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
    arrays = {name: np.asarray(v, dtype=np.float64) for name, v in ratios.underlying(scene, values).items()}
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
                    body[..., k, layout.OMEGA] = value
        elif name.kind == "every_body":
            body[..., BODY_COLUMNS.index(name.symbol)] = value[..., None]
        elif name.kind == "every_joint":
            joint[..., 1:] = value[..., None]
        elif name.kind == "joint":
            joint[..., name.index] = value
        elif name.kind == "projectile":  # M_alpha; S_g was turned into what it moves (ratios.underlying)
            joint[..., 0] = -value
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
