"""Cavity modes against independent numerics: mode fields integrated by quadrature, a second series for
the Zhukovsky deficit, the sum rule, brute-force selection, and the precessing-cylinder resonance.

Nothing here reuses stabmap.cavity's formulas: the reference builds each mode's velocity field from
the linearised equations in the rotating frame (i sigma v + 2 Omega z x v = -grad p, modes
~ exp(i sigma t + i phi)) and integrates E = |rho int r x V|^2 / (rho int |V|^2) (CAVITIES.md).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import optimize, special

from stabmap import cavity
from stabmap.errors import StabmapError

OMEGA = 1.0
GL = np.polynomial.legendre.leggauss(64)
PHI = np.linspace(0.0, 2 * np.pi, 16, endpoint=False)  # trapezoid: exact for the low harmonics here


def _velocity(f, f_r, f_z, r, sigma):
    """(v_r, v_phi, v_z) of p = f(r, z) e^{i phi}, without the e^{i phi}."""
    det = 4 * OMEGA**2 - sigma**2
    v_r = -1j * (sigma * f_r + 2 * OMEGA * f / r) / det
    v_phi = (2 * OMEGA * f_r + sigma * f / r) / det
    v_z = 1j * f_z / sigma
    return v_r, v_phi, v_z


def _E_by_quadrature(r, z, w, field, rho):
    """E = |a|^2 / N^2 from node arrays r, z (weights w include r dr dz), field -> (v_r, v_phi, v_z)."""
    v_r, v_phi, v_z = field
    a = np.zeros(3, dtype=complex)
    norm = 0.0
    for phi in PHI:
        e = np.exp(1j * phi)
        V = np.stack([(v_r * np.cos(phi) - v_phi * np.sin(phi)) * e, (v_r * np.sin(phi) + v_phi * np.cos(phi)) * e, v_z * e])
        pos = np.stack([r * np.cos(phi), r * np.sin(phi), z])
        a += rho * (np.cross(pos, V, axis=0) * w).sum(axis=1) * (2 * np.pi / len(PHI))
        norm += rho * ((np.abs(V) ** 2).sum(axis=0) * w).sum() * (2 * np.pi / len(PHI))
    return float(np.vdot(a, a).real / norm)


def _nodes(z_lo, z_hi, r_top):
    """Gauss-Legendre nodes over {z_lo < z < z_hi, 0 < r < r_top(z)} with weights r dr dz."""
    x, wx = GL
    z = 0.5 * (z_hi - z_lo) * x + 0.5 * (z_hi + z_lo)
    R = r_top(z)
    t, wt = 0.5 * (x + 1), 0.5 * wx
    r = np.outer(R, t)
    w = np.outer(0.5 * (z_hi - z_lo) * wx * R, wt) * r
    return r.ravel(), np.repeat(z, len(x)), w.ravel()


@pytest.mark.parametrize("a, c, rho", [(1.0, 0.4, 1000.0), (0.7, 0.7 * 1.8, 800.0), (2.0, 6.0, 1.0)])
def test_spheroid_spin_over_mode_by_quadrature(a, c, rho):
    kappa = 1 + c**2 / a**2
    r, z, w = _nodes(-c, c, lambda z: a * np.sqrt(1 - (z / c) ** 2))
    field = _velocity(r * z, z, r, r, 2 * OMEGA / kappa)
    E, k = cavity.modes("spheroid", a, c, rho)
    assert k.tolist() == pytest.approx([kappa], rel=1e-14)
    assert E[0] == pytest.approx(_E_by_quadrature(r, z, w, field, rho), rel=1e-10)
    # The wall condition picks the sign of kappa: the flow is tangent for +kappa only.
    zs = np.linspace(-0.9 * c, 0.9 * c, 7)
    rs = a * np.sqrt(1 - (zs / c) ** 2)
    for sign, tangent in ((+1, True), (-1, False)):
        v_r, _, v_z = _velocity(rs * zs, zs, rs, rs, sign * 2 * OMEGA / kappa)
        normal = np.abs(v_r * rs / a**2 + v_z * zs / c**2)
        assert (normal.max() < 1e-12) == tangent


def _cylinder_field(xi, kappa, n, a, c, r, z):
    k = (2 * n - 1) * np.pi / (2 * c)
    s = xi / a
    f = special.j1(s * r) * np.sin(k * z)
    f_r = s * special.jvp(1, s * r) * np.sin(k * z)
    f_z = special.j1(s * r) * k * np.cos(k * z)
    return _velocity(f, f_r, f_z, r, 2 * OMEGA / kappa)


@pytest.mark.parametrize("h_over_a", [0.5, 1.0, 1.99, 3.0, 6.0])
def test_cylinder_modes_by_quadrature(h_over_a):
    a, rho = 0.8, 950.0
    c = 0.5 * h_over_a * a
    modes = cavity.cylinder_modes(a, c, rho, 3, 4)
    zeros0, zeros1 = special.jn_zeros(0, 5), np.concatenate([[0.0], special.jn_zeros(1, 5)])
    for n in range(1, 4):
        beta = 2 * c / ((2 * n - 1) * np.pi * a)
        for j in range(1, 5):
            for b, sign in enumerate((+1, -1)):
                xi, kappa, E = (modes[key][n - 1, j - 1, b] for key in ("xi", "kappa", "E"))
                assert np.sign(kappa) == sign and kappa**2 == pytest.approx(1 + (beta * xi) ** 2, rel=1e-13)
                assert xi * special.jvp(1, xi) + kappa * special.j1(xi) == pytest.approx(0.0, abs=1e-12)
                lo, hi = (zeros0[j - 1], zeros1[j]) if sign > 0 else (zeros1[j], zeros1[j + 1])
                assert lo < xi < hi
                r, z, w = _nodes(-c, c, lambda z: np.full_like(z, a))
                field = _cylinder_field(xi, kappa, n, a, c, r, z)
                assert E == pytest.approx(_E_by_quadrature(r, z, w, field, rho), rel=1e-9)
                # no flow through the side wall or the lids
                zs = np.linspace(-c, c, 5)
                v_r, _, _ = _cylinder_field(xi, kappa, n, a, c, np.full(5, a), zs)
                _, _, v_z = _cylinder_field(xi, kappa, n, a, c, np.linspace(0.1, a, 5), np.full(5, c))
                assert np.abs(v_r).max() < 1e-12 and np.abs(v_z).max() < 1e-12


def _deficit_radial(a, c, rho, terms=20000):
    """J_rigid - J_Zh from psi = -yz + phi, phi a Neumann-Dini series in r (not CAVITIES.md's axial series)."""
    mu = special.jnp_zeros(1, terms)
    q = c / a
    return rho * a**5 * 16 * np.pi * np.sum(q / (mu**2 * (mu**2 - 1)) - np.tanh(mu * q) / (mu**3 * (mu**2 - 1)))


@pytest.mark.parametrize("c_over_a", [0.05, 0.3, 1.0, 2.5, 8.0, 20.0])
def test_cylinder_deficit_against_a_radial_series(c_over_a):
    a, rho = 0.3, 1100.0
    assert cavity.zhukovsky_deficit("cylinder", a, c_over_a * a, rho) == pytest.approx(_deficit_radial(a, c_over_a * a, rho), rel=1e-9)


def test_deficit_limits():
    a, rho = 1.0, 1.0
    # Long cylinder: the liquid slides along the axis, J_rigid - J_Zh -> m a^2 (the axial shear 2y).
    m = cavity.frozen_mass("cylinder", a, 200.0, rho)
    assert cavity.zhukovsky_deficit("cylinder", a, 200.0, rho) == pytest.approx(m * a**2, rel=0.01)
    # Spheroid: J_Zh = m (a^2 - c^2)^2 / (5 (a^2 + c^2)) (the equivalent body), and the one mode holds it all.
    for c in (0.3, 1.0, 2.7):
        m = cavity.frozen_mass("spheroid", a, c, rho)
        J_rigid, _ = cavity.frozen_inertia("spheroid", a, c, rho)
        deficit = J_rigid - m * (a**2 - c**2) ** 2 / (5 * (a**2 + c**2))
        assert cavity.zhukovsky_deficit("spheroid", a, c, rho) == pytest.approx(deficit, rel=1e-13)
        assert cavity.modes("spheroid", a, c, rho)[0][0] == pytest.approx(deficit, rel=1e-13)
        assert cavity.tail("spheroid", a, c, rho) == pytest.approx(0.0, abs=1e-13 * deficit)
    assert cavity.frozen_inertia("cylinder", 2.0, 1.5, 3.0)[0] == pytest.approx(cavity.frozen_mass("cylinder", 2.0, 1.5, 3.0) * (1.0 + 0.75))


@pytest.mark.parametrize("c_over_a", [0.25, 1.0, 4.0])
def test_sum_rule(c_over_a):
    a, rho = 1.0, 1.0
    c = c_over_a * a
    deficit = _deficit_radial(a, c, rho)
    sums = [cavity.cylinder_modes(a, c, rho, 200, j)["E"].sum() for j in (50, 100, 200)]
    residual = [deficit - s for s in sums]
    assert all(r > 0 for r in residual)
    # the high-j modes fall like j^-2, so the remainder halves with j_max ...
    assert 1.6 < residual[0] / residual[1] < 2.4 and 1.6 < residual[1] / residual[2] < 2.4
    # ... and Richardson's extrapolation to j_max = infinity lands on the deficit
    assert 2 * sums[2] - sums[1] == pytest.approx(deficit, rel=1e-4)
    for N in (1, 4, 16):
        E, _ = cavity.modes("cylinder", a, c, rho, N)
        assert cavity.tail("cylinder", a, c, rho, N) + E.sum() == pytest.approx(deficit, rel=1e-9)


@pytest.mark.parametrize("c_over_a", [0.03, 0.2, 1.0, 3.0, 12.0])
def test_the_largest_modes_are_chosen(c_over_a):
    modes = cavity.cylinder_modes(1.0, c_over_a, 1.0, 120, 400)
    E, kappa = modes["E"].ravel(), modes["kappa"].ravel()
    order = np.argsort(-E)
    for N in (1, 4, 16, 32):
        got_E, got_kappa = cavity.modes("cylinder", 1.0, c_over_a, 1.0, N)
        np.testing.assert_allclose(got_E, E[order[:N]], rtol=1e-12)
        np.testing.assert_allclose(got_kappa, kappa[order[:N]], rtol=1e-12)


def test_the_precessing_cylinder_resonance():
    # kappa = 2 (lambda_l = omega: fixed in space) for the largest mode near h/a = 1.99.
    h_over_a = optimize.brentq(lambda h: cavity.modes("cylinder", 1.0, h / 2, 1.0, 1)[1][0] - 2.0, 1.5, 2.5, xtol=1e-12)
    assert 1.98 < h_over_a < 2.00


def test_scaling_with_density_and_size():
    E1, k1 = cavity.modes("cylinder", 1.0, 0.7, 1.0, 8)
    E2, k2 = cavity.modes("cylinder", 3.0, 2.1, 5.0, 8)
    np.testing.assert_allclose(E2, 5.0 * 3.0**5 * E1, rtol=1e-12)
    np.testing.assert_allclose(k2, k1, rtol=1e-12)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: cavity.modes("cone", 1.0, 1.0, 1.0), "unknown cavity shape 'cone'"),
        (lambda: cavity.modes("cylinder", 0.0, 1.0, 1.0), "radius must be finite and > 0"),
        (lambda: cavity.modes("cylinder", 1.0, -1.0, 1.0), "half_height must be finite and > 0"),
        (lambda: cavity.frozen_mass("spheroid", 1.0, 1.0, float("nan")), "density must be finite and > 0"),
        (lambda: cavity.modes("spheroid", 1.0, 1.0, 1.0, 2), "exactly one coupling mode"),
        (lambda: cavity.modes("cylinder", 1.0, 1.0, 1.0, 0), "modes must be a whole number"),
    ],
)
def test_bad_input(call, message):
    with pytest.raises(StabmapError, match=message):
        call()
