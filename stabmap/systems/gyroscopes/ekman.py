"""Viscous (boundary-layer) corrections of a cavity's inertial modes at large Reynolds number.

At Re = |omega| a^2 / nu >> 1 each ideal mode's pole lambda_l = 2 omega / kappa_l moves off the real axis by

    epsilon_l = g_l sqrt(nu omega) / a        (omega > 0; ``epsilon`` gives the rule for omega < 0),

with g_l complex and O(1), set by the cavity's shape and the mode; Im g > 0 is decay (solutions ~ exp(i lambda t)).
In the notation of Greenspan (1968), *The Theory of Rotating Fluids*, ch. 2, the free mode ~ exp(s t) (units of
omega, lengths in a, E = nu / (omega a^2)) has s = i lambda_hat + E^{1/2} s_1 + ..., lambda_hat = 2 / kappa, and
g = -i s_1.  s_1 is the boundary-layer integral over the wall (no-slip Ekman/Stokes layers: pumping plus
solvability against the inviscid mode q),

    s_1 = -1 / (4 int |q|^2 dV)  oint  sum_{s = +-1} |q_T + s i n x q_T|^2 sqrt(i (lambda_hat - 2 s n.z)) dA,

principal root; q_T is the slip velocity and n the outward normal.  The integrand vanishes like a square root at
the critical latitudes lambda_hat = +-2 n.z, an integrable singularity of its derivative only.

- Spheroid: the one coupling (spin-over) mode, by quadrature of that integral; the sphere is Greenspan's value,
  also Zhang, Liao & Earnshaw (2004), "On inertial waves and oscillations in a rapidly rotating spheroid".
- Cylinder: every mode (n, j, +-) in closed form, the content of Wedemeyer's (1966) correction (end walls: Ekman
  layers; side wall: a Stokes-type layer), and the same integral by quadrature to check it.

First order in Re^{-1/2}: valid for Re >> 1 (about 1e3 and up), and not as lambda_hat -> +-2 or 0 (docs/cavities.md,
"Viscous corrections of the modes at large Reynolds number").  Nothing here is used by the atlases' labels yet.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import lru_cache

import numpy as np
from scipy import integrate, special

from ...errors import StabmapError
from .cavity import cylinder_modes, scaled_modes

# Quadrature tolerances: far below the 1e-6 at which the closed form is checked against the integral.
_EPSREL = 1e-11
_LIMIT = 400


def reynolds(omega: float, a: float, nu: float) -> float:
    """Re = |omega| a^2 / nu of a cavity of radius a [m] spinning at omega [rad/s], liquid of viscosity nu [m^2/s]."""
    return abs(omega) * a * a / nu


def epsilon(g: complex, nu: float, omega: float, a: float) -> complex:
    """The pole shift epsilon [rad/s] of a mode with coefficient g, at spin omega [rad/s] (either sign).

    epsilon = sgn(omega) Re g sqrt(nu |omega|) / a + i Im g sqrt(nu |omega|) / a: reversing the spin mirrors the
    roots, lambda -> -conj(lambda), so the frequency shift changes sign and the decay rate does not.
    """
    scale = math.sqrt(nu * abs(omega)) / a
    return complex(float(np.sign(omega)) * g.real * scale, g.imag * scale)


def layer_density(q: np.ndarray, normal: np.ndarray, lam: float) -> complex:
    """The wall integrand sum_s |q_T + s i n x q_T|^2 sqrt(i (lam - 2 s n.z)) at one wall point.

    ``q`` and ``normal`` are components in one right-handed orthonormal basis whose third vector is the spin axis
    (Cartesian, or cylindrical (r, phi, z)); ``normal`` is the unit outward normal, real.
    """
    q_t = q - np.dot(q, normal) * normal  # the slip: the inviscid flow is tangent to the wall anyway
    total = 0j
    for s in (1, -1):
        # circular components of the slip, each with its own layer thickness sqrt(E / (i (lam - 2 s n.z)))
        circ = q_t + s * 1j * np.cross(normal, q_t)
        total += float(np.vdot(circ, circ).real) * np.sqrt(1j * (lam - 2 * s * normal[2]))
    return complex(total)


def _quad(f: Callable[[float], complex], lo: float, hi: float, points: tuple[float, ...] = ()) -> complex:
    """int_lo^hi f for a complex f, split at ``points`` (kinks of the integrand, not evaluated there)."""
    edges = [lo, *sorted(p for p in points if lo < p < hi), hi]
    total = 0j
    for x0, x1 in zip(edges[:-1], edges[1:], strict=True):
        total += integrate.quad(f, x0, x1, complex_func=True, epsabs=0.0, epsrel=_EPSREL, limit=_LIMIT)[0]
    return total


def _check_aspect(c_over_a: float) -> float:
    if not (math.isfinite(c_over_a) and c_over_a > 0):
        raise StabmapError(f"c_over_a must be finite and > 0, got {c_over_a!r}")
    return float(c_over_a)


# --- spheroid: the spin-over mode -------------------------------------------------------------------------------


@lru_cache(maxsize=256)
def spheroid_g(c_over_a: float) -> complex:
    """g of the spin-over mode of the spheroid with polar over equatorial semi-axis c/a (1: the sphere)."""
    c = _check_aspect(c_over_a)
    kappa = float(scaled_modes("spheroid", np.array([c]), 1)[1][0, 0])  # stabmap's kappa_1 = 1 + c^2
    lam = 2.0 / kappa
    # On x^2 + y^2 + z^2/c^2 = 1 (a = 1) the mode is q = (z, i z, -c^2 (x + i y)) ~ exp(i lam t): each of its
    # cylindrical components goes as e^{i phi}, so the integrand does not depend on phi; take phi = 0, times 2 pi.

    def density(theta: float) -> complex:
        st, ct = math.sin(theta), math.cos(theta)
        x, z = st, c * ct
        root = math.hypot(c * st, ct)
        normal = np.array([c * st, 0.0, ct]) / root
        q = np.array([z, 1j * z, -c * c * x])
        return layer_density(q, normal, lam) * st * root  # dA = sin(theta) sqrt(c^2 sin^2 + cos^2) dtheta dphi

    surface = 2.0 * math.pi * _quad(density, 0.0, math.pi, _critical_latitudes(c, lam))
    volume = 8.0 * math.pi * c**3 * (1.0 + c * c) / 15.0  # int |q|^2 dV: int z^2 = V c^2/5, int x^2 = V/5, V = 4 pi c/3
    return -1j * (-surface / (4.0 * volume))


def _critical_latitudes(c: float, lam: float) -> tuple[float, ...]:
    """The polar angles theta where n.z = +-lam/2 on the spheroid (n.z = cos / sqrt(c^2 sin^2 + cos^2))."""
    t = abs(lam) / 2.0
    if t >= 1.0:
        return ()
    theta = math.atan2(math.sqrt(1.0 - t * t), t * c)
    return (theta, math.pi - theta)


# --- cylinder: modes (n, j, +-) ---------------------------------------------------------------------------------


def cylinder_mode(c_over_a: float, n: int, j: int, sign: int) -> tuple[float, float, float]:
    """(xi, lambda_hat, k) of mode (n, j, sign) of the cylinder of half-height c and radius a, lengths in a.

    xi and kappa are stabmap's own (cavity.cylinder_modes; docs/cavities.md), lambda_hat = 2 / kappa, and the axial
    wavenumber k = (2n - 1) pi / (2 c/a).
    """
    h = _check_aspect(c_over_a)
    if sign not in (1, -1):
        raise StabmapError(f"sign must be +1 or -1, got {sign!r}")
    for name, value in (("n", n), ("j", j)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise StabmapError(f"{name} must be a whole number >= 1, got {value!r}")
    table = cylinder_modes(1.0, h, 1.0, int(n), int(j))
    branch = 0 if sign > 0 else 1
    xi = float(table["xi"][n - 1, j - 1, branch])
    lam = 2.0 / float(table["kappa"][n - 1, j - 1, branch])
    return xi, lam, (2 * n - 1) * math.pi / (2.0 * h)


def _bessel_square_integral(order: int, xi: float) -> float:
    """I_nu = int_0^1 J_nu(xi r)^2 r dr = (J_nu'(xi)^2 + (1 - nu^2/xi^2) J_nu(xi)^2) / 2 (Lommel)."""
    return 0.5 * (special.jvp(order, xi) ** 2 + (1.0 - order * order / (xi * xi)) * special.jv(order, xi) ** 2)


def cylinder_g(c_over_a: float, n: int, j: int, sign: int) -> complex:
    """g of cylinder mode (n, j, sign) (c: half-height, a: radius) by the closed form s_1 = -N/D.

    N = h sqrt(i lam) J1(xi)^2 (1 + k^2) / lam^2                                     (side wall)
        + xi^2 [I0 (1 - i) / (sqrt2 (2 - lam)^{3/2}) + I2 (1 + i) / (sqrt2 (2 + lam)^{3/2})]    (both end walls)
    D = h [(xi^2 / 2) (I0 / (2 - lam)^2 + I2 / (2 + lam)^2) + k^2 I1 / lam^2]             (int |q|^2 dV / 2 pi)

    with h = c/a, lam = lambda_hat; the integral of the module docstring evaluated on the mode of p = J1(xi r)
    sin(k z) e^{i phi}.  ``cylinder_g_by_quadrature`` checks it.
    """
    xi, lam, k = cylinder_mode(c_over_a, n, j, sign)
    h = float(c_over_a)
    i0, i1, i2 = (_bessel_square_integral(order, xi) for order in (0, 1, 2))
    side = h * np.sqrt(1j * lam) * special.j1(xi) ** 2 * (1.0 + k * k) / lam**2
    # end walls: (1 -+ i)/sqrt2 (2 -+ lam)^{1/2} = sqrt(i (lam -+ 2)) (principal, |lam| < 2), and the slip's circular
    # components are xi J0(xi r)/(2 - lam) and xi J2(xi r)/(2 + lam) up to phases: hence (2 -+ lam)^{-3/2}
    ends = xi**2 * (i0 * (1 - 1j) / (math.sqrt(2.0) * (2.0 - lam) ** 1.5) + i2 * (1 + 1j) / (math.sqrt(2.0) * (2.0 + lam) ** 1.5))
    norm = h * (0.5 * xi**2 * (i0 / (2.0 - lam) ** 2 + i2 / (2.0 + lam) ** 2) + k * k * i1 / lam**2)
    return complex(-1j * (-(side + ends) / norm))


def _cylinder_velocity(r: float, z: float, xi: float, lam: float, k: float) -> np.ndarray:
    """(u_r, u_phi, w) at phi = 0 of the mode with pressure J1(xi r) sin(k z) e^{i phi} ~ exp(i lam t), Omega = 1.

    From i lam q + 2 z x q = -grad p: the horizontal 2 x 2 system has determinant 4 - lam^2.
    r = 0 is never asked for (quadrature nodes are interior), where J1(xi r)/r has the limit xi/2.
    """
    p = special.j1(xi * r)
    dp = xi * special.jvp(1, xi * r)
    u_r = -1j * (lam * dp + 2.0 * p / r) / (4.0 - lam * lam) * math.sin(k * z)
    u_phi = (lam * p / r + 2.0 * dp) / (4.0 - lam * lam) * math.sin(k * z)
    w = 1j * k / lam * p * math.cos(k * z)
    return np.array([u_r, u_phi, w])


def cylinder_g_by_quadrature(c_over_a: float, n: int, j: int, sign: int) -> complex:
    """g of cylinder mode (n, j, sign) by quadrature of the general wall integral (module docstring) over the side
    wall and both ends, and of int |q|^2 dV over the radius: none of ``cylinder_g``'s algebra."""
    xi, lam, k = cylinder_mode(c_over_a, n, j, sign)
    h = float(c_over_a)

    def side(z: float) -> complex:  # r = 1, n = r-hat, dA = dphi dz
        return layer_density(_cylinder_velocity(1.0, z, xi, lam, k), np.array([1.0, 0.0, 0.0]), lam)

    def end(r: float, z: float, nz: float) -> complex:  # z = +-h, n = +-z-hat, dA = r dr dphi
        return layer_density(_cylinder_velocity(r, z, xi, lam, k), np.array([0.0, 0.0, nz]), lam) * r

    surface = _quad(side, -h, h) + _quad(lambda r: end(r, h, 1.0), 0.0, 1.0) + _quad(lambda r: end(r, -h, -1.0), 0.0, 1.0)

    # |u_r|^2 + |u_phi|^2 goes as sin^2(k z) and |w|^2 as cos^2(k z), each integrating to h over (-h, h) since
    # cos(k h) = 0; so take the horizontal part at z = h (sin = +-1) and w at z = 0 (cos = 1).
    def shell(r: float) -> float:
        horizontal = _cylinder_velocity(r, h, xi, lam, k)[:2]
        w = _cylinder_velocity(r, 0.0, xi, lam, k)[2]
        return float((np.sum(np.abs(horizontal) ** 2) + abs(w) ** 2) * r)

    volume = h * integrate.quad(shell, 0.0, 1.0, epsabs=0.0, epsrel=_EPSREL, limit=_LIMIT)[0]
    # the common 2 pi of the phi integrals cancels between surface and volume
    return complex(-1j * (-surface / (4.0 * volume)))
