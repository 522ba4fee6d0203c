"""Closed chains: every label proved, or flagged undecided (stabmap/systems/closed/proofs.py, docs/closed.md).

The references are independent (tests/closed_reference.py, written from docs/closed.md): the closed forms at 60 digits
(mpmath) from the exact binary value of the ratio, docs/closed.md's Hessian on an orthonormal tangent basis (an
eigenvalue counts as zero below 1e-40), the energy probe (no forces, no Hessian formula) where its step resolves
the eigenvalues, and Newton on the general equations.  Labels are compared at random ratios, 1e-7, 1e-10 and
1e-13 (relative) either side of every boundary and at the doubles next to it; with the precision ladder cut to
53 bits, points within reach of a boundary must be flagged undecided and never wrongly labelled; and at points
where the old floating-point decision was wrong the proof must give the reference's label.
"""

from __future__ import annotations

import functools
import math

import closed_reference as ref
import mpmath as mp
import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

import stabmap
from stabmap import closed
from stabmap.cli import main
from stabmap.systems.closed import SYSTEM, equations, proofs
from stabmap.systems.closed.families import FAMILIES

# The paper's planar model (the chain confined to its plane): these tests check the planar results;
# tests/test_closed_space.py checks stability in space.
planar_solve = functools.partial(closed.solve, model="planar")
planar_search = functools.partial(closed.search, model="planar")

DIGITS = 60
ZERO = 1e-40  # the reference's zero for an eigenvalue, at DIGITS digits
RANGE = {"figure-eight-4": (0.01, 1.0), "figure-eight-6": (4.83, 60.0), "hinge": (0.01, 2.0), "hinge-straight": (0.01, 2.0)}
FOLDS = {"figure-eight-4": 1.0, "hinge": 2.0, "hinge-straight": 2.0}  # the ends of the ranges: folded, degenerate


def reference(family: str, r: float, n: int | None = None, j: int = 1) -> tuple[str, int, int]:
    """(stability, index, nullity) of the family at the exact ratio r = h2/h1, at 60 digits (absent: -1, -1)."""
    with mp.workdps(DIGITS):
        L = ref.lengths_of(family, mp.mpf(r), n)
        loops = ref.loops_of(family, len(L))
        if family == "ring":
            theta, forces = ref.closed_form("ring", L, j=j)
            gap = abs(mp.fsum(h * mp.expj(t) for h, t in zip(L, theta)))
            if gap > mp.mpf(10) ** (20 - DIGITS):
                return "absent", -1, -1
        else:
            cf = ref.closed_form(family, L)
            if cf is None:
                return ("degenerate", -2, -2) if FOLDS.get(family) == r else ("absent", -1, -1)
            theta, forces = cf
        index, nullity, _ = ref.hessian_inertia(theta, L, forces, loops, ZERO)
    return ("degenerate" if nullity else "unstable" if index else "stable"), index, nullity


def lengths(family: str, r: float, n: int | None = None) -> list[float]:
    return [float(x) for x in ref.lengths_of(family, mp.mpf(r), n)]  # h1 = 1: h2 = r exactly


def stability_boundary(family: str, guess: str) -> mp.mpf:
    """The ratio where the reference Hessian's determinant on the tangent space vanishes, at 50 digits."""

    def det(r):
        L = ref.lengths_of(family, r)
        theta, forces = ref.closed_form(family, L)
        basis = ref.tangent_basis(theta, L, ref.loops_of(family, len(L)))
        B = mp.matrix([[basis[i][k] for i in range(len(basis))] for k in range(len(L))])
        return mp.det(B.T * ref.hessian(theta, L, forces, ref.loops_of(family, len(L))) * B)

    with mp.workdps(50):
        return +mp.findroot(det, mp.mpf(guess))


BOUNDARIES = {
    "figure-eight-4 exists": ("figure-eight-4", lambda: mp.mpf(1)),
    "figure-eight-6 exists": ("figure-eight-6", lambda: 2 / (mp.sqrt(2) - 1)),
    "figure-eight-6 stable": ("figure-eight-6", lambda: stability_boundary("figure-eight-6", "5.986")),
    "hinge stable": ("hinge", lambda: stability_boundary("hinge", "1.414")),
    "hinge exists": ("hinge", lambda: mp.mpf(2)),
    "hinge-straight exists": ("hinge-straight", lambda: mp.mpf(2)),
}


