"""Scene files: the public TOML contract and its error messages."""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import stabmap
from stabmap import StabmapError, loads_scene
from scenes import TOP

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
    (_replace("joints = [120.0]", "joints = [1.0, 2.0]"), "joints has 2 values; a chain of 2 bodies has 1 joint between bodies (K_1)"),
    (_replace("joints = [120.0]", "joints = [-3.0]"), "joints[1] (K_1) must be >= 0"),
    (_replace('support = "fixed"', 'support = "floating"'), 'support must be "fixed" or "free"'),
    (_replace("kappa = [1.31, 2.7]", "kappa = [1.31, 0.0]"), "bodies[1].fluid.kappa[2] = 0: a liquid mode has |kappa| > 1"),
    (_replace("kappa = [1.31, 2.7]", "kappa = [1.31]"), "E has 2 values but kappa has 1"),
    (_replace("title =", "title = = "), "TOML syntax error"),
    (_replace("m_2 = {", "m_9 = {"), "'m_9': bodies are numbered 1..2"),
    (_replace("m_2 = {", "mass_2 = {"), "unknown parameter name 'mass_2'"),
    (_replace("K_1 = {", "K_2 = {"), "'K_2': a chain of 2 bodies has one joint, K_1, between its bodies"),
    (_replace("num = 5", "num = 0"), "grid.omega.num must be a whole number >= 1"),
    (_replace("K_1 = { values = [0.0, 10.0, 100.0] }", "K_1 = { values = [] }"), "grid.K_1.values must be a non-empty list"),
    (_replace("K_1 = { values = [0.0, 10.0, 100.0] }", "K_1 = { values = [0.0, 10.0, 5.0] }"), "grid.K_1: values must be distinct and sorted"),
    (_replace("start = 0.1, stop = 10.0", "start = -0.1, stop = 10.0"), "grid.m_2.start must be > 0"),
    (_replace("c = 0.10", "c = 0.10\nfoo = 1"), "bodies[1]: unknown key 'foo'; allowed keys are"),
    (_replace("c = 0.10", "c = 0.10\nfluids = { E = [1e-4], kappa = [1.31] }"), "bodies[1]: unknown key 'fluids'; did you mean 'fluid'?"),
    (_replace("C = 0.02", ""), "bodies[2].C is missing"),
]


@pytest.mark.parametrize("text,message", BAD, ids=[m[:40] for _, m in BAD])
def test_bad_input_names_the_key(text, message):
    with pytest.raises(StabmapError) as info:
        loads_scene(text)
    assert message in str(info.value)


def test_free_support_rejects_base_and_gravity_axes():
    free = GOOD.replace('support = "fixed"', 'support = "free"').replace("g = 9.81\n", "")
    with pytest.raises(StabmapError, match="K_0"):
        loads_scene(free.replace("joints = [120.0]", "joints = [120.0]\nK_0 = 1.0"))
    with pytest.raises(StabmapError, match="'g' has no effect"):
        loads_scene(free.replace("[grid]", "[grid]\ng = { values = [1.0, 2.0] }"))


def test_free_support_rejects_gravity_as_it_rejects_a_base_joint():
    """g has no torque about a free system's centre of mass: given, it is an error (issue 30), not silently ignored."""
    free = GOOD.replace('support = "fixed"', 'support = "free"')
    for text in (free, free.replace("g = 9.81", "g = 3.7")):
        with pytest.raises(StabmapError, match=r"^g: gravity exerts no torque about a free system's centre of mass"):
            loads_scene(text)
    scene = loads_scene(free.replace("g = 9.81\n", ""))
    with pytest.raises(StabmapError, match="^g: gravity"):
        dataclasses.replace(scene, g=1.62)


@pytest.mark.parametrize("text, message", [
    (_replace("m_2 = {", "mm_2 = {"), "unknown parameter name 'mm_2'; did you mean 'm_2'?"),
    (_replace("K_1 = {", "half_hieght_1 = {"), "unknown parameter name 'half_hieght_1'; did you mean 'half_height_1'?"),
    ('system = "closed"\nfamily = "hinge"\n[grid]\nratoi = { values = [1, 2] }\n', "unknown parameter name 'ratoi'; did you mean 'ratio'?"),
    ('system = "reactions"\nnodes = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n[body]\nmass = 1.0\n[grid]\nmas = { values = [1, 2] }\n',
     "unknown parameter name 'mas'; did you mean 'mass'?"),
])
def test_a_misspelt_grid_axis_gets_a_did_you_mean(text, message):
    with pytest.raises(StabmapError) as info:
        loads_scene(text)
    assert message in str(info.value)


