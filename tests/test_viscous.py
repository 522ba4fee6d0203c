"""The viscous-liquid system (docs/viscous.md): scenes, the proved first-order decision, and the pipeline around it.

References are the classical closed forms (a heavy top with a viscous filling, a free body and its major axis),
evaluated in mpmath, and FLINT/Arb on the exact polynomial; tests/test_viscous_model.py derives the model itself
independently (vector equations, the full cubic matrix polynomial).
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

import stabmap
from stabmap.cli import main
from stabmap.errors import StabmapError
from stabmap.systems.gyroscopes.points import point_arrays
from stabmap.systems.viscous import decide as vdecide
from stabmap.systems.viscous.outputs import ASYMPTOTIC_STABILITY, DECIDED_BY

AS, UN, UNDEC = (ASYMPTOTIC_STABILITY.value(m) for m in ("asymptotically_stable", "unstable", "undecided"))


def top(omega_grid: str, *, m=2.0, A=0.02, C=0.06, c=0.1, g=9.81, radius=0.04, density=1000.0, viscosity=0.5,
        support="fixed", extra: str = "") -> str:
    g_line = f"g = {g!r}\n" if support == "fixed" else ""
    return f"""
title = "top"
support = "{support}"
{g_line}[[bodies]]
m = {m!r}
A = {A!r}
C = {C!r}
c = {c!r}
cavity = {{ shape = "spheroid", radius = {radius!r}, half_height = {radius!r}, density = {density!r}, viscosity = {viscosity!r} }}
{extra}
[grid]
omega = {omega_grid}
"""


def sphere_eps(radius, density, viscosity):
    return mpmath.mpf(density) * 8 * mpmath.pi * mpmath.mpf(radius) ** 7 / 525 / mpmath.mpf(viscosity)


def top_rates(omega, *, m=2.0, A=0.02, C=0.06, c=0.1, g=9.81, radius=0.04, density=1000.0, viscosity=0.5):
    """The heavy top's two first-order growth rates, closed form (docs/viscous.md), in mpmath."""
    mpmath.mp.dps = 40
    Ap = mpmath.mpf(A) + mpmath.mpf(m) * mpmath.mpf(c) ** 2
    w, C_, k = mpmath.mpf(omega), mpmath.mpf(C), mpmath.mpf(g) * mpmath.mpf(m) * mpmath.mpf(c)
    disc = C_**2 * w**2 - 4 * Ap * k
    assert disc > 0
    eps = sphere_eps(radius, density, viscosity)
    out = []
    for s in (1, -1):
        lam = (-C_ * w + s * mpmath.sqrt(disc)) / (2 * Ap)
        out.append(-eps * lam**2 * (lam + w) / (2 * Ap * lam + C_ * w))
    return out


# ------------------------------------------------------------------------------------------------ classical checks
def test_heavy_top_is_asymptotically_stable_exactly_where_C_minus_A_times_omega_squared_exceeds_mgc():
    # A, C about the fixed point with the liquid frozen: A' = A + m c^2 = 0.04; omega* = sqrt(m g c / (C - A'))
    star = math.sqrt(2.0 * 9.81 * 0.1 / (0.06 - 0.04))
    maievskii = math.sqrt(4 * 0.04 * 2.0 * 9.81 * 0.1) / 0.06
    values = [maievskii * 0.99, maievskii * 1.01, star * (1 - 1e-6), star * (1 + 1e-6), star * 1.5, star * 4]
    ds = stabmap.compute_atlas(stabmap.loads_scene(top(f"{{ values = {values!r} }}")), progress=False)
    label = ds.asymptotic_stability.values.tolist()
    assert label == [UN, UN, UN, AS, AS, AS]
    by = [DECIDED_BY.meaning(int(v)) for v in ds.decided_by.values]
    assert by[0] == "frozen_chain_unstable" and by[1] == "first_order_balls"
    for w, rate, lo, hi in zip(values[1:], ds.growth_rate.values[1:], ds.growth_rate_lower.values[1:], ds.growth_rate_upper.values[1:]):
        want = max(top_rates(w))
        assert lo <= want <= hi
        assert float(rate) == pytest.approx(float(want), rel=1e-6)


def test_a_top_whose_axial_inertia_is_below_the_transverse_never_settles():
    ds = stabmap.compute_atlas(stabmap.loads_scene(top("{ start = 1, stop = 200, num = 30 }", C=0.035)), progress=False)
    assert set(ds.asymptotic_stability.values.tolist()) == {UN}


