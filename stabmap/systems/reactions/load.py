"""A scene and the values of its grid axes -> node positions and the load (F, M) at every point, as arrays.

The load of a ``[body]`` is d'Alembert's: the weight and the inertia forces of a rigid body of mass m, centre of
mass c and inertia tensor I (about c), whose frame (the nodes' frame) moves with origin acceleration a, angular
velocity omega and angular acceleration alpha, every vector in that frame:

    a_c = a + alpha x c + omega x (omega x c)             acceleration of the centre of mass
    F   = m (g - a_c)                                     weight and inertia force
    M   = c x F - (I alpha + omega x I omega)             about the nodes' origin (Euler's inertia torque)

and the whole load is multiplied by ``load_factor``.
"""

from __future__ import annotations

import numpy as np

from .scene import Scene, angles


def _shape(values: dict[str, np.ndarray]) -> tuple[int, ...]:
    return np.broadcast_shapes(*(np.shape(v) for v in values.values())) if values else ()


def node_positions(scene: Scene, values: dict[str, np.ndarray]) -> np.ndarray:
    """Node positions of shape L + (n, 3), L the broadcast shape of the scanned node coordinates only (() if none):
    a grid over the load alone has one layout, factored once."""
    scanned = {name: v for name, v in values.items() if scene.key(name)[0] == "node"}
    base = np.array(scene.nodes, dtype=np.float64)
    if not scanned:
        return base
    out = np.array(np.broadcast_to(base, _shape(scanned) + base.shape))
    for name, v in scanned.items():
        _, k, d = scene.key(name)
        out[..., k, d] = v
    return out


def vector(scene: Scene, prefix: str, values: dict[str, np.ndarray]) -> np.ndarray:
    """One of the scene's vectors (``F``, ``c``, ``omega``, ...) at every point: shape S' + (3,), S' broadcasting to S.

    Scanned components replace the scene's; scanned angles turn it, its magnitude kept.
    """
    base = np.array(scene.vectors[prefix], dtype=np.float64)
    keys = {name: scene.key(name) for name in values}
    parts = {key[2]: np.asarray(values[name], dtype=np.float64) for name, key in keys.items() if key[:2] in (("vector", prefix), ("angle", prefix))}
    if not parts:
        return base
    if "azimuth" in parts or "elevation" in parts:
        azimuth, elevation = angles(base)
        az = np.radians(parts.get("azimuth", azimuth))
        el = np.radians(parts.get("elevation", elevation))
        size = np.linalg.norm(base)
        return size * np.stack(np.broadcast_arrays(np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)), axis=-1)
    shape = np.broadcast_shapes(*(np.shape(v) for v in parts.values()))
    out = np.array(np.broadcast_to(base, shape + (3,)))
    for d, v in parts.items():
        out[..., d] = v
    return out


def load(scene: Scene, values: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """F [N] and M [N m] about the nodes' origin at every point, shapes broadcasting to S + (3,)."""
    factor = np.asarray(values.get("load_factor", scene.load_factor), dtype=np.float64)[..., None]
    if scene.load is not None:
        return factor * vector(scene, "F", values), factor * vector(scene, "M", values)
    b = scene.body
    assert b is not None  # the scene's own check: a load or a body
    m = np.asarray(values.get("mass", b.mass), dtype=np.float64)[..., None]
    c, g, a, omega, alpha = (vector(scene, p, values) for p in ("c", "g", "a", "omega", "alpha"))
    I = np.array(b.inertia, dtype=np.float64)
    a_c = a + np.cross(alpha, c) + np.cross(omega, np.cross(omega, c))
    F = m * (g - a_c)
    torque = np.einsum("ij,...j->...i", I, alpha) + np.cross(omega, np.einsum("ij,...j->...i", I, omega))
    M = np.cross(c, F) - torque
    return factor * F, factor * M