def near(b: mp.mpf) -> list[float]:
    """Ratios 1e-7, 1e-10, 1e-13 (relative) either side of b, b's nearest double and its two neighbours each side."""
    with mp.workdps(50):
        out = [float(b * (1 + s * mp.mpf(10) ** -e)) for e in (7, 10, 13) for s in (-1, 1)]
    x = float(b)
    for _ in range(2):
        out += [x]
        x = math.nextafter(x, math.inf)
    x = float(b)
    for _ in range(2):
        x = math.nextafter(x, -math.inf)
        out += [x]
    return sorted(set(out))


@pytest.fixture()
def ladder(monkeypatch):
    """Cut the precision ladder to the given bits (proofs at one precision leave a band of undecided points)."""

    def cut(*bits):
        monkeypatch.setattr(proofs, "PRECISIONS", tuple(bits))

    return cut


# ------------------------------------------------------------------------------------------------------- labels
def test_the_boundaries_are_irrational_or_rational_ends():
    """√2 and 2/(√2 - 1) are irrational: no double sits on them, so the ladder decides every point there."""
    assert abs(stability_boundary("hinge", "1.414") - mp.sqrt(2)) < mp.mpf(10) ** -35
    assert abs(float(stability_boundary("figure-eight-6", "5.986")) - 5.98605461610344) < 1e-14


@pytest.mark.parametrize("name", list(BOUNDARIES))
def test_labels_near_every_boundary_equal_the_reference_and_are_proved(name):
    family, where = BOUNDARIES[name]
    b = where()
    for r in near(b):
        eq = planar_solve(family, lengths(family, r))
        expected, index, nullity = reference(family, r)
        assert eq.stability == expected, (name, r, eq, expected)
        assert eq.proved and eq.decided_by in ("ball_arithmetic", "exact_rational_arithmetic"), (name, r, eq)
        if expected in ("stable", "unstable"):
            assert (eq.index, eq.nullity) == (index, nullity), (name, r)


@settings(max_examples=80, deadline=None)
@given(family=st.sampled_from(list(RANGE)), u=st.floats(0.0, 1.0), h1=st.sampled_from([1.0, 0.3, 7.0]))
def test_labels_at_random_ratios_equal_the_reference(family, u, h1):
    lo, hi = RANGE[family]
    r = lo * (hi / lo) ** u  # log-uniform over the family's range
    eq = planar_solve(family, [h1 * x for x in lengths(family, r)]) if h1 == 1.0 else None
    # with h1 != 1 the lengths h1 * r are rounded: take the atlas's point (h1, ratio), whose ratio is r exactly
    scene = stabmap.loads_scene(f'system = "closed"\nmodel = "planar"\nfamily = "{family}"\nh1 = {h1!r}\nratio = {r!r}\n')
    point = SYSTEM.evaluate(scene, {})
    expected, index, nullity = reference(family, r)
    label = SYSTEM.variable("stability").meaning(int(point["stability"]))
    assert label == expected and (eq is None or eq.stability == expected), (family, r, h1)
    assert int(point["decided_by"]) in (proofs.BY_BALLS, proofs.BY_EXACT)
    if expected in ("stable", "unstable"):
        assert (int(point["index"]), int(point["nullity"])) == (index, nullity)


@pytest.mark.parametrize("n,j", [(3, 1), (4, 1), (5, 1), (5, 2), (6, 1), (6, 2), (7, 3), (8, 2), (9, 2), (12, 3), (12, 5)])
def test_rings_exact_structure_against_the_reference(n, j):
    for r in (1.0, math.nextafter(1.0, 2.0), 0.5, 1.7):
        eq = planar_solve("ring", lengths("ring", r, n), j=j)
        expected, index, nullity = reference("ring", r, n, j)
        assert eq.stability == expected, (n, j, r)
        assert eq.decided_by == ("exact_structure" if expected != "absent" else "exact_rational_arithmetic")
        if expected != "absent":
            assert (eq.index, eq.nullity) == (index, nullity)


def test_a_ring_closes_with_lengths_of_period_three_and_not_one_ulp_off():
    # sum h_k w^k with w^3 = -1 (n = 6, j = 1) and h of period 3 is (h1 w + h2 w^2 + h3 w^3)(1 + w^3) = 0.
    closes = planar_solve("ring", [1.0, 2.0, 3.0, 1.0, 2.0, 3.0])
    assert closes.exists and closes.stability == "stable" and closes.decided_by == "exact_structure"
    assert closes.residual <= 1e-12
    off = planar_solve("ring", [1.0, 2.0, 3.0, 1.0, 2.0, math.nextafter(3.0, 4.0)])
    assert off.exists is False and off.stability == "absent"


