"""Critical values along one axis: located ends against closed forms and the independent exact reference."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import reference as ref
import stabmap
from stabmap.cli import main
from stabmap.critical import critical
from stabmap.scene import from_dict
from systems import reference_args

TOP = {"m": 1.0, "A": 0.02, "C": 0.03}


def _maievskii_scene(num=41):
    return from_dict({
        "support": "fixed", "g": 9.81, "bodies": [dict(TOP, c=0.1)],
        "grid": {"omega": {"start": -60.0, "stop": 60.0, "num": num}, "c_1": {"values": [0.05, 0.1, 0.2, 0.3]}},
    })


def test_maievskii_critical_spin_rates_are_bracketed_exactly():
    # C^2 w^2 >= 4 (A + m c^2) m c g: the stable set is |w| >= w*, checked in exact rationals on the binary values.
    ds = critical(_maievskii_scene(), "omega", rtol=1e-10)
    assert list(ds["n_stable_intervals"].values) == [2, 2, 2, 2]
    for j, c in enumerate(ds["c_1"].values):
        m, A, C, g, c = (Fraction(x) for x in (TOP["m"], TOP["A"], TOP["C"], 9.81, float(c)))
        w2 = 4 * (A + m * c * c) * m * c * g / (C * C)
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
    return {
        "support": "fixed", "g": 9.81, "joints": [5.0],
        "bodies": [
            {"m": 1.0, "A": 0.02, "C": 0.03, "c": 0.10, "s": 0.25, "fluid": {"E": [1e-3], "kappa": [1.31]}},
            {"m": 0.5, "A": 0.01, "C": 0.015, "c": 0.08, "fluid": {"E": [4e-4], "kappa": [-2.2]}},
        ],
    }


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


def _ref_count(system: dict, omega: float) -> int:
    point = {k: v for k, v in system.items() if k != "grid"}
    point["omega"] = omega
    return ref.count_complex_pairs(ref.char_poly(**reference_args(point)))


def test_stable_ends_stay_stable_when_one_scan_step_holds_several_changes():
    # Two ideal-jointed tops: N_c is 2 below omega ~ 9.1, 1 up to ~ 25.0, then 0.  A scan of two values puts both
    # changes into one step; the located lower end of the stable interval must still be a stable value, with
    # an unstable one within rtol below it (a plain bisection would have converged on the 2 -> 1 change).
    system = {
        "support": "fixed", "g": 9.81, "joints": [0.0],
        "bodies": [{"m": 1.0, "A": 0.02, "C": 0.03, "c": 0.10, "s": 0.25}, {"m": 0.5, "A": 0.01, "C": 0.015, "c": 0.08}],
        "grid": {"omega": {"values": [0.5, 150.0]}},
    }
    ds = critical(from_dict(system), "omega")
    assert int(ds["n_stable_intervals"]) == 1
    lower, outer = ds["omega_stable_lower"][0].item(), ds["omega_stable_lower_outer"][0].item()
    assert 24 < lower < 26 and 0 < lower - outer <= 1e-10 * lower
    assert _ref_count(system, lower) == 0 and _ref_count(system, outer) == 1


def test_three_axes_give_two_output_dimensions():
    scene = from_dict({
        "support": "fixed", "g": 9.81, "bodies": [dict(TOP, c=0.1)],
        "grid": {"c_1": {"values": [0.1, 0.2]}, "omega": {"start": 0.5, "stop": 60.0, "num": 20}, "m_1": {"values": [1.0, 2.0, 3.0]}},
    })
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
    assert main(["critical", str(scene), "--along", "K_1", "-o", str(bad)]) == 2
    assert "--along K_1: not a grid axis" in capsys.readouterr().err
    assert main(["critical", str(scene), "--rtol", "0", "-o", str(bad)]) == 2
    assert "rtol must be between" in capsys.readouterr().err
    assert not bad.exists()


def test_plot_with_two_other_axes_asks_for_sel(tmp_path):
    scene = from_dict({
        "support": "fixed", "g": 9.81, "bodies": [dict(TOP, c=0.1)],
        "grid": {"c_1": {"values": [0.1, 0.2]}, "omega": {"start": 0.5, "stop": 60.0, "num": 10}, "m_1": {"values": [1.0, 2.0]}},
    })
    ds = critical(scene, "omega")
    from stabmap.plot import plot_critical

    with pytest.raises(stabmap.StabmapError, match="fix all but one with --sel"):
        plot_critical(ds, tmp_path / "x.png")
    plot_critical(ds, tmp_path / "x.png", sel={"m_1": 2.0})
    assert (tmp_path / "x.png").exists()
