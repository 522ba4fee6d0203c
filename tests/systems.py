"""Random and special test systems, given once as plain dicts for both the engine and the reference."""

from __future__ import annotations

import random
from fractions import Fraction

import numpy as np

from stabmap import kernels
from stabmap.systems.gyroscopes.decide import decide
from stabmap.systems.gyroscopes.points import point_arrays
from stabmap.systems.gyroscopes.scene import from_dict


def random_system(rng: random.Random, n: int, modes: int, support: str) -> dict:
    """A chain with parameters spread over realistic ranges, some joints ideal, liquid optional."""
    bodies = []
    for k in range(n):
        b = {
            "m": rng.uniform(0.2, 3.0),
            "A": rng.uniform(0.005, 0.1),
            "C": rng.uniform(0.0, 0.1),
            "c": rng.uniform(-0.2, 0.4),
            "s": rng.uniform(0.05, 0.6),
        }
        if rng.random() < 0.3:
            b["omega"] = rng.uniform(-80, 80)
        if modes:
            b["fluid"] = {
                "E": [rng.uniform(1e-5, 0.3 * b["A"]) for _ in range(modes)],
                "kappa": [rng.choice([-1, 1]) * rng.uniform(1.05, 4.0) for _ in range(modes)],
            }
        bodies.append(b)
    scene = {"support": support, "omega": rng.uniform(-100, 100), "bodies": bodies}
    scene["joints"] = [rng.choice([0.0, rng.uniform(0, 200)]) for _ in range(n - 1)]
    if support == "fixed":
        scene["g"] = rng.choice([9.81, -9.81, rng.uniform(-20, 20)])
        scene["K_0"] = rng.choice([0.0, rng.uniform(0, 50)])
    return scene


def reference_args(system: dict) -> dict:
    """Keyword arguments of tests.reference.char_poly for the same system."""
    bodies = []
    for b in system["bodies"]:
        fluid = b.get("fluid", {})
        bodies.append(
            {
                "m": b["m"], "A": b["A"], "C": b["C"], "c": b["c"], "s": b.get("s", 0.0),
                "omega": b.get("omega", system.get("omega")),
                "E": fluid.get("E", []), "kappa": fluid.get("kappa", []),
            }
        )
    out = {"bodies": bodies, "support": system["support"], "joints": system.get("joints", [])}
    if system["support"] == "fixed":
        out["g"] = system.get("g", 9.81)
        out["K0"] = system.get("K_0", 0.0)
    return out


def engine_point(system: dict):
    """(N_c, decided_by) of the engine for the single point of a grid-less system."""
    nc, by = decide(point_arrays(from_dict(system), {}))
    return int(nc[0]), int(by[0])


def engine_enclosure(system: dict) -> list[tuple[Fraction, Fraction]]:
    """The kernel's coefficient intervals (midpoint, radius) as exact fractions."""
    scene = from_dict(system)
    pts = point_arrays(scene, {})
    out = np.zeros((1, scene.degree + 1, 3))
    kernels.charpoly_block(*pts.kernel_args(), out)
    return [(Fraction(h) + Fraction(lo), Fraction(r)) for h, lo, r in out[0]]


# The narrow-window case: a two-body fixed chain with small liquid modes, a stable window 0.108 rad/s wide near
# omega = 12 between scan values 1 rad/s apart.  Exact boundaries (roots of the discriminant in omega):
# 11.909452, 12.017778, 13.838770.
WINDOW = {
    "support": "fixed", "g": 9.81, "joints": [10.0],
    "bodies": [
        {"m": 1.0, "A": 0.02, "C": 0.06, "c": 0.1, "s": 0.2, "fluid": {"E": [5e-4], "kappa": [-2.5]}},
        {"m": 1.0, "A": 0.05, "C": 0.06, "c": 0.05, "fluid": {"E": [5e-4], "kappa": [4.5]}},
    ],
    "grid": {"omega": {"start": 0.5, "stop": 99.5, "num": 100}},
}
EXACT_BOUNDARIES = (11.909452, 12.017778, 13.838770)


def window_straddling_boxes():
    """Boxes of ``WINDOW`` (its liquid's E at 5e-4 and 1e-6) in omega x K_1 and omega x m_2 that hold points on both
    sides of a boundary of the stable window or a liquid band, 1e-9 to 1 rad/s wider than the boundary's bracket:
    yields (scene, the other axis, its value, lower, upper, sides), ``sides`` (boxes, 2) two spins of each box at
    that value, just beside the bracket, one on each side of the boundary (every box holds both)."""
    from stabmap.run.critical import critical

    for E in (5e-4, 1e-6):
        system = dict(WINDOW, bodies=[dict(b, fluid=dict(b["fluid"], E=[E])) for b in WINDOW["bodies"]])
        ds = critical(from_dict(system), "omega", rtol=1e-12, progress=False, threads=1)
        keep = np.isfinite(ds["boundary_lower"].values)
        brackets = list(zip(ds["boundary_lower"].values[keep], ds["boundary_upper"].values[keep], strict=True))
        assert len(brackets) >= 3
        for other, value in (("K_1", 10.0), ("m_2", 1.0)):
            scene = from_dict(dict(system, grid={"omega": {"values": [1.0]}, other: {"values": [value]}}))
            lower: dict[str, list] = {"omega": [], other: []}
            upper: dict[str, list] = {"omega": [], other: []}
            sides = []
            for a, b in brackets:
                for w in (1e-9, 1e-6, 1e-3, 1.0):
                    for h in (1e-6, 1e-2, 0.5):
                        lower["omega"].append(a - w), upper["omega"].append(b + w)
                        lower[other].append(value - h * value), upper[other].append(value + h * value)
                        sides.append((a - 1e-10, b + 1e-10))
            yield (scene, other, value, {k: np.array(v) for k, v in lower.items()}, {k: np.array(v) for k, v in upper.items()},
                   np.array(sides))
