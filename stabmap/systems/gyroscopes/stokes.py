"""Chernousko's viscous cavity tensor P¹ [m⁷]: closed forms for ellipsoids, a bundled table for the cylinder.

A cavity filled with a liquid of density rho and kinematic viscosity nu, at small Reynolds number, carries the
relative angular momentum lambda = -(rho / nu) P omega_dot + O(nu^-2) (Chernousko 1968). P depends only on the
cavity's shape and scales as length⁷. Definitions, derivations and the cylinder's accuracy: docs/viscous-tensors.md.
The cylinder table is written by scripts/cylinder_tensor.py (scikit-fem); this module only reads it.
"""

from __future__ import annotations

import functools
import math
import pathlib

import numpy as np
from scipy.interpolate import CubicSpline

from ...errors import StabmapError

SHAPES = ("spheroid", "cylinder")
_TABLE = pathlib.Path(__file__).with_name("data") / "cylinder_tensor.csv"


def ellipsoid_tensor(a1, a2, a3):
    """Diagonal (P_11, P_22, P_33) [m⁷] of the ellipsoid x²/a1² + y²/a2² + z²/a3² ≤ 1, semi-axes in [m].

    P_33 = (16 pi / 105) a1⁵ a2⁵ a3 / [S a1² a2² (a1² + a2²) + 2 (a1⁴ + a2⁴)], S = 1/a1² + 1/a2² + 1/a3², and the
    others by cyclic permutation. Broadcasts over numpy arrays.
    """
    a1, a2, a3 = (np.asarray(v, dtype=np.float64) for v in (a1, a2, a3))
    s = 1.0 / a1**2 + 1.0 / a2**2 + 1.0 / a3**2

    def entry(p, q, axial):  # the entry about the third axis, p and q the two across it
        return (16.0 * math.pi / 105.0) * p**5 * q**5 * axial / (s * p**2 * q**2 * (p**2 + q**2) + 2.0 * (p**4 + q**4))

    return entry(a2, a3, a1), entry(a3, a1, a2), entry(a1, a2, a3)


def spheroid_tensor(radius, half_height):
    """(P_t, P_a) [m⁷] of the spheroid with equatorial radius and polar half_height [m] (symmetry axis z)."""
    p11, _, p33 = ellipsoid_tensor(radius, radius, half_height)
    return p11, p33


def sphere_tensor(radius):
    """8 pi a⁷ / 525 [m⁷], the sphere's P (a multiple of the identity)."""
    return spheroid_tensor(radius, radius)[0]


@functools.cache
def _cylinder_table():
    """(q nodes, spline of log f_t, spline of log f_a, stated relative error) from the bundled table."""
    rel_error = None
    with _TABLE.open(encoding="utf-8") as fh:
        for line in fh:
            if line.startswith("# rel_error"):
                rel_error = float(line.split("=", 1)[1])
    data = np.loadtxt(_TABLE, delimiter=",", comments="#", usecols=(0, 1, 2), ndmin=2)
    logq = np.log(data[:, 0])
    return data[:, 0], CubicSpline(logq, np.log(data[:, 1])), CubicSpline(logq, np.log(data[:, 2])), rel_error


def cylinder_range() -> tuple[float, float]:
    """The aspect ratios half_height / radius the cylinder table covers."""
    q = _cylinder_table()[0]
    return float(q[0]), float(q[-1])


def cylinder_scaled(q):
    """(f_t(q), f_a(q), rel_error): P = radius⁷ f(q) for the cylinder of aspect ratio q = half_height / radius."""
    _, ft, fa, rel_error = _cylinder_table()
    q = np.asarray(q, dtype=np.float64)
    lq = np.log(q)
    return np.exp(ft(lq)), np.exp(fa(lq)), rel_error


def _check_size(radius, half_height):
    for name, value in (("radius", radius), ("half_height", half_height)):
        v = np.asarray(value, dtype=np.float64)
        if not np.all(np.isfinite(v)) or np.any(v <= 0):
            raise StabmapError(f"{name} must be finite and > 0 [m], got {value!r}")


