"""How many liquid modes a geometric cavity keeps: modes = "auto" and mode_tolerance (docs/cavities.md).

The reference for the tail is independent of stabmap's mode solver: the cylinder's roots
are found again with mpmath from the eigen-equation, E from the closed form, and the
Zhukovsky deficit from its axial series summed by mpmath.nsum.
"""

from __future__ import annotations

import subprocess
import sys

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from stabmap import loads_scene
from stabmap.errors import StabmapError
from stabmap.read.info import describe
from stabmap.run import atlas
from stabmap.systems.gyroscopes import cavity, liquid

TOP = """
title = "top with a cylinder"
support = "fixed"
g = 9.81
[[bodies]]
m = 3.0
A = {A}
C = 0.02
c = 0.2
cavity = {{ shape = "cylinder", radius = {a}, half_height = {a}, density = 1000.0{extra} }}
[grid]
omega = {{ start = 60.0, stop = 200.0, num = {nw} }}
half_height_1 = {{ start = {h0}, stop = {h1}, num = {nh} }}
"""


def top(extra: str = "", a: float = 0.05, A: float = 0.05, q=(0.25, 1.0), nw: int = 4, nh: int = 4):
    """A top whose cavity's half height runs over q = half_height / radius from q[0] to q[1]."""
    return loads_scene(TOP.format(extra=extra, a=a, A=A, nw=nw, nh=nh, h0=q[0] * a, h1=q[1] * a))


# ---------------------------------------------------------------------------------------------- the reference
def _root(n: int, j: int, sign: int, q: float) -> tuple[mp.mpf, mp.mpf]:
    """(xi, kappa) of cylinder mode (n, j, sign) from xi J1'(xi) + kappa J1(xi) = 0, bracketed by zeros of J1."""
    beta = 2 * mp.mpf(q) / ((2 * n - 1) * mp.pi)
    zeros = [mp.mpf("1e-3")] + [mp.besseljzero(1, i) for i in range(1, j + 2)]
    lo, hi = (zeros[j - 1], zeros[j]) if sign > 0 else (zeros[j], zeros[j + 1])

    def f(x):
        kappa = sign * mp.sqrt(1 + (beta * x) ** 2)
        return x * mp.besselj(1, x, derivative=1) + kappa * mp.besselj(1, x)

    xi = mp.findroot(f, (lo + mp.mpf("1e-12"), hi - mp.mpf("1e-12")), solver="anderson")
    return xi, sign * mp.sqrt(1 + (beta * xi) ** 2)


def reference_modes(q: float, n_max: int = 5, j_max: int = 7) -> list[float]:
    """Scaled E (by density radius^5) of every mode n <= n_max, j <= j_max on both branches, largest first."""
    out = []
    for n in range(1, n_max + 1):
        beta = 2 * mp.mpf(q) / ((2 * n - 1) * mp.pi)
        for j in range(1, j_max + 1):
            for sign in (+1, -1):
                xi, k = _root(n, j, sign, q)
                out.append(32 * beta**3 * (k + 1) ** 2 / ((2 * n - 1) * k * xi**2 * (k + (k - 1) * beta**2)))
    return sorted((float(e) for e in out), reverse=True)


def reference_deficit(q: float) -> float:
    """(J_rigid - J_Zh) / (density radius^5) of a cylinder, its axial series summed by mpmath."""
    q = mp.mpf(q)

    def term(n):
        x = (2 * n - 1) * mp.pi / (2 * q)
        return (x * mp.besseli(2, x) - mp.besseli(1, x)) / (x**5 * mp.besseli(1, x, derivative=1))

    return float(4 * mp.pi / 3 * q**3 + 8 * mp.pi / q * mp.nsum(term, [1, mp.inf]))


@pytest.fixture(scope="module")
def ref_q1():
    with mp.workdps(20):
        return reference_modes(1.0), reference_deficit(1.0)


# ------------------------------------------------------------------------------------------- the tail and the count
def test_tail_share_and_tail_over_A_match_an_independent_mode_table(ref_q1):
    E, deficit = ref_q1
    for N in (1, 2, 3, 4):
        s = top(f", modes = {N}", q=(1.0, 1.0), nh=1)
        c = s.bodies[0].cavity
        tail = deficit - sum(E[:N])
        assert c.tail_share == pytest.approx(tail / deficit, rel=1e-9)
        assert c.tail_over_A == pytest.approx(1000.0 * 0.05**5 * tail / 0.05, rel=1e-9)


