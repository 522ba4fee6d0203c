"""Growth rates, e-folding times, frequencies and ``query --roots`` (docs/rates.md) against independent references.

- one top without liquid: p = (A + m c^2) lambda^2 + C omega lambda + m c g, so its roots, its growth rate
  sqrt(4 A' m c g - C^2 omega^2) / (2 A') and its nutation and precession frequencies are closed forms, evaluated
  here in mpmath at 50 digits on the exact binary values of the parameters;
- chains of two and three tops with liquid: mpmath's polyroots at 50 digits on the exact rational polynomial;
- points proved over a box have their rates computed at the node; inferred ones carry a flagged NaN, never a
  computed-looking number.
"""

from __future__ import annotations

import json

import mpmath
import numpy as np
import pytest

import stabmap
from cellspare import spare
from stabmap.cli import main
from stabmap.errors import StabmapError
from stabmap.systems import of, loads_scene
from stabmap.systems.gyroscopes import exact, rates
from stabmap.systems.gyroscopes.outputs import BY_BOX, BY_INFERRED
from stabmap.systems.gyroscopes.points import point_arrays

mpmath.mp.dps = 50
M, A, C, c, G = 1.0, 0.02, 0.03, 0.10, 9.81

TOP = f"""
title = "one top"
g = {G}
{{extra}}
[[bodies]]
m = {M}
A = {A}
C = {C}
c = {c}
[grid]
omega = {{{{ start = -40.0, stop = 40.0, num = 33 }}}}
"""


def top(extra: str = ""):
    return loads_scene(TOP.format(extra=extra))


def top_roots(omega: float) -> list:
    """The two roots of the dry top at the exact binary values of its parameters, to 50 digits."""
    m, a, cc, cm, g, w = (mpmath.mpf(float(v)) for v in (M, A, C, c, G, omega))
    a1 = a + m * cm * cm
    disc = (cc * w) ** 2 - 4 * a1 * m * cm * g
    s = mpmath.sqrt(disc) if disc >= 0 else 1j * mpmath.sqrt(-disc)
    return sorted([(-cc * w - s) / (2 * a1), (-cc * w + s) / (2 * a1)], key=lambda z: (mpmath.re(z), mpmath.im(z)))


def evaluate(scene, **values):
    return of(scene).evaluate(scene, {k: np.asarray(v, dtype=np.float64) for k, v in values.items()})


def test_one_top_growth_rate_and_frequencies_match_the_closed_form():
    omega = np.linspace(-40.0, 40.0, 161)
    out = evaluate(top("frequencies = true"), omega=omega)
    for i, w in enumerate(omega):
        want = top_roots(w)
        rate = max(abs(mpmath.im(z)) for z in want)
        lo, hi = float(out["growth_rate_lower"][i]), float(out["growth_rate_upper"][i])
        if rate == 0:  # Maievskii's condition holds: N_c = 0 proved, the rate exactly 0
            assert out["n_complex_pairs"][i] == 0 and lo == hi == out["growth_rate"][i] == 0
            assert out["efolding_time"][i] == np.inf and out["growth_rate_method"][i] == rates.ALL_REAL
        else:
            assert lo <= rate <= hi and hi - lo <= 1e-6 * hi, (w, lo, rate, hi)
            assert lo <= out["growth_rate"][i] <= hi
            assert out["efolding_time"][i] == pytest.approx(1 / float(rate), rel=1e-6)
            assert out["growth_rate_method"][i] in (rates.DISKS, rates.EXACT)
        for k, z in enumerate(want):  # the nutation (larger |lambda|) and precession roots, or a pair's real parts
            assert abs(mpmath.re(z) - out["frequency"][i, k]) <= out["frequency_radius"][i, k], (w, k)
        kinds = {0: "real", 1: "complex"}
        assert all(kinds[int(x)] == ("real" if rate == 0 else "complex") for x in out["root_kind"][i])


def test_exact_fallback_gives_the_same_proved_enclosures(monkeypatch):
    """Disks wider than REL go to FLINT/Arb; with REL = 0 every unstable point does."""
    monkeypatch.setattr(rates, "REL", -1.0)
    omega = np.array([-11.0, 0.0, 7.5, 11.0])
    out = evaluate(top(), omega=omega)
    for i, w in enumerate(omega):
        rate = max(abs(mpmath.im(z)) for z in top_roots(w))
        assert out["growth_rate_method"][i] == rates.EXACT
        assert out["growth_rate_lower"][i] <= rate <= out["growth_rate_upper"][i]
    assert "frequency" not in out  # not asked for


