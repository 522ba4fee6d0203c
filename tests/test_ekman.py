"""stabmap.systems.gyroscopes.ekman against references it does not compute itself.

- The sphere's spin-over coefficient and the oblate slope at the sphere: Greenspan (1968), Zhang, Liao & Earnshaw
  (2004), as coded in the Kore solver's spin-over function (the note /work/shared/FINITE_RE.md, section 2b and 5).
- The spheroid and cylinder tables of FINITE_RE.md sections 2b and 2c (throwaway scripts with their own root solver
  and their own quadrature), and section 5's independent linear Navier-Stokes eigen-solves of the cylinder.
- The cylinder's closed form against the general wall integral evaluated by quadrature on the mode's velocity field.

Conventions: solutions ~ exp(i lambda t); g = -i s_1 where s = i lambda_hat + E^{1/2} s_1 (Greenspan's e^{st} form).
"""

from __future__ import annotations

import math

import pytest

from stabmap.errors import StabmapError
from stabmap.systems.gyroscopes import ekman


def s1_of(g: complex) -> complex:
    """Greenspan's s_1 from stabmap's g = -i s_1."""
    return 1j * g


# --- spheroid ---------------------------------------------------------------------------------------------------


def test_sphere_is_greenspans_spin_over_value():
    # s_1 = -2.62047 + 0.25846i (Greenspan 1968; Zhang, Liao & Earnshaw 2004), so g = 0.25846 + 2.62047i
    g = ekman.spheroid_g(1.0)
    assert abs(g.real - 0.25846) <= 5e-6
    assert abs(g.imag - 2.62047) <= 5e-6
    s1 = s1_of(g)
    assert abs(s1.real + 2.62047) <= 5e-6 and abs(s1.imag - 0.25846) <= 5e-6


def test_oblate_slope_at_the_sphere_is_zhang_liao_earnshaw():
    # Zhang et al. (2004): s_1 = (-2.62047 - 0.42634 e2) + i (0.25846 + 0.76633 e2) + O(e2^2), e2 = 1 - c^2/a^2,
    # E with the equatorial radius.  Central differences in e2 (e2 < 0 is prolate): error O(step^2) ~ 1e-7.
    step = 1e-3
    g_plus = ekman.spheroid_g(math.sqrt(1.0 - step))
    g_minus = ekman.spheroid_g(math.sqrt(1.0 + step))
    slope = s1_of((g_plus - g_minus) / (2 * step))
    assert abs(slope.real + 0.42634) <= 1e-5
    assert abs(slope.imag - 0.76633) <= 1e-5


# FINITE_RE.md section 2b: g of stabmap's spheroid mode, 4 decimals.
SPHEROID_TABLE = [
    (0.25, 2.1237, 3.1755),
    (0.5, 1.4284, 3.0319),
    (0.7, 0.8688, 2.8768),
    (0.9, 0.4278, 2.7063),
    (1.0, 0.2585, 2.6205),
    (1.2, 0.0090, 2.4546),
    (1.5, -0.2008, 2.2311),
    (2.0, -0.3180, 1.9356),
    (3.0, -0.2950, 1.5572),
]


@pytest.mark.parametrize(("c_over_a", "re_g", "im_g"), SPHEROID_TABLE)
def test_spheroid_table(c_over_a, re_g, im_g):
    # The table's 4 decimals were rounded from its script's 5 (1.42835 -> 1.4284 at c/a = 0.5, 1.93555 -> 1.9356 at
    # c/a = 2, where the values are 1.4283500 and 1.9355472): so up to half a unit of the 4th decimal plus half of
    # the 5th, 5.5e-5.
    g = ekman.spheroid_g(c_over_a)
    assert abs(g.real - re_g) <= 5.5e-5 + 1e-9
    assert abs(g.imag - im_g) <= 5.5e-5 + 1e-9
    assert g.imag > 0


def test_spheroid_decays_everywhere():
    for c_over_a in (0.1, 0.3, 0.6, 0.95, 1.05, 1.7, 2.5, 5.0):
        assert ekman.spheroid_g(c_over_a).imag > 0


# --- cylinder ---------------------------------------------------------------------------------------------------

# (c/a, n, j, sign): both branches, higher n and j, flat and tall cylinders, lambda_hat of either sign and near 0.
CYLINDER_MODES = [
    (0.5, 1, 1, 1),
    (1.0, 1, 1, 1),
    (1.0, 1, 1, -1),
    (0.3, 1, 3, 1),
    (0.5, 1, 2, -1),
    (1.3, 2, 3, -1),
    (2.0, 3, 2, 1),
    (3.1, 2, 1, 1),
    (4.0, 1, 1, -1),
    (6.0, 1, 5, 1),
]


@pytest.mark.parametrize(("c_over_a", "n", "j", "sign"), CYLINDER_MODES)
def test_cylinder_closed_form_is_the_wall_integral(c_over_a, n, j, sign):
    closed = ekman.cylinder_g(c_over_a, n, j, sign)
    quadrature = ekman.cylinder_g_by_quadrature(c_over_a, n, j, sign)
    assert abs(closed - quadrature) <= 1e-9 * abs(closed)
    assert closed.imag > 0


