"""A new system is one module and one registry line (docs/systems.md, "Adding a system").

The toy system below is registered at test time, by a fixture, and the whole pipeline must work on it: atlases
from Python and from the command line (netCDF), ``info``, ``query`` (fraction, boundaries, smallest stable),
``plot``, critical values, cells and a run on a local dask cluster.  Its label, the number of distinct real roots
of x^2 - a x + b in (0, 1), is decided in exact rational arithmetic by sign rules, and every label the pipeline
shows is checked against an independent count: sympy's Sturm sequences on the same exact rationals.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import ClassVar

import numpy as np
import pytest
import sympy

import stabmap
from stabmap import systems
from stabmap.cli import main
from stabmap.errors import StabmapError
from stabmap.scene.grid import Axis, parse_axes
from stabmap.scene.values import Parameter, check_value, no_unknown
from stabmap.store.variables import Variable
from stabmap.systems.base import SceneBase, System

# ------------------------------------------------------------------------------------------------- the system
PARAMETERS = {k: Parameter(k, "1", f"coefficient {k} of x^2 - a x + b") for k in ("a", "b")}
ROOTS = Variable("roots_in_unit", "int8", "distinct real roots of x^2 - a x + b in (0, 1)", units="1", fill=-2)


def _parameter(name: str) -> Parameter:
    if name not in PARAMETERS:
        raise StabmapError(f"unknown parameter name {name!r}; the toy scans a and b")
    return PARAMETERS[name]


@dataclass(frozen=True)
class ToyScene(SceneBase):
    system: ClassVar[str] = "toy"
    title: str = ""
    grid: tuple[Axis, ...] = ()
    a: float = 1.0
    b: float = 0.2

    def __post_init__(self):
        for k in "ab":
            check_value(k, getattr(self, k), PARAMETERS[k])

    @classmethod
    def from_dict(cls, table, base_dir=None):
        no_unknown(table, {"title", "a", "b", "grid"}, "scene")
        return cls(grid=parse_axes(table.get("grid", {}), _parameter), **{k: v for k, v in table.items() if k != "grid"})

    def to_dict(self):
        return {"title": self.title, "a": self.a, "b": self.b, "grid": {x.name: x.to_dict() for x in self.grid}}

    def parameter(self, name):
        return _parameter(name)

    def fixed_values(self):
        return {k: getattr(self, k) for k in "ab" if k not in {x.name for x in self.grid}}


def count(a: float, b: float) -> int:
    """Distinct roots of p = x^2 - a x + b in (0, 1), exactly: from the signs of p(0), p(1), the discriminant and
    the vertex a/2."""
    a, b = Fraction(a), Fraction(b)
    p0, p1, disc = b, 1 - a + b, a * a - 4 * b
    if disc <= 0:
        return int(disc == 0 and 0 < a / 2 < 1)
    if p0 == 0 or p1 == 0:  # a root at 0 (the other is a) or at 1 (the other is b)
        return int(0 < (a if p0 == 0 else b) < 1)
    if p0 * p1 < 0:
        return 1
    return int(p0 > 0 and 0 < a / 2 < 1) * 2  # p0, p1 < 0: 0 and 1 between the roots; > 0: both on one side


class Toy(System):
    name, title, references = "toy", "roots of a quadratic in the unit interval", "none: the plug-in contract's test"
    variables, label, label_symbol, label_title = (ROOTS,), ROOTS.name, "n", "roots in (0, 1)"
    scene_type, default_axis, stable_label = ToyScene, "a", 0

    def input_bytes(self, scene):
        return 16

    def evaluate(self, scene, values):
        a, b = np.broadcast_arrays(values.get("a", scene.a), values.get("b", scene.b))
        return {ROOTS.name: np.array([count(x, y) for x, y in zip(a.ravel(), b.ravel())], dtype=np.int8).reshape(a.shape)}

    # optional: box proofs, so that atlases decide whole cells: the count is one wherever p(0), p(1), the
    # discriminant and the vertex's distances to 0 and 1 keep strict signs (each is monotone in a and b, but a^2)
    def box_axes(self, scene):
        return {"a", "b"}

    def prove_boxes(self, scene, lower, upper):
        n = np.size(next(iter(lower.values())))
        label, proved = np.zeros(n, dtype=np.int8), np.zeros(n, dtype=bool)
        for i, box in enumerate(zip(*(np.broadcast_to(d.get(k, getattr(scene, k)), n) for k in "ab" for d in (lower, upper)))):
            a0, a1, b0, b1 = map(Fraction, box)  # exact: a proof may not round
            square = (0 if a0 <= 0 <= a1 else min(a0 * a0, a1 * a1), max(a0 * a0, a1 * a1))
            ranges = [(b0, b1), (1 - a1 + b0, 1 - a0 + b1), (a0, a1), (a0 - 2, a1 - 2), (square[0] - 4 * b1, square[1] - 4 * b0)]
            label[i], proved[i] = count(a0, b0), all(lo > 0 or hi < 0 for lo, hi in ranges)
        return label, proved

    def proved_box(self, label):
        return {}


SYSTEM = Toy()


# ------------------------------------------------------------------------------------------------- the reference
def reference(a: float, b: float) -> int:
    """Independent count: Sturm's theorem (sympy) on [0, 1], less the roots at its ends."""
    x = sympy.symbols("x")
    qa, qb = sympy.Rational(Fraction(a)), sympy.Rational(Fraction(b))
    p = sympy.Poly(x**2 - qa * x + qb, x)
    return p.count_roots(0, 1) - int(p.eval(0) == 0) - int(p.eval(1) == 0)


