"""Projectiles (an overturning moment M_alpha, the stability factor S_g) and the ratio axes C_over_A_k and aspect_k.

References: the classical rigid-shell criterion S_g >= 1 (p = A lam^2 + C omega lam + M_alpha, in exact rationals
of the kernel's inputs), docs/model.md restated in sympy (tests/reference.py) with the moment as -M_alpha at (1, 1),
and, for the ratio axes, the underlying values worked out by hand in the test and decided one by one.
"""

from __future__ import annotations

import math
from fractions import Fraction

import flint
import mpmath
import numpy as np
import pytest
import sympy as sp
from scipy import special

import reference as ref
from stabmap import loads_scene
from stabmap.errors import StabmapError
from stabmap.read.info import describe
from stabmap.run import atlas
from stabmap.run.critical import critical
from stabmap.systems.gyroscopes import SYSTEM, exact
from stabmap.systems.gyroscopes.boxes import box_axes
from stabmap.systems.gyroscopes.points import point_arrays

SHELL = """
title = "rigid shell"
M_alpha = {M}
omega = 10.0
{extra}
[[bodies]]
m = {m}
A = {A}
C = {C}
c = 0.0
{body}
[grid]
{grid}
"""


def shell(grid: str, M=4.0, A=1.0, C=0.5, extra="", body="", m=1.0):
    return loads_scene(SHELL.format(M=M, A=A, C=C, extra=extra, body=body, grid=grid, m=m))


def exact_pairs(scene, values: dict) -> list[int]:
    """N_c at the points ``values`` from the exact path (python-flint), on the kernel's inputs."""
    pts = point_arrays(scene, values)
    return [exact.complex_pairs(exact.char_poly(pts.body[p], pts.joint[p], pts.g[p], pts.E[p], pts.kappa[p], pts.nmodes,
                                                pts.free, pts.parent, pts.at[p])) for p in range(pts.body.shape[0])]


def test_moment_enters_as_minus_M_alpha_at_the_fixed_point():
    # One rigid body on its centre of mass: p = A lam^2 + C omega lam + M_alpha (M_alpha overturns: -K = +M_alpha).
    s = shell('M_alpha = { values = [-3.0, 0.0, 2.5] }', A=0.75, C=0.375)
    lam = sp.symbols("lam")
    for M in (-3.0, 0.0, 2.5):
        pts = point_arrays(s, {"M_alpha": np.array([M])})
        p = exact.char_poly(pts.body[0], pts.joint[0], pts.g[0], pts.E[0], pts.kappa[0], pts.nmodes, False, pts.parent, pts.at[0])
        want = sp.Poly(sp.Rational(3, 4) * lam**2 + sp.Rational(3, 8) * 10 * lam + sp.Rational(M), lam)
        assert [sp.Rational(str(c)) for c in p.coeffs()] == want.all_coeffs()[::-1]


def test_a_chain_with_a_moment_on_body_1_is_the_model_with_minus_M_alpha_at_1_1():
    text = """
    M_alpha = 3.5
    g = 9.81
    omega = 40.0
    joints = [12.0]
    [[bodies]]
    m = 2.0
    A = 0.03
    C = 0.02
    c = 0.0
    s = 0.2
    fluid = { E = [1e-3], kappa = [1.7] }
    [[bodies]]
    m = 0.5
    A = 0.004
    C = 0.006
    c = 0.05
    """
    s = loads_scene(text)
    pts = point_arrays(s, {})
    p = exact.char_poly(pts.body[0], pts.joint[0], pts.g[0], pts.E[0], pts.kappa[0], pts.nmodes, False, pts.parent, pts.at[0])
    bodies = [dict(m=2.0, A=0.03, C=0.02, c=0.0, s=0.2, omega=40.0, E=[1e-3], kappa=[1.7]),
              dict(m=0.5, A=0.004, C=0.006, c=0.05, s=0.0, omega=40.0)]
    want = ref.char_poly(bodies, "fixed", g=9.81, joints=[12.0], K0=-3.5)
    assert [sp.Rational(str(c)) for c in p.coeffs()] == want.all_coeffs()[::-1]