def test_auto_keeps_the_fewest_modes_meeting_the_tolerance(ref_q1):
    E, deficit = ref_q1
    over_A = [1000.0 * 0.05**5 * (deficit - sum(E[:N])) / 0.05 for N in range(8)]
    for N in (1, 2, 3, 5):
        tol = (over_A[N] + over_A[N - 1]) / 2  # met by N modes and not by N - 1
        c = top(f", mode_tolerance = {tol!r}", q=(1.0, 1.0), nh=1).bodies[0].cavity
        assert (c.modes, c.kept) == ("auto", N)
        assert c.tail_over_A <= tol


def test_one_count_for_the_whole_grid_set_by_its_worst_point():
    # A tail share grows with the aspect ratio here, so the tallest cavity of the scan decides.
    tol = 5e-3
    chosen = top(f", mode_tolerance = {tol}", q=(0.25, 1.0)).bodies[0].cavity
    per_point = [top(f", mode_tolerance = {tol}", q=(q, q), nh=1).bodies[0].cavity.kept for q in np.linspace(0.25, 1.0, 4)]
    assert chosen.kept == max(per_point) and min(per_point) < chosen.kept
    fewer = top(f", modes = {chosen.kept - 1}", q=(0.25, 1.0)).bodies[0].cavity
    assert fewer.tail_over_A > tol >= chosen.tail_over_A


def test_scanned_radius_and_A_take_the_worst_pairing():
    # The tail scales as radius^5 at a fixed ratio: the largest radius against the smallest A bounds every point.
    text = TOP.format(extra=", mode_tolerance = 4e-3", a=0.05, A=0.05, nw=3, nh=1, h0=0.05, h1=0.05)
    s = loads_scene(text + "radius_1 = { values = [0.03, 0.05] }\nA = { values = [0.05, 0.2] }\n")
    c = s.bodies[0].cavity
    single = top(f", modes = {c.kept}", q=(1.0, 1.0), nh=1).bodies[0].cavity  # radius 0.05, A 0.05: the worst point
    assert c.tail_over_A == pytest.approx(single.tail_over_A, rel=1e-12)


@settings(max_examples=25, deadline=None)
@given(st.floats(-2.3, -0.5), st.floats(0.1, 1.0))  # down to 5e-4: 64 modes reach 3.2e-4 here
def test_a_tighter_tolerance_never_keeps_fewer_modes(log_tol, factor):
    loose = 10.0**log_tol
    tight = loose * factor
    kept = [top(f", mode_tolerance = {t!r}", q=(0.25, 1.0)).bodies[0].cavity for t in (tight, loose)]
    assert kept[0].kept >= kept[1].kept
    assert kept[0].tail_over_A <= tight and kept[1].tail_over_A <= loose


def test_default_is_the_count_and_auto_is_capped_at_it():
    # Without modes or mode_tolerance the cavity keeps the default count, whatever its tail: the tail bound
    # says nothing about the resonance bands of the modes it would drop (docs/cavities.md, "Choosing N").
    plain = top(a=0.02).bodies[0].cavity
    assert (plain.modes, plain.mode_tolerance, plain.kept) == (cavity.DEFAULT_MODES, None, cavity.DEFAULT_MODES)
    small = top(', modes = "auto"', a=0.02).bodies[0].cavity  # a small cavity in the body: one mode is enough
    assert (small.modes, small.mode_tolerance, small.kept) == ("auto", None, 1)
    assert small.tail_over_A <= liquid.DEFAULT_TOLERANCE
    heavy = top(', modes = "auto"', q=(0.25, 3.0)).bodies[0].cavity  # tall and heavy: auto keeps its cap, says so
    assert heavy.kept == cavity.DEFAULT_MODES and heavy.tail_over_A > liquid.DEFAULT_TOLERANCE
    assert "not met" in liquid.describe(heavy)
    # A stated tolerance may keep more than the default's cap.
    stated = top(", mode_tolerance = 1e-2", q=(0.25, 3.0)).bodies[0].cavity
    assert stated.kept > cavity.DEFAULT_MODES and stated.tail_over_A <= 1e-2


def test_explicit_count_is_kept_whatever_the_grid():
    for q, nh in (((0.25, 0.25), 1), ((0.25, 3.0), 4)):
        s = top(", modes = 5", q=q, nh=nh)
        assert (s.bodies[0].cavity.kept, int(s.nmodes[0])) == (5, 5)
        assert "mode_tolerance" not in s.to_dict()["bodies"][0]["cavity"]


def test_spheroid_auto_is_its_one_mode():
    text = TOP.format(extra=", mode_tolerance = 1e-6", a=0.05, A=0.05, nw=2, nh=2, h0=0.03, h1=0.06).replace("cylinder", "spheroid")
    c = loads_scene(text).bodies[0].cavity
    assert (c.kept, c.tail_over_A) == (1, 0.0)