# FINITE_RE.md section 2c: lambda_hat to 6 decimals, g to 4.
CYLINDER_TABLE = [
    (0.5, 1, 1, 1, 1.561654, 1.0752 + 1.8659j),
    (1.0, 1, 1, 1, 0.995534, 0.0534 + 1.4471j),
    (1.0, 1, 1, -1, -0.627854, 0.0298 + 1.5218j),
    (1.1, 1, 1, 1, 0.913229, -0.0506 + 1.3786j),
    (2.0, 1, 1, 1, 0.489818, -0.3603 + 0.9607j),
    (3.0, 2, 1, 1, 0.995534, -0.3953 + 0.8955j),
    (3.1, 2, 1, 1, 0.966970, -0.4107 + 0.8905j),
    (4.0, 1, 1, -1, -0.186633, 0.2462 + 0.5484j),
]


@pytest.mark.parametrize(("c_over_a", "n", "j", "sign", "lam", "g_ref"), CYLINDER_TABLE)
def test_cylinder_table(c_over_a, n, j, sign, lam, g_ref):
    _, lam_hat, _ = ekman.cylinder_mode(c_over_a, n, j, sign)
    assert abs(lam_hat - lam) <= 5e-7 + 1e-12
    g = ekman.cylinder_g(c_over_a, n, j, sign)
    assert abs(g.real - g_ref.real) <= 5e-5 + 1e-12
    assert abs(g.imag - g_ref.imag) <= 5e-5 + 1e-12
    assert g.imag > 0


def test_cylinder_mode_n_at_c_is_mode_1_at_c_over_2n_minus_1():
    # the table's (2, 1, +) at c/a = 3 has the frequency of (1, 1, +) at c/a = 1 (0.995534 both)
    assert ekman.cylinder_mode(3.0, 2, 1, 1)[1] == pytest.approx(ekman.cylinder_mode(1.0, 1, 1, 1)[1], rel=1e-13)


# FINITE_RE.md section 5: s_1 of the closed form to 5 decimals, and the Navier-Stokes eigen-solves (Chebyshev
# collocation, no slip, E = 1e-3 ... 3e-5) extrapolated in E^{1/2}, which agree within 0.1-1.5 %.
NAVIER_STOKES = [
    (1.0, 1, 1, 1, -1.44709 + 0.05335j, -1.446 + 0.052j),
    (1.0, 1, 1, -1, -1.52179 + 0.02983j, -1.513 + 0.035j),
    (0.5, 1, 1, 1, -1.86593 + 1.07517j, -1.852 + 1.091j),
]


@pytest.mark.parametrize(("c_over_a", "n", "j", "sign", "s1_closed", "s1_ns"), NAVIER_STOKES)
def test_cylinder_against_navier_stokes(c_over_a, n, j, sign, s1_closed, s1_ns):
    s1 = s1_of(ekman.cylinder_g(c_over_a, n, j, sign))
    assert abs(s1.real - s1_closed.real) <= 5e-6 + 1e-12
    assert abs(s1.imag - s1_closed.imag) <= 5e-6 + 1e-12
    assert abs(s1 - s1_ns) <= 0.015 * abs(s1_ns)


def test_every_cylinder_mode_decays():
    for c_over_a in (0.2, 0.5, 1.0, 1.99, 2.5, 5.0, 10.0):
        for n in (1, 2, 3):
            for j in range(1, 7):
                for sign in (1, -1):
                    assert ekman.cylinder_g(c_over_a, n, j, sign).imag > 0, (c_over_a, n, j, sign)


# --- epsilon and Re ---------------------------------------------------------------------------------------------


def test_epsilon_of_water_in_the_shell_of_the_note():
    # FINITE_RE.md section 4: water (nu = 1e-6), a = 5 cm, omega = 1593 rad/s: Re 4e6, and Im epsilon = 1.10 1/s
    # for mode (1, 1, +) at c/a = 1.1
    assert ekman.reynolds(1593.0, 0.05, 1e-6) == pytest.approx(3.9825e6, rel=1e-12)
    eps = ekman.epsilon(ekman.cylinder_g(1.1, 1, 1, 1), 1e-6, 1593.0, 0.05)
    assert abs(eps.imag - 1.10) <= 0.005


@pytest.mark.parametrize("g", [0.25846 + 2.62047j, -0.3603 + 0.9607j, 0.2462 + 0.5484j])
def test_epsilon_mirrors_with_the_spin(g):
    for nu, omega, a in ((1e-6, 1593.0, 0.05), (1e-4, 20.0, 0.3), (2.5e-5, 0.7, 1.0)):
        up = ekman.epsilon(g, nu, omega, a)
        down = ekman.epsilon(g, nu, -omega, a)
        assert down == pytest.approx(-up.conjugate(), rel=1e-15)
        assert up == pytest.approx(g * math.sqrt(nu * omega) / a, rel=1e-15)
        assert up.imag > 0 and down.imag > 0  # decay for either spin
        # epsilon = g omega Re^{-1/2}
        assert up == pytest.approx(g * omega / math.sqrt(ekman.reynolds(omega, a, nu)), rel=1e-14)
    assert ekman.epsilon(g, 1e-6, 0.0, 0.05) == 0


@pytest.mark.parametrize(
    "call",
    [
        lambda: ekman.spheroid_g(0.0),
        lambda: ekman.spheroid_g(float("nan")),
        lambda: ekman.cylinder_g(-1.0, 1, 1, 1),
        lambda: ekman.cylinder_g(1.0, 0, 1, 1),
        lambda: ekman.cylinder_g(1.0, 1, 0, 1),
        lambda: ekman.cylinder_g(1.0, 1, 1, 0),
        lambda: ekman.cylinder_g_by_quadrature(1.0, 1, 1, 2),
    ],
)
def test_bad_input(call):
    with pytest.raises(StabmapError):
        call()
