"""Closed chains in space (docs/closed.md, sections 1b and 5): every spatial label against the independent reference
of tests/closed_space_reference.py (three rotation angles per body, the energy from rotation matrices, its second
differences along closed spatial polygons: no multipliers and no Hessian), the rings' closed forms, Michell's
threshold, and the user-facing parts (scenes, atlases, critical values, bad input)."""

from __future__ import annotations

import math

import closed_reference as planar_ref
import closed_space_reference as ref
import mpmath as mp
import numpy as np
import pytest
import xarray as xr

import stabmap
from stabmap import closed
from stabmap.cli import main
from stabmap.errors import StabmapError
from stabmap.systems.closed import SYSTEM, Scene

HINGE_CRITICAL = mp.mpf(333) / 125  # the hinge at h2/h1 = 1.2: its out-of-plane block turns singular at c2^2/c1^2 = 2.664


def lengths(family, r, n=None):
    return [float(x) for x in planar_ref.lengths_of(family, r, n)]


def total(split):
    (pi, pn), (oi, on) = split
    return pi + oi, pn + on


# ------------------------------------------------------------------------------------------ against the probe
@pytest.mark.parametrize("family, ratio, c2sq", [
    ("figure-eight-6", 5.5, 0.1), ("figure-eight-6", 5.5, 3.0), ("figure-eight-6", 7.0, 0.3), ("figure-eight-6", 7.0, 1.0),
    ("figure-eight-6", 9.0, 0.05), ("hinge", 0.5, 1.0), ("hinge", 1.2, 1.0), ("hinge", 1.2, 10.0), ("hinge", 1.6, 0.1),
    ("hinge", 1.6, 10.0), ("figure-eight-4", 0.5, 0.1), ("figure-eight-4", 0.8, 10.0), ("hinge-straight", 1.0, 1.0),
    ("hinge-straight", 1.5, 20.0),
])
def test_the_spatial_label_equals_the_energy_probe_of_the_three_angle_formulation(family, ratio, c2sq):
    eq = closed.solve(family, lengths(family, ratio), c2sq=c2sq, c1sq=1.0)
    split = ref.family_split_inertia(family, ratio, c2sq)
    assert (eq.planar_index, eq.planar_nullity) == split[0]
    assert (eq.index, eq.nullity) == total(split)
    assert eq.proved and eq.decided_by == "ball_arithmetic"
    stable = total(split) == (0, 0)
    assert eq.stable == stable and eq.stability == ("stable" if stable else "unstable")


def test_labels_depend_on_c2_over_c1_only_and_scale_free_inputs_leave_them():
    a = closed.solve("figure-eight-6", lengths("figure-eight-6", 7.0), c1sq=1.0, c2sq=0.5)
    b = closed.solve("figure-eight-6", [3 * x for x in lengths("figure-eight-6", 7.0)], c1sq=4.0, c2sq=2.0, h=0.7)
    assert (a.index, a.nullity, a.planar_index) == (b.index, b.nullity, b.planar_index) == (1, 0, 0)


@pytest.mark.parametrize("n, j, ratio", [(5, 1, 1), (6, 1, 1), (6, 2, 1), (8, 1, 2.0), (8, 3, 1), (9, 2, 1), (10, 2, 1),
                                         (10, 3, 0.5), (12, 5, 1), (8, 2, 1)])
def test_rings_match_the_closed_forms_and_the_probe(n, j, ratio):
    """Out of the plane the ring of winding j has index 2 (j - 1) for every c1, c2 (reference: Fourier modes)."""
    for c2sq in (0.1, 1.0, 7.0):
        eq = closed.solve("ring", lengths("ring", ratio, n), j=j, c2sq=c2sq)
        if ratio == 1:
            split = ref.ring_split_inertia_formula(n, j)
        else:
            x, L, loops = ref.family("ring", ratio, n, j)
            split = ref.split_inertia(x, L, loops, 1, c2sq)
        assert (eq.planar_index, eq.planar_nullity) == split[0], (n, j, c2sq)
        assert (eq.index, eq.nullity) == total(split), (n, j, c2sq)
        if 4 * j != n:
            assert eq.index - eq.planar_index == 2 * (j - 1)


def test_a_doubly_wound_ring_is_stable_in_its_plane_and_unstable_in_space():
    eq = closed.solve("ring", [1.0] * 10, j=2)
    assert eq.planar_stability == "stable" and eq.stability == "unstable" and eq.index == 2
    assert closed.solve("ring", [1.0] * 10, j=2, model="planar").stability == "stable"