# ---------------------------------------------------------------------------------------- round trip and info
def test_round_trip_and_atlas_reproduce_the_choice(tmp_path):
    s = top(", mode_tolerance = 3e-4", a=0.03, nw=6, nh=3)
    assert 1 < s.nmodes[0] < cavity.DEFAULT_MODES
    table = s.to_dict()["bodies"][0]["cavity"]
    assert (table["modes"], table["mode_tolerance"]) == ("auto", 3e-4)
    again = loads_scene(s.to_toml())
    assert again == s and again.nmodes.tolist() == s.nmodes.tolist()
    ds = atlas.compute(s, progress=False)
    rebuilt = loads_scene(ds.attrs["scene"])
    assert rebuilt.nmodes.tolist() == s.nmodes.tolist()
    assert np.array_equal(atlas.compute(rebuilt, progress=False).n_complex_pairs.values, ds.n_complex_pairs.values)
    text = describe(ds, "a.nc")
    lines = text.splitlines()
    start = next(i for i, x in enumerate(lines) if "body 1:" in x)
    # body 1's group: its line and the wrapped lines under it, up to the next group
    group = " ".join([lines[start]] + [x for x in lines[start + 1 :] if x.startswith(" " * 12)][:4])
    c = s.bodies[0].cavity
    assert f"{c.kept} liquid modes kept" in group and "mode_tolerance = 0.0003" in group
    assert f"{100 * c.tail_over_A:.2g} % of A" in group


def test_default_scene_writes_its_count_and_auto_without_a_tolerance():
    assert top(a=0.02).to_dict()["bodies"][0]["cavity"]["modes"] == cavity.DEFAULT_MODES
    table = top(', modes = "auto"', a=0.02).to_dict()["bodies"][0]["cavity"]
    assert table["modes"] == "auto" and "mode_tolerance" not in table


# --------------------------------------------------------------------------------------------------- errors
@pytest.mark.parametrize(
    "extra, message",
    [
        (", mode_tolerance = 0.0", "bodies[1].cavity.mode_tolerance must be a number with 0 < mode_tolerance < 1"),
        (", mode_tolerance = -1e-3", "bodies[1].cavity.mode_tolerance must be a number with 0 < mode_tolerance < 1"),
        (", mode_tolerance = 1.5", "bodies[1].cavity.mode_tolerance must be a number with 0 < mode_tolerance < 1"),
        (', mode_tolerance = "tight"', "bodies[1].cavity.mode_tolerance must be a number"),
        (", mode_tolerance = true", "bodies[1].cavity.mode_tolerance must be a number"),
        (", modes = 4, mode_tolerance = 1e-3", "bodies[1].cavity: give modes = 4 (a count) or mode_tolerance = 0.001"),
        (', modes = "some"', 'bodies[1].cavity.modes must be a whole number or "auto"'),
        (", mode_tolerance = 1e-6", "bodies[1].cavity.mode_tolerance = 1e-06 needs more than 64 modes"),
    ],
)
def test_bad_requests_name_the_key_and_the_fix(extra, message):
    with pytest.raises(StabmapError) as err:
        top(extra)
    assert message in str(err.value)


def test_cli_exits_2_on_a_bad_tolerance(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(TOP.format(extra=", mode_tolerance = -1", a=0.05, A=0.05, nw=2, nh=2, h0=0.01, h1=0.05))
    run = subprocess.run([sys.executable, "-m", "stabmap", "atlas", str(path), "-o", str(tmp_path / "a.nc")], capture_output=True, text=True)
    assert run.returncode == 2 and "mode_tolerance" in run.stderr and not (tmp_path / "a.nc").exists()


# ------------------------------------------------------------------------------------------------- the answer
def _near_boundary(nc: np.ndarray) -> np.ndarray:
    """Points whose label differs from a grid neighbour's (along either axis)."""
    near = np.zeros(nc.shape, dtype=bool)
    for axis in range(nc.ndim):
        step = np.diff(nc, axis=axis) != 0
        lo = [slice(None)] * nc.ndim
        hi = [slice(None)] * nc.ndim
        lo[axis], hi[axis] = slice(None, -1), slice(1, None)
        near[tuple(lo)] |= step
        near[tuple(hi)] |= step
    return near


def test_auto_labels_agree_with_many_modes_away_from_boundaries():
    # A small cavity: "auto" keeps 1 mode; 16 modes plus the tail is the reference.
    auto = top(', modes = "auto"', a=0.03, q=(0.25, 2.0), nw=40, nh=8)
    assert auto.nmodes.tolist() == [1]
    ref = top(", modes = 16", a=0.03, q=(0.25, 2.0), nw=40, nh=8)
    nc_auto = atlas.compute(auto, progress=False).n_complex_pairs.values
    nc_ref = atlas.compute(ref, progress=False).n_complex_pairs.values
    differ = nc_auto != nc_ref
    assert not (differ & ~_near_boundary(nc_ref)).any()
    assert differ.mean() < 0.02