def test_rigid_shell_is_stable_exactly_where_S_g_is_at_least_one():
    # The classical criterion, on the kernel's inputs: the spin S_g sets is a rounded 2 sqrt(A M S_g) / C, so the
    # reference is the discriminant of A lam^2 + C omega lam + M_alpha at that very omega, in exact rationals.
    values = np.concatenate([np.linspace(0.2, 3.0, 57), 1.0 + np.array([-1e-12, -1e-15, 1e-15, 1e-12])])
    values = np.unique(values)
    A, C, M = 0.0123, 0.00207, 11.3
    s = shell("S_g = { values = [%s] }" % ", ".join(repr(float(v)) for v in values), M=M, A=A, C=C)
    ds = atlas.compute(s, progress=False, threads=1)
    omega = ds["omega"].values
    for S, w, nc in zip(values, omega, ds.n_complex_pairs.values):
        assert abs(w - 2 * math.sqrt(A * M * S) / C) <= 4e-16 * w  # the coordinate is the spin S_g set
        disc = (Fraction(C) * Fraction(float(w))) ** 2 - 4 * Fraction(A) * Fraction(M)
        assert nc == (1 if disc < 0 else 0)
        if abs(S - 1) > 1e-12:
            assert nc == (1 if S < 1 else 0)
    sg = ds["omega"].attrs
    assert "S_g" in sg["comment"] and sg["units"] == "rad s-1"


def test_S_g_equal_to_one_is_a_double_root_and_counts_as_stable():
    # A M S_g = 4 and C = 0.5: omega = 8 exactly, p = lam^2 + 4 lam + 4 = (lam + 2)^2 (python-flint).
    s = shell("S_g = { values = [0.75, 1.0, 1.25] }")
    pts = point_arrays(s, {"S_g": np.array([1.0])})
    assert pts.body[0, 0, 5] == 8.0
    p = exact.char_poly(pts.body[0], pts.joint[0], pts.g[0], pts.E[0], pts.kappa[0], pts.nmodes, False, pts.parent, pts.at[0])
    assert p == flint.fmpq_poly([4, 4, 1])
    assert p.numer().complex_roots() == [(p.numer().complex_roots()[0][0], 2)] and exact.complex_pairs(p) == 0
    ds = atlas.compute(s, progress=False, threads=1)
    assert ds.n_complex_pairs.values.tolist() == [1, 0, 0]
    assert SYSTEM.variable("decided_by").meaning(int(ds.decided_by.values[1])) == "exact_rational_arithmetic"


def test_critical_along_S_g_brackets_one_with_no_gaps():
    s = shell("S_g = { start = 0.3, stop = 2.0, num = 18 }", A=0.0123, C=0.00207, M=11.3)
    assert "S_g" in box_axes(s)
    ds = critical(s, "S_g", rtol=1e-10)
    assert int(ds["n_undecided"].values) == 0 and "omega" not in ds.coords  # the spin moves along S_g
    lower, outer = ds["S_g_stable_lower"].values[-1], ds["S_g_stable_lower_outer"].values[-1]
    # certified stable at lower, unstable at outer: on the spins they set, the discriminant changes sign between them
    for S, sign in ((lower, 1), (outer, -1)):
        (w,) = point_arrays(s, {"S_g": np.array([S])}).body[:, 0, 5]
        disc = (Fraction(0.00207) * Fraction(float(w))) ** 2 - 4 * Fraction(0.0123) * Fraction(11.3)
        assert (disc >= 0) if sign > 0 else (disc < 0)
    assert outer < 1.0 + 1e-15 and 1.0 - 1e-15 < lower and lower - outer <= 1e-10