def test_the_rigid_triangle_is_stable_out_of_its_plane_too():
    eq = closed.solve("ring", [2.0, 2.0, 2.0])
    assert (eq.index, eq.nullity, eq.stability) == (0, 0, "stable")


@pytest.mark.parametrize("family, ratio", [("figure-eight-4", 1.0), ("hinge", 2.0), ("hinge-straight", 2.0)])
def test_folded_ends_are_degenerate_in_space_exactly(family, ratio):
    eq = closed.solve(family, lengths(family, ratio), c2sq=2.0)
    assert eq.decided_by == "exact_rational_arithmetic" and eq.stability == "degenerate"
    assert eq.nullity >= eq.planar_nullity > 0 and eq.index >= eq.planar_index


# ------------------------------------------------------------------------------------ boundaries in c2^2/c1^2
def test_the_hinge_boundary_in_c2sq_is_the_rational_2_664():
    x, L, loops = ref.family("hinge", mp.mpf(6) / 5)
    below = ref.split_probe(x, L, loops, 1, HINGE_CRITICAL * (1 - mp.mpf("1e-6")))[1]
    above = ref.split_probe(x, L, loops, 1, HINGE_CRITICAL * (1 + mp.mpf("1e-6")))[1]
    assert ref.inertia(below, 3)[0] == 1 and ref.inertia(above, 3)[0] == 0


@pytest.mark.parametrize("rel", [1e-7, 1e-10, 1e-13])
def test_points_either_side_of_the_hinges_c2sq_boundary(rel):
    L = lengths("hinge", 1.2)
    for side, index in ((-1, 1), (1, 0)):
        c2sq = float(HINGE_CRITICAL * (1 + side * mp.mpf(rel)))
        eq = closed.solve("hinge", L, c2sq=c2sq)
        assert (eq.index, eq.nullity, eq.planar_index) == (index, 0, 0) and eq.proved


def test_the_doubles_next_to_the_hinges_boundary_are_decided_on_their_exact_side():
    from flint import fmpq

    L = lengths("hinge", 1.2)
    nearest = float(HINGE_CRITICAL)
    for c2sq in (math.nextafter(nearest, 0), nearest, math.nextafter(nearest, 9)):
        num, den = c2sq.as_integer_ratio()
        below = fmpq(num, den) < fmpq(333, 125)  # c1^2 = 1: gamma is the double c2sq exactly
        eq = closed.solve("hinge", L, c2sq=c2sq)
        assert eq.proved and eq.index == (1 if below else 0), c2sq


@pytest.mark.parametrize("rel", [1e-7, 1e-10])
def test_points_either_side_of_the_figure_eights_c2sq_boundary(rel):
    crit = ref.family_critical_c2sq("figure-eight-6", 7)
    L = lengths("figure-eight-6", 7.0)
    for side, index in ((-1, 1), (1, 0)):
        eq = closed.solve("figure-eight-6", L, c2sq=float(crit * (1 + side * mp.mpf(rel))))
        assert (eq.index, eq.planar_index) == (index, 0) and eq.proved


def test_critical_along_c2sq_brackets_the_hinges_boundary(tmp_path):
    scene = tmp_path / "hinge.toml"
    scene.write_text('system = "closed"\nfamily = "hinge"\nratio = 1.2\n[grid]\nc2sq = { start = 0.5, stop = 4.0, num = 8 }\n')
    out = tmp_path / "c.nc"
    assert main(["critical", str(scene), "--along", "c2sq", "-o", str(out), "-q"]) == 0
    with xr.open_dataset(out) as ds:
        lo, hi = ds["boundary_lower"].values.ravel(), ds["boundary_upper"].values.ravel()
        found = [(a, b) for a, b in zip(lo, hi) if np.isfinite(a)]
        assert len(found) == 1
        a, b = found[0]
        assert a <= float(HINGE_CRITICAL) <= b and (b - a) <= 1e-9 * b


# ----------------------------------------------------------------------------------------------- twisted rings
@pytest.mark.parametrize("n, m", [(8, 1), (12, 1), (12, 2)])
def test_twisted_rings_lose_stability_where_the_reference_says(n, m):
    gamma = ref.critical_ratio(n, 1, m)
    for side in (-1, 1):
        eq = closed.solve("ring", [1.0] * n, twist=m, c2sq=float(gamma * (1 + side * mp.mpf("1e-7"))))
        assert eq.proved and (eq.stability == "stable") == (side < 0), (n, m, side)


