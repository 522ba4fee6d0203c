"""Cavities in scenes: parsing, validation, the engine's use of the modes, and the physical limits.

The closed forms themselves are checked against quadrature in test_cavity_modes.py;
here the references are the paper-independent limits of docs/model.md (Greenhill's
spinning shell, the sphere) worked out in sympy, and scenes written out by hand.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import sympy as sp

from stabmap import load_scene, loads_scene
from stabmap.run import atlas
from stabmap.systems.gyroscopes import cavity, scene
from stabmap.errors import StabmapError
from stabmap.systems.gyroscopes.points import point_arrays
from tests import reference

TOP = """
title = "top with a cavity"
support = "fixed"
g = 9.81
omega = 120.0
[[bodies]]
m = 3.0
A = 0.05
C = 0.02
c = 0.2
{cavity}
{grid}
"""
CYLINDER = 'cavity = { shape = "cylinder", radius = 0.05, half_height = 0.055, density = 1000.0, modes = 3 }'


def top(cavity_line=CYLINDER, grid="") -> scene.Scene:
    return loads_scene(TOP.format(cavity=cavity_line, grid=grid))


def test_greenhill_closed_form_from_the_spheroid_formulas():
    # Massless shell, fixed point at the centre, no gravity: p / lam must be
    # proportional to lam^2 + omega lam + 2 omega^2 a^2 / (c^2 - a^2) (docs/model.md).
    a, c, rho, w, lam = sp.symbols("a c rho omega lam", positive=True)
    m_f = sp.Rational(4, 3) * sp.pi * rho * a**2 * c
    A, C = m_f * (a**2 + c**2) / 5, 2 * m_f * a**2 / 5
    E = sp.Rational(16, 15) * sp.pi * rho * a**4 * c**3 / (a**2 + c**2)
    kappa = 1 + c**2 / a**2
    beta = lam + w - 2 * w / kappa
    p = sp.expand((lam**2 * A + lam * C * w) * beta - lam**2 * (lam + w) * E)
    quadratic = sp.Poly(sp.cancel(p / lam), lam)
    target = sp.Poly(lam**2 + w * lam + 2 * w**2 * a**2 / (c**2 - a**2), lam)
    ratio = sp.simplify(quadratic.LC() / target.LC())
    assert all(sp.simplify(x - ratio * y) == 0 for x, y in zip(quadratic.all_coeffs(), target.all_coeffs()))


def test_greenhill_band_in_the_engine():
    # Kelvin's spinning shell: unstable exactly for a < c < 3a.
    ratios = np.array([0.3, 0.6, 0.9, 0.99, 1.01, 1.5, 2.0, 2.9, 2.99, 3.01, 3.5, 5.0])
    s = loads_scene(f"""
support = "fixed"
g = 0.0
omega = 7.0
[[bodies]]
m = 0.0
A = 0.0
C = 0.0
c = 0.0
cavity = {{ shape = "spheroid", radius = 1.0, half_height = 1.0, density = 800.0, liquid_in_body = false, centre = 0.0 }}
[grid]
half_height_1 = {{ values = {ratios.tolist()} }}
""")
    ds = atlas.compute(s, progress=False, threads=1)
    expected = ((ratios > 1) & (ratios < 3)).astype(int)
    assert ds.n_complex_pairs.values.tolist() == expected.tolist()


def _dry_equivalent(m_s, A_s, C_s, c_s, z, m_f):
    """The shell plus the liquid as a point mass at z: what a spherical cavity must reduce to."""
    m = m_s + m_f
    c = (m_s * c_s + m_f * z) / m
    return m, A_s + m_s * (c_s - c) ** 2 + m_f * (z - c) ** 2, C_s, c


def test_sphere_drops_out_exactly():
    # In exact arithmetic: p_wet = lam * p_dry when E = J_f = C_f and kappa = 2.
    m_s, A_s, C_s, c_s, z, w, g = (sp.Rational(v) for v in ("1.5", "0.02", "0.03", "0.1", "0.25", "40", "9.81"))
    m_f, J_f = sp.Rational(3, 10), sp.Rational(3, 1000)
    m, A, C, c = _dry_equivalent(m_s, A_s, C_s, c_s, z, m_f)
    wet = reference.char_poly([dict(m=m, A=A + J_f, C=C + J_f, c=c, s=0, omega=w, E=[J_f], kappa=[2])], "fixed", g=g)
    dry = reference.char_poly([dict(m=m, A=A, C=C, c=c, s=0, omega=w)], "fixed", g=g)
    assert wet == sp.Poly(reference.lam, reference.lam, domain=sp.QQ) * dry


def test_sphere_drops_out_in_the_engine():
    # The same through the scene layer: a spherical cavity changes nothing but the mass distribution.
    m_s, A_s, C_s, c_s, z, a, rho = 1.5, 0.02, 0.03, 0.1, 0.25, 0.04, 1000.0
    m_f = float(cavity.frozen_mass("spheroid", a, a, rho))
    m, A, C, c = _dry_equivalent(m_s, A_s, C_s, c_s, z, m_f)
    omega = np.linspace(1.0, 60.0, 400)
    wet = loads_scene(f"""
