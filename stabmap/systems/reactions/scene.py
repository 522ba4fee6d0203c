"""Scenes of reactions: the nodes, their releases, the load (given, or made by a moving body) and the grid.

``Scene`` validates itself when it is made (``__post_init__``), so a scene built in Python gets the same checks
and messages as one read from TOML; ``from_dict`` only turns the TOML layout into the dataclasses.

```toml
system = "reactions"
title = "square plate on four corner supports"
nodes = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]   # [m]
releases = [{ node = 1, direction = [1.0, 0.0, 0.0] }]      # optional, 0-based node index
[load]                                       # either F and M about the nodes' origin ...
F = [0.0, 0.0, -100.0]                       # [N]
M = [0.0, 0.0, 0.0]                          # [N m]
# [body]                                     # ... or a body whose weight and motion make them
# mass = 10.0, centre = [...], gravity = [0, 0, -9.81], acceleration, omega, alpha, inertia
[grid]
c_x = { start = -0.4, stop = 0.4, num = 81 }
```
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from ...errors import StabmapError
from ...scene.grid import Axis, check_axes, parse_axes
from ...scene.values import Parameter, check_value, no_unknown
from ..base import SceneBase
from . import parameters
from .solver import check_nodes, check_releases

DEFAULT_GRAVITY = (0.0, 0.0, -9.81)
ZERO = (0.0, 0.0, 0.0)
_TOP_KEYS = {"title", "nodes", "releases", "load", "body", "load_factor", "grid"}
_RELEASE_KEYS = {"node", "direction"}
_LOAD_KEYS = {"F", "M"}
_BODY_KEYS = {"mass", "centre", "gravity", "acceleration", "omega", "alpha", "inertia"}
_ANY = Parameter("", "", "")
# the TOML file and the Python scene take the load in the same two ways: one message for both
_ONE_LOAD = ("give the load either as a [load] table (F and M) or as a [body] table (mass, centre, gravity, motion), "
             "exactly one of the two")

Vector = tuple[float, float, float]


@dataclass(frozen=True)
class Release:
    """Node ``node`` (0-based) carries no force along ``direction`` (a cylindrical hinge's axis, say)."""

    node: int
    direction: Vector


@dataclass(frozen=True)
class Load:
    """The load on the body: main vector F [N] and main moment M [N m] about the nodes' origin."""

    F: Vector
    M: Vector = ZERO


@dataclass(frozen=True)
class Body:
    """A body whose weight and motion make the load (d'Alembert), every vector in the nodes' frame.

    ``acceleration`` is that of the nodes' origin, ``omega`` and ``alpha`` the body's angular velocity and
    acceleration, ``inertia`` its inertia tensor about its centre of mass [kg m^2] (3 principal values, or 3x3).
    """

    mass: float
    centre: Vector = ZERO
    gravity: Vector = DEFAULT_GRAVITY
    acceleration: Vector = ZERO
    omega: Vector = ZERO
    alpha: Vector = ZERO
    inertia: tuple[Vector, Vector, Vector] = (ZERO, ZERO, ZERO)

    @property
    def vectors(self) -> dict[str, Vector]:
        """The body's vectors by the prefix of their scannable names (``c_x``, ``g_y``, ...)."""
        return {"c": self.centre, "g": self.gravity, "a": self.acceleration, "omega": self.omega, "alpha": self.alpha}


@dataclass(frozen=True)
class Scene(SceneBase):
    """n point nodes holding a rigid body, their releases, its load (``load`` or ``body``), and the grid."""

    system: ClassVar[str] = "reactions"

    nodes: tuple[Vector, ...]
    load: Load | None = None
    body: Body | None = None
    releases: tuple[Release, ...] = ()
    load_factor: float = 1.0
    title: str = ""
    grid: tuple[Axis, ...] = field(default=())

    def __post_init__(self):
        _validate(self)

    @property
    def n(self) -> int:
        return len(self.nodes)

    @property
    def kind(self) -> str:
        """How the load is given: "load" (F and M) or "body" (a body's weight and motion)."""
        return "load" if self.load is not None else "body"

    @property
    def vectors(self) -> dict[str, Vector]:
        """The scene's load vectors by the prefix of their scannable names."""
        if self.load is not None:
            return {"F": self.load.F, "M": self.load.M}
        if self.body is None:  # __post_init__ lets no such scene through
            raise StabmapError(_ONE_LOAD)
        return self.body.vectors

    def parameter(self, name: str) -> Parameter:
        """The parameter a grid axis called ``name`` scans, or a StabmapError saying why it cannot be scanned."""
        return parameters.parse(name, self.n, self.kind)[1]

    @classmethod
    def from_dict(cls, table: dict, base_dir: str | Path | None = None) -> Scene:
        return from_dict(table, base_dir)

    def fixed_values(self) -> dict[str, float]:
        return fixed_values(self)

    def key(self, name: str) -> tuple:
        return parameters.parse(name, self.n, self.kind)[0]

    def to_dict(self) -> dict:
        out: dict[str, object] = {"title": self.title, "nodes": [list(p) for p in self.nodes]}
        if self.releases:
            out["releases"] = [{"node": r.node, "direction": list(r.direction)} for r in self.releases]
        if self.load_factor != 1.0:
            out["load_factor"] = self.load_factor
        if self.load is not None:
            out["load"] = {"F": list(self.load.F), "M": list(self.load.M)}
        elif self.body is not None:  # always: a scene has a load or a body (__post_init__)
            b = self.body
            out["body"] = {"mass": b.mass, "centre": list(b.centre), "gravity": list(b.gravity),
                           "acceleration": list(b.acceleration), "omega": list(b.omega), "alpha": list(b.alpha),
                           "inertia": [list(row) for row in b.inertia]}
        if self.grid:
            out["grid"] = {a.name: a.to_dict() for a in self.grid}
        return out


# ---------------------------------------------------------------------------------------------------- TOML layout
def from_dict(data: dict, base_dir: str | Path | None = None) -> Scene:
    """The scene of a TOML table; the layout is checked here, every value by ``Scene`` itself."""
    no_unknown(data, _TOP_KEYS, "scene")
    if "nodes" not in data:
        raise StabmapError("nodes is missing: give the node positions, e.g. nodes = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] [m]")
    if ("load" in data) == ("body" in data):
        raise StabmapError(_ONE_LOAD)
    values = {k: data[k] for k in ("title", "load_factor") if k in data}
    if not isinstance(data["nodes"], list) or not data["nodes"]:
        raise StabmapError(f"nodes must be a non-empty list of [x, y, z] positions [m], got {data['nodes']!r}")
    nodes = tuple(_vector(p, f"nodes[{i}]") for i, p in enumerate(data["nodes"]))
    raw = data.get("releases", [])
    if not isinstance(raw, list):
        raise StabmapError("releases must be a list of tables such as { node = 0, direction = [1.0, 0.0, 0.0] }")
    releases = []
    for k, r in enumerate(raw):
        where = f"releases[{k}]"
        no_unknown(r, _RELEASE_KEYS, where)
        for key in ("node", "direction"):
            if key not in r:
                raise StabmapError(f"{where}.{key} is missing: a release is {{ node = 0, direction = [1.0, 0.0, 0.0] }} (node 0-based)")
        releases.append(Release(r["node"], r["direction"]))
    if "load" in data:
        no_unknown(data["load"], _LOAD_KEYS, "load")
        if "F" not in data["load"]:
            raise StabmapError("load.F is missing: the main vector of the load [N], e.g. F = [0.0, 0.0, -100.0]")
        values["load"] = Load(**data["load"])
    else:
        no_unknown(data["body"], _BODY_KEYS, "body")
        if "mass" not in data["body"]:
            raise StabmapError("body.mass is missing: the body's mass [kg]")
        values["body"] = Body(**data["body"])
    kind = "load" if "load" in data else "body"
    grid = parse_axes(data.get("grid", {}), lambda name: parameters.parse(name, len(nodes), kind)[1])
    return Scene(nodes=nodes, releases=tuple(releases), grid=grid, **values)


# ------------------------------------------------------------------------------------------------------ the checks
def _vector(value, where: str, info: Parameter = _ANY) -> Vector:
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 3:
        raise StabmapError(f"{where} must be a 3-vector [x, y, z], got {value!r}")
    x, y, z = (check_value(f"{where}[{d}]", v, info) for d, v in enumerate(value))
    return x, y, z


def _validate(scene: Scene) -> None:
    """Check every value of ``scene`` and store the normalised ones (floats, tuples); errors name the TOML key."""

    def put(name, value):
        object.__setattr__(scene, name, value)

    if not isinstance(scene.title, str):
        raise StabmapError(f"title must be a string, got {scene.title!r}")
    if isinstance(scene.nodes, (str, bytes)) or not hasattr(scene.nodes, "__len__"):
        raise StabmapError(f"nodes must be a list of [x, y, z] positions, got {scene.nodes!r}")
    for i, p in enumerate(scene.nodes):
        _vector(p, f"nodes[{i}]")
    nodes = check_nodes(scene.nodes)
    if nodes.ndim != 2:
        raise StabmapError(f"nodes must be a list of [x, y, z] positions, got an array of shape {nodes.shape}")
    put("nodes", tuple(tuple(p) for p in nodes.tolist()))
    if not all(isinstance(r, Release) for r in scene.releases):
        raise StabmapError("releases must be Release(node, direction) entries")
    check_releases([(r.node, r.direction) for r in scene.releases], scene.n)
    put("releases", tuple(Release(r.node, _vector(r.direction, f"releases[{k}].direction")) for k, r in enumerate(scene.releases)))
    put("load_factor", check_value("load_factor", scene.load_factor, parameters.LOAD_FACTOR))
    if (scene.load is None) == (scene.body is None):
        raise StabmapError(_ONE_LOAD)
    if scene.load is not None:
        if not isinstance(scene.load, Load):
            raise StabmapError(f"load must be a Load(F, M), got {scene.load!r}")
        put("load", Load(_vector(scene.load.F, "load.F"), _vector(scene.load.M, "load.M")))
    else:
        put("body", _checked_body(scene.body))
    put("grid", tuple(scene.grid))
    check_axes(scene.grid, scene.parameter)
    _check_directions(scene)
    _check_distinct_on_grid(scene)


def _checked_body(b: object) -> Body:
    if not isinstance(b, Body):
        raise StabmapError(f"body must be a Body(mass, ...), got {b!r}")
    mass = check_value("body.mass", b.mass, parameters.MASS)
    vectors = {key: _vector(getattr(b, key), f"body.{key}") for key in ("centre", "gravity", "acceleration", "alpha")}
    vectors["omega"] = _vector(b.omega, "body.omega", parameters.BODY_VECTORS["omega"])  # rad/s, or rpm and Hz
    raw = b.inertia
    if isinstance(raw, (str, bytes)) or not hasattr(raw, "__len__") or len(raw) != 3:
        raise StabmapError(f"body.inertia must be 3 principal moments [Ixx, Iyy, Izz] or a 3x3 tensor [kg m2], got {raw!r}")
    rows: list[Sequence[float]]
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in raw):
        rows = [[check_value(f"body.inertia[{d}]", v, _ANY) if e == d else 0.0 for e in range(3)] for d, v in enumerate(raw)]
    else:
        rows = [_vector(row, f"body.inertia[{d}]") for d, row in enumerate(raw)]
    I = np.array(rows, dtype=np.float64)
    size = float(np.abs(I).max())
    if np.abs(I - I.T).max() > 1e-12 * size:
        raise StabmapError("body.inertia must be symmetric (I[i][j] = I[j][i]); give the tensor about the centre of mass")
    if size and np.linalg.eigvalsh((I + I.T) / 2).min() < -1e-12 * size:
        raise StabmapError("body.inertia has a negative principal moment; an inertia tensor is positive semi-definite")
    r0, r1, r2 = ((float(x), float(y), float(z)) for x, y, z in I.tolist())
    return Body(mass=mass, inertia=(r0, r1, r2), **vectors)


