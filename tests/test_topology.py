"""Bodies joined as a tree (Wittenburg 5.2.1, docs/trees.md): S and T, regular numbering, scenes, physics.

The physics is checked against ``reference.tree_char_poly``, which derives M and K
from the Lagrangian of the geometry (exact trigonometry, Hessians, Routh's
elimination of the translation of a free system) and shares nothing with the
engine's lever arms built from S and T.
"""

from __future__ import annotations

import copy
import random
import re
from fractions import Fraction
from pathlib import Path

import matplotlib
import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from stabmap import kernels
import stabmap
from stabmap.scene.grid import resample
from stabmap import StabmapError, loads_scene
from stabmap.run.tasks import block_values
from stabmap.systems.gyroscopes import exact, topology
from stabmap.systems.gyroscopes.outputs import BY_EXACT
from stabmap.systems.gyroscopes.points import PointArrays, point_arrays
from stabmap.systems.gyroscopes.scene import fixed_values, from_dict

import reference as ref
from systems import engine_enclosure, engine_point

matplotlib.use("Agg")

DOCS = Path(__file__).resolve().parents[1] / "docs" / "trees.md"

# The example graph of docs/trees.md: 7 bodies, arcs numbered and directed at will (arc 1 joins body 1
# to the base), as in the seed's Fig. 5.8c.  Arc a leaves EXAMPLE_PLUS[a - 1] and enters EXAMPLE_MINUS[a - 1].
EXAMPLE_PLUS = (1, 3, 7, 1, 4, 5, 3)
EXAMPLE_MINUS = (0, 6, 5, 5, 6, 2, 1)


# ---------------------------------------------------------------------------------------------------------
# The seed's graph formalism


@st.composite
def trees(draw, max_n: int = 9) -> tuple[int, ...]:
    """A valid parent array in any numbering (body 1 on the base, the rest labelled at random)."""
    n = draw(st.integers(1, max_n))
    regular = [0] + [draw(st.integers(1, k - 1)) for k in range(2, n + 1)]
    rest = draw(st.permutations(list(range(2, n + 1))))
    label = dict(zip(range(1, n + 1), [1] + list(rest)))  # regular body k is called label[k]
    label[0] = 0
    parent = [0] * n
    for k in range(1, n + 1):
        parent[label[k] - 1] = label[regular[k - 1]]
    return tuple(parent)


@given(trees(), st.data())
@settings(max_examples=150, deadline=None)
def test_incidence_and_path_matrix_relations(parent, data):
    """Seed (5.5) and (5.6): S_0 T = -1^T and S T = T S = E, for every direction of the arcs."""
    n = len(parent)
    toward = data.draw(st.lists(st.booleans(), min_size=n, max_size=n))
    plus, minus = topology.arcs(parent, toward)
    S_full = topology.incidence(plus, minus)
    T = topology.path_matrix(plus, minus)
    S0, S = S_full[0], S_full[1:]
    assert (S0 @ T == -np.ones(n, dtype=np.int64)).all()
    assert (S @ T == np.eye(n, dtype=np.int64)).all()
    assert (T @ S == np.eye(n, dtype=np.int64)).all()
    # Column i of T holds exactly the arcs on the path from the base to body i, +1 where they point at the base.
    for i in range(1, n + 1):
        on_path = set(topology.path(parent, i))
        for a in range(1, n + 1):
            expected = (1 if toward[a - 1] else -1) if a in on_path else 0
            assert T[a - 1, i - 1] == expected


def _edges(parent) -> set[frozenset]:
    return {frozenset((k, p)) for k, p in enumerate(parent, start=1)}