@pytest.mark.parametrize("C, expected", [(0.03, AS), (0.015, UN)])
def test_free_body_settles_only_about_its_axis_of_largest_inertia(C, expected):
    ds = stabmap.compute_atlas(stabmap.loads_scene(top("{ values = [3.0, 40.0] }", A=0.02, C=C, c=0.0, support="free")),
                               progress=False)
    assert ds.asymptotic_stability.values.tolist() == [expected, expected]
    eps = sphere_eps(0.04, 1000.0, 0.5)
    for w, lo, hi in zip((3.0, 40.0), ds.growth_rate_lower.values, ds.growth_rate_upper.values):
        want = eps * C * w**2 * (mpmath.mpf(0.02) - C) / mpmath.mpf(0.02) ** 3  # the nutation's rate; lambda = 0 is neutral
        assert lo <= want <= hi


def test_free_body_at_rest_is_undecided_for_its_double_zero_root():
    ds = stabmap.compute_atlas(stabmap.loads_scene(top("{ values = [0.0, 1.0] }", c=0.0, C=0.03, support="free")), progress=False)
    assert ds.asymptotic_stability.values.tolist() == [UNDEC, AS]
    assert DECIDED_BY.meaning(int(ds.decided_by.values[0])) == "zero_root"


# ------------------------------------------------------------------------------------------------ undecided, proved
def test_a_double_root_of_the_frozen_top_is_undecided():
    # A' = 0.5 + 0.5 * 1 = 1, g m c = 2 * 0.5 * 1 = 1, C omega = 2: C^2 omega^2 = 4 A' g m c exactly (a double root)
    text = top("{ values = [1.0] }", m=0.5, A=0.5, C=2.0, c=1.0, g=2.0, radius=0.01)
    ds = stabmap.compute_atlas(stabmap.loads_scene(text), progress=False)
    assert ds.asymptotic_stability.values.tolist() == [UNDEC]
    assert DECIDED_BY.meaning(int(ds.decided_by.values[0])) == "multiple_root"


def test_a_double_root_the_liquid_feels_splits_and_one_branch_grows():
    # A' = 1, C = 4, g m c = 4, omega = 1: a double root at lambda = -2 (not -omega): q(-2) = -4 eps != 0, and
    # delta^2 = i 2! q / p'' splits it into two branches of size sqrt(eps), one growing at sqrt(4 eps) sin(pi/4)
    text = top("{ values = [1.0] }", m=0.5, A=0.5, C=4.0, c=1.0, g=8.0, radius=0.01)
    ds = stabmap.compute_atlas(stabmap.loads_scene(text), progress=False)
    assert ds.asymptotic_stability.values.tolist() == [UN]
    assert DECIDED_BY.meaning(int(ds.decided_by.values[0])) == "split_multiple_root"
    mpmath.mp.dps = 60
    eps = sphere_eps(0.01, 1000.0, 0.5)
    # the full cubic det Phi_eps = lambda^2 + 4 lambda + 4 - i eps lambda^2 (lambda + 1): its two bounded roots
    bounded = sorted(mpmath.polyroots([-1j * eps, 1 - 1j * eps, 4, 4], maxsteps=400, extraprec=400), key=abs)[:2]
    fastest = max(-mpmath.im(r) for r in bounded)
    assert float(ds.growth_rate_lower[0]) <= float(mpmath.sqrt(2 * eps)) <= float(ds.growth_rate_upper[0])
    assert float(fastest) == pytest.approx(float(mpmath.sqrt(2 * eps)), rel=1e-5)  # the cubic agrees to O(eps)


def test_a_root_the_liquid_does_not_feel_is_undecided():
    # A' = 1, C = 3, g m c = 2, omega = 1: roots -1 and -2; lambda = -omega is still in the body frame (zero rate)
    text = top("{ values = [1.0] }", m=0.5, A=0.5, C=3.0, c=1.0, g=4.0, radius=0.01)
    ds = stabmap.compute_atlas(stabmap.loads_scene(text), progress=False)
    assert ds.asymptotic_stability.values.tolist() == [UNDEC]
    assert DECIDED_BY.meaning(int(ds.decided_by.values[0])) == "zero_rate"


