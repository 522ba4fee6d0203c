"""The names a reactions scene can scan (grid axes) and their units.

Names are API: grid axes, Dataset dimensions, scalar coordinates and query keys.

- ``x_k``, ``y_k``, ``z_k``: coordinates of node k (0-based, as in ``releases``);
- a scene with an explicit ``[load]``: ``F_x`` ... ``M_z`` (components), ``F_azimuth`` and ``F_elevation`` (the
  direction of F, its magnitude kept);
- a scene with a ``[body]`` whose motion makes the load: ``mass``, ``c_x`` ... (centre of mass), ``g_x`` ...
  (gravity), ``a_x`` ... (acceleration of the nodes' origin), ``omega_x`` ... (angular velocity), ``alpha_x`` ...
  (angular acceleration), ``g_azimuth`` and ``g_elevation`` (the direction of gravity, its magnitude kept);
- either: ``load_factor``, a factor on the whole load (its magnitude).
"""

from __future__ import annotations

import re

from ...errors import StabmapError
from ...scene.values import Parameter, did_you_mean

AXES = ("x", "y", "z")
NODE = Parameter("x", "m", "{axis} coordinate of node {k}")
# Vectors of the two ways to give a load, by the prefix of their component names.
LOAD_VECTORS = {
    "F": Parameter("F", "N", "{axis} component of the main vector F of the load"),
    "M": Parameter("M", "N m", "{axis} component of the main moment M of the load about the nodes' origin"),
}
BODY_VECTORS = {
    "c": Parameter("c", "m", "{axis} coordinate of the body's centre of mass"),
    "g": Parameter("g", "m s-2", "{axis} component of the gravitational acceleration"),
    "a": Parameter("a", "m s-2", "{axis} component of the acceleration of the nodes' origin"),
    "omega": Parameter("omega", "rad s-1", "{axis} component of the body's angular velocity"),
    "alpha": Parameter("alpha", "rad s-2", "{axis} component of the body's angular acceleration"),
}
MASS = Parameter("m", "kg", "mass of the body", 0.0, False)
LOAD_FACTOR = Parameter("load_factor", "1", "factor on the whole load (F and M)", None, False)
# The direction of one vector as two angles, its magnitude kept: F of a [load], gravity of a [body].
ANGLES = {
    "azimuth": Parameter("azimuth", "degree", "azimuth of {v} (from x towards y)"),
    "elevation": Parameter("elevation", "degree", "elevation of {v} above the xy-plane (towards z)"),
}
DIRECTED = {"load": ("F", "the main vector F of the load"), "body": ("g", "gravity")}

_NODE = re.compile(r"^([xyz])_(\d+)$")
_VECTOR = re.compile(r"^([A-Za-z]+)_([xyz])$")
_ANGLE = re.compile(r"^([A-Za-z]+)_(azimuth|elevation)$")


def parse(name: str, n_nodes: int, kind: str) -> tuple[tuple, Parameter]:
    """A scannable name -> (key, parameter); ``kind`` is "load" or "body" (how the scene gives its load).

    Keys: ``("node", k, d)``, ``("vector", prefix, d)``, ``("angle", prefix, "azimuth" | "elevation")``,
    ``("mass",)``, ``("load_factor",)``; d is the component 0, 1, 2.
    """
    vectors = LOAD_VECTORS if kind == "load" else BODY_VECTORS
    directed, what = DIRECTED[kind]
    if name == "load_factor":
        return ("load_factor",), LOAD_FACTOR
    if name == "mass" and kind == "body":
        return ("mass",), MASS
    m = _NODE.match(name)
    if m:
        k, axis = int(m.group(2)), m.group(1)
        if k >= n_nodes:
            raise StabmapError(f"grid axis {name!r}: node {k} does not exist; the nodes are numbered 0..{n_nodes - 1}")
        return ("node", k, AXES.index(axis)), Parameter(f"{axis}_{k}", NODE.units, NODE.long_name.format(axis=axis, k=k))
    m = _VECTOR.match(name)
    if m and m.group(1) in vectors:
        info = vectors[m.group(1)]
        return ("vector", m.group(1), AXES.index(m.group(2))), Parameter(name, info.units, info.long_name.format(axis=m.group(2)))
    m = _ANGLE.match(name)
    if m and m.group(1) == directed:
        info = ANGLES[m.group(2)]
        return ("angle", directed, m.group(2)), Parameter(name, info.units, info.long_name.format(v=what))
    other = "body" if kind == "load" else "load"
    other_vectors = BODY_VECTORS if kind == "load" else LOAD_VECTORS
    if name == "mass" or (m and m.group(1) in other_vectors) or name.startswith(DIRECTED[other][0] + "_"):
        raise StabmapError(
            f"grid axis {name!r} belongs to a scene whose load is given by a [{other}] table; this scene gives "
            f"a [{kind}] table: {_names(kind)}"
        )
    vectors = LOAD_VECTORS if kind == "load" else BODY_VECTORS
    known = [f"{p}_{a}" for p in vectors for a in AXES] + [f"{DIRECTED[kind][0]}_{a}" for a in ANGLES] + ["load_factor"]
    known += ["mass"] if kind == "body" else []
    raise StabmapError(f"unknown parameter name {name!r}; {did_you_mean(name, known)}a reactions scene with a [{kind}] table "
                       f"scans {_names(kind)}")


def _names(kind: str) -> str:
    vectors = LOAD_VECTORS if kind == "load" else BODY_VECTORS
    directed = DIRECTED[kind][0]
    parts = ["x_k y_k z_k (node k)", " ".join(f"{p}_x {p}_y {p}_z" for p in vectors), f"{directed}_azimuth {directed}_elevation [degree]"]
    if kind == "body":
        parts.append("mass")
    return ", ".join(parts + ["load_factor"])