@given(trees())
@settings(max_examples=150, deadline=None)
def test_regular_numbering_from_any_labelling(parent):
    n = len(parent)
    order = topology.regular_numbering(parent)
    assert sorted(order) == list(range(1, n + 1)) and order[0] == 1
    new = topology.relabel(parent, order)
    assert topology.is_regular(new)
    old_of = {i: old for i, old in enumerate(order, start=1)} | {0: 0}
    assert {frozenset(old_of[v] for v in e) for e in _edges(new)} == _edges(parent)  # the same tree
    # The seed's procedure gives the terminal bodies the largest numbers.
    terminal = [k for k, kids in enumerate(topology.children(new)) if k and not kids]
    n_star = n - len(terminal)
    assert sorted(terminal) == list(range(n_star + 1, n + 1))
    for toward, sign in ((False, -1), (True, 1)):
        S = topology.incidence(*topology.arcs(new, toward))[1:]
        T = topology.path_matrix(*topology.arcs(new, toward))
        assert (np.diag(S) == sign).all() and (np.diag(T) == sign).all()
        assert not np.tril(S, -1).any() and not np.tril(T, -1).any()  # both upper triangular
        assert set(np.unique(T)) <= {0, sign}
        above = np.triu(T, 1).any(axis=1)
        assert above[:n_star].all() and not above[n_star:].any()  # above the diagonal: the first n* rows


@given(trees())
@settings(max_examples=60, deadline=None)
def test_kernel_layout_keeps_a_regular_numbering(parent):
    order, kparent = topology.kernel_layout(parent)
    if topology.is_regular(parent):
        assert list(order) == list(range(len(parent)))
    assert kparent[0] == -1 and all(0 <= kparent[k] < k for k in range(1, len(parent)))
    assert list(kparent + 1) == list(topology.relabel(parent, tuple(order + 1)))


def _matrix_text(M: np.ndarray) -> str:
    return "\n".join(" ".join(f"{int(x):3d}" for x in row) for row in M)


def test_example_graph_of_the_docs():
    S_full = topology.incidence(EXAMPLE_PLUS, EXAMPLE_MINUS)
    T = topology.path_matrix(EXAMPLE_PLUS, EXAMPLE_MINUS)
    assert (S_full[0] @ T == -1).all() and (S_full[1:] @ T == np.eye(7)).all()
    parent, joint = topology.parent_from_arcs(EXAMPLE_PLUS, EXAMPLE_MINUS)
    assert joint[0] == 1  # arc 1 joins body 1 to the base
    order = topology.regular_numbering(parent)
    regular = topology.relabel(parent, order)
    S_reg = topology.incidence(*topology.arcs(regular))
    T_reg = topology.path_matrix(*topology.arcs(regular))
    n_star = max(r for r in range(8) if r == 0 or np.triu(T_reg, 1)[r - 1].any())
    assert n_star == 4  # the seed: "in this particular case n* = 4"
    text = DOCS.read_text(encoding="utf-8")
    for M in (S_full, T, S_reg, T_reg):
        assert _matrix_text(M) in text
    assert f"parent = {list(regular)}" in text
    assert f"order = {list(order)}" in text


def test_arcs_that_are_not_a_tree():
    # Arcs 3 and 4 both join bodies 2 and 3: a loop, and body 4 is cut off from the base.
    with pytest.raises(StabmapError, match=r"no path leads from body 0 to \[4\]"):
        topology.check_arcs((1, 2, 3, 2), (0, 1, 2, 3))
    with pytest.raises(StabmapError, match="arc 2 = \\(2, 2\\) must join two different vertices"):
        topology.check_arcs((1, 2), (0, 2))


def test_kernels_reject_a_parent_that_is_not_a_regular_numbering():
    pts = point_arrays(from_dict(_tree_system("fixed", (0, 1, 1), (0.0, 0.3, 0.3))), {})
    nc, st_ = np.empty(1, np.int16), np.empty(1, np.int8)
    for bad in ([-1, 2, 0], [-1, -1, 0], [0, 0, 1], [-1, 0]):
        with pytest.raises(ValueError, match="parent"):
            kernels.count_block(*pts.kernel_args()[:7], np.array(bad, dtype=np.int64), pts.at, nc, st_)


# ---------------------------------------------------------------------------------------------------------
# Scenes

CARRIER = {"m": 2.0, "A": 0.05, "C": 0.01, "c": 0.1}
ROTOR = {"m": 0.5, "A": 0.01, "C": 0.015, "c": 0.08}
HANGING = {"m": 0.75, "A": 0.02, "C": 0.025, "c": -0.1}