CHAIN = """
title = "two bodies"
support = "{support}"
joints = [{K}]
[[bodies]]
m = 2.0
A = 0.02
C = {C1}
c = 0.05
s = 0.15
omega = {w1}
cavity = {{ shape = "spheroid", radius = 0.04, half_height = 0.03, density = 1000, viscosity = 0.3 }}
[[bodies]]
m = 1.0
A = 0.01
C = 0.03
c = 0.08
cavity = {{ shape = "spheroid", radius = 0.03, half_height = 0.045, density = 900, viscosity = 0.2 }}
[grid]
omega = {{ start = 1, stop = 120, num = 24 }}
K_1 = {{ values = [0.0, 3.0, 40.0] }}
"""


@pytest.mark.parametrize("support, w1", [("fixed", '"30 rad/s"'), ("free", 25.0), ("fixed", None)])
def test_ball_decisions_agree_with_arb_on_the_exact_polynomial(support, w1):
    text = CHAIN.format(support=support, K="0.0", C1=0.09, w1=w1 if w1 is not None else 0.0)
    if w1 is None:
        text = text.replace("omega = 0.0\n", "")
    scene = stabmap.loads_scene(text)
    ds = stabmap.compute_atlas(scene, progress=False)
    values = {k: v.reshape(-1) for k, v in zip(("omega", "K_1"), np.meshgrid(ds.omega.values, ds.K_1.values, indexing="ij"))}
    points = point_arrays(scene, values)
    eps, eps_r, liquid, _ = vdecide.dissipation(scene, values, points)
    zeros = vdecide.structural_zeros(points)
    label = np.full(points.body.shape[0], -9, dtype=np.int8)
    by = np.zeros_like(label)
    rate = {key: np.full(label.size, np.nan) for key in ("best", "lower", "upper", "frequency")}
    frozen = ds.decided_by.values.reshape(-1) == DECIDED_BY.value("frozen_chain_unstable")
    balls = ds.decided_by.values.reshape(-1) == DECIDED_BY.value("first_order_balls")
    assert balls.sum() > 5
    for i in np.flatnonzero(~frozen):
        vdecide._exact(points, i, eps[i], eps_r[i], liquid, int(zeros[i]), i, label, by, rate)
    mine = ds.asymptotic_stability.values.reshape(-1)
    assert np.array_equal(label[~frozen], mine[~frozen])
    both = balls & np.isfinite(rate["lower"])
    lo, hi = ds.growth_rate_lower.values.reshape(-1), ds.growth_rate_upper.values.reshape(-1)
    assert np.all(np.maximum(lo[both], rate["lower"][both]) <= np.minimum(hi[both], rate["upper"][both]))


def test_an_ideal_joint_in_a_free_chain_gives_two_neutral_zero_roots():
    scene = stabmap.loads_scene(CHAIN.format(support="free", K="0.0", C1=0.09, w1=25.0))
    points = point_arrays(scene, {"omega": np.array([50.0]), "K_1": np.array([0.0])})
    assert vdecide.structural_zeros(points).tolist() == [2]
    ds = stabmap.compute_atlas(scene, progress=False)
    assert not np.any(ds.decided_by.sel(K_1=0.0).values == DECIDED_BY.value("zero_root"))


def test_rates_scale_with_the_inverse_viscosity_and_reynolds_is_omega_a2_over_nu():
    text = top("{ values = [20.0] }") + "viscosity_1 = { values = [0.1, 0.2, 0.4] }\n"
    ds = stabmap.compute_atlas(stabmap.loads_scene(text), progress=False).isel(omega=0)
    rate = ds.growth_rate.values.astype(float)
    assert rate * np.array([0.1, 0.2, 0.4]) == pytest.approx(np.full(3, rate[0] * 0.1), rel=1e-6)
    assert ds.reynolds.values == pytest.approx(20.0 * 0.04**2 / np.array([0.1, 0.2, 0.4]), rel=1e-6)
    assert ds.time_constant.values == pytest.approx(1 / np.abs(rate), rel=1e-6)


def test_liquid_outside_the_body_is_added_frozen():
    inside = stabmap.loads_scene(top("{ values = [12.0, 30.0] }"))
    a, rho = 0.04, 1000.0
    m_f = 4 / 3 * math.pi * rho * a**3
    J_f = 2 / 5 * m_f * a**2
    # the shell alone, the liquid's centre at the body's centre of mass (c = 0.1), added by the engine
    text = top("{ values = [12.0, 30.0] }", m=2.0 - m_f, A=0.02 - J_f, C=0.06 - J_f).replace(
        "viscosity = 0.5 }", "viscosity = 0.5, liquid_in_body = false, centre = 0.1 }")
    outside = stabmap.loads_scene(text)
    one, two = (stabmap.compute_atlas(s, progress=False) for s in (inside, outside))
    assert np.array_equal(one.asymptotic_stability.values, two.asymptotic_stability.values)
    assert two.growth_rate.values == pytest.approx(one.growth_rate.values, rel=1e-9)


