"""Liquid modes (E_l, kappa_l) of a cavity from its shape, size and density.

Conventions and closed forms: docs/model.md (liquid modes). E_l has units of a moment of
inertia; kappa_l is dimensionless, |kappa_l| > 1, negative on the prograde
branch of the cylinder. Every E scales as density * radius**5 at a fixed aspect
ratio half_height / radius and every kappa depends on that ratio alone, so the
work is done once per ratio (``scaled_*``) and scaled afterwards.

A viscous liquid's cavity tensor P¹ [m⁷] (Chernousko; docs/viscous-tensors.md) comes from stokes.py:
``viscous_tensor(shape, radius, half_height) -> (P_t, P_a, rel_error)``, the closed forms ``ellipsoid_tensor``,
``spheroid_tensor``, ``sphere_tensor``, and ``check_viscous_tensor`` for a tensor a scene gives directly.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import special
from scipy.optimize import elementwise

from ...errors import StabmapError
from .stokes import check_tensor as check_viscous_tensor  # noqa: F401  (re-exported: stabmap.cavity)
from .stokes import ellipsoid_tensor, sphere_tensor, spheroid_tensor  # noqa: F401
from .stokes import tensor as viscous_tensor  # noqa: F401

SHAPES = ("spheroid", "cylinder")
DEFAULT_MODES = 8  # cylinder modes kept with the tail: 1e-4 on the critical spin (scripts/bench_truncation.py, BENCHMARKS.md)
MAX_MODES = 64


def check_shape(shape: str, n_modes: int | None, where: str = "shape") -> int:
    """The number of modes kept, after checking the shape and the request."""
    if shape not in SHAPES:
        raise StabmapError(f'{where}: unknown cavity shape {shape!r}; use "spheroid", "cylinder" or "table"')
    if shape == "spheroid":
        if n_modes not in (None, 1):
            raise StabmapError(f"modes: a spheroid has exactly one coupling mode; remove modes or set modes = 1, got {n_modes!r}")
        return 1
    if n_modes is None:
        return DEFAULT_MODES
    if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or not 1 <= n_modes <= MAX_MODES:
        raise StabmapError(f"modes must be a whole number from 1 to {MAX_MODES}, got {n_modes!r}")
    return int(n_modes)


def _check_size(radius, half_height, density) -> None:
    for name, value in (("radius", radius), ("half_height", half_height), ("density", density)):
        v = np.asarray(value, dtype=np.float64)
        if not np.all(np.isfinite(v)) or np.any(v <= 0):
            raise StabmapError(f"{name} must be finite and > 0, got {value!r}")


def frozen_mass(shape: str, radius, half_height, density):
    """Mass of the liquid [kg]."""
    check_shape(shape, None)
    _check_size(radius, half_height, density)
    factor = 4.0 / 3.0 if shape == "spheroid" else 2.0
    return factor * math.pi * density * np.square(radius) * half_height


def frozen_inertia(shape: str, radius, half_height, density):
    """(transverse inertia about the cavity centre, axial inertia) of the frozen liquid [kg m^2]."""
    m = frozen_mass(shape, radius, half_height, density)
    a2, c2 = np.square(radius), np.square(half_height)
    if shape == "spheroid":
        return m * (a2 + c2) / 5.0, 2.0 * m * a2 / 5.0
    return m * (a2 / 4.0 + c2 / 3.0), m * a2 / 2.0


def zhukovsky_deficit(shape: str, radius, half_height, density):
    """J_rigid - J_Zh about a transverse axis through the cavity centre [kg m^2]: the sum of all modes' E."""
    check_shape(shape, None)
    _check_size(radius, half_height, density)
    q = np.asarray(half_height, dtype=np.float64) / radius
    return density * np.power(radius, 5) * scaled_deficit(shape, q)


def modes(shape: str, radius: float, half_height: float, density: float, n_modes: int | None = None):
    """The n_modes modes with the largest E, largest first: (E [kg m^2], kappa [1]) as float arrays."""
    n_modes = check_shape(shape, n_modes)
    _check_size(radius, half_height, density)
    e, kappa = scaled_modes(shape, np.array([half_height / radius]), n_modes)
    return density * radius**5 * e[0], kappa[0]


def tail(shape: str, radius: float, half_height: float, density: float, n_modes: int | None = None) -> float:
    """The lumped remainder: deficit minus the kept modes' E [kg m^2], subtracted from A by the engine."""
    E, _ = modes(shape, radius, half_height, density, n_modes)
    return float(zhukovsky_deficit(shape, radius, half_height, density)) - float(E.sum())