CHAINS = {
    2: """
title = "two tops with liquid"
g = 9.81
joints = [3.0]
frequencies = true
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25
fluid = { E = [1e-3, 2e-4], kappa = [1.31, 2.7] }
[[bodies]]
m = 0.5
A = 0.01
C = 0.012
c = 0.08
fluid = { E = [5e-4], kappa = [-1.8] }
[grid]
omega = { start = 0.0, stop = 100.0, num = 3 }
""",
    3: """
title = "three tops with liquid"
g = 9.81
joints = [120.0, 80.0]
frequencies = true
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25
fluid = { E = [1e-4, 2e-5], kappa = [1.31, 2.7] }
[[bodies]]
m = 0.8
A = 0.015
C = 0.02
c = 0.12
s = 0.2
[[bodies]]
m = 0.6
A = 0.01
C = 0.02
c = 0.05
fluid = { E = [3e-4], kappa = [1.5] }
[grid]
omega = { start = 0.0, stop = 100.0, num = 3 }
""",
}


def mp_roots(points, p: int) -> list:
    poly = exact.char_poly(points.body[p], points.joint[p], points.g[p], points.E[p], points.kappa[p], points.nmodes,
                           points.free, points.parent, points.at[p])
    coeffs = [mpmath.mpf(int(q.p)) / mpmath.mpf(int(q.q)) for q in reversed(poly.coeffs())]
    zeros = 0
    while coeffs[-1] == 0:  # exact lambda = 0 roots, counted from the exact coefficients
        coeffs.pop()
        zeros += 1
    return [mpmath.mpf(0)] * zeros + list(mpmath.polyroots(coeffs, maxsteps=400, extraprec=400))


@pytest.mark.parametrize("n", [2, 3])
def test_chains_with_liquid_enclose_the_mpmath_roots(n):
    scene = loads_scene(CHAINS[n])
    omega = np.array([0.0, 3.0, 8.0, 15.0, 30.0, 60.0, 120.0])
    out = evaluate(scene, omega=omega)
    points = point_arrays(scene, {"omega": omega})
    assert np.any(out["n_complex_pairs"] > 0) and np.any(out["n_complex_pairs"] == 0)
    for i in range(omega.size):
        want = mp_roots(points, i)
        rate = max(abs(mpmath.im(z)) for z in want)
        if out["n_complex_pairs"][i] == 0:
            assert rate < 1e-30 and out["growth_rate"][i] == 0
        else:
            assert out["growth_rate_lower"][i] <= rate <= out["growth_rate_upper"][i], (n, omega[i])
        # every mpmath root lies in the enclosure of a stored root, one stored root each
        free = list(range(scene.degree))
        for z in sorted(want, key=lambda z: float(mpmath.re(z))):
            hit = [k for k in free if abs(float(mpmath.re(z)) - out["frequency"][i, k]) <= out["frequency_radius"][i, k]]
            assert hit, (n, omega[i], z)
            free.remove(hit[0])


FREE = """
support = "free"
joints = [2.0]
frequencies = true
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25
fluid = { E = [1e-3], kappa = [1.31] }
[[bodies]]
m = 0.5
A = 0.01
C = 0.002
c = 0.08
[grid]
omega = { start = 0.0, stop = 100.0, num = 3 }
"""


def test_free_chain_keeps_its_exact_zero_roots():
    """A free chain's lambda = 0 roots (the rigid tilts) are exact: stored as 0 with radius 0, proved real."""
    scene = loads_scene(FREE)
    omega = np.array([0.0, 10.0, 55.0])
    out = evaluate(scene, omega=omega)
    points = point_arrays(scene, {"omega": omega})
    for i in range(omega.size):
        want = sorted(mp_roots(points, i), key=lambda z: float(mpmath.re(z)))
        zeros = sum(1 for z in want if z == 0)
        assert zeros >= 1 and int(np.sum((out["frequency"][i] == 0) & (out["frequency_radius"][i] == 0))) >= zeros
        for k, z in enumerate(want):
            assert abs(float(mpmath.re(z)) - out["frequency"][i, k]) <= out["frequency_radius"][i, k]
        assert np.all(out["root_kind"][i] == 0) and out["growth_rate"][i] == 0


def test_box_proved_nodes_are_computed_and_inferred_ones_flagged():
    scene = top()
    with spare(1.0):  # a coarse grid: boxes that descend to prove unstable nodes too
        ds = stabmap.compute_atlas(scene, progress=False, threads=1)
    by, nc = ds.decided_by.values, ds.n_complex_pairs.values
    box = by == BY_BOX
    assert box.any() and (box & (nc == 0)).any() and (box & (nc > 0)).any()
    assert np.all(ds.growth_rate.values[box & (nc == 0)] == 0)
    assert np.all(ds.growth_rate_method.values[box & (nc == 0)] == rates.ALL_REAL)
    # a box-proved unstable node has its roots computed at the node, as a decided one
    assert np.all(np.isin(ds.growth_rate_method.values[nc > 0], [rates.PAIRS, rates.DISKS, rates.EXACT]))
    for w, lo, hi in zip(ds.omega.values[nc > 0], ds.growth_rate_lower.values[nc > 0], ds.growth_rate_upper.values[nc > 0]):
        assert lo <= max(abs(mpmath.im(z)) for z in top_roots(w)) <= hi
    refined = stabmap.compute_refined(loads_scene(TOP.format(extra="").replace("num = 33", "num = 65")), coarse_stride=8, margin=0,
                                      progress=False, threads=1)
    inferred = refined.decided_by.values == BY_INFERRED
    assert inferred.any()
    assert np.all(np.isnan(refined.growth_rate.values[inferred]))
    assert np.all(refined.growth_rate_method.values[inferred] == rates.NOT_COMPUTED)