def reference_grid(ds) -> np.ndarray:
    return np.array([[reference(a, b) for b in ds.b.values] for a in ds.a.values])


# Steps of 1/4 and 1/8: the grid holds double roots (a = 1, b = 1/4), roots at 0 (b = 0) and at 1 (a = 1 + b).
SCENE = """system = "toy"
title = "roots of x^2 - a x + b in (0, 1)"
[grid]
a = { start = 0.0, stop = 2.5, num = 11 }
b = { start = -0.5, stop = 1.0, num = 13 }
"""


@pytest.fixture
def toy(monkeypatch):
    """The toy system in the registry for one test: this module is its subpackage."""
    monkeypatch.setitem(systems.SYSTEMS, "toy", __name__)
    return stabmap.loads_scene(SCENE)


@pytest.fixture
def atlas(toy):
    return stabmap.compute_atlas(toy, threads=1, progress=False)


def test_the_contract_is_checked_when_a_system_is_made():
    class Half(System):  # no evaluate, no scene type, no default axis
        name, title, references, variables, label, label_symbol, label_title = "half", "", "", (), "x", "x", "x"

    with pytest.raises(TypeError, match="abstract") as err:
        Half()
    assert all(m in str(err.value) for m in ("default_axis", "evaluate", "input_bytes", "scene_type"))

    class NoFill(Toy):  # a label that cannot pad a table
        variables = (Variable("roots_in_unit", "int8", "roots"),)

    with pytest.raises(TypeError, match="'roots_in_unit' must be an integer variable with a fill"):
        NoFill()


def test_the_toy_count_matches_the_reference_where_the_sign_rules_branch():
    cases = [(1, 0.25), (1, 0), (1.5, 0.5), (2, 1), (0.5, 0), (1.2, 0.3), (3, 2), (0.9, 0.2), (0.5, -0.25), (1.0, 0.0)]
    assert [count(a, b) for a, b in cases] == [reference(a, b) for a, b in cases]


def test_atlas_from_python_and_its_cells(atlas):
    ref = reference_grid(atlas)
    assert {0, 1, 2} <= set(ref.ravel().tolist())
    np.testing.assert_array_equal(atlas["roots_in_unit"].transpose("a", "b").values, ref)
    assert atlas.attrs["stabmap_system"] == "toy"
    # cells: every cell the atlas says is whole holds its node's count at every point; checked at random points
    cell = atlas["cell"].transpose("a", "b").values
    meanings = dict(zip(atlas["cell"].attrs["flag_meanings"].split(), atlas["cell"].attrs["flag_values"].tolist()))
    whole = np.argwhere(cell == meanings["whole_cell"])
    assert 0 < len(whole) < cell.size and (cell == meanings["contains_change"]).any()
    rng = np.random.default_rng(0)
    for i, j in whole:
        (a0, a1), (b0, b1) = atlas["a_bounds"].values[i], atlas["b_bounds"].values[j]
        inside = zip(rng.uniform(a0, a1, 8), rng.uniform(b0, b1, 8))
        assert {reference(a, b) for a, b in [(a0, b0), (a1, b1), *inside]} == {ref[i, j]}
    np.testing.assert_array_equal(atlas["a_bounds"].values[1:, 0], 0.5 * (atlas.a.values[1:] + atlas.a.values[:-1]))


def test_queries_against_the_reference(atlas):
    ref = reference_grid(atlas)
    assert stabmap.stable_fraction(atlas).fraction == pytest.approx(np.mean(ref == 0), abs=0)
    # boundaries along the default axis a: every neighbouring pair of grid values with different counts
    b = stabmap.boundaries(atlas, b=0.25)
    column = ref[:, list(atlas.b.values).index(0.25)]
    changes = [(atlas.a.values[i], atlas.a.values[i + 1]) for i in range(column.size - 1) if column[i] != column[i + 1]]
    assert list(zip(b.boundary_lower.values, b.boundary_upper.values)) == changes
    np.testing.assert_array_equal(b["roots_in_unit_below"].values, [reference(lo, 0.25) for lo, _ in changes])
    s = stabmap.smallest_stable(atlas, over="b")
    for j, value in enumerate(atlas.b.values):
        stable = [a for i, a in enumerate(atlas.a.values) if ref[i, j] == 0]
        assert (stable[0] if stable else math.nan) == pytest.approx(float(s.smallest_stable.sel(b=value)), nan_ok=True)


