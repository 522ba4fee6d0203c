"""Chernousko's viscous cavity tensor P¹ (stabmap.systems.gyroscopes.stokes, scripts/cylinder_tensor.py).

References, independent of the code under test: the ellipsoid's polynomial Stokes solution verified in sympy (PDE,
divergence, wall, integral, exact arithmetic), the sphere's 8 pi a^7 / 525 by mpmath quadrature, and the finite
element solver (scikit-fem), checked on spheroids against the closed form, for the cylinder table.
"""

from __future__ import annotations

import functools
import math
import pathlib
import runpy

import mpmath
import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import stabmap
from stabmap.errors import StabmapError
from stabmap.systems.gyroscopes import stokes

SCRIPT = pathlib.Path(__file__).resolve().parents[1] / "scripts" / "cylinder_tensor.py"


@functools.cache
def fem():
    return runpy.run_path(str(SCRIPT))


# ---- the ellipsoid, symbolically ------------------------------------------------------------------------------------
X = sp.symbols("x y z", real=True)
A = sp.symbols("a1 a2 a3", positive=True)


def _ellipsoid_field(i):
    """The claimed Stokes solution (w, pi) for rotation about axis i: the e_3 solution with the axes renamed
    cyclically, and the pressure coefficient left as an unknown c."""
    j, k = (i + 1) % 3, (i + 2) % 3
    F = 1 - sum(X[m] ** 2 / A[m] ** 2 for m in range(3))
    S = sum(1 / a**2 for a in A)
    kk = -2 / (2 * S * (A[j] ** 2 + A[k] ** 2) + 4 * (A[j] ** 2 / A[k] ** 2 + A[k] ** 2 / A[j] ** 2))
    w = [sp.Integer(0)] * 3
    w[j] = -kk * F * A[j] ** 2 * X[k]
    w[k] = kk * F * A[k] ** 2 * X[j]
    c = sp.Symbol("c")
    return sp.Matrix(w), c * X[j] * X[k], c


def _ball_integral(poly, scale):
    """∫ over the ellipsoid of a polynomial in x, y, z, by x = a1 u etc. and the unit ball's monomial moments."""
    u = sp.symbols("u0:3", real=True)
    p = sp.Poly(sp.expand(poly.subs({X[m]: scale[m] * u[m] for m in range(3)}, simultaneous=True)), *u)
    total = 0
    for powers, coef in p.terms():
        if any(e % 2 for e in powers):
            continue
        g = [sp.gamma(sp.Rational(e + 1, 2)) for e in powers]
        d = sum(powers) + 3
        total += coef * 2 * g[0] * g[1] * g[2] / (sp.gamma(sp.Rational(d, 2)) * d)
    return total * scale[0] * scale[1] * scale[2]


@pytest.mark.parametrize("i", [0, 1, 2])
def test_ellipsoid_solution_solves_the_stokes_problem(i):
    w, pi, c = _ellipsoid_field(i)
    e = sp.Matrix([1 if m == i else 0 for m in range(3)])
    forcing = e.cross(sp.Matrix(X))
    residual = [sp.together(sum(sp.diff(w[m], x, 2) for x in X) - sp.diff(pi, X[m]) - forcing[m]) for m in range(3)]
    # one pressure coefficient makes every component vanish identically
    sol = sp.solve(sp.numer(residual[(i + 1) % 3]).coeff(X[(i + 2) % 3]), c)
    assert len(sol) == 1
    assert all(sp.simplify(r.subs(c, sol[0])) == 0 for r in residual)
    assert sp.simplify(sum(sp.diff(w[m], X[m]) for m in range(3))) == 0
    # on the wall: w is a multiple of F, which is 0 there (parametrised by two angles)
    th, ph = sp.symbols("theta phi", real=True)
    wall = {X[0]: A[0] * sp.sin(th) * sp.cos(ph), X[1]: A[1] * sp.sin(th) * sp.sin(ph), X[2]: A[2] * sp.cos(th)}
    assert all(sp.simplify(w[m].subs(wall, simultaneous=True)) == 0 for m in range(3))