def _tree_system(support, parent, at, bodies=None, joints=None, **extra) -> dict:
    bodies = bodies or [CARRIER, ROTOR, HANGING][: len(parent)]
    system = {"support": support, "omega": 30.0, "bodies": copy.deepcopy(bodies),
              "topology": {"parent": list(parent), "at": list(at)}}
    if joints is not None:
        system["joints"] = list(joints)
    if support == "fixed":
        system["g"] = 9.81
    system.update(extra)
    return system


TREE_TOML = """
title = "a carrier with a gyroscope above and one below"
support = "fixed"
g = 9.81
omega = 40.0
joints = [5.0, 8.0]
K_0 = 2.0

[topology]
parent = [0, 1, 1]
at = [0.0, 0.3, -0.2]

[[bodies]]
m = 2.0
A = 0.05
C = 0.01
c = 0.1

[[bodies]]
m = 0.5
A = 0.01
C = 0.015
c = 0.08

[[bodies]]
m = 0.75
A = 0.02
C = 0.025
c = -0.1

[grid]
omega = { start = 5.0, stop = 80.0, num = 4 }
at_3 = { values = [-0.3, -0.2, -0.1] }
"""


def test_tree_scene_parses_and_round_trips():
    scene = loads_scene(TREE_TOML)
    assert scene.topology.parent == (0, 1, 1) and scene.topology.at == (0.0, 0.3, -0.2)
    assert all(b.s == 0.0 for b in scene.bodies)
    assert loads_scene(scene.to_toml()) == scene
    fixed = fixed_values(scene)
    assert fixed["at_2"] == 0.3 and "at_3" not in fixed and not any(k.startswith("s_") for k in fixed)


def _toml_replace(old: str, new: str) -> str:
    assert old in TREE_TOML
    return TREE_TOML.replace(old, new, 1)


BAD_TREES = [
    (_toml_replace("parent = [0, 1, 1]", "parent = [0, 3, 2]"),
     "topology.parent: bodies 2 -> 3 -> 2 form a closed loop that never reaches the base"),
    (_toml_replace("parent = [0, 1, 1]", "parent = [0, 1, 0]"),
     "topology.parent[3] = 0: only body 1 may be joined to the base"),
    (_toml_replace("parent = [0, 1, 1]", "parent = [1, 0, 1]"),
     "topology.parent[1] = 1: body 1 cannot be its own parent"),
    (_toml_replace("parent = [0, 1, 1]", "parent = [2, 0, 1]"),
     "topology.parent[1] = 2: body 1 is the body on the base (Wittenburg's numbering); set topology.parent[1] = 0"),
    (_toml_replace("parent = [0, 1, 1]", "parent = [0, 1, 4]"), "topology.parent[3] = 4: bodies are numbered 1..3"),
    (_toml_replace("parent = [0, 1, 1]", "parent = [0, 1, 1.5]"), "topology.parent[3] must be a whole number"),
    (_toml_replace("parent = [0, 1, 1]", "parent = [0, 1]"),
     "topology.parent must be a list with one value per body (3 [[bodies]] tables), got 2 values"),
    (_toml_replace("at = [0.0, 0.3, -0.2]\n", ""), "topology.at is missing: give the position of each body's joint"),
    (_toml_replace("at = [0.0, 0.3, -0.2]", "at = [0.1, 0.3, -0.2]"), "topology.at[1] must be 0, got 0.1"),
    (_toml_replace("at = [0.0, 0.3, -0.2]", "at = [0.0, 0.3, nan]"), "topology.at[3] must be finite"),
    (_toml_replace("[topology]", "[topology]\nchildren = [1]"), "topology: unknown key 'children'"),
    (_toml_replace("c = 0.08", "c = 0.08\ns = 0.2"), "bodies[2].s is not used in a scene with [topology]"),
    (_toml_replace("at_3 = {", "s_1 = {"), "grid axis 's_1' has no effect in a scene with [topology]"),
    (_toml_replace("at_3 = {", "at_1 = {"), "'at_1': body 1's joint is the base point"),
    (_toml_replace("joints = [5.0, 8.0]", "joints = [5.0]"), "a tree of 3 bodies has 2 joints between bodies"),
]