def test_a_tree_is_the_chain_it_describes():
    chain = CHAIN.format(support="fixed", K="5.0", C1=0.09, w1=30.0).replace("K_1 = { values = [0.0, 3.0, 40.0] }\n", "")
    tree = chain.replace("s = 0.15\n", "").replace('joints = [5.0]', 'joints = [5.0]\n[topology]\nparent = [0, 1]\nat = [0.0, 0.15]')
    a, b = (stabmap.compute_atlas(stabmap.loads_scene(t), progress=False) for t in (chain, tree))
    assert np.array_equal(a.asymptotic_stability.values, b.asymptotic_stability.values)
    assert b.growth_rate.values == pytest.approx(a.growth_rate.values, rel=1e-9)


# ------------------------------------------------------------------------------------------------ scenes and errors
def test_a_viscosity_makes_the_scene_viscous_and_it_round_trips():
    scene = stabmap.loads_scene(top("{ values = [1.0] }"))
    assert scene.system == "viscous" and 'system = "viscous"' in scene.to_toml()
    assert stabmap.loads_scene(scene.to_toml()) == scene
    ideal = stabmap.loads_scene(top("{ values = [1.0] }").replace(", viscosity = 0.5", ""))
    assert ideal.system == "gyroscopes"


@pytest.mark.parametrize("edit, words", [
    (lambda t: t.replace("viscosity = 0.5", "viscosity = -0.5"), "viscosity"),
    (lambda t: t.replace("viscosity = 0.5", "viscosity = 0.5, modes = 1"), "no modes"),
    (lambda t: t.replace("c = 0.1\n", "c = 0.1\nfluid = { E = [0.001], kappa = [3.0] }\n"), "one liquid model"),
    (lambda t: t + "viscosity_2 = { values = [0.1] }\n", "viscosity_2"),
    (lambda t: t.replace('title = "top"', 'title = "top"\nfrequencies = true'), "frequencies"),
    (lambda t: 'system = "viscous"\n' + t.replace(", viscosity = 0.5", ""), "needs a viscous liquid"),
    (lambda t: t.replace('shape = "spheroid", radius = 0.04, half_height = 0.04', 'shape = "table", tensor = [1e-12, 1e-12, 3.0], radius = 0.04'),
     "tensor"),
    (lambda t: t.replace('shape = "spheroid", radius = 0.04, half_height = 0.04', 'shape = "table", tensor = [[1e-12, 0, 0], [0, 2e-12, 0], [0, 0, 1e-12]], radius = 0.04'),
     "tensor"),
    (lambda t: t.replace('shape = "spheroid"', 'shape = "cylinder"') + "half_height_1 = { values = [0.0001, 0.04] }\n",
     "tabulated"),
])
def test_bad_viscous_scenes_are_refused_by_name(edit, words):
    with pytest.raises(StabmapError, match=words):
        stabmap.loads_scene(edit(top("{ values = [1.0] }")))