def tensor(shape: str, radius, half_height):
    """(P_t, P_a, rel_error) of a spheroid or cylinder cavity, broadcast over numpy arrays.

    Parameters
    ----------
    shape : "spheroid" (equatorial ``radius``, polar ``half_height``) or "cylinder" (|z| ≤ half_height,
        r ≤ radius); z is the symmetry axis.
    radius, half_height : [m], finite and > 0.

    Returns
    -------
    P_t = P_11 = P_22 and P_a = P_33 [m⁷], and the stated relative accuracy of both (0 for the closed forms up to
    rounding; the cylinder's from its convergence study and interpolation, docs/viscous-tensors.md).
    """
    if shape not in SHAPES:
        raise StabmapError(f'shape: viscous cavity tensors know "spheroid" and "cylinder", got {shape!r}; give the '
                           "tensor directly instead (tensor = [P_t, P_a])")
    _check_size(radius, half_height)
    radius = np.asarray(radius, dtype=np.float64)
    half_height = np.asarray(half_height, dtype=np.float64)
    if shape == "spheroid":
        p_t, p_a = spheroid_tensor(radius, half_height)
        return p_t, p_a, 0.0
    q = half_height / radius
    lo, hi = cylinder_range()
    # a hair of slack, so that the table's own end nodes, recomputed from sizes, stay inside
    if np.any(q < lo * (1 - 1e-12)) or np.any(q > hi * (1 + 1e-12)):
        bad = float(q.min() if np.any(q < lo * (1 - 1e-12)) else q.max())
        raise StabmapError(f"half_height / radius = {bad:g}: the cylinder's viscous tensor is tabulated for "
                           f"{lo:g} <= half_height / radius <= {hi:g}; change half_height or radius, or give the "
                           "tensor directly (tensor = [P_t, P_a])")
    f_t, f_a, rel_error = cylinder_scaled(np.clip(q, lo, hi))
    scale = radius**7
    return scale * f_t, scale * f_a, rel_error


def _has_bool(value) -> bool:
    return isinstance(value, (bool, np.bool_)) or (isinstance(value, (list, tuple)) and any(map(_has_bool, value)))


def check_tensor(value, where: str = "tensor") -> tuple[float, float]:
    """(P_t, P_a) [m⁷] from a user's tensor: [P_t, P_a], or a 3×3 nested list, symmetric, diagonal and
    axisymmetric about z (P_11 == P_22) to 1e-12 relative; entries finite and > 0."""
    forms = "give [P_t, P_a] or a 3x3 list [[P_t, 0, 0], [0, P_t, 0], [0, 0, P_a]] in m^7"
    try:
        if _has_bool(value):  # TOML's true would pass as 1.0
            raise TypeError
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):  # text, tables, booleans, or rows of unequal length
        raise StabmapError(f"{where}: a cavity tensor is 2 numbers or 3x3 numbers; {forms}, got {value!r}") from None
    if isinstance(value, (str, bytes)) or arr.shape not in ((2,), (3, 3)):
        raise StabmapError(f"{where}: a cavity tensor has 2 entries or 3x3; {forms}, got {value!r}")
    if not np.all(np.isfinite(arr)):
        raise StabmapError(f"{where}: every entry of the cavity tensor must be finite; {forms}, got {value!r}")
    if arr.shape == (3, 3):
        scale = np.abs(arr).max()
        tol = 1e-12 * scale
        if np.any(np.abs(arr - arr.T) > tol):
            raise StabmapError(f"{where}: the cavity tensor must be symmetric; {forms}, got {value!r}")
        if np.any(np.abs(arr - np.diag(np.diag(arr))) > tol):
            raise StabmapError(f"{where}: the cavity tensor must be diagonal in the body axes (z the symmetry axis); "
                               f"{forms}, got {value!r}")
        if abs(arr[0, 0] - arr[1, 1]) > tol:
            raise StabmapError(f"{where}: the cavity tensor must be axisymmetric about z (P_11 == P_22); {forms}, "
                               f"got {value!r}")
        arr = np.array([arr[0, 0], arr[2, 2]])
    if np.any(arr <= 0):
        raise StabmapError(f"{where}: the cavity tensor's entries must be > 0 (it is positive definite); {forms}, "
                           f"got {value!r}")
    return float(arr[0]), float(arr[1])