@pytest.mark.parametrize("text,message", BAD_TREES)
def test_bad_topologies_name_the_key_and_the_fix(text, message):
    with pytest.raises(StabmapError) as info:
        loads_scene(text)
    assert message in str(info.value)


def test_joint_positions_belong_to_trees():
    chain = {"support": "fixed", "omega": 30.0, "bodies": [dict(CARRIER, s=0.3), ROTOR],
             "grid": {"at_2": {"values": [0.1, 0.2]}}}
    with pytest.raises(StabmapError, match="in a chain body 2 hangs at s_1 on body 1, so scan s_1"):
        from_dict(chain)


# ---------------------------------------------------------------------------------------------------------
# Physics against the independent Lagrangian derivation


def _fractions(rng: random.Random, n: int) -> list[dict]:
    return [{"m": Fraction(rng.randint(1, 40), 8), "A": Fraction(rng.randint(1, 40), 400),
             "C": Fraction(rng.randint(0, 40), 400), "c": Fraction(rng.randint(-20, 20), 64),
             "omega": Fraction(rng.randint(-40, 40), 2)} for _ in range(n)]


def test_hand_derived_two_rotors_on_a_fixed_carrier():
    """Carrier 1 on the base, rotors 2 and 3 both at its joint at height h: M and K written out by hand."""
    rng = random.Random(1)
    for _ in range(5):
        b = _fractions(rng, 3)
        (m1, A1, c1), (m2, A2, c2), (m3, A3, c3) = ((x["m"], x["A"], x["c"]) for x in b)
        h, g = Fraction(rng.randint(1, 30), 32), Fraction(981, 100)
        K0, K1, K2 = (Fraction(rng.randint(0, 9)) for _ in range(3))
        M, _, K = ref.tree_matrices(b, [0, 1, 1], [0, h, h], "fixed", g, [K0, K1, K2])
        hand_M = sympy.Matrix([
            [A1 + m1 * c1**2 + (m2 + m3) * h**2, m2 * h * c2, m3 * h * c3],
            [m2 * h * c2, A2 + m2 * c2**2, 0],
            [m3 * h * c3, 0, A3 + m3 * c3**2],
        ])
        hand_K = sympy.Matrix([
            [K0 + K1 + K2 - g * (m1 * c1 + (m2 + m3) * h), -K1, -K2],
            [-K1, K1 - g * m2 * c2, 0],
            [-K2, 0, K2 - g * m3 * c3],
        ])
        assert M == hand_M.applyfunc(sympy.Rational) and K == hand_K.applyfunc(sympy.Rational)


def test_hand_derived_gyroscopes_above_and_below_a_free_carrier():
    """Free carrier 1, gyroscope 2 at h above its joint, gyroscope 3 at d below it: M by hand."""
    rng = random.Random(2)
    for _ in range(5):
        b = _fractions(rng, 3)
        m = [x["m"] for x in b]
        h, d = Fraction(rng.randint(1, 30), 32), Fraction(rng.randint(1, 30), 32)
        J = [[b[0]["c"], 0, 0], [h, b[1]["c"], 0], [-d, 0, b[2]["c"]]]
        mt = sum(m)
        mean = [sum(m[k] * J[k][i] for k in range(3)) / mt for i in range(3)]
        # Kinetic energy with the centre of mass at rest: sum_k m_k (y_k - y_mean)^2 / 2.
        hand_M = sympy.Matrix([[(b[i]["A"] if i == j else 0) + sum(m[k] * (J[k][i] - mean[i]) * (J[k][j] - mean[j]) for k in range(3))
                                for j in range(3)] for i in range(3)])
        M, _, K = ref.tree_matrices(b, [0, 1, 1], [0, h, -d], "free", 0, [0, 3, 4])
        assert M == hand_M.applyfunc(sympy.Rational)
        assert K == sympy.Matrix([[7, -3, -4], [-3, 3, 0], [-4, 0, 4]])