@pytest.mark.parametrize("i", [0, 1, 2])
def test_ellipsoid_closed_form_is_the_integral(i):
    w, _, _ = _ellipsoid_field(i)
    r_cross_w = sp.Matrix(X).cross(w)
    entries = [sp.simplify(-_ball_integral(r_cross_w[m], A)) for m in range(3)]
    off = [m for m in range(3) if m != i]
    assert all(entries[m] == 0 for m in off)  # P is diagonal
    for semi in [(1, 1, 1), (1, 2, 3), (sp.Rational(3, 10), sp.Rational(7, 4), 1), (5, sp.Rational(1, 20), 2)]:
        exact = entries[i].subs(dict(zip(A, semi)))
        got = stokes.ellipsoid_tensor(*(float(s) for s in semi))[i]
        assert float(got) == pytest.approx(float(exact), rel=1e-14)


def test_sphere_value_by_quadrature():
    # w = (r^2 - a^2)/10 (e_3 x r): -(r x w)_3 = (a^2 - r^2)/10 (x^2 + y^2), shells of area 4 pi r^2, mean of
    # x^2 + y^2 over a shell 2 r^2 / 3
    for a in (1.0, 0.37, 2.5):
        quad = mpmath.quad(lambda r: (a**2 - r**2) / 10 * (2 * r**2 / 3) * 4 * mpmath.pi * r**2, [0, a])
        assert stokes.sphere_tensor(a) == pytest.approx(float(quad), rel=1e-14)
        assert stokes.sphere_tensor(a) == pytest.approx(8 * math.pi * a**7 / 525, rel=1e-15)
        p_t, p_a, err = stabmap.cavity.viscous_tensor("spheroid", a, a)
        assert p_t == pytest.approx(8 * math.pi * a**7 / 525, rel=1e-15) and p_a == pytest.approx(p_t, rel=1e-15)
        assert err == 0.0


@pytest.mark.parametrize("radius, half_height", [(1.0, 2.5), (0.8, 0.24)])  # prolate, oblate
def test_spheroid_against_exact_integral(radius, half_height):
    w, _, _ = _ellipsoid_field(2)
    semi = [sp.nsimplify(radius), sp.nsimplify(radius), sp.nsimplify(half_height)]
    p_a = -_ball_integral(sp.Matrix(X).cross(w)[2].subs(dict(zip(A, semi))), semi)
    w, _, _ = _ellipsoid_field(0)
    p_t = -_ball_integral(sp.Matrix(X).cross(w)[0].subs(dict(zip(A, semi))), semi)
    got_t, got_a, _ = stokes.tensor("spheroid", radius, half_height)
    assert got_t == pytest.approx(float(p_t), rel=1e-14)
    assert got_a == pytest.approx(float(p_a), rel=1e-14)


def test_slender_limits():
    # long prolate spheroid: slices of Poiseuille-like flow give 2 pi a^6 c / 105 (axial) and twice that transverse
    # (the turning flow at the ends does as much work as the axial flow); flat oblate: a lubrication layer
    # gives 16 pi a^2 c^5 / 315 transverse (docs/viscous-tensors.md)
    a, c = 1.0, 1e4
    p_t, p_a, _ = stokes.tensor("spheroid", a, c)
    assert p_a == pytest.approx(2 * math.pi * a**6 * c / 105, rel=1e-6)
    assert p_t == pytest.approx(4 * math.pi * a**6 * c / 105, rel=1e-6)
    p_t, p_a, _ = stokes.tensor("spheroid", a, 1e-4)
    assert p_t == pytest.approx(16 * math.pi * a**2 * 1e-20 / 315, rel=1e-6)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(1e-3, 1e3), min_size=3, max_size=3), st.permutations([0, 1, 2]))
def test_ellipsoid_entries_follow_their_axes(semi, perm):
    """Renaming the axes renames the entries; each entry is positive and scales like length^7."""
    p = stokes.ellipsoid_tensor(*semi)
    q = stokes.ellipsoid_tensor(*(semi[i] for i in perm))
    assert np.allclose([p[i] for i in perm], q, rtol=1e-13, atol=0)
    assert all(v > 0 for v in p)
    assert np.allclose(stokes.ellipsoid_tensor(*(2.0 * s for s in semi)), [128.0 * v for v in p], rtol=1e-13, atol=0)


@pytest.mark.parametrize("shape", ["spheroid", "cylinder"])
def test_scaling_and_broadcasting(shape):
    radius = np.array([0.1, 0.5, 2.0])
    half_height = np.array([[0.3], [0.9]]) * radius
    p_t, p_a, _ = stokes.tensor(shape, radius, half_height)
    assert p_t.shape == p_a.shape == (2, 3)
    for k in range(3):
        ref_t, ref_a, _ = stokes.tensor(shape, 1.0, half_height[:, k] / radius[k])
        assert np.allclose(p_t[:, k], ref_t * radius[k] ** 7, rtol=1e-13, atol=0)
        assert np.allclose(p_a[:, k], ref_a * radius[k] ** 7, rtol=1e-13, atol=0)


