"""stabmap.cavity against numerics that share none of its formulas (docs/model.md is the spec).

Reference: each mode's velocity is built from its pressure by solving the linearised rotating-frame
equations i sigma v + 2 Omega z x v = -grad p, div v = 0 (modes ~ exp(i sigma t + i phi)), and
E = |rho int r x V|^2 / (rho int |V|^2) is integrated by Gauss-Legendre in (r, z) and the trapezoid
in phi. The cylinder's Zhukovsky deficit comes from a radial (Neumann-Dini) series, not the axial
series cavity.py sums. Omega is deliberately not 1: E and kappa must not depend on it.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import optimize, special

from stabmap.systems.gyroscopes import cavity
from stabmap.errors import StabmapError

OMEGA = 1.3
GOLDEN = (1 + 5**0.5) / 2


def velocity(f, f_r, f_z, r, sigma):
    """(v_r, v_phi, v_z) without e^{i phi} for p = f(r, z) e^{i phi}; test_reference_field checks it."""
    det = 4 * OMEGA**2 - sigma**2
    return -1j * (sigma * f_r + 2 * OMEGA * f / r) / det, (2 * OMEGA * f_r + sigma * f / r) / det, 1j * f_z / sigma


def nodes(c, r_wall, k=64):
    """Gauss-Legendre nodes of {|z| < c, r < r_wall(z)}; weights carry r dr dz (times 2 pi: phi)."""
    x, wx = np.polynomial.legendre.leggauss(k)
    z = c * x
    R = r_wall(z)
    r = np.outer(R, 0.5 * (x + 1))
    w = np.outer(c * wx * R, 0.5 * wx) * r
    return r.ravel(), np.repeat(z, k), w.ravel()


def energy(r, z, w, v, rho, n_phi=8):
    """E = |a|^2 / N^2 with the full complex a; the phi integrand has harmonics |m| <= 2 only."""
    v_r, v_phi, v_z = v
    a = np.zeros(3, dtype=complex)
    for phi in 2 * np.pi * np.arange(n_phi) / n_phi:
        e, cos, sin = np.exp(1j * phi), np.cos(phi), np.sin(phi)
        V = np.stack([(v_r * cos - v_phi * sin) * e, (v_r * sin + v_phi * cos) * e, v_z * e])
        a += np.cross(np.stack([r * cos, r * sin, z]), V, axis=0) @ w
    a *= rho * 2 * np.pi / n_phi
    norm = rho * 2 * np.pi * ((np.abs(v_r) ** 2 + np.abs(v_phi) ** 2 + np.abs(v_z) ** 2) @ w)
    return np.vdot(a, a).real / norm


def cylinder_field(xi, kappa, n, a, c, r, z):
    """Velocity of p = J1(xi r / a) sin(k_n z) e^{i phi} at sigma = 2 Omega / kappa."""
    k, s = (2 * n - 1) * np.pi / (2 * c), xi / a
    f, f_r, f_z = special.j1(s * r) * np.sin(k * z), s * special.jvp(1, s * r) * np.sin(k * z), special.j1(s * r) * k * np.cos(k * z)
    return velocity(f, f_r, f_z, r, 2 * OMEGA / kappa)


def deficit_radial(a, c, rho, terms=4000):
    """J_rigid - J_Zh = rho int |(0, 0, 2y) - grad phi|^2 (u - grad psi is orthogonal to gradients)
    with psi = -yz + phi, phi = sin(phi) sum A_j J1(mu_j r/a) sinh(mu_j z/a), J1'(mu_j) = 0. The lid
    condition d phi/dz = 2y gives A_j = 4a^2 / (mu (mu^2 - 1) J1(mu) cosh(mu c/a)), and
    D / (rho a^5) = 2 pi c/a - 16 pi sum tanh(mu c/a) / (mu^3 (mu^2 - 1)); the tail past `terms`
    (mu_j ~ (j + 1/4) pi) is added as pi^-5 zeta(5, terms + 5/4)."""
    mu = special.jnp_zeros(1, terms)
    q = c / a
    s = np.sum(np.tanh(mu * q) / (mu**3 * (mu**2 - 1))) + np.pi**-5 * special.zeta(5, terms + 1.25)
    return rho * a**5 * (2 * np.pi * q - 16 * np.pi * s)


def test_reference_field_solves_the_rotating_frame_equations():
    # The momentum equation holds for any f by construction; div v = 0 only with the Poincare
    # relation kappa^2 = 1 + beta^2 xi^2, checked here by central differences.
    a, c, n, xi = 0.9, 0.7, 2, 4.1
    beta = 2 * c / ((2 * n - 1) * np.pi * a)
    r, z, h = np.array([0.2, 0.5, 0.8]), np.array([-0.5, 0.1, 0.6]), 1e-5
    for kappa in (np.hypot(1, beta * xi), -np.hypot(1, beta * xi), 1.5):
        v_r, v_phi, _ = cylinder_field(xi, kappa, n, a, c, r, z)
        d_r = ((r + h) * cylinder_field(xi, kappa, n, a, c, r + h, z)[0] - (r - h) * cylinder_field(xi, kappa, n, a, c, r - h, z)[0]) / (2 * h * r)
        d_z = (cylinder_field(xi, kappa, n, a, c, r, z + h)[2] - cylinder_field(xi, kappa, n, a, c, r, z - h)[2]) / (2 * h)
        div = np.abs(d_r + 1j * v_phi / r + d_z).max() / np.abs(v_r).max()
        assert (div < 1e-6) == (kappa != 1.5)


@pytest.mark.parametrize("a, c, rho", [(1.0, 0.4, 1000.0), (0.7, 1.3, 3.0), (2.0, 6.0, 1.0), (1.1, 1.1, 850.0), (0.5, 0.05, 13.6e3)])
def test_spheroid_spin_over_mode(a, c, rho):
    kappa = 1 + c**2 / a**2
    # On the wall (r, z) = (a sin t, c cos t) the normal is along (r / a^2, z / c^2); the flow of
    # p = r z e^{i phi} is tangent there for +kappa only.
    t = np.linspace(0.1, np.pi - 0.1, 9)
    rs, zs = a * np.sin(t), c * np.cos(t)
    n_hat = np.stack([rs / a**2, zs / c**2]) / np.hypot(rs / a**2, zs / c**2)
    for sign in (+1, -1):
        v_r, v_phi, v_z = velocity(rs * zs, zs, rs, rs, sign * 2 * OMEGA / kappa)
        leak = np.abs(v_r * n_hat[0] + v_z * n_hat[1]).max() / np.abs(v_phi).max()
        assert leak < 1e-13 if sign > 0 else leak > 1e-2
    r, z, w = nodes(c, lambda z: a * np.sqrt(1 - (z / c) ** 2))
    E, k = cavity.modes("spheroid", a, c, rho)
    assert E.dtype == k.dtype == np.float64 and E.shape == k.shape == (1,)
    assert k[0] == pytest.approx(kappa, rel=1e-14)
    assert E[0] == pytest.approx(energy(r, z, w, velocity(r * z, z, r, r, 2 * OMEGA / kappa), rho), rel=1e-10)


@pytest.mark.parametrize("h_over_a", [0.5, 1.0, 1.99, 3.0, 6.0])
def test_cylinder_modes_by_quadrature(h_over_a):
    a, rho = 0.8, 950.0
    c = 0.5 * h_over_a * a
    got = cavity.cylinder_modes(a, c, rho, 3, 4)
    assert all(got[key].shape == (3, 4, 2) for key in ("E", "kappa", "xi"))
    j0, j1 = special.jn_zeros(0, 4), np.concatenate([[0.0], special.jn_zeros(1, 5)])
    r, z, w = nodes(c, lambda z: np.full_like(z, a))
    for n in (1, 2, 3):
        beta = 2 * c / ((2 * n - 1) * np.pi * a)
        for j in range(1, 5):
            for b, sign in enumerate((+1, -1)):
                xi, kappa, E = (got[key][n - 1, j - 1, b] for key in ("xi", "kappa", "E"))
                assert np.sign(kappa) == sign and kappa**2 == pytest.approx(1 + (beta * xi) ** 2, rel=1e-13)
                assert abs(xi * special.jvp(1, xi) + kappa * special.j1(xi)) < 1e-12 * max(1.0, abs(kappa))
                # Branch +: xi J0 + (kappa - 1) J1 keeps one sign from j_{1,j-1} up to j_{0,j}
                # (J0 J1 > 0 there), so its root lies in (j_{0,j}, j_{1,j}); branch -: (j_{1,j}, j_{1,j+1}).
                assert (j0[j - 1] < xi < j1[j]) if sign > 0 else (j1[j] < xi < j1[j + 1])
                field = cylinder_field(xi, kappa, n, a, c, r, z)
                assert E == pytest.approx(energy(r, z, w, field, rho), rel=1e-10)
                scale = np.abs(field[1]).max()
                v_side = cylinder_field(xi, kappa, n, a, c, np.full(7, a), np.linspace(-c, c, 7))[0]
                v_lids = cylinder_field(xi, kappa, n, a, c, np.tile(np.linspace(0.05, 1, 4) * a, 2), np.repeat([-c, c], 4))[2]
                assert np.abs(v_side).max() < 1e-11 * scale and np.abs(v_lids).max() < 1e-11 * scale


@pytest.mark.parametrize("c_over_a", [0.05, 0.1, 0.3, 1.0, 2.5, 8.0, 20.0])
def test_cylinder_deficit_against_the_radial_series(c_over_a):
    a, rho = 0.3, 1100.0
    c = c_over_a * a
    assert cavity.zhukovsky_deficit("cylinder", a, c, rho) == pytest.approx(deficit_radial(a, c, rho), rel=1e-9)


@pytest.mark.parametrize("shape, a, c, rho", [("spheroid", 1.0, 0.3, 2.0), ("spheroid", 0.6, 1.6, 900.0), ("spheroid", 1.0, 1.0, 1.0), ("cylinder", 0.7, 1.9, 3.0)])
def test_frozen_liquid_and_the_spheroid_deficit(shape, a, c, rho):
    r, z, w = nodes(c, (lambda z: a * np.sqrt(1 - (z / c) ** 2)) if shape == "spheroid" else (lambda z: np.full_like(z, a)))
    m = 2 * np.pi * rho * w.sum()
    J_rigid, J_axial = np.pi * rho * (r**2 + 2 * z**2) @ w, 2 * np.pi * rho * r**2 @ w  # <y^2> over phi is r^2/2
    assert cavity.frozen_mass(shape, a, c, rho) == pytest.approx(m, rel=1e-13)
    assert cavity.frozen_inertia(shape, a, c, rho) == pytest.approx((J_rigid, J_axial), rel=1e-13)
    if shape == "spheroid":
        # psi = A yz meets d psi/dn = (0, -z, y).n on the ellipsoid for A = (a^2 - c^2)/(a^2 + c^2).
        D = J_rigid - m * (a**2 - c**2) ** 2 / (5 * (a**2 + c**2))
        assert cavity.zhukovsky_deficit(shape, a, c, rho) == pytest.approx(D, rel=1e-12)
        assert cavity.modes(shape, a, c, rho)[0][0] == pytest.approx(D, rel=1e-12)
        assert abs(cavity.tail(shape, a, c, rho, 1)) < 1e-12 * D


def test_cylinder_deficit_limits():
    a, rho = 1.0, 1.0
    # Long: far from the lids psi -> -yz, leaving the axial shear 2y: D -> 4 rho int y^2 = m a^2.
    for c in (20.0, 200.0):
        m = cavity.frozen_mass("cylinder", a, c, rho)
        assert abs(cavity.zhukovsky_deficit("cylinder", a, c, rho) / (m * a**2) - 1) < a / c
    # Flat: psi -> +yz, leaving the shear -2z: D -> 4 rho int z^2 = (4/3) m c^2 << J_rigid.
    for c in (0.002, 0.02):
        m = cavity.frozen_mass("cylinder", a, c, rho)
        assert abs(cavity.zhukovsky_deficit("cylinder", a, c, rho) / (m * c**2) - 4 / 3) < c / a


@pytest.mark.parametrize("c_over_a", [0.25, 1.0, 4.0])
def test_sum_rule(c_over_a):
    a, rho = 1.3, 700.0
    c = c_over_a * a
    D = deficit_radial(a, c, rho)
    E = cavity.cylinder_modes(a, c, rho, 60, 400)["E"]
    assert (E > 0).all()
    sums = [E[:, :j_max].sum() for j_max in (100, 200, 400)]
    residual = [D - s for s in sums]
    assert all(res > 0 for res in residual)
    # E_nj ~ j^-2 at large j, so the remainder ~ 1/j_max: it halves as j_max doubles ...
    assert all(1.9 < residual[i] / residual[i + 1] < 2.1 for i in (0, 1))
    # ... and Richardson's extrapolation to j_max -> infinity lands on the deficit.
    assert 2 * sums[2] - sums[1] == pytest.approx(D, rel=3e-5)
    for N in (1, 4, 16, 32):
        E_kept, _ = cavity.modes("cylinder", a, c, rho, N)
        t = cavity.tail("cylinder", a, c, rho, N)
        assert t >= 0 and t + E_kept.sum() == pytest.approx(D, rel=1e-12)


@pytest.mark.parametrize("c_over_a", [0.03, 0.2, 1.0, 3.0, 12.0])
def test_the_largest_modes_are_chosen(c_over_a):
    got = cavity.cylinder_modes(1.0, c_over_a, 1.0, 150, 400)
    E, kappa = got["E"], got["kappa"]
    flat = np.argsort(-E.ravel(), kind="stable")
    for N in (1, 4, 16, 32):
        # the brute-force set is big enough: nothing on its outer frame reaches the N-th largest
        frame = max(E[-1].max(), E[:, -1].max())
        assert frame < E.ravel()[flat[N - 1]]
        E_top, kappa_top = cavity.modes("cylinder", 1.0, c_over_a, 1.0, N)
        assert E_top.shape == (N,) and (np.diff(E_top) <= 0).all()
        np.testing.assert_allclose(E_top, E.ravel()[flat[:N]], rtol=1e-12)
        np.testing.assert_allclose(kappa_top, kappa.ravel()[flat[:N]], rtol=1e-12)
    assert len(cavity.modes("cylinder", 1.0, c_over_a, 1.0)[0]) == cavity.DEFAULT_MODES
    assert (np.diff(E, axis=0) < 0).all()  # in n, both branches
    assert (np.diff(E[:, :, 0], axis=1) < 0).all()  # in j, branch +
    # Branch - is not monotone in j: for small beta, E ~ (s-1)/(s^2 (s+1)) with s = |kappa|, which
    # peaks at s = golden ratio (lower for larger beta); so E falls from there on and rises below 1.5.
    dE, s = np.diff(E[:, :, 1], axis=1), -kappa[:, :, 1]
    assert (dE[s[:, :-1] >= GOLDEN] < 0).all() and (dE[s[:, 1:] <= 1.5] > 0).all()


def test_the_precessing_cylinder_resonance():
    # kappa = 2 means beta xi = sqrt 3 and xi J0(xi) + J1(xi) = 0 (root in (j_{0,1}, j_{1,1})),
    # so the mode (1, 1, +) resonates at h/a = 2 pi c/(pi a) = pi beta = pi sqrt(3) / xi.
    xi = optimize.brentq(lambda x: x * special.j0(x) + special.j1(x), special.jn_zeros(0, 1)[0], special.jn_zeros(1, 1)[0], xtol=1e-15)
    expected = np.pi * np.sqrt(3) / xi
    h = optimize.brentq(lambda h: cavity.modes("cylinder", 1.0, h / 2, 1.0, 1)[1][0] - 2.0, 1.5, 2.5, xtol=1e-14)
    assert 1.98 < h < 2.00
    assert h == pytest.approx(expected, rel=1e-10)
    assert cavity.cylinder_modes(1.0, h / 2, 1.0, 1, 1)["kappa"][0, 0, 0] == pytest.approx(2.0, rel=1e-12)


@pytest.mark.parametrize("shape", ["spheroid", "cylinder"])
def test_scaling_with_density_and_size(shape):
    q, a, rho = 0.7, 3.0, 5.0
    E1, k1 = cavity.modes(shape, 1.0, q, 1.0, 1 if shape == "spheroid" else 16)
    E2, k2 = cavity.modes(shape, a, q * a, rho, 1 if shape == "spheroid" else 16)
    np.testing.assert_allclose(E2, rho * a**5 * E1, rtol=1e-12)
    np.testing.assert_allclose(k2, k1, rtol=1e-13)
    D1, D2 = cavity.zhukovsky_deficit(shape, 1.0, q, 1.0), cavity.zhukovsky_deficit(shape, a, q * a, rho)
    assert D2 == pytest.approx(rho * a**5 * D1, rel=1e-12)
    if shape == "cylinder":
        m1, m2 = cavity.cylinder_modes(1.0, q, 1.0, 5, 7), cavity.cylinder_modes(a, q * a, rho, 5, 7)
        np.testing.assert_allclose(m2["E"], rho * a**5 * m1["E"], rtol=1e-12)
        np.testing.assert_allclose(m2["kappa"], m1["kappa"], rtol=1e-13)
        np.testing.assert_allclose(m2["xi"], m1["xi"], rtol=1e-13)


SIZE_CALLS = {
    "modes": lambda a, c, rho: cavity.modes("cylinder", a, c, rho, 4),
    "spheroid modes": lambda a, c, rho: cavity.modes("spheroid", a, c, rho),
    "cylinder_modes": lambda a, c, rho: cavity.cylinder_modes(a, c, rho, 2, 2),
    "frozen_mass": lambda a, c, rho: cavity.frozen_mass("cylinder", a, c, rho),
    "frozen_inertia": lambda a, c, rho: cavity.frozen_inertia("spheroid", a, c, rho),
    "zhukovsky_deficit": lambda a, c, rho: cavity.zhukovsky_deficit("cylinder", a, c, rho),
    "tail": lambda a, c, rho: cavity.tail("cylinder", a, c, rho, 4),
}


@pytest.mark.parametrize("call", SIZE_CALLS.values(), ids=SIZE_CALLS.keys())
@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
@pytest.mark.parametrize("name", ["radius", "half_height", "density"])
def test_bad_size(call, bad, name):
    args = {"radius": 1.0, "half_height": 1.0, "density": 1.0}
    args[name] = bad
    with pytest.raises(StabmapError, match=name):
        call(*args.values())


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: cavity.modes("cone", 1.0, 1.0, 1.0), "shape"),
        (lambda: cavity.zhukovsky_deficit("sphere", 1.0, 1.0, 1.0), "shape"),
        (lambda: cavity.frozen_mass("Cylinder", 1.0, 1.0, 1.0), "shape"),
        (lambda: cavity.tail("cone", 1.0, 1.0, 1.0, 1), "shape"),
        (lambda: cavity.modes("spheroid", 1.0, 1.0, 1.0, 2), "modes"),
        (lambda: cavity.tail("spheroid", 1.0, 1.0, 1.0, 3), "modes"),
        (lambda: cavity.modes("cylinder", 1.0, 1.0, 1.0, 0), "modes"),
    ],
)
def test_bad_shape_or_mode_count(call, name):
    with pytest.raises(StabmapError, match=name):
        call()