@pytest.mark.parametrize("family,r", [("figure-eight-4", 1.0), ("hinge", 2.0), ("hinge-straight", 2.0)])
def test_folded_ends_are_proved_exactly(family, r):
    eq = planar_solve(family, lengths(family, r))
    assert eq.stability == "degenerate" and eq.decided_by == "exact_rational_arithmetic"
    float_inertia = equations.inertia(eq.theta[None], np.asarray(eq.lengths)[None], eq.forces[None], FAMILIES[family].loop_of(),
                                      eq.c1sq, eq.h)
    assert (eq.index, eq.nullity) == (int(float_inertia.index[0]), int(float_inertia.nullity[0]))


# --------------------------------------------------------------------------------- the proof is what decides
# Points where the floating-point decision of the former code (equations.inertia with its tolerances, and float
# comparisons for existence) is wrong.  If the proof were skipped, the labels here would be the float ones.
FLOAT_WRONG = [
    ("hinge", 1.41421356237309, "stable"),  # 5e-15 below sqrt 2: float called it degenerate (|ev| < 1e-12)
    ("hinge", 1.4142135623731, "unstable"),  # 3e-14 above
    ("figure-eight-6", 5.98605461610344, "unstable"),  # float: degenerate
    ("figure-eight-6", 4.82842712474619, "absent"),  # float: exists (h1/h2 <= A_STAR_6 after rounding)
    ("figure-eight-6", 4.828427124746191, "unstable"),  # float: degenerate (the constraints "lost rank")
]


def _float_label(family, r):
    L = np.array([lengths(family, r)])
    fam = FAMILIES[family]
    theta, forces, exists = fam.closed_form(L, 1.0, L.min(-1))
    if not exists[0]:
        return "absent"
    inertia = equations.inertia(theta, L, forces, fam.loop_of(), 1.0, L.min(-1))
    return "degenerate" if inertia.nullity[0] else "unstable" if inertia.index[0] else "stable"


@pytest.mark.parametrize("family,r,truth", FLOAT_WRONG)
def test_where_floating_point_was_wrong_the_proof_is_right(family, r, truth):
    assert reference(family, r)[0] == truth
    assert _float_label(family, r) != truth  # the old decision: this test fails if the proof is skipped
    eq = planar_solve(family, lengths(family, r))
    assert eq.stability == truth and eq.proved


# ------------------------------------------------------------------------------------------- the undecided band
@pytest.mark.parametrize("name", ["hinge stable", "figure-eight-6 stable"])
def test_at_one_precision_points_within_reach_of_a_boundary_are_flagged_never_wrong(name, ladder):
    ladder(53)
    family, where = BOUNDARIES[name]
    b = where()
    flagged = []
    for r in near(b):
        eq = planar_solve(family, lengths(family, r))
        expected = reference(family, r)[0]
        if eq.stability == "undecided":
            assert eq.decided_by == "undecided" and eq.exists is True and eq.index == eq.nullity == -1
            flagged.append(float(abs(r / b - 1)))
        else:
            assert eq.stability == expected, (name, r)
    # 53-bit balls leave a band of about 1e-15 (relative) around the boundary: the doubles next to it are
    # flagged, points 1e-13 away are already proved.
    assert flagged and max(flagged) < 1e-13, flagged
    for s in (-1, 1):
        assert planar_solve(family, lengths(family, float(b * (1 + s * mp.mpf("1e-13"))))).proved


def test_the_precision_ladder_decides_the_doubles_next_to_sqrt_2():
    below, above = math.nextafter(math.sqrt(2), 0), math.nextafter(math.sqrt(2), 2)
    for r in (math.sqrt(2), below, above):
        eq = planar_solve("hinge", lengths("hinge", r))
        assert eq.proved and eq.stability == reference("hinge", r)[0]
        assert eq.stability == ("unstable" if mp.mpf(r) > mp.sqrt(2) else "stable")
    # math.sqrt(2) = 1.41421356237309514547... lies 1e-16 above sqrt 2 (which is stable below): unstable
    assert mp.mpf(math.sqrt(2)) > mp.sqrt(2) > mp.mpf(below)