# ---- the finite element solver --------------------------------------------------------------------------------------
def test_fem_sphere_coarse():
    """Quick: the meridional solvers (m = 1 Taylor-Hood, m = 0 swirl) on a coarse sphere mesh."""
    s = fem()
    exact = 8 * math.pi / 525
    errors = []
    for n in (4, 8):
        mesh = s["half_ellipse_mesh"](1.0, 1.0, n)
        errors.append([s["transverse"](mesh) / exact - 1, s["axial"](mesh) / exact - 1])
    errors = np.abs(errors)
    print("sphere, relative errors (transverse, axial) at n = 4, 8:", errors.tolist())
    assert np.all(errors[1] < 1e-4)
    assert np.all(errors[1] < errors[0] / 8)  # about n^-4 on this smooth cavity


@pytest.mark.parametrize("radius, half_height", [(1.0, 2.5), (2.0, 0.7), (1.0, 0.2)])
def test_fem_spheroids(radius, half_height):
    s = fem()
    mesh = s["half_ellipse_mesh"](radius, half_height, 32)
    p_t, p_a, _ = stokes.tensor("spheroid", radius, half_height)
    err = [s["transverse"](mesh) / p_t - 1, s["axial"](mesh) / p_a - 1]
    print(f"spheroid {radius} x {half_height}: relative errors {err}")
    assert np.all(np.abs(err) < 1e-6)