g = 9.81
[[bodies]]
m = {m_s}
A = {A_s}
C = {C_s}
c = {c_s}
cavity = {{ shape = "spheroid", radius = {a}, half_height = {a}, density = {rho}, liquid_in_body = false, centre = {z} }}
[grid]
omega = {{ values = {omega.tolist()} }}
""")
    nc = atlas.compute(wet, progress=False, threads=1).n_complex_pairs.values
    critical = np.sqrt(4 * A_dry_about_joint(m, A, c) * m * c * 9.81) / C  # Maievskii
    far = np.abs(omega - critical) > 1e-6 * critical
    assert np.array_equal(nc[far], (omega < critical)[far].astype(int))


def A_dry_about_joint(m, A, c):
    return A + m * c**2


def test_cavity_equals_explicit_modes_with_the_tail_in_A():
    s = top()
    E, kappa = cavity.modes("cylinder", 0.05, 0.055, 1000.0, 3)
    tail = cavity.tail("cylinder", 0.05, 0.055, 1000.0, 3)
    assert tail > 0
    explicit = loads_scene(TOP.format(cavity=f"fluid = {{ E = {E.tolist()}, kappa = {kappa.tolist()} }}", grid="").replace("A = 0.05", f"A = {0.05 - tail!r}"))
    got, want = point_arrays(s, {}), point_arrays(explicit, {})
    for x, y in zip(got.kernel_args()[:5], want.kernel_args()[:5]):
        np.testing.assert_array_equal(x, y)
    no_tail = point_arrays(top(CYLINDER.replace("modes = 3", "modes = 3, tail = false")), {})
    assert no_tail.body[0, 0, 1] == 0.05


def test_scanned_cavity_axes_match_one_scene_per_value():
    grid = """[grid]