@pytest.mark.parametrize("support", ["fixed", "free"])
def test_lagrangian_reference_restates_model_for_chains(support):
    """The tree oracle, given a chain, is docs/model.md's chain (ref.char_poly), which the paper's determinants check."""
    rng = random.Random(3 if support == "fixed" else 4)
    for n in (1, 2, 3):
        bodies = [dict(b, s=Fraction(rng.randint(1, 20), 32), E=[Fraction(1, 500)], kappa=[Fraction(27, 10)])
                  for b in _fractions(rng, n)]
        joints = [Fraction(rng.randint(0, 9)) for _ in range(n - 1)]
        K0, g = (Fraction(3), Fraction(981, 100)) if support == "fixed" else (0, 0)
        chain = ref.char_poly(bodies, support, g=g, joints=joints, K0=K0)
        tree = ref.tree_char_poly(bodies, list(range(n)), [0] + [b["s"] for b in bodies[:-1]], support, g, [K0] + joints)
        assert chain == tree


def _reference_poly(system: dict) -> sympy.Poly:
    """ref.tree_char_poly for a scene dict; the scene's K_0 is body 1's joint, K_k that of body k + 1."""
    bodies = [{"m": b["m"], "A": b["A"], "C": b["C"], "c": b["c"], "omega": b.get("omega", system["omega"]),
               "E": b.get("fluid", {}).get("E", []), "kappa": b.get("fluid", {}).get("kappa", [])}
              for b in system["bodies"]]
    n = len(bodies)
    stiffness = [system.get("K_0", 0.0)] + list(system.get("joints", [0.0] * (n - 1)))
    tree = system.get("topology", {"parent": list(range(n)), "at": [0.0] + [b.get("s", 0.0) for b in system["bodies"][:-1]]})
    return ref.tree_char_poly(bodies, tree["parent"], tree["at"], system["support"], system.get("g", 0), stiffness)


def _engine_poly(system: dict) -> sympy.Poly:
    """The engine's exact-path polynomial (systems/gyroscopes/exact.py) for a grid-less scene dict."""
    pa = point_arrays(from_dict(system), {})
    p = exact.char_poly(pa.body[0], pa.joint[0], pa.g[0], pa.E[0], pa.kappa[0], pa.nmodes, pa.free, pa.parent, pa.at[0])
    return sympy.Poly([sympy.Rational(int(c.p), int(c.q)) for c in reversed(p.coeffs())] or [0], ref.lam)


def _check_engine(system: dict) -> int:
    """Exact polynomial, kernel enclosure and N_c of the engine against the reference; returns N_c."""
    p = _reference_poly(system)
    assert _engine_poly(system) == p, system
    coeffs = list(reversed(p.all_coeffs()))
    for i, (mid, rad) in enumerate(engine_enclosure(system)):
        assert abs(ref.exact(mid) - (coeffs[i] if i < len(coeffs) else 0)) <= ref.exact(rad), (system, i)
    nc = ref.count_complex_pairs(p)
    assert engine_point(system)[0] == nc, system
    return nc


HANDMADE = {
    # two rotors mounted at the same joint of a carrier
    "two rotors, fixed carrier": _tree_system("fixed", (0, 1, 1), (0.0, 0.25, 0.25), [CARRIER, ROTOR, ROTOR],
                                              joints=[6.0, 9.0], K_0=1.5),
    "two rotors, free carrier": _tree_system("free", (0, 1, 1), (0.0, 0.25, 0.25), [CARRIER, ROTOR, dict(ROTOR, m=0.25)],
                                             joints=[6.0, 9.0]),
    "two ideal rotors, fixed carrier": _tree_system("fixed", (0, 1, 1), (0.0, 0.25, 0.25), [CARRIER, ROTOR, ROTOR]),
    # a carrier with one gyroscope above and one below it
    "above and below, fixed": _tree_system("fixed", (0, 1, 1), (0.0, 0.3, -0.2), joints=[0.5, 8.0]),
    "above and below, free": _tree_system("free", (0, 1, 1), (0.0, 0.3, -0.2), joints=[5.0, 8.0]),
    # the same fixed system with bodies 2 and 3 swapped: K_1, K_2 are the joints of bodies 2, 3
    "above and below, numbered otherwise": _tree_system("fixed", (0, 1, 1), (0.0, -0.2, 0.3),
                                                        [CARRIER, HANGING, ROTOR], joints=[8.0, 0.5]),
    # two bodies: a gyroscope hanging below its carrier's joint; a three-body branch on a free carrier
    "two bodies, hanging": _tree_system("fixed", (0, 1), (0.0, -0.15), [CARRIER, HANGING], joints=[4.0]),
    "branch of two on a free carrier": _tree_system("free", (0, 3, 1), (0.0, 0.1, 0.3), [CARRIER, ROTOR, HANGING],
                                                    joints=[2.0, 0.0]),
}