def _check_directions(scene: Scene) -> None:
    """A vector is scanned by its components or by its direction, not both; a direction needs a nonzero vector."""
    names = {a.name: scene.key(a.name) for a in scene.grid}
    angles = {key[1] for key in names.values() if key[0] == "angle"}
    for name, key in names.items():
        if key[0] == "vector" and key[1] in angles:
            raise StabmapError(
                f"grid axis {name!r}: {key[1]} is also scanned by its direction ({key[1]}_azimuth/{key[1]}_elevation); "
                "scan its components or its direction, not both"
            )
    for prefix in angles:
        what = "load.F" if prefix == "F" else "body.gravity"
        x, y, z = scene.vectors[prefix]
        if not (x or y or z):
            raise StabmapError(f"grid axis {prefix}_azimuth/{prefix}_elevation turns {what}, which is zero; give {what} a magnitude")
        if not (x or y) and (prefix, "elevation") not in {key[1:] for key in names.values() if key[0] == "angle"}:
            raise StabmapError(
                f"grid axis {prefix}_azimuth has no effect: {what} is vertical (elevation {'+' if z > 0 else '-'}90 degrees); "
                f"scan {prefix}_elevation as well, or tilt {what}"
            )


def _check_distinct_on_grid(scene: Scene) -> None:
    """No grid point puts two nodes at one point (a scanned coordinate crossing another node's)."""
    values = {}
    for a in scene.grid:
        key = scene.key(a.name)
        if key[0] == "node":
            values[key[1:]] = (a.name, set(a.values))
    if not values:
        return
    for i in range(scene.n):
        for j in range(i + 1, scene.n):
            meet = []
            for d in range(3):
                vi = values.get((i, d), (None, {scene.nodes[i][d]}))
                vj = values.get((j, d), (None, {scene.nodes[j][d]}))
                common = vi[1] & vj[1]
                if not common:
                    break
                meet.append((vi[0] or vj[0], min(common)))
            else:
                where = ", ".join(f"{name} = {v:g}" for name, v in meet if name)
                raise StabmapError(
                    f"grid: at {where} nodes {i} and {j} are at the same point; choose grid values that keep the "
                    "nodes apart (e.g. an even number of points across the other node's coordinate)"
                )


