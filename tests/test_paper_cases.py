"""The paper's cases n = 1, 2, 3: stabmap.systems.gyroscopes.paper against the sympy oracle, golden atlases, scripts/paper_cases.py.

stabmap.systems.gyroscopes.paper restates the paper's printed determinants and closed forms in python-flint; here it is
checked against tests/reference.py (docs/model.md in sympy, sharing no code with stabmap), and then used
to check the golden atlases under tests/data point by point, in exact arithmetic.
"""

from __future__ import annotations

import dataclasses
import random
import runpy
import tomllib
from pathlib import Path

import flint
import numpy as np
import pytest
import sympy
import xarray as xr

import reference as ref
from systems import random_system, reference_args
from stabmap import example
from stabmap.run import atlas
from stabmap.systems.gyroscopes import paper
from stabmap.systems.gyroscopes.outputs import BY_BOX
from stabmap.systems.gyroscopes.points import point_arrays
from stabmap.systems.gyroscopes.scene import from_dict
from stabmap.systems import loads_scene as loads

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parent / "data"
SCRIPT = runpy.run_path(str(ROOT / "scripts" / "paper_cases.py"))
CASES = {c.name: c for c in SCRIPT["CASES"]}


def _chain(system: dict) -> paper.Chain:
    pa = point_arrays(from_dict(system), {})
    return paper.chain_from_arrays(pa.body[0], pa.joint[0], pa.g[0], pa.E[0], pa.kappa[0], pa.nmodes, pa.free)


def _sympy(p) -> sympy.Poly:
    return sympy.Poly([sympy.Rational(int(c.p), int(c.q)) for c in reversed(p.coeffs())], ref.lam)


def _identical(rng: random.Random, n: int, modes: int, joints: bool) -> dict:
    system = random_system(rng, n, modes, "free")
    b = dict(system["bodies"][0], c=abs(system["bodies"][0]["c"]) + 0.05)
    b.pop("omega", None)
    b["s"] = 2 * b["c"]
    system["bodies"] = [dict(b) for _ in range(n)]
    if not joints:
        system["joints"] = [0.0] * (n - 1)
    return system


# ---------------------------------------------------------------- the printed determinants

@pytest.mark.parametrize("support, n", [("fixed", 1), ("fixed", 2), ("fixed", 3), ("fixed", 4), ("free", 2), ("free", 3)])
@pytest.mark.parametrize("seed", range(3))
def test_printed_determinant_equals_model(support, n, seed):
    system = random_system(random.Random(1000 * n + seed), n, seed % 3, support)
    assert _sympy(paper.paper_polynomial(_chain(system))) == ref.char_poly(**reference_args(system))


@pytest.mark.parametrize("n", [4, 5])
def test_printed_identical_free_determinant_28_with_joints(n):
    system = _identical(random.Random(n), n, 2, joints=True)
    assert _sympy(paper.paper_polynomial(_chain(system))) == ref.char_poly(**reference_args(system))


def test_free_chain_without_printed_determinant_is_refused():
    system = random_system(random.Random(5), 4, 1, "free")
    with pytest.raises(Exception, match="n = 2, 3 and for identical bodies"):
        paper.paper_polynomial(_chain(system))


def test_exact_count_matches_oracle():
    rng = random.Random(7)
    for _ in range(20):
        system = random_system(rng, rng.randint(1, 3), rng.randint(0, 2), rng.choice(["fixed", "free"]))
        p = ref.char_poly(**reference_args(system))
        assert paper.complex_pairs(paper.paper_polynomial(_chain(system))) == ref.count_complex_pairs(p)


# ---------------------------------------------------------------- closed forms

def _closed_form_system(case: str, rng: random.Random) -> dict:
    if case == "top":
        return random_system(rng, 1, rng.randint(0, 1), "fixed")
    if case == "free-body":
        return random_system(rng, 1, rng.randint(1, 2), "free")
    if case.startswith("identical"):
        return _identical(rng, int(case[-1]), rng.randint(1, 2), joints=False)
    system = random_system(rng, 3, 1, "fixed")  # split: a_2 = a_3 = 0 exactly in binary, ideal joints
    b = system["bodies"]
    b[1].update(m=1.0, s=0.25, c=-0.125)
    b[2].update(m=0.5, c=0.0)
    system["joints"] = [0.0, 0.0]
    system["K_0"] = 0.0
    return system


@pytest.mark.parametrize("case", ["top", "free-body", "identical-2", "identical-3", "split"])
@pytest.mark.parametrize("seed", range(4))
def test_closed_form_factors_divide_into_model_polynomial(case, seed):
    system = _closed_form_system(case, random.Random(seed))
    fs = paper.factors(_chain(system), "identical-free" if case.startswith("identical") else case)
    product = sympy.Poly(1, ref.lam)
    for f in fs:
        product *= _sympy(flint.fmpq_poly(f))
    p = ref.char_poly(**reference_args(system))
    # p = lambda^k x const x product: divide out and compare.
    quotient, remainder = sympy.div(p, product)
    assert remainder.is_zero
    assert quotient.is_monomial
    # And the closed-form count is the oracle's exact count.
    assert paper.closed_form_pairs(fs) == ref.count_complex_pairs(p)


def test_maievskii_boundary_is_the_explicit_formula():
    scene = example("paper-n1-fixed-dry")
    for row in (0.05, 0.1, 0.25):
        (t, below, above), = SCRIPT["closed_form_along"](scene, CASES["paper-n1-fixed-dry"], row)
        b = scene.bodies[0]
        assert t == pytest.approx(paper.maievskii_omega(b.A, b.m, row, b.C, scene.g), rel=1e-12)
        assert (below, above) == (1, 0)