def test_undecided_points_are_a_class_of_their_own_in_files_info_query_and_plot(ladder, tmp_path, capsys):
    ladder(53)
    b = float(mp.sqrt(2))
    ratios = [b * (1 - 1e-7), math.nextafter(b, 0), b, math.nextafter(b, 2), b * (1 + 1e-7)]
    scene = tmp_path / "s.toml"
    scene.write_text('system = "closed"\nmodel = "planar"\nfamily = "hinge"\n[grid]\nratio = { values = [' + ", ".join(repr(r) for r in ratios) + "] }\n")
    out = tmp_path / "s.nc"
    assert main(["atlas", str(scene), "-o", str(out), "-q"]) == 0
    with xr.open_dataset(out) as ds:
        st_ = ds["stability"]
        assert "undecided" in st_.attrs["flag_meanings"].split() and -3 in list(st_.attrs["flag_values"])
        by = ds["decided_by"]
        assert by.attrs["flag_meanings"] == "ball_arithmetic exact_rational_arithmetic exact_structure interval_newton undecided"
        labels = [SYSTEM.variable("stability").meaning(int(v)) for v in st_.values]
        assert labels[0] == "stable" and labels[-1] == "unstable" and "undecided" in labels
        undecided = st_.values == -3
        assert (by.values[undecided] == proofs.UNDECIDED).all() and (by.values[~undecided] == proofs.BY_BALLS).all()
        assert (ds["index"].values[undecided] == -1).all() and (ds["exists"].values == 1).all()
        k = int(undecided.sum())
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    assert f"undecided (not proved): {k}" in text and f"undecided: {k}" in text and "decided by: ball arithmetic" in text
    assert main(["query", str(out), f"ratio={b!r}"]) == 0
    text = capsys.readouterr().out
    assert "stability = undecided" in text and "(not proved: the class is undecided)" in text
    png = tmp_path / "s.png"
    assert main(["plot", str(out), "-o", str(png)]) == 0 and png.stat().st_size > 3000
    from stabmap.read.plot import class_label, colour

    assert class_label(-3, SYSTEM) == "undecided (not proved)"
    assert colour(-3, 0, -2, -3) not in (colour(-1, 0, -2, -3), colour(-2, 0, -2, -3))  # not drawn as degenerate or absent
    assert main(["query", str(out), "--fraction"]) == 0
    assert f"{k} undecided (not proved)" in capsys.readouterr().out


# ------------------------------------------------------------------------------------ no closed form: Krawczyk
def test_lengths_off_the_pattern_by_rounding_are_proved_by_krawczyk():
    L = [1.0, 0.5, 1.0, math.nextafter(0.5, 1.0)]  # figure-eight-4's pattern, one length one ulp off
    eq = planar_solve("figure-eight-4", L)
    assert eq.decided_by == "interval_newton" and eq.exists and eq.stability == "unstable"
    with mp.workdps(40):
        loops = [[0, 1, 2, 3]]
        theta, forces = ref.newton([mp.mpf(float(t)) for t in eq.theta], [tuple(mp.mpf(float(f)) for f in eq.forces[0])], L, loops)
        assert ref.residual(theta, L, forces, loops) < mp.mpf(10) ** -30
        assert ref.hessian_inertia(theta, L, forces, loops, 1e-25)[:2] == (eq.index, eq.nullity)
    # ... and absent when every pattern within the lengths is absent; flagged next to the fold
    assert planar_solve("figure-eight-4", [1.0, 1.5, 1.0, math.nextafter(1.5, 2.0)]).stability == "absent"
    folded = planar_solve("figure-eight-4", [1.0, 1.0, 1.0, math.nextafter(1.0, 2.0)])
    assert folded.stability == "undecided" and folded.exists is None and not folded.proved


def test_every_search_result_is_proved_by_krawczyk():
    for L in ([1.0, 2.0, 1.5, 1.2, 0.7], [1.0, 6.0, 1.0, 1.0, 6.0, 1.0]):
        eqs = planar_search(L, starts=120)
        assert eqs and all(e.decided_by == "interval_newton" and e.proved for e in eqs)
        for e in eqs:
            with mp.workdps(40):
                loops = [list(range(len(L)))]
                theta, forces = ref.newton([mp.mpf(float(t)) for t in e.theta], [tuple(mp.mpf(float(f)) for f in e.forces[0])], L, loops)
                assert ref.hessian_inertia(theta, L, forces, loops, 1e-25)[:2] == (e.index, e.nullity)