@pytest.mark.parametrize("name", list(HANDMADE))
def test_handmade_trees_match_the_lagrangian_reference(name):
    dry = HANDMADE[name]
    wet = copy.deepcopy(dry)  # the carrier's liquid near resonance with the nutation
    wet["bodies"][0]["fluid"] = {"E": [3e-3], "kappa": [2.7]}
    counts = {(system is wet, omega): _check_engine(dict(system, omega=omega))
              for system in (dry, wet) for omega in (0.5, 5.0, 20.0, 60.0, 200.0)}
    assert len(set(counts.values())) > 1, counts  # the verdict changes: the test can see a wrong matrix


@pytest.mark.parametrize("carrier,h", [({"m": 2.0, "A": 0.5, "C": 0.25, "c": 0.5}, -0.5),
                                       ({"m": 2.0, "A": 0.5, "C": 2.0, "c": -0.5}, 0.5)])
def test_exact_fallback_decides_trees(carrier, h):
    """Two identical rotors at one joint, each exactly at Maievskii's boundary: a double root no interval proves.

    The antisymmetric motion of the rotors decouples with p = (lam + 2)^2 / 4, so the point goes to
    the exact path (systems/gyroscopes/exact.py), which must build the same tree (read as a chain, these bodies give another N_c).
    """
    rotor = {"m": 1.0, "A": 0.1875, "C": 1.0, "c": 0.25}  # A + m c^2 = 1/4, C^2 omega^2 = 4 (A + m c^2) m c g
    system = _tree_system("fixed", (0, 1, 1), (0.0, h, h), [carrier, rotor, rotor], g=4.0, omega=1.0)
    p = _reference_poly(system)
    assert max(mult for _, mult in p.sqf_list()[1]) >= 2
    assert engine_point(system) == (ref.count_complex_pairs(p), BY_EXACT)
    pa = point_arrays(from_dict(system), {})
    as_chain = PointArrays(pa.body, pa.joint, pa.g, pa.E, pa.kappa, pa.nmodes, pa.free)
    assert exact.decide_points(*as_chain.kernel_args(), [0])[0] != ref.count_complex_pairs(p)


def _random_tree_system(rng: random.Random, n: int, modes: int, support: str) -> dict:
    parent = [0] + [rng.randint(1, k - 1) for k in range(2, n + 1)]
    labels = [1] + rng.sample(range(2, n + 1), n - 1)  # regular body k is called labels[k - 1]
    relabelled = [0] * n
    for k in range(1, n + 1):
        relabelled[labels[k - 1] - 1] = labels[parent[k - 1] - 1] if parent[k - 1] else 0
    at = [0.0] + [rng.choice([-1, 1]) * rng.uniform(0.05, 0.5) for _ in range(n - 1)]
    bodies = []
    for _ in range(n):
        b = {"m": rng.uniform(0.2, 3.0), "A": rng.uniform(0.005, 0.1), "C": rng.uniform(0.0, 0.1),
             "c": rng.uniform(-0.2, 0.4)}
        if rng.random() < 0.3:
            b["omega"] = rng.uniform(-80, 80)
        if modes:
            b["fluid"] = {"E": [rng.uniform(1e-5, 0.3 * b["A"]) for _ in range(modes)],
                          "kappa": [rng.choice([-1, 1]) * rng.uniform(1.05, 4.0) for _ in range(modes)]}
        bodies.append(b)
    system = _tree_system(support, relabelled, at, bodies, joints=[rng.choice([0.0, rng.uniform(0, 50)]) for _ in range(n - 1)])
    system["omega"] = rng.uniform(-100, 100)
    if support == "fixed":
        system["g"] = rng.choice([9.81, -9.81, rng.uniform(-20, 20)])
        system["K_0"] = rng.choice([0.0, rng.uniform(0, 20)])
    return system