def test_one_point_axis_with_a_different_stop_is_an_error():
    with pytest.raises(StabmapError, match=r"grid.omega: num = 1 gives the one value start = 1 and would ignore stop = 200"):
        loads_scene(_replace("num = 5", "num = 1"))
    scene = loads_scene(_replace("omega = { start = 1.0, stop = 200.0, num = 5 }", "omega = { start = 7.0, stop = 7.0, num = 1 }"))
    assert [a.values for a in scene.grid if a.name == "omega"] == [(7.0,)]


def test_missing_scene_file(tmp_path):
    with pytest.raises(StabmapError, match="does not exist"):
        stabmap.load_scene(tmp_path / "nope.toml")


def test_omega_must_come_from_somewhere():
    text = GOOD.replace("omega = 50.0\n", "").replace("omega = { start = 1.0, stop = 200.0, num = 5 }\n", "")
    with pytest.raises(StabmapError, match="omega is missing"):
        loads_scene(text)


def _three_bodies(grid: str) -> str:
    body = "[[bodies]]\nm = 1.0\nA = 0.02\nC = 0.03\nc = 0.10\ns = 0.25\n"
    return f'support = "fixed"\nomega = 40.0\njoints = [5.0, 6.0]\nK_0 = 7.0\n' + body * 3 + "[grid]\n" + grid


def test_axes_for_every_body_and_every_joint():
    from stabmap.systems.gyroscopes.points import point_arrays

    scene = loads_scene(_three_bodies("C = { values = [0.01, 0.05] }\nK = { values = [0.0, 9.0] }\nA_2 = { values = [0.5] }\n"))
    pa = point_arrays(scene, {"C": [0.05], "K": [9.0], "A_2": [0.5], "C_3": [0.07]})
    assert pa.body[0, :, 2].tolist() == [0.05, 0.05, 0.07]  # C_3 wins over the common C on body 3
    assert pa.body[0, :, 1].tolist() == [0.02, 0.5, 0.02]
    assert pa.joint[0].tolist() == [7.0, 9.0, 9.0]  # K sets K_1 and K_2, never the base K_0
    ds = stabmap.compute_atlas(scene, progress=False)
    assert ds["C"].attrs["long_name"] == "axial moment of inertia of every body"
    assert "every joint" in ds["K"].attrs["long_name"]
    assert not {"C_1", "C_2", "C_3", "K_1", "K_2"} & set(ds.coords)  # no stale fixed values beside the axis
    assert float(ds["K_0"]) == 7.0 and float(ds["A_1"]) == 0.02


def test_common_axis_equals_setting_every_body():
    scene = loads_scene(_three_bodies("m = { values = [0.5, 2.0] }\nomega = { values = [5.0, 50.0] }\n"))
    ds = stabmap.compute_atlas(scene, progress=False)
    assert (ds["n_complex_pairs"].sel(m=0.5) != ds["n_complex_pairs"].sel(m=2.0)).any()  # the axis matters here
    for m in (0.5, 2.0):
        one = loads_scene(_three_bodies("omega = { values = [5.0, 50.0] }\n").replace("m = 1.0", f"m = {m}"))
        expected = stabmap.compute_atlas(one, progress=False)["n_complex_pairs"]
        assert (ds["n_complex_pairs"].sel(m=m).values == expected.values).all()


def test_every_joint_axis_needs_joints():
    with pytest.raises(StabmapError, match="grid axis 'K' \\(every joint\\) needs two or more bodies"):
        loads_scene('support = "fixed"\nomega = 1.0\n[[bodies]]\nm = 1.0\nA = 0.02\nC = 0.03\nc = 0.1\n[grid]\nK = { values = [1.0] }\n')


# --- one place for the checks ------------------------------------------------------------------------------