def test_command_line_atlas_info_query_plot(toy, tmp_path, capsys):
    scene = tmp_path / "toy.toml"
    scene.write_text(SCENE)
    out, png = tmp_path / "toy.nc", tmp_path / "toy.png"
    assert main(["atlas", str(scene), "-o", str(out), "--png", str(png), "--threads", "1"]) == 0
    assert out.read_bytes()[:8] == b"\x89HDF\r\n\x1a\n" and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ds = stabmap.open_atlas(out)
    ref = reference_grid(ds)
    np.testing.assert_array_equal(ds["roots_in_unit"].transpose("a", "b").values, ref)
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    text = " ".join(capsys.readouterr().out.split())  # wrapped to the terminal's width
    counts = ", ".join(f"{k}: {int((ref == k).sum())}" for k in (0, 1, 2))
    assert "roots of x^2 - a x + b in (0, 1)" in text and f"roots_in_unit (n): {counts}" in text
    assert f"points: {ref.size}, stable: {int((ref == 0).sum())}" in text
    cells = {m: int((ds["cell"].values == v).sum()) for m, v in zip(ds["cell"].attrs["flag_meanings"].split(), ds["cell"].attrs["flag_values"])}
    assert f"cells: node only {cells['node_only']}, whole cell {cells['whole_cell']}, contains change {cells['contains_change']}" in text
    assert main(["query", str(out), "a=1", "b=0.25"]) == 0
    assert "roots_in_unit" in (text := capsys.readouterr().out) and str(reference(1, 0.25)) in text
    assert main(["query", str(out), "--smallest-stable", "b=0.5", "--json"]) == 0  # along the toy's default axis
    first = next(a for i, a in enumerate(ds.a.values) if ref[i, list(ds.b.values).index(0.5)] == 0)
    assert f'"smallest_stable": {first}' in capsys.readouterr().out
    assert main(["plot", str(out), "-o", str(tmp_path / "again.png")]) == 0
    assert (tmp_path / "again.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["paper", "toy"]) == 2
    assert "no paper check for system 'toy': it declares none" in capsys.readouterr().err


def test_critical_values_bracket_the_closed_form_boundaries(toy, tmp_path):
    # along a at fixed b the count changes only where a root crosses 0 or 1 or two roots meet: a = 1 + b (p(1) = 0),
    # a = 2 sqrt(b) (double root), a = 0 and a = 2 (the vertex leaves (0, 1))
    scene = toy.with_grid((toy.grid[0], Axis("b", (0.09, 0.25, 0.5))))
    crit = stabmap.critical(scene, progress=False)  # along the default axis a, to the default rtol 1e-10
    assert crit.attrs["critical_along"] == "a"
    for b in crit.b.values:
        line = crit.sel(b=b)
        lo, hi = line.boundary_lower.values, line.boundary_upper.values
        keep = np.isfinite(lo)
        assert keep.any()
        for x0, x1, below, above in zip(lo[keep], hi[keep], line.roots_in_unit_below.values[keep], line.roots_in_unit_above.values[keep]):
            assert (below, above) == (reference(x0, b), reference(x1, b)) and below != above
            assert x1 - x0 <= 1e-10 * max(abs(x0), abs(x1)) + 1e-15
            assert any(x0 <= c <= x1 for c in (0.0, 2.0, 1 + b, 2 * math.sqrt(b)))
    toml, path, png = tmp_path / "toy.toml", tmp_path / "crit.nc", tmp_path / "crit.png"
    toml.write_text(scene.to_toml())
    assert main(["critical", str(toml), "-o", str(path), "--png", str(png), "-q", "--threads", "1"]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    again = stabmap.open_atlas(path)
    np.testing.assert_array_equal(again.boundary_lower.values, crit.boundary_lower.values)
    assert main(["info", str(path)]) == 0


def test_a_run_on_a_local_cluster_equals_the_run_in_process(toy, atlas):
    # the workers never saw the registry line this test added: they find the system from the scene's type
    on_cluster = stabmap.compute_atlas(toy, workers=2, progress=False)
    np.testing.assert_array_equal(on_cluster["roots_in_unit"].values, atlas["roots_in_unit"].values)
    np.testing.assert_array_equal(on_cluster["cell"].values, atlas["cell"].values)
