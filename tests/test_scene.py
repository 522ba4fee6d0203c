"""Scene files: the public TOML contract and its error messages."""

from __future__ import annotations

import pytest

import stabmap
from stabmap import StabmapError, loads_scene

GOOD = """
title = "two tops"
support = "fixed"
g = 9.81
omega = 50.0
joints = [120.0]

[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25
fluid = { E = [1e-4, 2e-5], kappa = [1.31, 2.7] }

[[bodies]]
m = 0.5
A = 0.01
C = 0.02
c = 0.05
omega = 30.0

[grid]
omega = { start = 1.0, stop = 200.0, num = 5 }
m_2 = { start = 0.1, stop = 10.0, num = 3, scale = "log" }
K_1 = { values = [0.0, 10.0, 100.0] }
"""


def test_good_scene_parses():
    scene = loads_scene(GOOD)
    assert scene.n == 2 and scene.support == "fixed"
    assert scene.bodies[0].E == (1e-4, 2e-5)
    assert scene.bodies[1].s == 0.0  # top body: no upper joint
    assert [a.name for a in scene.grid] == ["omega", "m_2", "K_1"]
    assert scene.grid[1].values == pytest.approx((0.1, 1.0, 10.0))
    assert scene.degree == 2 * 2 + 2


def test_round_trip_through_toml():
    scene = loads_scene(GOOD)
    assert loads_scene(scene.to_toml()) == scene


def test_every_example_loads():
    names = stabmap.example_names()
    assert {"paper-n1-fixed", "paper-n1-free", "paper-n2-fixed", "paper-n2-free", "paper-n3-fixed", "paper-n3-free"} <= set(names)
    for name in names:
        assert stabmap.example(name).grid


def _replace(old: str, new: str) -> str:
    assert old in GOOD
    return GOOD.replace(old, new, 1)


BAD = [
    (_replace("m = 0.5", "m = -1.0"), "bodies[2].m must be > 0, got -1.0"),
    (_replace("m = 0.5", "m = nan"), "bodies[2].m must be finite"),
    (_replace("A = 0.01", "A = 0.0"), "bodies[2].A must be > 0"),
    (_replace("joints = [120.0]", "joints = [1.0, 2.0]"), "joints has 2 values; a chain of 2 bodies has 1 joints"),
    (_replace("joints = [120.0]", "joints = [-3.0]"), "joints[1] (K_1) must be >= 0"),
    (_replace('support = "fixed"', 'support = "floating"'), 'support must be "fixed" or "free"'),
    (_replace("kappa = [1.31, 2.7]", "kappa = [1.31, 0.0]"), "bodies[1].fluid.kappa[2] must be nonzero"),
    (_replace("kappa = [1.31, 2.7]", "kappa = [1.31]"), "E has 2 values but kappa has 1"),
    (_replace("title =", "title = = "), "TOML syntax error"),
    (_replace("m_2 = {", "m_9 = {"), "'m_9': bodies are numbered 1..2"),
    (_replace("m_2 = {", "mass_2 = {"), "unknown parameter name 'mass_2'"),
    (_replace("K_1 = {", "K_2 = {"), "'K_2': a chain of 2 bodies has joints K_1..K_1"),
    (_replace("num = 5", "num = 0"), "grid.omega.num must be a whole number >= 1"),
    (_replace("K_1 = { values = [0.0, 10.0, 100.0] }", "K_1 = { values = [] }"), "grid.K_1.values must be a non-empty list"),
    (_replace("K_1 = { values = [0.0, 10.0, 100.0] }", "K_1 = { values = [0.0, 10.0, 5.0] }"), "grid.K_1: values must be distinct and sorted"),
    (_replace("start = 0.1, stop = 10.0", "start = -0.1, stop = 10.0"), "grid.m_2.start must be > 0"),
    (_replace("c = 0.10", "c = 0.10\nfoo = 1"), "bodies[1]: unknown key 'foo'"),
    (_replace("C = 0.02", ""), "bodies[2].C is missing"),
]


@pytest.mark.parametrize("text,message", BAD, ids=[m[:40] for _, m in BAD])
def test_bad_input_names_the_key(text, message):
    with pytest.raises(StabmapError) as info:
        loads_scene(text)
    assert message in str(info.value)


def test_free_support_rejects_base_and_gravity_axes():
    free = GOOD.replace('support = "fixed"', 'support = "free"')
    with pytest.raises(StabmapError, match="K_0"):
        loads_scene(free.replace("joints = [120.0]", "joints = [120.0]\nK_0 = 1.0"))
    with pytest.raises(StabmapError, match="'g' has no effect"):
        loads_scene(free.replace("[grid]", "[grid]\ng = { values = [1.0, 2.0] }"))


def test_missing_scene_file(tmp_path):
    with pytest.raises(StabmapError, match="does not exist"):
        stabmap.load_scene(tmp_path / "nope.toml")


def test_omega_must_come_from_somewhere():
    text = GOOD.replace("omega = 50.0\n", "").replace("omega = { start = 1.0, stop = 200.0, num = 5 }\n", "")
    with pytest.raises(StabmapError, match="omega is missing"):
        loads_scene(text)