def test_box_proofs_along_M_alpha_and_omega_agree_with_the_closed_form():
    s = shell("M_alpha = { start = 1.0, stop = 10.0, num = 19 }\nomega = { start = 5.0, stop = 20.0, num = 16 }")
    ds = atlas.compute(s, progress=False, threads=1)
    assert (ds.decided_by.values == SYSTEM.variable("decided_by").value("box_proof")).any()
    M, w = np.meshgrid(ds.M_alpha.values, ds.omega.values, indexing="ij")
    disc = [(Fraction(0.5) * Fraction(float(x))) ** 2 - 4 * Fraction(float(y)) for x, y in zip(w.ravel(), M.ravel())]
    assert ds.n_complex_pairs.values.ravel().tolist() == [1 if d < 0 else 0 for d in disc]
    # a cell proved whole: its label holds at its corners' far values too (the closed form on the cell's edges)
    whole = ds.cell.values == SYSTEM.variable("cell").value("whole_cell")
    lo_M, hi_M = ds.M_alpha_bounds.values[:, 0], ds.M_alpha_bounds.values[:, 1]
    lo_w, hi_w = ds.omega_bounds.values[:, 0], ds.omega_bounds.values[:, 1]
    for i, j in zip(*np.nonzero(whole)):
        corners = [(Fraction(float(a)), Fraction(float(b))) for a in (lo_M[i], hi_M[i]) for b in (lo_w[j], hi_w[j])]
        assert {int((Fraction(1, 2) * b) ** 2 < 4 * a) for a, b in corners} == {int(ds.n_complex_pairs.values[i, j])}


def test_the_S_g_coordinate_where_M_alpha_is_given():
    s = shell("omega = { start = 2.0, stop = 20.0, num = 7 }\nA_1 = { values = [0.5, 1.0] }", M=3.0)
    ds = atlas.compute(s, progress=False, threads=1)
    assert ds["S_g"].dims == ("omega", "A_1")
    w, A = np.meshgrid(ds.omega.values, ds.A_1.values, indexing="ij")
    np.testing.assert_allclose(ds["S_g"].values, 0.25 * w**2 / (4 * A * 3.0), rtol=1e-15)
    nc = ds.n_complex_pairs.values
    assert ((nc == 0) == (ds["S_g"].values >= 1)).all()  # no grid point sits on S_g = 1 within rounding here
    assert "M_alpha" in ds.coords and float(ds["M_alpha"]) == 3.0 and "K_0" not in ds.coords
    text = describe(ds, "shell.nc")
    assert "set by the axes:" in text and "S_g        over omega, A_1: 0.0833333 .. 16.6667" in text


def test_hold_omega_moves_M_alpha():
    s = shell("S_g = { values = [0.5, 2.0] }", extra='[hold]\nS_g = "omega"')
    assert loads_scene(s.to_toml()) == s
    pts = point_arrays(s, {"S_g": np.array([0.5, 2.0])})
    # M_alpha = C^2 omega^2 / (4 A S_g) = 0.25 * 100 / (4 S_g)
    assert pts.joint[:, 0].tolist() == [-12.5, -3.125]
    assert (pts.body[:, 0, 5] == 10.0).all()
    assert "S_g" not in box_axes(s)
    ds = atlas.compute(s, progress=False, threads=1)
    assert ds["M_alpha"].dims == ("S_g",) and "K_0" not in ds.coords and float(ds["omega"]) == 10.0


# ------------------------------------------------------------------------------------------------ the ratio axes
CAVITY = 'cavity = { shape = "cylinder", radius = 0.03, half_height = 0.05, density = 1000.0, modes = 3 }'