def fixed_values(scene: Scene) -> dict[str, float]:
    """Every scalar parameter of the scene that is not a grid axis, by its scannable name."""
    keys = {scene.key(a.name) for a in scene.grid}
    out = {}
    for k, p in enumerate(scene.nodes):
        for d, axis in enumerate(parameters.AXES):
            if ("node", k, d) not in keys:
                out[f"{axis}_{k}"] = p[d]
    angled = {key[1] for key in keys if key[0] == "angle"}
    for prefix, v in scene.vectors.items():
        if prefix in angled:
            azimuth, elevation = angles(v)
            for which, value in (("azimuth", azimuth), ("elevation", elevation)):
                if ("angle", prefix, which) not in keys:
                    out[f"{prefix}_{which}"] = value
            continue
        for d, axis in enumerate(parameters.AXES):
            if ("vector", prefix, d) not in keys:
                out[f"{prefix}_{axis}"] = v[d]
    if scene.body is not None and ("mass",) not in keys:
        out["mass"] = scene.body.mass
    if ("load_factor",) not in keys:
        out["load_factor"] = scene.load_factor
    return out


def angles(v) -> tuple[float, float]:
    """Azimuth (from x towards y) and elevation (above the xy-plane) of a vector [degree]."""
    x, y, z = v
    return float(np.degrees(np.arctan2(y, x))), float(np.degrees(np.arctan2(z, np.hypot(x, y))))


__all__ = ["Body", "Load", "Release", "Scene", "angles", "fixed_values", "from_dict"]