omega = { start = 80.0, stop = 200.0, num = 25 }
half_height_1 = { values = [0.02, 0.055, 0.09] }
density_1 = { values = [500.0, 1000.0] }"""
    ds = atlas.compute(top(grid=grid), progress=False, threads=1)
    for h in (0.02, 0.055, 0.09):
        for rho in (500.0, 1000.0):
            line = CYLINDER.replace("half_height = 0.055", f"half_height = {h}").replace("density = 1000.0", f"density = {rho}")
            one = atlas.compute(top(line, "[grid]\nomega = { start = 80.0, stop = 200.0, num = 25 }"), progress=False, threads=1)
            assert np.array_equal(ds.n_complex_pairs.sel(half_height_1=h, density_1=rho).values, one.n_complex_pairs.values)
    assert ds.half_height_1.attrs["units"] == "m" and float(ds.radius_1) == 0.05


def test_liquid_not_in_body_is_added_with_parallel_axes():
    dry = top(CYLINDER.replace("modes = 3", "modes = 3, liquid_in_body = false, centre = 0.3"))
    m_f = float(cavity.frozen_mass("cylinder", 0.05, 0.055, 1000.0))
    J_f, Jz_f = (float(v) for v in cavity.frozen_inertia("cylinder", 0.05, 0.055, 1000.0))
    m, A, C, c = _dry_equivalent(3.0, 0.05, 0.02, 0.2, 0.3, m_f)
    tail = cavity.tail("cylinder", 0.05, 0.055, 1000.0, 3)
    body = point_arrays(dry, {}).body[0, 0]
    np.testing.assert_allclose(body[:4], [m, A + J_f - tail, C + Jz_f, c], rtol=1e-14)


def test_table_inline_csv_and_toml_files(tmp_path):
    (tmp_path / "modes.csv").write_text("# two modes\nE,lambda_over_omega\n0.002,1.0\n0.0003,-0.5\n")
    (tmp_path / "modes.toml").write_text("E = [0.002, 0.0003]\nkappa = [2.0, -4.0]\n")
    inline = top('cavity = { shape = "table", E = [0.002, 0.0003], kappa = [2.0, -4.0] }')
    for name in ("modes.csv", "modes.toml"):
        path = tmp_path / "scene.toml"
        path.write_text(TOP.format(cavity=f'cavity = {{ shape = "table", file = "{name}" }}', grid=""))
        from_file = load_scene(path)
        assert from_file.bodies[0].cavity == inline.bodies[0].cavity
        assert loads_scene(from_file.to_toml()) == from_file  # the atlas stores the modes, not the path
    with_tail = top('cavity = { shape = "table", E = [0.002], kappa = [2.0], deficit = 0.0025 }')
    assert point_arrays(with_tail, {}).body[0, 0, 1] == pytest.approx(0.05 - 0.0005, rel=1e-14)


def test_round_trip_of_geometric_cavities():
    for line in (CYLINDER, CYLINDER.replace("modes = 3", "modes = 2, tail = false, liquid_in_body = false, centre = -0.1"),
                 'cavity = { shape = "spheroid", radius = 0.05, half_height = 0.08, density = 900.0 }'):
        s = top(line)
        assert loads_scene(s.to_toml()) == s
    assert top().degree == 2 + 3
    assert top('cavity = { shape = "spheroid", radius = 0.05, half_height = 0.08, density = 900.0 }').degree == 3


@pytest.mark.parametrize(
    "line, grid, message",
    [
        ('cavity = { shape = "cone", radius = 1.0 }', "", "bodies[1].cavity.shape must be"),
        (CYLINDER.replace("radius = 0.05", "radius = 0.0"), "", "bodies[1].cavity.radius must be > 0"),
        (CYLINDER.replace("half_height = 0.055", "half_height = -1.0"), "", "bodies[1].cavity.half_height must be > 0"),
        (CYLINDER.replace("density = 1000.0", "density = 0"), "", "bodies[1].cavity.density must be > 0"),
        (CYLINDER.replace(", density = 1000.0", ""), "", "bodies[1].cavity.density is missing"),
        (CYLINDER.replace("modes = 3", "modes = 0"), "", "bodies[1].cavity.modes must be a whole number"),
        ('cavity = { shape = "spheroid", radius = 0.05, half_height = 0.05, density = 1000.0, modes = 3 }', "", "exactly one coupling mode"),
        (CYLINDER.replace("modes = 3", "modes = 3, centre = 0.1"), "", "centre is used only with liquid_in_body = false"),
        (CYLINDER.replace("modes = 3", "modes = 3, tail = 1"), "", "tail must be true or false"),
        (CYLINDER.replace("modes = 3", "modes = 3, E = [1.0]"), "", "unknown key 'E' for shape 'cylinder'"),
        ('cavity = { shape = "table", E = [0.001], kappa = [1.0] }', "", "kappa[1] = 1.0: a cavity mode has |kappa| > 1"),
        ('cavity = { shape = "table", E = [0.001], kappa = [-0.5] }', "", "|kappa| > 1"),
        ('cavity = { shape = "table", E = [0.0], kappa = [2.0] }', "", "E[1] must be > 0"),
        ('cavity = { shape = "table", E = [0.001], kappa = [2.0], inertia = 0.0005 }', "", "exceeds the frozen liquid's transverse inertia"),
        ('cavity = { shape = "table", E = [0.06], kappa = [2.0] }', "", "exceeds A = 0.05"),
        ('cavity = { shape = "table", E = [0.001], lambda_over_omega = [2.5] }', "", "0 < |lambda/omega| < 2"),
        ('cavity = { shape = "table", E = [0.001, 0.002], kappa = [2.0] }', "", "E has 2 values but kappa has 1"),
        ('cavity = { shape = "table", file = "nope.csv" }', "", "cannot read"),
        (CYLINDER.replace("radius = 0.05, half_height = 0.055", "radius = 0.04, half_height = 0.25"), "", "A = 0.05 is less than the frozen liquid's"),
        (CYLINDER, "[grid]\nradius_1 = { values = [0.05, 0.1] }", "m = 3 is less than the frozen liquid's"),
        ('cavity = { shape = "table", E = [0.001], kappa = [2.0] }', "[grid]\nradius_1 = { values = [0.05] }", "body 1 has no spheroid or cylinder cavity"),
        ("", "[grid]\ndensity_1 = { values = [1000.0] }", "body 1 has no spheroid or cylinder cavity"),
        (CYLINDER, "[grid]\nradius_2 = { values = [0.05] }", "bodies are numbered 1..1"),
    ],
)
def test_bad_cavities_are_named(line, grid, message):
    with pytest.raises(StabmapError) as err:
        top(line, grid)
    assert message in str(err.value)


def test_cli_rejects_a_bad_cavity_without_writing(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(TOP.format(cavity=CYLINDER.replace("density = 1000.0", "density = -5.0"), grid=""))
    run = subprocess.run([sys.executable, "-m", "stabmap", "atlas", str(path), "-o", str(tmp_path / "a.nc")], capture_output=True, text=True)
    assert run.returncode == 2 and "bodies[1].cavity.density must be > 0" in run.stderr
    assert not (tmp_path / "a.nc").exists()


def test_info_says_why_a_cylinder_keeps_its_modes():
    """A scene without modes keeps the default count and info says so (issue 30: it used to claim the scene asked)."""
    default = dict(top(CYLINDER.replace(", modes = 3", "")).notes())["body 1"]
    assert "8 liquid modes kept (modes = 8, the default count)" in default
    assert "as the scene's modes = 3 asks" in dict(top().notes())["body 1"]


def test_a_cylinders_height_axis_is_not_called_a_polar_semi_axis():
    """issue 30: the half_height axis of a cylinder was labelled "(polar semi-axis)", a spheroid's word."""
    s = top(grid="[grid]\nhalf_height_1 = { start = 0.04, stop = 0.08, num = 3 }")
    name = s.parameter("half_height_1").long_name
    assert name.startswith("half height of the cavity of body 1") and "half a cylinder's length" in name