def test_C_over_A_holding_A_equals_scanning_C():
    ratios = np.array([0.1, 0.35, 0.8, 1.3])
    s = shell("C_over_A_1 = { values = [0.1, 0.35, 0.8, 1.3] }\nS_g = { values = [0.8, 1.1] }", A=0.06, body=CAVITY, M=40.0)
    by_C = shell("C_1 = { values = [%s] }\nS_g = { values = [0.8, 1.1] }" % ", ".join(repr(float(0.06 * r)) for r in ratios),
                 A=0.06, body=CAVITY, M=40.0)
    r, S = np.meshgrid(ratios, [0.8, 1.1], indexing="ij")
    got = SYSTEM.evaluate(s, {"C_over_A_1": r, "S_g": S})["n_complex_pairs"]
    want = SYSTEM.evaluate(by_C, {"C_1": 0.06 * r, "S_g": S})["n_complex_pairs"]
    assert got.tolist() == want.tolist()
    assert got.ravel().tolist() == exact_pairs(s, {"C_over_A_1": r.ravel(), "S_g": S.ravel()})
    ds = atlas.compute(s, progress=False, threads=1)
    assert ds.n_complex_pairs.values.tolist() == atlas.compute(by_C, progress=False, threads=1).n_complex_pairs.values.tolist()
    np.testing.assert_array_equal(ds["C_1"].values, 0.06 * ratios)
    assert ds["C_1"].dims == ("C_over_A_1",) and ds["omega"].dims == ("C_over_A_1", "S_g")
    assert "C_over_A_1" in box_axes(shell("C_over_A_1 = { values = [0.1, 0.3] }")) and "S_g" not in box_axes(s)


def test_C_over_A_holding_C_moves_A():
    s = shell("C_over_A_1 = { values = [0.25, 0.5] }", C=0.5, extra='[hold]\nC_over_A = "C"')
    pts = point_arrays(s, {"C_over_A_1": np.array([0.25, 0.5])})
    assert pts.body[:, 0, 1].tolist() == [2.0, 1.0] and (pts.body[:, 0, 2] == 0.5).all()
    assert "C_over_A_1" not in box_axes(s)


@pytest.mark.parametrize("hold", ["radius", "half_height", "volume"])
def test_aspect_ratio_equals_scanning_the_sizes(hold):
    aspects = np.array([0.8, 1.5, 2.2, 3.6])
    a0, c0 = 0.03, 0.05
    if hold == "radius":
        a, c = np.full(4, a0), 0.5 * aspects * a0
    elif hold == "half_height":
        a, c = 2.0 * c0 / aspects, np.full(4, c0)
    else:  # a^2 c held: a = (2 a0^2 c0 / aspect)^(1/3), by mpmath
        a = np.array([float(mpmath.cbrt(mpmath.mpf(2) * a0 * a0 * c0 / mpmath.mpf(float(x)))) for x in aspects])
        c = 0.5 * aspects * a
    text = "aspect_1 = { values = [0.8, 1.5, 2.2, 3.6] }\nomega = { values = [1.0, 60.0] }"  # S_g 0.11 and 400
    s = shell(text, M=0.3, A=0.3, C=0.2, m=9.0, extra=f'[hold]\naspect = "{hold}"', body=CAVITY)
    pts = point_arrays(s, {"aspect_1": aspects})
    by_size = point_arrays(s, {"radius_1": a, "half_height_1": c}) if hold != "volume" else None
    if by_size is not None:
        np.testing.assert_array_equal(pts.E, by_size.E)
        np.testing.assert_array_equal(pts.body, by_size.body)
    else:
        np.testing.assert_allclose(a * a * c, a0 * a0 * c0, rtol=1e-15)
        np.testing.assert_allclose(pts.E, point_arrays(s, {"radius_1": a, "half_height_1": c}).E, rtol=1e-13)
    x, w = np.meshgrid(aspects, [1.0, 60.0], indexing="ij")
    got = SYSTEM.evaluate(s, {"aspect_1": x, "omega": w})["n_complex_pairs"]
    assert set(got[:, 0]) == {1} and set(got[:, 1]) == {0}  # below and above S_g = 1
    assert got.ravel().tolist() == exact_pairs(s, {"aspect_1": x.ravel(), "omega": w.ravel()})
    ds = atlas.compute(s, progress=False, threads=1)
    moved = {"radius": ["half_height_1"], "half_height": ["radius_1"], "volume": ["radius_1", "half_height_1"]}[hold]
    for name in moved:
        assert ds[name].dims == ("aspect_1",) and "aspect_1" in ds[name].attrs["comment"]
    np.testing.assert_allclose(2 * ds["half_height_1"].values / ds["radius_1"].values, aspects, rtol=1e-15)