def _python_and_toml(change_python, change_toml):
    """The message of a bad scene built in Python, and of the same scene read from TOML."""
    from stabmap.scene.grid import Axis
    from stabmap.systems.gyroscopes.liquid import Cavity
    from stabmap.systems.gyroscopes.scene import Body, Scene
    from stabmap.systems.gyroscopes.topology import Topology

    kw = {"bodies": (Body(**TOP, s=0.25), Body(**TOP)), "omega": 50.0, "joints": (120.0,), "grid": (Axis("omega", (1.0, 2.0)),)}
    with pytest.raises(StabmapError) as python:  # a part (an Axis, a Topology) may refuse itself already
        change_python(kw, Body, Axis, Cavity, Topology)
        Scene(**kw)
    text = GOOD
    for old, new in change_toml:
        assert old in text
        text = text.replace(old, new, 1)
    with pytest.raises(StabmapError) as toml:
        loads_scene(text)
    return str(python.value), str(toml.value)


SAME = [
    (lambda kw, Body, *_: kw.update(bodies=(kw["bodies"][0], Body(**{**TOP, "m": -1.0}))), [("m = 0.5", "m = -1.0")]),
    (lambda kw, *_: kw.update(support="floating"), [('support = "fixed"', 'support = "floating"')]),
    (lambda kw, *_: kw.update(joints=(1.0, 2.0)), [("joints = [120.0]", "joints = [1.0, 2.0]")]),
    (lambda kw, *_: kw.update(joints=(-3.0,)), [("joints = [120.0]", "joints = [-3.0]")]),
    (lambda kw, Body, *_: kw.update(bodies=(Body(**TOP, s=0.25, E=(1e-4,), kappa=(0.0,)), kw["bodies"][1])),
     [("kappa = [1.31, 2.7]", "kappa = [0.0, 2.7]")]),
    (lambda kw, Body, *_: kw.update(bodies=(Body(**TOP, s=0.25, E=(1e-4, 2e-5), kappa=(1.31,)), kw["bodies"][1])),
     [("kappa = [1.31, 2.7]", "kappa = [1.31]")]),
    (lambda kw, _, Axis, *__: kw.update(grid=(Axis("m_9", (1.0,)),)), [("m_2 = {", "m_9 = {")]),
    (lambda kw, _, Axis, *__: kw.update(grid=(Axis("K_1", (0.0, 10.0, 5.0)),)), [("K_1 = { values = [0.0, 10.0, 100.0] }", "K_1 = { values = [0.0, 10.0, 5.0] }")]),
    (lambda kw, _, Axis, *__: kw.update(grid=(Axis("K_1", (-1.0, 10.0)),)), [("K_1 = { values = [0.0, 10.0, 100.0] }", "K_1 = { values = [-1.0, 10.0] }")]),
    (lambda kw, *_: kw.update(K_0=1.0, support="free"), [('support = "fixed"', 'support = "free"'), ("g = 9.81", "K_0 = 1.0")]),
    (lambda kw, Body, Axis, Cavity, _: kw.update(bodies=(Body(**TOP, s=0.25, cavity=Cavity("cylinder", 0.0, 0.05, 1000.0)), kw["bodies"][1])),
     [("fluid = { E = [1e-4, 2e-5], kappa = [1.31, 2.7] }", 'cavity = { shape = "cylinder", radius = 0.0, half_height = 0.05, density = 1000.0 }')]),
    (lambda kw, Body, Axis, Cavity, Topology: kw.update(topology=Topology((0, 2), (0.0, 0.3))),
     [("[[bodies]]", "[topology]\nparent = [0, 2]\nat = [0.0, 0.3]\n\n[[bodies]]")]),
]


@pytest.mark.parametrize("change_python,change_toml", SAME, ids=[str(i) for i in range(len(SAME))])
def test_a_scene_built_in_python_gets_the_checks_and_messages_of_toml(change_python, change_toml):
    python, toml = _python_and_toml(change_python, change_toml)
    assert python == toml


@given(st.text(max_size=40))
@settings(max_examples=200, deadline=None)
def test_any_title_survives_the_trip_through_the_atlas_toml(title):
    scene = dataclasses.replace(loads_scene(GOOD), title=title)
    assert loads_scene(scene.to_toml()) == scene


def test_the_stored_scene_names_its_system_and_old_files_default_to_gyroscopes():
    scene = loads_scene(GOOD)
    assert scene.to_toml().startswith('system = "gyroscopes"\n')
    assert loads_scene(scene.to_toml()) == scene == loads_scene('system = "gyroscopes"\n' + GOOD)
    with pytest.raises(StabmapError, match="system = 'pendulum' is not a system stabmap knows; choose one of: gyroscopes"):
        loads_scene('system = "pendulum"\n' + GOOD)
