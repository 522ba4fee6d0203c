"""Registry of the parameter names a scene can set and a grid can scan.

Names are API: they are the TOML keys, the grid axis names, the Dataset
dimension names and the CLI query keys.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from .errors import StabmapError


@dataclass(frozen=True)
class ParameterInfo:
    symbol: str
    units: str
    long_name: str
    minimum: float | None  # None: any finite value
    strict: bool  # minimum excluded


BODY = {
    "m": ParameterInfo("m", "kg", "mass of body {k} (liquid included)", 0.0, True),
    "A": ParameterInfo("A", "kg m2", "equatorial moment of inertia of body {k} about its centre of mass", 0.0, True),
    "C": ParameterInfo("C", "kg m2", "axial moment of inertia of body {k}", 0.0, False),
    "c": ParameterInfo("c", "m", "distance from the lower joint of body {k} to its centre of mass", None, False),
    "s": ParameterInfo("s", "m", "distance between the lower and upper joints of body {k}", 0.0, False),
    "omega": ParameterInfo("omega", "rad s-1", "spin rate of body {k}", None, False),
}
BODY_COLUMNS = ("m", "A", "C", "c", "s", "omega")  # column order of the kernels' body array
JOINT = ParameterInfo("K", "N m rad-1", "stiffness of joint {k}", 0.0, False)
BASE = ParameterInfo("K", "N m rad-1", "stiffness of the base joint", 0.0, False)
# A tree (scene [topology]): where body k's joint sits on its parent's axis, up positive.
POSITION = ParameterInfo("at", "m", "position of the joint of body {k} on its parent's axis", None, False)
CAVITY = {
    "radius": ParameterInfo("a", "m", "radius (equatorial semi-axis) of the cavity of body {k}", 0.0, True),
    "half_height": ParameterInfo("c", "m", "half height (polar semi-axis) of the cavity of body {k}", 0.0, True),
    "density": ParameterInfo("rho", "kg m-3", "density of the liquid in the cavity of body {k}", 0.0, True),
    "centre": ParameterInfo("z", "m", "height of the cavity centre above the lower joint of body {k}", None, False),
    "E": ParameterInfo("E", "kg m2", "inertia coefficient of a liquid mode", 0.0, True),
    "kappa": ParameterInfo("kappa", "1", "frequency parameter of a liquid mode", None, False),
}
SCANNABLE_CAVITY = ("radius", "half_height", "density")
EVERY_BODY = ("m", "A", "C", "c", "s")  # grid axes that set one parameter of every body at once (identical bodies)
GLOBAL = {
    "omega": ParameterInfo("omega", "rad s-1", "common spin rate", None, False),
    "g": ParameterInfo("g", "m s-2", "gravitational acceleration", None, False),
}

_NAME = re.compile(r"^(m|A|C|c|s|omega|K|at|radius|half_height|density)_(\d+)$")


@dataclass(frozen=True)
class Name:
    """A parsed parameter name: kind is 'global', 'body', 'cavity', 'joint', 'position', 'every_body' or 'every_joint'.

    index is 1-based (K: 0 = base); 0 for the common axes of every body (``m``, ``A``, ``C``, ``c``, ``s``)
    and of every joint between bodies (``K``, which leaves the base joint K_0 alone).
    """

    name: str
    kind: str
    symbol: str
    index: int

    @property
    def info(self) -> ParameterInfo:
        if self.kind == "global":
            return GLOBAL[self.symbol]
        if self.kind in ("joint", "every_joint"):
            return BASE if self.kind == "joint" and self.index == 0 else JOINT
        if self.kind == "cavity":
            return CAVITY[self.symbol]
        if self.kind == "position":
            return POSITION
        return BODY[self.symbol]

    @property
    def units(self) -> str:
        return self.info.units

    @property
    def long_name(self) -> str:
        if self.kind == "every_body":
            return self.info.long_name.replace("body {k}", "every body")
        if self.kind == "every_joint":
            return "stiffness of every joint between bodies (K_1..K_n-1)"
        return self.info.long_name.format(k=self.index)


def parse_name(name: str, n_bodies: int, support: str) -> Name:
    """Parse and check a scannable parameter name such as ``omega``, ``m_2`` or ``K_1``."""
    if name in GLOBAL:
        if name == "g" and support == "free":
            raise StabmapError("grid axis 'g' has no effect with support = \"free\" (gravity exerts no torque about the centre of mass); remove it")
        return Name(name, "global", name, 0)
    if name in EVERY_BODY:
        return Name(name, "every_body", name, 0)
    if name == "K":
        if n_bodies < 2:
            raise StabmapError("grid axis 'K' (every joint) needs two or more bodies; a single body has no joint between bodies")
        return Name(name, "every_joint", name, 0)
    match = _NAME.match(name)
    if not match:
        raise StabmapError(
            f"unknown parameter name {name!r}; scannable names are omega, g, "
            "m_k A_k C_k c_k s_k omega_k (body k = 1..n), radius_k half_height_k density_k (the cavity "
            "of body k), K_k (joint k, K_0 the base), at_k (a tree's joint positions), and m A C c s K "
            "for every body or joint at once"
        )
    symbol, index = match.group(1), int(match.group(2))
    if symbol == "K":
        if index == 0 and support == "free":
            raise StabmapError(f"{name!r}: a free system has no base joint; K_0 is for support = \"fixed\"")
        if index > n_bodies - 1:
            raise StabmapError(
                f"{name!r}: a chain of {n_bodies} bodies has joints K_1..K_{n_bodies - 1} (and K_0 at a fixed base); "
                "in a tree, K_k is the joint of body k+1 with its parent"
            )
        return Name(name, "joint", symbol, index)
    if not 1 <= index <= n_bodies:
        raise StabmapError(f"{name!r}: bodies are numbered 1..{n_bodies}")
    if symbol == "at":
        if index == 1:
            raise StabmapError(f"{name!r}: body 1's joint is the base point (or a free system's reference point); it has no position to scan")
        return Name(name, "position", symbol, index)
    return Name(name, "cavity" if symbol in CAVITY else "body", symbol, index)


def check_value(where: str, value, info: ParameterInfo) -> float:
    """Return ``value`` as a float or raise a StabmapError naming ``where``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise StabmapError(f"{where} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise StabmapError(f"{where} must be finite, got {value}")
    if info.minimum is not None:
        if info.strict and value <= info.minimum:
            raise StabmapError(f"{where} must be > {info.minimum:g}, got {value}")
        if not info.strict and value < info.minimum:
            raise StabmapError(f"{where} must be >= {info.minimum:g}, got {value}")
    return value