@pytest.mark.parametrize("support", ["fixed", "free"])
@pytest.mark.parametrize("n,modes", [(2, 1), (3, 0), (3, 1), (4, 0)])
def test_random_trees_match_the_lagrangian_reference(n, modes, support):
    rng = random.Random(100 * n + 10 * modes + (support == "free"))
    for _ in range(4):
        _check_engine(_random_tree_system(rng, n, modes, support))


def test_numbering_does_not_change_the_polynomial():
    system = _tree_system("fixed", (0, 1, 2, 1), (0.0, 0.3, 0.2, -0.2), [CARRIER, ROTOR, ROTOR, HANGING],
                          joints=[1.0, 2.0, 3.0], K_0=0.5)
    # Swap bodies 2 and 4: body 4 (was 2) carries body 3, body 2 (was 4) hangs below body 1.
    other = _tree_system("fixed", (0, 1, 4, 1), (0.0, -0.2, 0.2, 0.3), [CARRIER, HANGING, ROTOR, ROTOR],
                         joints=[3.0, 2.0, 1.0], K_0=0.5)
    assert not topology.is_regular(other["topology"]["parent"])
    assert _engine_poly(system) == _engine_poly(other) == _reference_poly(system)
    assert engine_point(system)[0] == engine_point(other)[0]


# ---------------------------------------------------------------------------------------------------------
# A chain given as a tree, and trees through the whole product

CHAIN = {
    "fixed": {"support": "fixed", "g": 9.81, "omega": 40.0, "joints": [20.0, 5.0], "K_0": 3.0,
              "bodies": [dict(CARRIER, s=0.25, fluid={"E": [1e-3], "kappa": [1.31]}), dict(ROTOR, s=0.2), HANGING]},
    "free": {"support": "free", "omega": 40.0, "joints": [20.0, 0.0],
             "bodies": [dict(CARRIER, s=0.25), dict(ROTOR, s=0.2, fluid={"E": [1e-3], "kappa": [2.7]}), HANGING]},
}


def _as_tree(chain: dict) -> dict:
    tree = copy.deepcopy(chain)
    bodies = tree["bodies"]
    tree["topology"] = {"parent": list(range(len(bodies))), "at": [0.0] + [b["s"] for b in bodies[:-1]]}
    for b in bodies:
        b.pop("s", None)
    return tree


@pytest.mark.parametrize("support", ["fixed", "free"])
def test_chain_as_tree_gives_the_chain_atlas_exactly(support):
    chain = dict(CHAIN[support], grid={"omega": {"start": 0.5, "stop": 120.0, "num": 25},
                                       "m_2": {"start": 0.1, "stop": 3.0, "num": 7}})
    tree = _as_tree(chain)
    a, b = (stabmap.compute_atlas(from_dict(s), threads=1, chunk_points=40, progress=False) for s in (chain, tree))
    for var in ("n_complex_pairs", "stability", "decided_by"):
        assert a[var].dims == b[var].dims and np.array_equal(a[var].values, b[var].values)
    assert len(np.unique(a["n_complex_pairs"].values)) > 1
    # The kernels see the same numbers and return the same enclosures, bit for bit.
    pa, pb = point_arrays(from_dict(chain), block_values(from_dict(chain), [(0, 25), (0, 7)])), point_arrays(from_dict(tree), block_values(from_dict(tree), [(0, 25), (0, 7)]))
    deg = from_dict(chain).degree
    ca, cb = np.zeros((175, deg + 1, 3)), np.zeros((175, deg + 1, 3))
    kernels.charpoly_block(*pa.kernel_args(), ca)
    kernels.charpoly_block(*pb.kernel_args(), cb)
    assert ca.tobytes() == cb.tobytes()
    # Scanning the joint position: s_1 of the chain is at_2 of the tree.
    chain_s = dict(CHAIN[support], grid={"omega": {"start": 0.5, "stop": 120.0, "num": 25},
                                         "s_1": {"values": [0.05, 0.15, 0.3, 0.5]}})
    tree_s = dict(_as_tree(chain_s), grid={"omega": chain_s["grid"]["omega"], "at_2": chain_s["grid"]["s_1"]})
    a, b = (stabmap.compute_atlas(from_dict(s), threads=1, progress=False) for s in (chain_s, tree_s))
    assert np.array_equal(a["n_complex_pairs"].values, b["n_complex_pairs"].values)