def test_outputs_follow_the_scene_keys():
    ds = stabmap.compute_atlas(top('growth_rate = false'), progress=False, threads=1)
    assert "growth_rate" not in ds and "frequency" not in ds
    ds = stabmap.compute_atlas(top("frequencies = true"), progress=False, threads=1)
    assert ds.frequency.dims == ("omega", "mode") and ds.growth_rate.attrs["units"] == "s-1"
    assert ds.frequency.attrs["units"] == "rad s-1" and ds.efolding_time.attrs["units"] == "s"
    with pytest.raises(StabmapError, match="frequencies must be true or false"):
        top('frequencies = "yes"')


def test_roots_lists_every_root_with_its_kind_and_origin():
    got = stabmap.roots(top(), omega=10.0)
    want = top_roots(10.0)
    assert [r.kind for r in got.roots] == ["complex pair", "complex pair"] and got.n_complex_pairs == 1
    for r, z in zip(got.roots, want):
        assert abs(complex(z) - r.value) <= r.radius and r.origin == "structural" and r.multiplicity == 1
    assert got.growth_rate == pytest.approx(float(abs(mpmath.im(want[0]))), rel=1e-12)
    # a nearly dry body: its liquid root sits near -beta = -omega (kappa - 2) / kappa, by continuation from E = 0
    wet = loads_scene(TOP.format(extra="").replace("c = 0.1\n", "c = 0.1\nfluid = { E = [1e-6], kappa = [1.31] }\n"))
    found = stabmap.roots(wet, omega=30.0).roots
    liquid = [r for r in found if r.origin == "liquid"]
    assert len(liquid) == 1 and liquid[0].kind == "real"
    assert liquid[0].value.real == pytest.approx(-30.0 * (1.31 - 2) / 1.31, rel=1e-3)
    with pytest.raises(StabmapError, match="missing: omega"):
        stabmap.roots(top())
    with pytest.raises(StabmapError, match="'m_1' is not a grid axis"):
        stabmap.roots(top(), omega=1.0, m_1=2.0)


def test_query_roots_cli(tmp_path, capsys):
    path = tmp_path / "top.nc"
    stabmap.write_atlas(stabmap.compute_atlas(top(), progress=False, threads=1), path)
    assert main(["query", str(path), "omega=5", "--roots"]) == 0
    text = capsys.readouterr().out
    z = top_roots(5.0)[1]
    assert f"{float(mpmath.re(z)):.12g} + {float(mpmath.im(z)):.12g}i" in text
    assert "N_c = 1: unstable" in text and "complex pair" in text and "a rule, not a proof" in text
    assert main(["query", str(path), "omega=20", "--roots", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["n_complex_pairs"] == 0 and [r["kind"] for r in data["roots"]] == ["real", "real"]
    for r, want in zip(data["roots"], top_roots(20.0)):
        assert abs(r["real"] - float(mpmath.re(want))) <= r["radius"]
    assert stabmap.open_atlas(path).stabmap.roots(omega=20.0).roots[0].kind == "real"
    assert main(["query", str(path), "--roots", "--fraction"]) == 2
    assert "one question at a time" in capsys.readouterr().err


def test_info_gives_the_largest_growth_rate_and_queries_take_rpm(tmp_path, capsys):
    path = tmp_path / "top.nc"
    stabmap.write_atlas(stabmap.compute_atlas(top(), progress=False, threads=1), path)
    # the grid's largest rate is at its slowest spin, |omega| = 0 being a grid value: sqrt(m c g / A') there
    grid = np.linspace(-40.0, 40.0, 33)
    want = max(float(mpmath.im(top_roots(w)[1])) for w in grid)
    assert main(["info", str(path)]) == 0
    line = next(s for s in capsys.readouterr().out.splitlines() if "growth rate:" in s)
    shown = float(line.split("largest ")[1].split()[0])
    assert abs(shown - want) <= 1e-5 * want
    assert "all roots real" in line and "newton pairs" in line  # the pairs' disks, not every root's
    # a spin rate in rpm reaches the point itself: 5 rad/s = 150/pi rpm
    assert main(["query", str(path), f"omega={5 * 60 / (2 * np.pi)!r} rpm", "--roots"]) == 0
    z = top_roots(5.0)[1]
    assert f"{float(mpmath.im(z)):.12g}i" in capsys.readouterr().out
