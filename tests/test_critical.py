"""Critical values along one axis: located ends against closed forms and the independent exact reference."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import reference as ref
import stabmap
from stabmap.cli import main
from stabmap.run.critical import critical
from stabmap.systems.gyroscopes.scene import from_dict
from systems import reference_args
from scenes import maievskii_w2, top_system, two_tops


def _maievskii_scene(num=41):
    return from_dict(top_system({"omega": {"start": -60.0, "stop": 60.0, "num": num}, "c_1": {"values": [0.05, 0.1, 0.2, 0.3]}}))


def test_bad_arguments_from_python_name_the_parameters():
    # the messages of test_cli_roundtrip_plot_and_errors, as a Python caller wrote them
    scene = _maievskii_scene(num=3)
    with pytest.raises(stabmap.StabmapError, match=r"^rtol=2: must be between 1e-15"):
        critical(scene, rtol=2)
    with pytest.raises(stabmap.StabmapError, match=r"^along='K_0': not a grid axis of this scene; its grid axes are: omega, c_1"):
        critical(scene, "K_0")
    with pytest.raises(stabmap.StabmapError, match=r"^atol=-1: must be a finite number >= 0"):
        critical(scene, atol=-1)


def test_the_default_axis_is_the_systems():
    # no along: the gyroscopes' default_axis, omega; a scene without it says which default it took and why
    assert critical(_maievskii_scene(num=5), rtol=1e-6).attrs["critical_along"] == "omega"
    scene = from_dict(top_system({"m_1": {"values": [0.5, 1.0]}}, omega=50.0))
    with pytest.raises(stabmap.StabmapError, match=r"along not given, so the gyroscopes system's default axis 'omega': not a grid "
                                                   r"axis of this scene; its grid axes are: m_1. .*, or give along one of them"):
        critical(scene)


def test_maievskii_critical_spin_rates_are_bracketed_exactly():
    # C^2 w^2 >= 4 (A + m c^2) m c g: the stable set is |w| >= w*, checked in exact rationals on the binary values.
    ds = critical(_maievskii_scene(), "omega", rtol=1e-10)
    assert list(ds["n_stable_intervals"].values) == [2, 2, 2, 2]
    for j, c in enumerate(ds["c_1"].values):
        w2 = maievskii_w2(c)
        # upper interval: [w*, 60]; its lower end is certified stable, the outer value certified unstable
        lower = ds["omega_stable_lower"][j, 1].item()
        outer = ds["omega_stable_lower_outer"][j, 1].item()
        assert Fraction(outer) ** 2 < w2 <= Fraction(lower) ** 2
        assert 0 < lower - outer <= 1e-10 * lower
        # lower interval: [-60, -w*] by the omega-sign symmetry
        upper = ds["omega_stable_upper"][j, 0].item()
        assert Fraction(upper) ** 2 >= w2 > Fraction(ds["omega_stable_upper_outer"][j, 0].item()) ** 2
        assert ds["omega_stable_lower"][j, 0].item() == -60.0 and np.isnan(ds["omega_stable_lower_outer"][j, 0].item())


def _liquid_pair():
    """The two tops on a softer joint, with liquid in both."""
    system = two_tops(joints=[5.0])
    del system["omega"]
    system["bodies"][1]["fluid"] = {"E": [4e-4], "kappa": [-2.2]}
    return system


def test_every_boundary_is_a_real_change_of_the_exact_count():
    system = _liquid_pair()
    system["grid"] = {"omega": {"start": 1.0, "stop": 150.0, "num": 60}, "m_2": {"values": [0.3, 2.0]}}
    ds = critical(from_dict(system), "omega", rtol=1e-10)
    found = 0
    for j, m2 in enumerate(ds["m_2"].values):
        for k in range(ds.sizes["boundary"]):
            lo, hi = ds["boundary_lower"][j, k].item(), ds["boundary_upper"][j, k].item()
            if np.isnan(lo):
                continue
            found += 1
            assert 0 < hi - lo <= 1e-10 * max(abs(lo), abs(hi))
            counts = []
            for omega in (lo, hi):
                point = dict(system, omega=omega)
                point.pop("grid")
                point["bodies"] = [dict(b) for b in system["bodies"]]
                point["bodies"][1]["m"] = float(m2)
                counts.append(ref.count_complex_pairs(ref.char_poly(**reference_args(point))))
            assert counts == [ds["n_complex_pairs_below"][j, k].item(), ds["n_complex_pairs_above"][j, k].item()]
            assert counts[0] != counts[1]
    assert found >= 2


def test_the_label_at_scan_start_and_the_boundaries_give_the_label_of_every_scan_value():
    # The file states the label everywhere in the scan: the start's, then each boundary's label above it.
    system = _liquid_pair()
    system["grid"] = {"omega": {"start": 1.0, "stop": 150.0, "num": 60}, "m_2": {"values": [0.3, 2.0]}}
    scene = from_dict(system)
    ds = critical(scene, "omega", rtol=1e-10)
    atlas = stabmap.compute_atlas(scene, progress=False)["n_complex_pairs"].transpose("m_2", "omega")
    for j in range(ds.sizes["m_2"]):
        lo = ds["boundary_lower"][j].values
        ok = np.isfinite(lo)
        labels = [int(ds["n_complex_pairs_at_scan_start"][j]), *ds["n_complex_pairs_above"][j].values[ok]]
        for i, omega in enumerate(atlas["omega"].values):
            stretch = int(np.searchsorted(lo[ok], omega, side="left"))  # boundaries whose bracket lies below omega
            assert labels[stretch] == int(atlas[j, i]), (j, omega)


def _ref_count(system: dict, omega: float) -> int:
    point = {k: v for k, v in system.items() if k != "grid"}
    point["omega"] = omega
    return ref.count_complex_pairs(ref.char_poly(**reference_args(point)))


def test_stable_ends_stay_stable_when_one_scan_step_holds_several_changes():
    # Two ideal-jointed tops: N_c is 2 below omega ~ 9.1, 1 up to ~ 25.0, then 0.  A scan of two values puts both
    # changes into one step; the located lower end of the stable interval must still be a stable value, with
    # an unstable one within rtol below it (a plain bisection would have converged on the 2 -> 1 change).
    system = two_tops(joints=[0.0], grid={"omega": {"values": [0.5, 150.0]}})
    del system["omega"], system["bodies"][0]["fluid"]
    ds = critical(from_dict(system), "omega")
    assert int(ds["n_stable_intervals"]) == 1
    lower, outer = ds["omega_stable_lower"][0].item(), ds["omega_stable_lower_outer"][0].item()
    assert 24 < lower < 26 and 0 < lower - outer <= 1e-10 * lower
    assert _ref_count(system, lower) == 0 and _ref_count(system, outer) == 1


def test_three_axes_give_two_output_dimensions():
    scene = from_dict(top_system({"c_1": {"values": [0.1, 0.2]}, "omega": {"start": 0.5, "stop": 60.0, "num": 20}, "m_1": {"values": [1.0, 2.0, 3.0]}}))
    ds = critical(scene, "omega")
    assert ds["omega_stable_lower"].dims == ("c_1", "m_1", "interval")
    assert ds["n_stable_intervals"].shape == (2, 3)


def test_cli_roundtrip_plot_and_errors(tmp_path, capsys):
    scene = tmp_path / "top.toml"
    scene.write_text(_maievskii_scene().to_toml())
    out, png = tmp_path / "crit.nc", tmp_path / "crit.png"
    assert main(["critical", str(scene), "--along", "omega", "-o", str(out), "--png", str(png)]) == 0
    printed = capsys.readouterr().out
    assert "stable omega [rad s-1]" in printed and "(boundary)" in printed
    ds = stabmap.open_atlas(out)
    assert ds.attrs["stabmap_kind"] == "critical values" and ds.attrs["critical_rtol"] == 1e-10
    assert png.stat().st_size > 10_000
    assert main(["plot", str(out), "-o", str(tmp_path / "again.png")]) == 0
    assert main(["info", str(out)]) == 0
    # Bad input: exit 2, a message naming the option, and no file.
    bad = tmp_path / "bad.nc"
    assert main(["critical", str(scene), "--along", "K_0", "-o", str(bad)]) == 2
    assert "--along K_0: not a grid axis" in capsys.readouterr().err  # a parameter, not scanned: add it to [grid]
    assert main(["critical", str(scene), "--along", "K1", "-o", str(bad)]) == 2
    err = capsys.readouterr().err  # not a parameter at all: no advice to add it to [grid]
    assert "--along K1: unknown parameter name 'K1'" in err and "under [grid]" not in err
    assert main(["critical", str(scene), "--rtol", "0", "-o", str(bad)]) == 2
    assert "--rtol 0.0: must be between" in capsys.readouterr().err
    assert not bad.exists()


def test_plot_with_two_other_axes_asks_for_sel(tmp_path):
    scene = from_dict(top_system({"c_1": {"values": [0.1, 0.2]}, "omega": {"start": 0.5, "stop": 60.0, "num": 10}, "m_1": {"values": [1.0, 2.0]}}))
    ds = critical(scene, "omega")
    from stabmap.read.plot import plot_critical

    with pytest.raises(stabmap.StabmapError, match=r"fix all but one with sel=\{'NAME': VALUE\}"):
        plot_critical(ds, tmp_path / "x.png")
    plot_critical(ds, tmp_path / "x.png", sel={"m_1": 2.0})
    assert (tmp_path / "x.png").exists()


def test_boundary_at_exactly_zero_uses_the_absolute_floor(tmp_path):
    # At omega = 0 a top is stable iff c <= 0 (p = (A + m c^2) lam^2 + m c g), so the boundary is c = 0 exactly, where
    # no relative width can be reached. Also: a decreasing scan, an axis other than omega, no other axis, its plot.
    scene = from_dict(top_system({"c_1": {"start": 0.2, "stop": -0.2, "num": 40}}, omega=0.0))
    ds = critical(scene, "c_1", rtol=1e-10)
    atol = 1e-6 * 1e-10 * 0.2
    assert ds.attrs["critical_atol"] == pytest.approx(atol) and ds["c_1_stable_lower"].dims == ("interval",)
    assert int(ds["n_stable_intervals"]) == 1
    assert ds["c_1_stable_lower"].item() == -0.2 and np.isnan(ds["c_1_stable_lower_outer"].item())
    upper, outer = ds["c_1_stable_upper"].item(), ds["c_1_stable_upper_outer"].item()
    assert upper <= 0.0 < outer and outer - upper <= atol
    from stabmap.read.plot import plot_critical

    assert plot_critical(ds, tmp_path / "line.png").read_bytes()[:4] == b"\x89PNG"


# Dyadic parameters: the floats are the rationals, so the discriminant below has small integer coefficients.
_DYADIC = {
    "support": "fixed", "g": 9.75,
    "bodies": [
        {"m": 1.0, "A": 0.0234375, "C": 0.03125, "c": 0.125, "s": 0.25, "fluid": {"E": [0.0009765625], "kappa": [1.3125]}},
        {"m": 0.5, "A": 0.009765625, "C": 0.015625, "c": 0.0625, "fluid": {"E": [0.00048828125], "kappa": [3.0]}},
    ],
}


def _bivariate(joints: list[float]):
    """p(lam, w) of the dyadic pair at spin rate w: total degree <= 6 in (lam, w) (docs/model.md), so 7 nodes fix it."""
    import sympy

    w = sympy.Symbol("w")

    def at(omega):
        point = dict(_DYADIC, joints=joints, omega=omega)
        return ref.char_poly(**reference_args(point)).as_expr()

    nodes = [sympy.Integer(k) for k in range(1, 9)]  # one more than needed
    P = sympy.Poly(sympy.expand(sympy.interpolate([(x, at(x)) for x in nodes], w)), ref.lam)
    assert sympy.expand(P.as_expr().subs(w, sympy.Rational(37, 3)) - at(Fraction(37, 3))) == 0
    return P, w, at


def test_boundaries_are_the_real_roots_of_discriminant_times_leading_coefficient():
    # N_c can change only where p has a multiple root (discriminant 0) or loses degree (leading coefficient 0).
    # Each located bracket must hold such a root, and each such root at which N_c changes must lie in a bracket.
    import sympy

    system = dict(_DYADIC, joints=[0.0])
    system["grid"] = {"omega": {"start": -150.0, "stop": 150.0, "num": 601}, "K_1": {"values": [0.0, 2.0]}}
    ds = critical(from_dict(system), "omega", rtol=1e-10)
    for j, K in enumerate(ds["K_1"].values):
        P, w, at = _bivariate([float(K)])
        D = (sympy.Poly(sympy.discriminant(P, ref.lam), w) * sympy.Poly(P.LC(), w)).sqf_part()
        lo, hi = ds["boundary_lower"][j].values, ds["boundary_upper"][j].values
        lo, hi = lo[np.isfinite(lo)], hi[np.isfinite(hi)]
        assert lo.size >= 6
        for a, b in zip(lo, hi):
            assert D.count_roots(sympy.Rational(a), sympy.Rational(b)) >= 1
        changes = 0
        for (a, b), _ in D.intervals(eps=Fraction(1, 10**12), inf=-150, sup=150):
            if a == b:  # a rational root: look just beside it
                a, b = a - Fraction(1, 10**9), b + Fraction(1, 10**9)
            if ref.count_complex_pairs(at(a)) != ref.count_complex_pairs(at(b)):
                changes += 1
                assert np.any((lo <= float(b)) & (hi >= float(a))), (float(a), float(b))
        assert changes == lo.size


def test_a_coarse_scan_finds_every_boundary_of_a_fine_one():
    # Box proofs between scan values: a stable window about 1 rad/s wide near omega = 24 lies inside one step of
    # 25 rad/s, and the coarse scan still reports it, with every boundary in the fine scan's bracket and the same
    # N_c on each side.  What no box proof settled is listed as an undecided gap, with equal N_c at its ends.
    found = {}
    for num in (13, 601):
        system = dict(_DYADIC, joints=[2.0])
        system["grid"] = {"omega": {"start": -150.0, "stop": 150.0, "num": num}}
        ds = critical(from_dict(system), "omega")
        assert ds.attrs["critical_boxes_proved"] > 0
        gaps = ds["undecided_lower"].values[: int(ds["n_undecided"])], ds["undecided_upper"].values[: int(ds["n_undecided"])]
        assert np.all(gaps[0] < gaps[1]) and np.all(gaps[1][:-1] <= gaps[0][1:])
        # the only stretch left unproved is around omega = 0, where no spin-scaled box applies (u = 1/omega^2)
        assert np.all(np.abs(gaps) < 1e-12)
        for lo, hi in zip(*gaps):
            at = [ref.count_complex_pairs(ref.char_poly(**reference_args(dict(system, omega=float(x)))).as_expr()) for x in (lo, hi)]
            assert at[0] == at[1]
        keep = np.isfinite(ds["boundary_lower"].values)
        found[num] = [(ds[v].values[keep]) for v in ("boundary_lower", "boundary_upper", "n_complex_pairs_below", "n_complex_pairs_above")]
    fine_lo, fine_hi, fine_below, fine_above = found[601]
    assert fine_lo.size == 6 and found[13][0].size == 6
    for lo, hi, below, above in zip(*found[13]):
        k = np.flatnonzero((fine_lo <= hi) & (fine_hi >= lo))
        assert k.size == 1 and (fine_below[k[0]], fine_above[k[0]]) == (below, above)


def test_cli_png_with_two_other_axes_fails_before_the_work(tmp_path, capsys):
    scene = tmp_path / "three.toml"
    scene.write_text(from_dict(top_system({"c_1": {"values": [0.1, 0.2]}, "omega": {"start": 0.5, "stop": 60.0, "num": 10}, "m_1": {"values": [1.0, 2.0]}})).to_toml())
    out = tmp_path / "c.nc"
    assert main(["critical", str(scene), "-o", str(out), "--png", str(tmp_path / "c.png")]) == 2
    assert "--sel m_1=VALUE" in capsys.readouterr().err and not out.exists()