def test_closed_form_boundary_is_a_root_where_the_exact_count_changes():
    scene, case = example("paper-n1-fixed-1mode"), CASES["paper-n1-fixed-1mode"]
    found = SCRIPT["closed_form_along"](scene, case, 0.15)
    assert found
    for t, below, above in found:
        for value, expected in ((t * (1 - 1e-9), below), (t * (1 + 1e-9), above)):
            system = _scene_point(scene, {"omega": value, "c_1": 0.15})
            assert ref.count_complex_pairs(ref.char_poly(**reference_args(system))) == expected


def _scene_point(scene, values: dict) -> dict:
    """The scene at one point as a plain dict for systems.reference_args."""
    text = scene.to_toml().split("[grid]")[0]
    system = tomllib.loads(text)
    for name, v in values.items():
        symbol, _, k = name.partition("_")
        if k:
            system["bodies"][int(k) - 1][symbol] = v
        else:
            system[name] = v
    return system


# ---------------------------------------------------------------- golden atlases

GOLDEN = sorted(DATA.glob("paper-*.nc"))


def test_every_case_has_a_golden_atlas_and_a_bundled_scene():
    assert {p.stem for p in GOLDEN} == set(CASES)


@pytest.mark.parametrize("path", GOLDEN, ids=lambda p: p.stem)
def test_golden_atlas_recomputes_cell_for_cell(path):
    golden = xr.load_dataset(path)
    scene = loads(golden.attrs["scene"])
    nodes = atlas.compute(scene, progress=False, prove_cells=False)
    xr.testing.assert_equal(nodes["n_complex_pairs"], golden["n_complex_pairs"])
    xr.testing.assert_equal(nodes["decided_by"], golden["decided_by"])
    # Decided cell by cell, every node keeps its label; a node no box holds is computed as before.
    ds = atlas.compute(scene, progress=False)
    xr.testing.assert_equal(ds["n_complex_pairs"], golden["n_complex_pairs"])
    computed = ds["decided_by"] != BY_BOX
    xr.testing.assert_equal(ds["decided_by"].where(computed), golden["decided_by"].where(computed))
    # The golden scene is the bundled one on a coarser grid.
    bundled = example(path.stem)
    assert dataclasses.replace(loads(golden.attrs["scene"]), grid=bundled.grid).to_toml() == bundled.to_toml()


@pytest.mark.parametrize("path", GOLDEN, ids=lambda p: p.stem)
def test_golden_atlas_matches_the_paper_exactly(path):
    golden = xr.load_dataset(path)
    scene, case = loads(golden.attrs["scene"]), CASES[path.stem]
    values = SCRIPT["grid_values"](golden)
    if case.closed_form is not None:
        expected = SCRIPT["closed_form_pairs_at"](scene, case, values)
    else:
        expected = SCRIPT["paper_pairs_at"](scene, values)
    np.testing.assert_array_equal(golden["n_complex_pairs"].values.ravel(), expected)
    assert (golden["n_complex_pairs"] == 0).any() or path.stem in ("paper-n2-free", "paper-n3-free")


# ---------------------------------------------------------------- the script

@pytest.mark.slow
def test_paper_cases_quick_check_agrees(tmp_path, capsys):
    out = SCRIPT["main"](["--check", "--quick", "--out", str(tmp_path)])
    assert out["problems"] == []
    rows = {r["case"].name: r for r in out["results"]}
    assert set(rows) == set(CASES)
    for name, r in rows.items():
        if CASES[name].closed_form:
            assert r["matched"] == r["boundaries"] > 0 and r["worst_rel"] < SCRIPT["RTOL"]
        assert (tmp_path / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "| case | paper |" in capsys.readouterr().out


def test_paper_cases_check_fails_on_a_wrong_closed_form(monkeypatch):
    # A closed form with A' off by 1 % must be caught: the check can fail.
    original = paper.F_polynomial

    def skewed(A_prime, *args):
        return original(A_prime * paper.q(1.01), *args)

    monkeypatch.setattr(paper, "F_polynomial", skewed)
    case = CASES["paper-n1-fixed-1mode"]
    result = SCRIPT["check_case"](case, quick=True, rows=2, out=None)
    assert any("closed form" in msg for msg in result["problems"])


@pytest.mark.parametrize("n", range(2, 11))
def test_conjecture_counterexample_from_the_printed_determinants(n):
    # docs/conjecture.md's counterexample, rechecked with the paper's own (32), (30) and (28): one free body
    # (24) is unstable, the chain of n copies is unstable with ideal joints and stable with K = 1024.
    q = paper.q
    body = dict(m=[q(2)] * n, A=[q(4)] * n, C=[q(1)] * n, c=[q(1)] * n, s=[q(2)] * (n - 1) + [q(0)], omega=[q(1)] * n,
                E=[[q(0.5)]] * n, kappa=[[q(4)]] * n, free=True)
    assert paper.closed_form_pairs(paper.factors(paper.Chain(**{k: v[:1] if isinstance(v, list) else v for k, v in body.items()}, K=[]), "free-body")) == 1
    assert paper.complex_pairs(paper.paper_polynomial(paper.Chain(**body, K=[q(0)] * (n - 1)))) >= 1
    assert paper.complex_pairs(paper.paper_polynomial(paper.Chain(**body, K=[q(1024)] * (n - 1)))) == 0
