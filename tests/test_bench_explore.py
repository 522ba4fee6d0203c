"""scripts/bench_explore.py: its synthetic atlases hold Maievskii's condition (checked against exact rationals and
numpy's roots, not against the script), and its quick mode runs once, its pages within their size bound (no timing
is asserted)."""

from __future__ import annotations

import itertools
import math
import pathlib
import runpy
from fractions import Fraction

import numpy as np
import pytest
from scenes import maievskii_stable, maievskii_w2

SCRIPT = pathlib.Path(__file__).resolve().parents[1] / "scripts" / "bench_explore.py"


@pytest.fixture(scope="module")
def bench():
    return runpy.run_path(str(SCRIPT))


def _stable(omega, c, m, A, C=0.03, g=9.81) -> bool:
    """Maievskii's condition in rationals, point by point: C² ω² ≥ 4 (A + m c²) m c g."""
    w, c, m, A, C, g = (Fraction(float(v)) for v in (omega, c, m, A, C, g))
    return C * C * w * w >= 4 * (A + m * c * c) * m * c * g


def test_exact_condition_at_the_boundary(bench):
    """Spin rates within 3 ulp of the critical one: plain floats mislabel some, the script's condition none."""
    omega, c = [], []
    for cv in np.linspace(0.02, 0.3, 50):
        w = float(math.sqrt(maievskii_w2(float(cv))))
        for k in range(-3, 4):
            omega.append(w + k * math.ulp(w))
            c.append(float(cv))
    omega, c = np.array(omega), np.array(c)
    want = [maievskii_stable(w, cv) for w, cv in zip(omega, c, strict=True)]
    assert bench["maievskii_stable"](omega, c, 1.0, 0.02, 0.03, 9.81).tolist() == want
    floats = 0.03 * 0.03 * omega * omega >= 4.0 * (0.02 + c * c) * c * 9.81
    assert (floats != want).any()  # the points are close enough to need the rationals
    assert 0 < sum(want) < len(want)


@pytest.mark.parametrize("points", [{"omega": 23, "c_1": 17}, {"omega": 9, "c_1": 6, "m_1": 4, "A_1": 3}])
def test_synthetic_atlas_is_maievskii(bench, points):
    real = bench["template"](list(points))
    bench["check_template"](real)  # raises where the synthetic values differ from the computed atlas
    ds = bench["synthetic_atlas"](points, real).compute()
    assert dict(ds.sizes) == {**points, "bnds": 2}
    assert set(ds.data_vars) == set(real.data_vars)
    assert all(ds[k].attrs.keys() == real[k].attrs.keys() for k in ds.variables if k in real.variables)
    flags = {k: dict(zip(ds[k].attrs["flag_meanings"].split(), ds[k].attrs["flag_values"].tolist(), strict=True))
             for k in ("cell", "decided_by", "stability")}
    assert (ds.decided_by == flags["decided_by"]["interval_sturm_sequence"]).all()
    fixed = {"m_1": 1.0, "A_1": 0.02}
    dims = list(ds.n_complex_pairs.dims)
    edges = {d: ds[f"{d}_bounds"].values for d in dims}
    kinds = set()
    for idx in itertools.product(*(range(n) for n in points.values())):
        at = dict(zip(dims, idx, strict=True))
        p = {**fixed, **{d: float(ds[d][i]) for d, i in at.items()}}
        node = _stable(p["omega"], p["c_1"], p["m_1"], p["A_1"])
        assert int(ds.n_complex_pairs[idx]) == (0 if node else 1)
        assert int(ds.stability[idx]) == flags["stability"]["stable" if node else "unstable"]
        if len(points) == 2:
            assert node == maievskii_stable(p["omega"], p["c_1"])
        # The cell: its corners all on the node's side (whole cell) or on both sides (a change), the condition being
        # monotone in each parameter over positive values.
        corners = {_stable(*({**p, **dict(zip(dims, corner, strict=True))}[k] for k in ("omega", "c_1", "m_1", "A_1")))
                   for corner in itertools.product(*(edges[d][i] for d, i in at.items()))}
        kind = "contains_change" if len(corners) == 2 else "whole_cell"
        assert int(ds.cell[idx]) == flags["cell"][kind]
        kinds.add(kind)
        if not node:  # the growth rate: the largest |Im λ| of (A + m c²) λ² − C ω λ + m c g
            roots = np.roots([p["A_1"] + p["m_1"] * p["c_1"] ** 2, -0.03 * p["omega"], p["m_1"] * p["c_1"] * 9.81])
            rate = float(ds.growth_rate[idx])
            assert rate == pytest.approx(np.abs(roots.imag).max(), rel=1e-5)
            assert float(ds.growth_rate_lower[idx]) < rate < float(ds.growth_rate_upper[idx])
            assert float(ds.efolding_time[idx]) == pytest.approx(1 / rate, rel=1e-6)
        else:
            assert float(ds.growth_rate[idx]) == 0 and np.isinf(float(ds.efolding_time[idx]))
    assert kinds == {"contains_change", "whole_cell"}


@pytest.mark.slow
def test_bench_explore_quick(bench, tmp_path, capsys):
    out = bench["main"](["--quick", "--dir", str(tmp_path)])
    rows = out["rows"]
    assert [(r["atlas"], r["max_mb"]) for r in rows] == [("1300 × 20", None), ("60 × 40 × 8 × 8", None), ("60 × 40 × 8 × 8", 1.8)]
    for r in rows:
        page = pathlib.Path(r["page"])
        assert page.is_file() and page.stat().st_size / 1e6 == pytest.approx(r["page_mb"])
        assert pathlib.Path(r["page"].replace(".html", "-py.html")).is_file()
        assert 1.6 < r["page_mb"] <= (20 if r["max_mb"] is None else r["max_mb"])  # BokehJS inlined, within the bound
        assert r["page_mb"] <= r["model_mb"] * 1.05  # bokeh compresses its arrays: the model is an upper estimate
        assert r["segments"] > 0  # Maievskii's boundary crosses every map
    # omega's 1300 values in blocks of 3 (no block under a pixel of the 600 px wide map), c's 20 one each
    assert rows[0]["blocks"] == math.ceil(1300 / 3) * 20 and rows[0]["frames"] == 1
    assert rows[1]["blocks"] == 60 * 40 and rows[1]["frames"] == rows[1]["frames_all"] == 64 and not rows[1]["notes"]
    thinned = rows[2]
    assert thinned["frames"] < thinned["frames_all"] == 64
    assert thinned["notes"] and all("max_mb=1.8" in n for n in thinned["notes"])  # in Python's spelling; the CLI's:
    assert thinned["cli_notes"] == [f"note: {n.replace('max_mb=1.8', '--max-mb 1.8').replace('with sel', 'with --sel')}" for n in thinned["notes"]]
    printed = capsys.readouterr().out
    assert "| atlas | grid points |" in printed and "note: m_1:" in printed