def test_example_scene_of_a_branched_system(tmp_path):
    names = [n for n in stabmap.example_names() if n.startswith("tree-")]
    assert names
    for name in names:
        scene = stabmap.example(name)
        assert scene.topology is not None and not all(p == k for k, p in enumerate(scene.topology.parent))
    scene = resample(stabmap.example(names[0]), **{a.name: 6 for a in stabmap.example(names[0]).grid})
    ds = stabmap.compute_atlas(scene, threads=1, progress=False)
    path = tmp_path / "tree.nc"
    stabmap.write_atlas(ds, path)
    back = stabmap.open_atlas(path)
    assert loads_scene(back.attrs["scene"]) == scene
    assert np.array_equal(back["n_complex_pairs"].values, ds["n_complex_pairs"].values)
    for name in (a.name for a in scene.grid):
        assert back[name].attrs["units"] and back[name].attrs["long_name"]
    # A point of the atlas against the reference.
    point = {a.name: a.values[2] for a in scene.grid}
    label = stabmap.label_at(back, **point)
    system = _scene_point(scene, point)
    assert label.n_complex_pairs == ref.count_complex_pairs(_reference_poly(system))
    stabmap.stable_fraction(back)
    along = scene.grid[0].name
    stabmap.boundaries(back, along)
    fig = stabmap.atlas_figure(back)
    fig.savefig(tmp_path / "tree.png")


def _scene_point(scene, point: dict) -> dict:
    """The scene at one grid point as a grid-less scene dict (for the reference)."""
    import tomllib

    system = tomllib.loads(scene.to_toml())
    system.pop("grid", None)
    for name, value in point.items():
        match = re.fullmatch(r"([A-Za-z]+)_(\d+)", name)
        if name in ("omega", "g"):
            system[name] = value
        elif match and match.group(1) == "at":
            system["topology"]["at"][int(match.group(2)) - 1] = value
        elif match and match.group(1) == "K":
            k = int(match.group(2))
            if k == 0:
                system["K_0"] = value
            else:
                system["joints"][k - 1] = value
        elif match:
            system["bodies"][int(match.group(2)) - 1][match.group(1)] = value
        else:
            raise AssertionError(f"no rule for {name}")
    return system


@pytest.mark.slow
def test_cli_atlas_info_of_a_tree_on_a_cluster_and_here(tmp_path, capsys):
    """The branched example through the CLI: streamed on a local cluster and in-process, the same file; info says tree."""
    from stabmap import cli

    scene = stabmap.example("tree-carrier-above-below")
    small = tmp_path / "tree.toml"
    small.write_text(resample(scene, omega=40, at_3=30).to_toml())
    assert cli.main(["atlas", str(small), "-o", str(tmp_path / "here.nc"), "-q"]) == 0
    assert cli.main(["atlas", str(small), "-o", str(tmp_path / "cluster.nc"), "--workers", "2", "--chunk-points", "300", "-q"]) == 0
    here, there = stabmap.open_atlas(tmp_path / "here.nc"), stabmap.open_atlas(tmp_path / "cluster.nc")
    assert np.array_equal(here["n_complex_pairs"].values, there["n_complex_pairs"].values)
    assert list(here.attrs["topology_parent"]) == [0, 1, 1]
    capsys.readouterr()
    assert cli.main(["info", str(tmp_path / "here.nc")]) == 0
    assert "a tree: parent = [0, 1, 1]" in capsys.readouterr().out