@pytest.mark.parametrize("edit, words", [
    (lambda t: t.replace(", viscosity = 0.2", ""), "one liquid model"),
    (lambda t: t.replace("viscosity = 0.2", "viscosity = -0.2"), "viscosity must be > 0"),
    (lambda t: t.replace('shape = "spheroid", radius = 0.03, half_height = 0.045', 'shape = "table", tensor = [[1e-12, 0], [0, 1e-12]], radius = 0.03'),
     "tensor"),
])
def test_bad_input_is_one_line_exit_2_and_no_file(tmp_path, capsys, edit, words):
    (tmp_path / "bad.toml").write_text(edit(CHAIN.format(support="fixed", K="1.0", C1=0.09, w1=30.0)))
    code = main(["atlas", str(tmp_path / "bad.toml"), "-o", str(tmp_path / "bad.nc")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and words in err[0]
    assert not list(tmp_path.glob("bad.nc*"))


# ------------------------------------------------------------------------------------------------ the pipeline
def test_atlas_info_query_plot_critical_and_refine_on_a_viscous_scene(tmp_path, capsys):
    (tmp_path / "top.toml").write_text(top("{ start = 5, stop = 20, num = 31 }") + "C_1 = { start = 0.03, stop = 0.09, num = 13 }\n")
    assert main(["atlas", str(tmp_path / "top.toml"), "-o", str(tmp_path / "top.nc")]) == 0
    assert "asymptotically stable" in capsys.readouterr().err
    assert main(["info", str(tmp_path / "top.nc")]) == 0
    info = capsys.readouterr().out
    assert "asymptotically_stable" in info and "Re = " in info and "0 % of the points" in info
    assert main(["query", str(tmp_path / "top.nc"), "omega=12", "C_1=0.08"]) == 0
    assert "asymptotic_stability = asymptotically_stable" in capsys.readouterr().out
    assert main(["plot", str(tmp_path / "top.nc"), "-o", str(tmp_path / "top.png")]) == 0
    assert (tmp_path / "top.png").stat().st_size > 10_000
    assert main(["critical", str(tmp_path / "top.toml"), "--along", "omega", "-o", str(tmp_path / "crit.nc")]) == 0
    crit = stabmap.open_atlas(tmp_path / "crit.nc")
    # every located boundary lies between the heavy top's omega* at the bracket's C_1 (criterion above)
    for C in crit.C_1.values:
        star = math.sqrt(2.0 * 9.81 * 0.1 / (C - 0.04)) if C > 0.04 else math.inf
        row = crit.sel(C_1=C)
        for lo, hi in zip(np.atleast_1d(row.boundary_lower.values), np.atleast_1d(row.boundary_upper.values)):
            if np.isfinite(lo):
                assert lo <= star <= hi
    assert main(["atlas", str(tmp_path / "top.toml"), "-o", str(tmp_path / "ref.nc"), "--refine", "--coarse-stride", "4"]) == 0
    ref, dense = stabmap.open_atlas(tmp_path / "ref.nc"), stabmap.open_atlas(tmp_path / "top.nc")
    assert np.array_equal(ref.asymptotic_stability.values, dense.asymptotic_stability.values)


def test_paper_cases_with_a_viscous_liquid_agree_with_kelvin_tait_chetaev(capsys):
    assert main(["paper", "viscous", "--quick"]) == 0
    text = capsys.readouterr().out
    assert "all agree with the papers" in text and "DISAGREES" not in text
    rows = [line for line in text.splitlines() if line.startswith("| paper-")]
    assert len(rows) == 14
    # each row: | case | points | stable share | undecided | agree | disagree |
    assert all(int(r.split("|")[6]) == 0 and int(r.split("|")[5]) > 500 for r in rows)
    assert sum(float(r.split("|")[3].strip(" %")) > 10 for r in rows) >= 5  # both classes occur


def test_a_tensor_table_and_a_cylinder_decide_as_their_tensors_say():
    # the same top with a sphere's tensor given as a table; and a cylinder, whose label (one body) needs only P_t > 0
    sphere = stabmap.loads_scene(top("{ values = [8.0, 12.0, 30.0] }"))
    P = float(8 * mpmath.pi * mpmath.mpf(0.04) ** 7 / 525)
    table = stabmap.loads_scene(top("{ values = [8.0, 12.0, 30.0] }").replace(
        'shape = "spheroid", radius = 0.04, half_height = 0.04', f'shape = "table", tensor = [{P!r}, {P!r}], radius = 0.04'))
    cylinder = stabmap.loads_scene(top("{ values = [8.0, 12.0, 30.0] }", radius=0.03).replace('"spheroid"', '"cylinder"'))
    a, b, c = (stabmap.compute_atlas(s, progress=False) for s in (sphere, table, cylinder))
    assert np.array_equal(a.asymptotic_stability.values, b.asymptotic_stability.values)
    assert np.array_equal(a.asymptotic_stability.values, c.asymptotic_stability.values)
    assert b.growth_rate.values == pytest.approx(a.growth_rate.values, rel=1e-6)
    # a cylinder's rates are its tensor's: P_t from stabmap.cavity, within the table's stated accuracy
    Pt, _, rel = stabmap.cavity.viscous_tensor("cylinder", 0.03, 0.03)
    ratio = c.growth_rate.values[1:] / a.growth_rate.values[1:]  # the decaying points: rates proportional to P_t
    assert ratio == pytest.approx(np.full(2, float(Pt) / P), rel=1e-5 + float(rel))