def scaled_tails(shape: str, q: np.ndarray, n_max: int):
    """(E, kappa, tails) scaled by density radius^5 at aspect ratios q: E and kappa (len(q), n_max), largest
    E first, and tails (len(q), n_max + 1), the deficit minus the N largest E for N = 0..n_max.

    The N largest modes are the first N of the n_max largest, so one search serves every N up to n_max.
    """
    q = np.atleast_1d(np.asarray(q, dtype=np.float64))
    e, kappa = scaled_modes(shape, q, 1 if shape == "spheroid" else n_max)
    kept = np.concatenate([np.zeros((len(q), 1)), np.cumsum(e, axis=1)], axis=1)
    tails = scaled_deficit(shape, q)[:, None] - kept
    if shape == "spheroid":  # its one mode is the whole deficit; more modes add nothing
        tails = np.concatenate([tails, np.repeat(tails[:, -1:], n_max - 1, axis=1)], axis=1)
    return e, kappa, tails


def scaled_deficit(shape: str, q: np.ndarray) -> np.ndarray:
    """Deficit / (density radius^5) at aspect ratios q = half_height / radius."""
    q = np.asarray(q, dtype=np.float64)
    if shape == "spheroid":
        return _spheroid_e(q)
    # docs/model.md's axial series; its terms fall like x^-4, so a finite sum plus
    # the asymptotic expansion x^-4 - 2 x^-5 - x^-6 summed by Hurwitz zeta.
    n_terms = 64 + int(np.ceil(16.0 * q.max(initial=0.0)))
    n = np.arange(1, n_terms + 1)
    x = (2 * n - 1) * np.pi / (2.0 * q[..., None])
    i1, i2 = special.ive(1, x), special.ive(2, x)
    di1 = special.ive(0, x) - i1 / x
    series = ((x * i2 - i1) / (np.power(x, 5) * di1)).sum(axis=-1)
    scale = 2.0 * q / np.pi  # 1 / x_n = scale / (2n - 1)
    for s, coef in ((4, 1.0), (5, -2.0), (6, -1.0)):
        series += coef * scale**s * 2.0**-s * special.zeta(s, n_terms + 0.5)
    return (4.0 * np.pi / 3.0) * q**3 + (8.0 * np.pi / q) * series


def _spheroid_e(q: np.ndarray) -> np.ndarray:
    return (16.0 * np.pi / 15.0) * q**3 / (1.0 + q**2)


def scaled_modes(shape: str, q: np.ndarray, n_modes: int):
    """(E / (density radius^5), kappa), each (len(q), n_modes), largest E first, at aspect ratios q."""
    q = np.atleast_1d(np.asarray(q, dtype=np.float64))
    if shape == "spheroid":
        return _spheroid_e(q)[:, None], (1.0 + q**2)[:, None]
    e = np.empty((len(q), n_modes))
    kappa = np.empty((len(q), n_modes))
    order = np.argsort(q, kind="stable")
    # Neighbouring aspect ratios need nearly the same candidate modes.
    for start in range(0, len(q), _GROUP):
        idx = order[start : start + _GROUP]
        e[idx], kappa[idx] = _largest(q[idx], n_modes)
    return e, kappa


_GROUP = 128