@pytest.mark.parametrize("text, message", [
    ('support = "free"\nM_alpha = 1.0\nomega = 1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0', 'support = "fixed"'),
    ("M_alpha = 1.0\nK_0 = 2.0\nomega = 1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0", "remove K_0"),
    ("M_alpha = 1.0\nomega = 1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.1", "bodies[1].c = 0"),
    ("M_alpha = 1.0\nomega = 1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\n[grid]\nc_1 = { values = [0.0, 0.1] }", "do not scan c_1"),
    ("omega = 1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\nM_alpha = 2.0", "top-level key"),
    ("omega = 1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\n[grid]\nS_g = { values = [1.0, 2.0] }", "needs M_alpha"),
    ("M_alpha = -1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\n[grid]\nS_g = { values = [1.0, 2.0] }", "must be > 0"),
    ("M_alpha = 1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\n[grid]\nS_g = { values = [1.0, 2.0] }\nomega = { values = [1.0] }",
     "moves omega"),
    ('M_alpha = 1.0\n[hold]\nS_g = "omega"\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\nomega = 3.0\n[grid]\n'
     "S_g = { values = [1.0, 2.0] }\nM_alpha = { values = [1.0] }", "moves M_alpha"),
    ("omega = 1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\n[grid]\nC_over_A_1 = { values = [1.0] }\nC_1 = { values = [1.0] }",
     'hold.C_over_A = "C"'),
    ('omega = 1.0\n[hold]\nC_over_A = "C"\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\n[grid]\nC_over_A_1 = { values = [1.0] }\n'
     "A = { values = [1.0] }", "remove 'A'"),
    ('omega = 1.0\n[hold]\nC_over_A = "C"\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\n[grid]\nC_over_A_1 = { values = [0.0, 1.0] }',
     "must be > 0"),
    ("omega = 1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\n[grid]\naspect_1 = { values = [1.0] }", "has no spheroid or cylinder"),
    ("omega = 1.0\n[[bodies]]\nm = 9.0\nA = 1.0\nC = 1.0\nc = 0.0\n" + CAVITY + "\n[grid]\naspect_1 = { values = [1.0] }\n"
     "half_height_1 = { values = [0.01] }", 'hold.aspect = "half_height"'),
    ('omega = 1.0\n[hold]\naspect = "volume"\n[[bodies]]\nm = 9.0\nA = 1.0\nC = 1.0\nc = 0.0\n' + CAVITY + "\n[grid]\n"
     "aspect_1 = { values = [1.0] }\nradius_1 = { values = [0.01] }", "remove 'radius_1'"),
    ('omega = 1.0\n[hold]\naspect = "volume"\n[[bodies]]\nm = 9.0\nA = 1.0\nC = 1.0\nc = 0.0\n' + CAVITY + "\n[grid]\n"
     "aspect_1 = { values = [1.0] }\nhalf_height_1 = { values = [0.01] }", "hold.aspect = 'volume'.*set hold.aspect = \"half_height\""),
    ('omega = 1.0\n[hold]\naspect = "length"\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0', "hold.aspect must be one of"),
    ('omega = 1.0\n[hold]\nC_over_a = "A"\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0', "did you mean 'C_over_A'"),
    ("omega = 1.0\n[[bodies]]\nm = 1.0\nA = 1.0\nC = 1.0\nc = 0.0\n[grid]\nC_over_A = { values = [1.0] }", "did you mean"),
    ("M_alpha = 1.0\nomega = 1.0\n[[bodies]]\nm = 9.0\nA = 1.0\nC = 1.0\nc = 0.0\n"
     'cavity = { shape = "cylinder", radius = 0.03, half_height = 0.05, density = 1000.0, liquid_in_body = false }',
     "liquid_in_body = true"),
])
def test_bad_projectiles_and_ratios_are_named(text, message):
    with pytest.raises(StabmapError, match=message.replace("(", r"\(").replace("[", r"\[")):
        loads_scene(text)