def test_the_twisted_rings_force_and_residual():
    eq = closed.solve("ring", [2.0] * 12, twist=1, c1sq=3.0, c2sq=0.7, h=1.5)
    x, L, loops = ref.twisted_ring(12, 1, 1)
    want = ref.twisted_ring_force(12, 1, 1, c1sq=3, c2sq=mp.mpf("0.7"), h=mp.mpf("1.5"), h1=2)
    assert eq.force_x[0] == pytest.approx(float(want[0]), rel=1e-13)
    assert eq.residual < 1e-13 and np.allclose(eq.phi, 2 * np.pi * np.arange(1, 13) / 12)


def test_michells_threshold_is_approached_as_n_grows():
    """m c2^2/c1^2 at the loss of stability of the ring with one turn of twist tends to sqrt 3 (Michell 1889)."""
    from stabmap.run.critical import critical
    from stabmap.scene.grid import Axis

    scene = Scene(family="ring", n=24, twist=1, grid=(Axis("c2sq", tuple(np.linspace(1.5, 1.9, 5).tolist())),))
    ds = critical(scene, "c2sq", progress=False)
    lo = ds["boundary_lower"].values.ravel()
    hi = ds["boundary_upper"].values.ravel()
    found = [(a + b) / 2 for a, b in zip(lo, hi) if np.isfinite(a)]
    assert len(found) == 1
    assert found[0] == pytest.approx(1.70437901565, rel=1e-9)  # the reference's Gamma_c(24)
    assert 1.70 < found[0] < math.sqrt(3)


# ------------------------------------------------------------------------------------------------ search, files
def test_search_reports_each_shapes_class_in_space_against_the_probe():
    found = closed.search([1.0, 6.0, 1.0, 1.0, 6.0, 1.0], starts=120, c2sq=0.4)
    assert found and all(e.proved for e in found)
    for e in found[:3]:
        theta = [mp.mpf(float(t)) for t in e.theta]
        x = ref.pack(theta)
        split = ref.split_inertia(x, [mp.mpf(v) for v in e.lengths], [list(range(6))], 1, mp.mpf("0.4"))
        assert (e.index, e.nullity) == total(split) and (e.planar_index, e.planar_nullity) == split[0]


def test_atlas_over_ratio_and_c2sq_keeps_both_classes(tmp_path):
    scene = stabmap.loads_scene('system = "closed"\nfamily = "figure-eight-6"\n[grid]\nratio = { values = [5.5, 7.0] }\n'
                                'c2sq = { values = [0.1, 1.0] }\n')
    ds = stabmap.compute_atlas(scene, threads=1, progress=False)
    assert ds["stability"].values.tolist() == [[1, 1], [1, 0]]
    assert ds["planar_stability"].values.tolist() == [[1, 1], [0, 0]]
    assert ds["index"].values.tolist() == [[2, 1], [1, 0]] and ds["planar_index"].values.tolist() == [[1, 1], [0, 0]]
    assert ds.attrs["closed_model"] == "spatial"
    assert "space" in ds["stability"].attrs["long_name"] and "plane" in ds["planar_stability"].attrs["long_name"]


def test_c2sq_defaults_to_c1sq_at_each_point():
    scene = Scene(family="figure-eight-6", ratio=7.0)
    out = SYSTEM.evaluate(scene, {"c1sq": np.array([0.5, 2.0])})
    same = SYSTEM.evaluate(Scene(family="figure-eight-6", ratio=7.0, c2sq=1.0), {"c1sq": np.array([1.0, 1.0])})
    np.testing.assert_array_equal(out["index"], same["index"])


def test_the_planar_model_is_the_papers():
    scene = Scene(family="hinge", ratio=1.2, model="planar")
    out = SYSTEM.evaluate(scene, {})
    assert int(out["stability"]) == 0 and int(out["planar_stability"]) == 0
    out = SYSTEM.evaluate(Scene(family="hinge", ratio=1.2), {})
    assert int(out["stability"]) == 1 and int(out["planar_stability"]) == 0


# ------------------------------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kw, message", [
    ({"c2sq": -1.0}, "c2sq must be > 0"), ({"twist": 1}, "leave twist out"), ({"model": "flat"}, "model = 'flat'"),
])
def test_bad_spatial_input_from_python(kw, message):
    with pytest.raises(StabmapError, match=message):
        closed.solve("hinge", lengths("hinge", 1.2), **kw)
    with pytest.raises(StabmapError, match="equal lengths"):
        closed.solve("ring", [1.0, 2.0] * 4, twist=1)