def _largest(q: np.ndarray, n_modes: int):
    """The n_modes largest cylinder modes at each q: no mode whose upper bound is below the
    n_modes-th largest of a first guess can be among them."""
    first = [(n, j, b) for n in range(1, n_modes + 1) for j in range(1, n_modes // n + 1) for b in (+1, -1)]
    e0, _ = _modes_at(q, first)
    threshold = np.sort(e0, axis=1)[:, -n_modes].min()
    candidates = _candidates(q.max(), n_modes, threshold)
    e, kappa = _modes_at(q, candidates)
    top = np.argsort(-e, axis=1, kind="stable")[:, :n_modes]
    return np.take_along_axis(e, top, axis=1), np.take_along_axis(kappa, top, axis=1)


def _candidates(q_max: float, n_modes: int, threshold: float) -> list[tuple[int, int, int]]:
    """Every (n, j, branch) whose scaled E may reach threshold at some q <= q_max.

    Bounds (E scaled by density radius^5, beta_n = 2q / ((2n-1) pi), xi the mode's root):
    branch +: E <= 128 beta^3 / ((2n-1) xi^2); branch -: E <= 32 beta^3 / ((2n-1) xi^2)
    and E <= 2.9 beta^5 / (2n-1). Both grow with q, so q_max bounds the group.
    """
    # Branch +'s j-th root lies above the j-th zero of J0 (xi J0 + (kappa - 1) J1 > 0 below
    # it), branch -'s above the j-th zero of J1.
    plus_lo = special.jn_zeros(0, 4096)
    minus_lo = special.jn_zeros(1, 4096)
    out = []
    for n in range(1, 100_000):
        beta = 2.0 * q_max / ((2 * n - 1) * np.pi)
        scale = beta**3 / (2 * n - 1)
        plus = np.flatnonzero(128.0 * scale / plus_lo**2 >= threshold) + 1
        minus = np.flatnonzero(32.0 * scale / minus_lo**2 >= threshold) + 1
        if 2.9 * beta**5 / (2 * n - 1) < threshold:
            minus = minus[:0]
        if len(plus) == len(plus_lo) or len(minus) == len(minus_lo):
            raise StabmapError(f"cylinder modes: aspect ratio {q_max:g} needs more than {len(plus_lo)} radial modes")
        if not len(plus) and not len(minus):
            break  # the bounds fall with n, so no later n qualifies either
        out += [(n, int(j), +1) for j in plus] + [(n, int(j), -1) for j in minus]
    return out


def _modes_at(q: np.ndarray, which: list[tuple[int, int, int]]):
    """Scaled E and kappa, (len(q), len(which)), of the listed (n, j, branch) modes."""
    n, j, branch = (np.array(col) for col in zip(*which, strict=True))
    e = np.empty((len(q), len(which)))
    kappa = np.empty_like(e)
    for sign in (+1, -1):
        sel = branch == sign
        if sel.any():
            e[:, sel], kappa[:, sel], _ = _cylinder(q[:, None], n[sel], j[sel], sign)
    return e, kappa


def cylinder_modes(radius: float, half_height: float, density: float, n_max: int, j_max: int) -> dict:
    """Every mode n = 1..n_max, j = 1..j_max on both branches: arrays (n_max, j_max, 2) of E, kappa, xi.

    Branch 0 is kappa > 0 (retrograde in the body), branch 1 is kappa < 0.
    """
    _check_size(radius, half_height, density)
    n, j = np.meshgrid(np.arange(1, n_max + 1), np.arange(1, j_max + 1), indexing="ij")
    out: dict[str, list[np.ndarray]] = {"E": [], "kappa": [], "xi": []}
    for sign in (+1, -1):
        e, kappa, xi = _cylinder(np.float64(half_height / radius), n, j, sign)
        out["E"].append(density * radius**5 * e)
        out["kappa"].append(kappa)
        out["xi"].append(xi)
    return {key: np.stack(v, axis=-1) for key, v in out.items()}


def _cylinder(q, n, j, sign):
    """Scaled E, kappa and root xi of mode (n, j) on one branch, broadcast over q, n, j."""
    q, n, j = np.broadcast_arrays(q, n, j)
    beta = 2.0 * q / ((2 * n - 1) * np.pi)
    zeros = np.concatenate([[0.0], special.jn_zeros(1, int(j.max(initial=1)) + 1)])
    # xi J1'(xi) + kappa J1(xi) = 0 has one root between consecutive zeros of J1:
    # branch + in (z_{j-1}, z_j), branch - in (z_j, z_{j+1}) (xi = 0 is trivial).
    lo = zeros[j - 1] if sign > 0 else zeros[j]
    hi = zeros[j] if sign > 0 else zeros[j + 1]
    lo = np.where(lo == 0.0, 1e-3, lo)

    def f(xi, beta):
        s = sign * np.sqrt(1.0 + (beta * xi) ** 2)
        return xi * special.j0(xi) + (s - 1.0) * special.j1(xi)

    res = elementwise.find_root(f, (lo, hi), args=(beta,), tolerances={"xatol": 0.0, "xrtol": 4 * np.finfo(float).eps})
    if not np.all(res.success):
        raise StabmapError("cylinder modes: the root finder did not converge; report this aspect ratio as a bug")
    xi = res.x
    kappa = sign * np.sqrt(1.0 + (beta * xi) ** 2)
    e = 32.0 * beta**3 * (kappa + 1.0) ** 2 / ((2 * n - 1) * kappa * xi**2 * (kappa + (kappa - 1.0) * beta**2))
    return e, kappa, xi