def test_the_moved_quantity_replaces_its_fixed_coordinate_and_the_aspect_keeps_the_liquid_in_the_checks():
    # the cavity's frozen liquid must fit in m, A, C at the largest size an aspect axis reaches (docs/cavities.md)
    text = ("omega = 1.0\n[[bodies]]\nm = 3.0\nA = 0.05\nC = 0.02\nc = 0.1\n" + CAVITY + "\n[grid]\naspect_1 = { values = [1.0, 40.0] }")
    with pytest.raises(StabmapError, match="less than the frozen liquid"):
        loads_scene(text)


# ------------------------------------------------------------------------------- Stewartson's cylinder eigenfrequencies
def _kelvin_roots(ka: float, lo: float = 0.2) -> list[float]:
    """Every frequency sigma (body frame, over the spin) with lo < |sigma| < 2 of an m = 1 inertial wave of axial
    wavenumber k in a full cylinder of radius a (Kelvin): xi^2 = (ka)^2 (4 - sigma^2) / sigma^2 and no flow through
    the wall, sigma xi J1'(xi) + 2 J1(xi) = 0.  Found by a scan in sigma (scipy) and refined by mpmath, without the
    cavity module's brackets."""
    mpmath.mp.dps = 30

    def f(s):
        s = mpmath.mpf(s)
        xi = ka * mpmath.sqrt(4 - s * s) / abs(s)
        return s * xi * mpmath.besselj(1, xi, derivative=1) + 2 * mpmath.besselj(1, xi)

    roots = []
    for a, b in ((-2.0, -lo), (lo, 2.0)):
        grid = np.linspace(a, b, 4001)
        xi = ka * np.sqrt(4 - grid**2) / np.abs(grid)
        vals = grid * xi * special.jvp(1, xi) + 2 * special.jv(1, xi)  # the scan in floats, each root refined by mpmath
        for x0, x1, v0, v1 in zip(grid, grid[1:], vals, vals[1:]):
            if v0 * v1 < 0:
                roots.append(float(mpmath.findroot(f, (x0, x1), solver="anderson")))
    return sorted(roots)


@pytest.mark.parametrize("c_over_a", [0.5, 1.0, 2.0, 3.5])
def test_cylinder_modes_are_kelvins_inertial_waves(c_over_a):
    # Stewartson (1959) tabulates these eigenfrequencies against c/a; his tables are not at hand, so the reference is
    # the dispersion relation itself, solved for sigma = lambda_l / omega = 2 / kappa (docs/projectile.md).
    from stabmap import cavity

    modes = cavity.cylinder_modes(1.0, c_over_a, 1.0, n_max=2, j_max=40)
    for n in (1, 2):
        ka = (2 * n - 1) * math.pi / (2 * c_over_a)
        sigma = sorted(s for s in (2.0 / modes["kappa"][n - 1].ravel()) if abs(s) > 0.2)
        want = _kelvin_roots(ka)
        assert len(sigma) == len(want) > 0
        np.testing.assert_allclose(sigma, want, rtol=1e-11, atol=1e-13)


def test_S_g_moves_body_1s_own_spin_and_leaves_the_others():
    text = """
    M_alpha = 2.0
    g = 0.0
    omega = 30.0
    [[bodies]]
    m = 2.0
    A = 0.5
    C = 0.25
    c = 0.0
    s = 0.3
    omega = 7.0
    [[bodies]]
    m = 0.5
    A = 0.01
    C = 0.02
    c = 0.05
    [grid]
    S_g = { values = [1.0, 4.0] }
    """
    s = loads_scene(text)
    pts = point_arrays(s, {"S_g": np.array([1.0, 4.0])})
    assert pts.body[:, 0, 5].tolist() == [8.0, 16.0]  # 2 sqrt(0.5 * 2 * S_g) / 0.25
    assert pts.body[:, 1, 5].tolist() == [30.0, 30.0]
    ds = atlas.compute(s, progress=False, threads=1)
    assert ds["omega_1"].values.tolist() == [8.0, 16.0] and float(ds["omega"]) == 30.0
    with pytest.raises(StabmapError, match="remove 'omega_1'"):
        loads_scene(text + "omega_1 = { values = [1.0] }")