def test_fem_scaling():
    s = fem()
    small = s["cylinder_mesh"](1.0, 0.7, 8)
    big = s["cylinder_mesh"](3.0, 2.1, 8)
    assert s["transverse"](big) == pytest.approx(3.0**7 * s["transverse"](small), rel=1e-9)
    assert s["axial"](big) == pytest.approx(3.0**7 * s["axial"](small), rel=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("q", [0.0683, 1.0317, 11.7663])  # a third of the way between nodes
def test_cylinder_table_against_fresh_solve(q):
    s = fem()
    lo, hi = stokes.cylinder_range()
    nodes = np.geomspace(lo, hi, s["N_NODES"])
    assert np.min(np.abs(nodes / q - 1)) > 0.02
    f_t, f_a = s["cylinder_entries"](q, s["MESH_N"])
    t, a, rel_error = stokes.tensor("cylinder", 1.0, q)
    print(f"q = {q}: table vs fresh solve {t / f_t - 1:.2e}, {a / f_a - 1:.2e}, stated {rel_error}")
    assert abs(t / f_t - 1) <= rel_error and abs(a / f_a - 1) <= rel_error


def test_cylinder_table_against_finer_mesh():
    """The stated accuracy covers the discretisation: a solve on twice the table's mesh, where the change from
    n/2 to n was largest (h/a near 1, the coarsest mesh)."""
    s = fem()
    q = 1.0317
    f_t, f_a = s["cylinder_entries"](q, 2 * s["MESH_N"])
    t, a, rel_error = stokes.tensor("cylinder", 1.0, q)
    print(f"q = {q}: table vs mesh n = {2 * s['MESH_N']}: {t / f_t - 1:.2e}, {a / f_a - 1:.2e}, stated {rel_error}")
    assert abs(t / f_t - 1) <= rel_error and abs(a / f_a - 1) <= rel_error


def test_cylinder_table_limits():
    """The table's ends against the slender and thin-layer limits (docs/viscous-tensors.md): slopes pi/12, pi/24
    for a long cylinder; 8 pi q^5 / 45 and pi q^3 / 3 for a flat one, up to an edge correction of order q."""
    lo, hi = stokes.cylinder_range()
    assert lo <= 0.05 and hi >= 20.0
    q1, q2 = 16.0, 20.0
    (t1, t2), (a1, a2), _ = stokes.cylinder_scaled(np.array([q1, q2]))
    assert (t2 - t1) / (q2 - q1) == pytest.approx(math.pi / 12, rel=1e-4)
    assert (a2 - a1) / (q2 - q1) == pytest.approx(math.pi / 24, rel=1e-4)
    for q in (0.05, 0.1):
        t, a, _ = stokes.cylinder_scaled(q)
        assert abs(t / (8 * math.pi * q**5 / 45) - 1) < 1.5 * q
        assert abs(a / (math.pi * q**3 / 3) - 1) < 3.0 * q
    t05, a05, _ = stokes.cylinder_scaled(0.05)
    t10, a10, _ = stokes.cylinder_scaled(0.1)  # the edge correction halves with q
    assert 1.6 < (1 - t10 / (8 * math.pi * 0.1**5 / 45)) / (1 - t05 / (8 * math.pi * 0.05**5 / 45)) < 2.4


def test_generator_quick_mode(capsys, tmp_path):
    """The script's own pipeline (meshes, both solvers, the spline check) runs, coarse, and writes nothing."""
    fem()["main"](["--quick", "-o", str(tmp_path / "t.csv")])
    assert "5 nodes, mesh n = 8" in capsys.readouterr().out
    assert not (tmp_path / "t.csv").exists()


def test_cylinder_table_file():
    text = (pathlib.Path(stokes.__file__).with_name("data") / "cylinder_tensor.csv").read_text()
    assert "scripts/cylinder_tensor.py" in text and "rel_error" in text
    _, _, rel_error = stokes.tensor("cylinder", 1.0, 1.0)
    assert 0 < rel_error <= 1e-4


# ---- errors ---------------------------------------------------------------------------------------------------------
def test_cylinder_range_errors():
    lo, hi = stokes.cylinder_range()
    stokes.tensor("cylinder", 1.0, lo)
    stokes.tensor("cylinder", 2.0, 2.0 * hi)
    for radius, half_height in [(1.0, 0.9 * lo), (1.0, 1.1 * hi), (np.array([1.0, 1.0]), np.array([1.0, 30.0]))]:
        with pytest.raises(StabmapError, match=r"half_height.*radius.*0\.05.*20"):
            stokes.tensor("cylinder", radius, half_height)
    with pytest.raises(StabmapError, match="radius"):
        stokes.tensor("cylinder", -1.0, 1.0)
    with pytest.raises(StabmapError, match="half_height"):
        stokes.tensor("spheroid", 1.0, float("nan"))
    with pytest.raises(StabmapError, match="shape.*cone"):
        stokes.tensor("cone", 1.0, 1.0)


def test_check_tensor_accepts():
    assert stabmap.cavity.check_viscous_tensor([2e-5, 3e-5]) == (2e-5, 3e-5)
    assert stokes.check_tensor([[2.0, 0, 0], [0, 2.0 * (1 + 1e-14), 0], [0, 0, 3.0]]) == (2.0, 3.0)
    assert stokes.check_tensor(np.diag([1.0, 1.0, 0.5]).tolist()) == (1.0, 0.5)


@pytest.mark.parametrize("value, words", [
    ([1.0, 2.0, 3.0], "2 entries or 3x3"),
    ([[1.0, 0.0], [0.0, 1.0]], "2 entries or 3x3"),
    ("1e-5", "2 entries or 3x3"),
    ([[1.0, 2.0]], "2 entries or 3x3"),
    ([1.0, "x"], "2 numbers or 3x3 numbers"),
    ([[1.0, 0, 0], [0, 1.0], [0, 0, 2.0]], "2 numbers or 3x3 numbers"),
    ({"P_t": 1.0}, "2 numbers or 3x3 numbers"),
    ([True, 2.0], "2 numbers or 3x3 numbers"),
    ([1.0, float("inf")], "finite"),
    ([-1.0, 2.0], "> 0"),
    ([0.0, 2.0], "> 0"),
    ([[1.0, 0, 0], [0, 1.0, 0], [0, 0, -2.0]], "> 0"),
    ([[1.0, 0.1, 0], [0, 1.0, 0], [0, 0, 2.0]], "symmetric"),
    ([[1.0, 0.1, 0], [0.1, 1.0, 0], [0, 0, 2.0]], "diagonal"),
    ([[1.0, 0, 0], [0, 1.1, 0], [0, 0, 2.0]], "axisymmetric"),
])
def test_check_tensor_errors(value, words):
    with pytest.raises(StabmapError) as info:
        stokes.check_tensor(value, "bodies[2].cavity.tensor")
    msg = str(info.value)
    assert msg.startswith("bodies[2].cavity.tensor:") and words in msg and "[P_t, P_a]" in msg