def test_krawczyk_encloses_the_reference_equilibrium():
    L = [1.0, 2.0, 1.5, 1.2, 0.7]
    e = planar_search(L, starts=60)[0]
    rho = e.forces * (e.h / e.c1sq)
    with proofs.precision(64):
        theta_b, rho_b = proofs.krawczyk(e.theta, rho, L, [0] * 5, 64)
        with mp.workdps(40):
            loops = [list(range(5))]
            theta, forces = ref.newton([mp.mpf(float(t)) for t in e.theta], [tuple(mp.mpf(float(f)) for f in e.forces[0])], L, loops)
            # the reference's theta_1 is the code's (held fixed); rho = R h / c1^2
            for ball, x in zip(theta_b, theta):
                assert ball.contains(proofs.arb(mp.nstr(x, 30)))
            for ball, x in zip(rho_b[0], forces[0]):
                assert ball.contains(proofs.arb(mp.nstr(x * mp.mpf(e.h) / mp.mpf(e.c1sq), 30)))
            assert max(float(b.rad()) for b in theta_b) < 1e-12


# ------------------------------------------------------------------------------------------------ the closed forms
@pytest.mark.parametrize("family", list(RANGE))
def test_the_ball_closed_forms_solve_the_general_equations_and_match_the_reference(family):
    fam = FAMILIES[family]
    lo, hi = RANGE[family]
    for r in np.geomspace(lo, hi * (1 - 1e-9), 7):
        with proofs.precision(128):
            rb = proofs.arb(float(r))
            c, s, rho = proofs.closed_form(family, rb, lambda x: x.sqrt())
            h = [proofs.arb(1) if p == 1 else rb for p in fam.pattern]
            loop_of = list(fam.loop_of())
            n = len(c)
            for k in range(n):  # (22): sin(t_(k+1) - t_k) - sin(t_k - t_(k-1)) = h_k (rho_z sin t_k + rho_y cos t_k)
                nx, pv = (k + 1) % n, k - 1
                sin_next = s[nx] * c[k] - c[nx] * s[k]
                sin_prev = s[k] * c[pv] - c[k] * s[pv]
                ry, rz = rho[loop_of[k]]
                assert (sin_next - sin_prev - h[k] * (rz * s[k] + ry * c[k])).contains(0)
                assert (c[k] * c[k] + s[k] * s[k] - 1).contains(0)
            for loop in range(len(rho)):
                assert sum((h[k] * s[k] for k in range(n) if loop_of[k] == loop), proofs.arb(0)).contains(0)
                assert sum((h[k] * c[k] for k in range(n) if loop_of[k] == loop), proofs.arb(0)).contains(0)
        with mp.workdps(40):
            theta, forces = ref.closed_form(family, ref.lengths_of(family, mp.mpf(float(r))), c1sq=1, h=1)
        np.testing.assert_allclose([float(x) for x in c], [float(mp.cos(t)) for t in theta], atol=1e-15)
        np.testing.assert_allclose([float(x) for x in s], [float(mp.sin(t)) for t in theta], atol=1e-15)
        np.testing.assert_allclose([float(v) for f in rho for v in f], [float(v) for f in forces for v in f], atol=1e-14)


def test_critical_says_proved_and_brackets_sqrt_2():
    scene = stabmap.loads_scene('system = "closed"\nmodel = "planar"\nfamily = "hinge"\n[grid]\nratio = { start = 1.2, stop = 1.6, num = 5 }\n')
    ds = stabmap.critical(scene, "ratio", threads=1, progress=False)
    assert "proved" in ds.attrs["comment"] and "proved" in ds["ratio_stable_upper"].attrs["comment"]
    assert "undecided: 0" in ds.attrs["critical_decided_by"]
    upper, outer = float(ds["ratio_stable_upper"].values.ravel()[0]), float(ds["ratio_stable_upper_outer"].values.ravel()[0])
    assert upper < math.sqrt(2) < outer and outer - upper <= 1e-10 * math.sqrt(2)


def test_bench_closed_quick(capsys):
    """scripts/bench_closed.py in quick mode, so it cannot rot (no timing is asserted)."""
    import pathlib
    import runpy

    script = pathlib.Path(__file__).resolve().parents[1] / "scripts" / "bench_closed.py"
    rows = runpy.run_path(str(script))["main"](["--quick"])
    assert [r["block"] for r in rows][:2] == ["figure-eight-6 ratio", "hinge ratio"]
    for r in rows:
        assert r["us_per_point"] > 0 and sum(r["decided_by"].values()) == r["points"]
        assert "undecided" not in r["decided_by"]
    assert "| block | points |" in capsys.readouterr().out
