"""Registry of the parameter names a scene can set and a grid can scan.

Names are API: they are the TOML keys, the grid axis names, the Dataset
dimension names and the CLI query keys.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

from ...errors import StabmapError
from ...kernels.layout import BODY_COLUMNS as BODY_COLUMNS  # the scenes name the columns as the kernels do (points.py)
from ...scene.values import Parameter, did_you_mean

BODY = {
    "m": Parameter("m", "kg", "mass of body {k} (liquid included)", 0.0, True),
    "A": Parameter("A", "kg m2", "equatorial moment of inertia of body {k} about its centre of mass", 0.0, True),
    "C": Parameter("C", "kg m2", "axial moment of inertia of body {k}", 0.0, False),
    "c": Parameter("c", "m", "distance from the lower joint of body {k} to its centre of mass", None, False),
    "s": Parameter("s", "m", "distance between the lower and upper joints of body {k}", 0.0, False),
    "omega": Parameter("omega", "rad s-1", "spin rate of body {k}", None, False),
}
JOINT = Parameter("K", "N m rad-1", "stiffness of joint {k}", 0.0, False)
BASE = Parameter("K", "N m rad-1", "stiffness of the base joint", 0.0, False)
# A tree (scene [topology]): where body k's joint sits on its parent's axis, up positive.
POSITION = Parameter("at", "m", "position of the joint of body {k} on its parent's axis", None, False)
CAVITY = {
    "radius": Parameter("a", "m", "radius (equatorial semi-axis) of the cavity of body {k}", 0.0, True),
    "half_height": Parameter("c", "m", "half height of the cavity of body {k} (half a cylinder's length, a spheroid's polar semi-axis)", 0.0, True),
    "density": Parameter("rho", "kg m-3", "density of the liquid in the cavity of body {k}", 0.0, True),
    # a viscous liquid (docs/viscous.md): kinematic, as the Reynolds number omega a^2 / nu takes it
    "viscosity": Parameter("nu", "m2 s-1", "kinematic viscosity of the liquid in the cavity of body {k}", 0.0, True),
    "centre": Parameter("z", "m", "height of the cavity centre above the lower joint of body {k}", None, False),
    "E": Parameter("E", "kg m2", "inertia coefficient of a liquid mode", 0.0, True),
    "kappa": Parameter("kappa", "1", "frequency parameter of a liquid mode", None, False),
}
SCANNABLE_CAVITY = ("radius", "half_height", "density")  # the sizes that give an ideal cavity its modes
EVERY_BODY = ("m", "A", "C", "c", "s")  # grid axes that set one parameter of every body at once (identical bodies)
# A projectile (docs/projectile.md): an aerodynamic overturning moment on body 1 about a fixed point at its centre
# of mass, and the gyroscopic stability factor it gives, S_g = C_1^2 omega_1^2 / (4 A_1 M_alpha).
PROJECTILE = {
    "M_alpha": Parameter("M_alpha", "N m rad-1", "aerodynamic overturning moment coefficient of body 1 about its centre of mass", None, False),
    "S_g": Parameter("S_g", "1", "gyroscopic stability factor of body 1", 0.0, True),  # C^2 omega^2 / (4 A M_alpha)
}
# Dimensionless axes (``ratios``): each moves one underlying quantity, the scene's [hold] says which is held.
RATIO = {
    "C_over_A": Parameter("C/A", "1", "ratio of the axial to the equatorial moment of inertia of body {k}", 0.0, False),
    "aspect": Parameter("h/a", "1", "aspect ratio of the cavity of body {k}: height (twice half_height) over radius", 0.0, True),
}
GLOBAL = {
    "omega": Parameter("omega", "rad s-1", "common spin rate", None, False),
    "g": Parameter("g", "m s-2", "gravitational acceleration", None, False),
}

_NAME = re.compile(r"^(m|A|C|c|s|omega|K|at|radius|half_height|density|viscosity|C_over_A|aspect)_(\d+)$")


@dataclass(frozen=True)
class Name:
    """A parsed parameter name: kind is 'global', 'body', 'cavity', 'joint', 'position', 'every_body', 'every_joint',
    'projectile' (M_alpha, S_g) or 'ratio' (C_over_A_k, aspect_k).

    index is 1-based (K: 0 = base); 0 for the common axes of every body (``m``, ``A``, ``C``, ``c``, ``s``)
    and of every joint between bodies (``K``, which leaves the base joint K_0 alone).
    """

    name: str
    kind: str
    symbol: str
    index: int

    @property
    def info(self) -> Parameter:
        if self.kind == "global":
            return GLOBAL[self.symbol]
        if self.kind == "projectile":
            return PROJECTILE[self.symbol]
        if self.kind == "ratio":
            return RATIO[self.symbol]
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

    @property
    def parameter(self) -> Parameter:
        """The parameter of this name, its long name saying which body or joint."""
        return replace(self.info, long_name=self.long_name)


def parse_name(name: str, n_bodies: int, support: str) -> Name:
    """Parse and check a scannable parameter name such as ``omega``, ``m_2`` or ``K_1``."""
    if name in GLOBAL:
        if name == "g" and support == "free":
            raise StabmapError("grid axis 'g' has no effect with support = \"free\" (gravity exerts no torque about the centre of mass); remove it")
        return Name(name, "global", name, 0)
    if name in PROJECTILE:
        if support == "free":
            raise StabmapError(
                f"{name!r}: M_alpha acts about a fixed point at body 1's centre of mass; use support = \"fixed\" with "
                "bodies[1].c = 0 (a single body in flight moves about its centre of mass as on a fixed point there)"
            )
        return Name(name, "projectile", name, 0)
    if name in EVERY_BODY:
        return Name(name, "every_body", name, 0)
    if name == "K":
        if n_bodies < 2:
            raise StabmapError("grid axis 'K' (every joint) needs two or more bodies; a single body has no joint between bodies")
        return Name(name, "every_joint", name, 0)
    match = _NAME.match(name)
    if not match:
        known = [*GLOBAL, *PROJECTILE, *EVERY_BODY, "K"] + [f"K_{k}" for k in range(n_bodies)] + [
            f"{sym}_{k}" for sym in ("m", "A", "C", "c", "s", "omega", "at", *CAVITY, *RATIO) for k in range(1, n_bodies + 1)]
        raise StabmapError(
            f"unknown parameter name {name!r}; {did_you_mean(name, known)}scannable names are omega, g, "
            "m_k A_k C_k c_k s_k omega_k C_over_A_k (body k = 1..n), radius_k half_height_k density_k aspect_k "
            "viscosity_k (the cavity of body k), K_k (joint k, K_0 the base), at_k (a tree's joint positions), M_alpha S_g "
            "(a projectile), and m A C c s K for every body or joint at once"
        )
    symbol, index = match.group(1), int(match.group(2))
    if symbol == "K":
        if index == 0 and support == "free":
            raise StabmapError(f"{name!r}: a free system has no base joint; K_0 is for support = \"fixed\"")
        if index > n_bodies - 1:
            joints = ("no joint between bodies" if n_bodies == 1 else "one joint, K_1, between its bodies" if n_bodies == 2
                      else f"joints K_1..K_{n_bodies - 1} between its bodies")
            raise StabmapError(
                f"{name!r}: a chain of {n_bodies} bod{'y' if n_bodies == 1 else 'ies'} has {joints} (and K_0 at a fixed base); "
                "in a tree, K_k is the joint of body k+1 with its parent"
            )
        return Name(name, "joint", symbol, index)
    if not 1 <= index <= n_bodies:
        raise StabmapError(f"{name!r}: bodies are numbered 1..{n_bodies}")
    if symbol == "at":
        if index == 1:
            raise StabmapError(f"{name!r}: body 1's joint is the base point (or a free system's reference point); it has no position to scan")
        return Name(name, "position", symbol, index)
    if symbol in RATIO:
        return Name(name, "ratio", symbol, index)
    return Name(name, "cavity" if symbol in CAVITY else "body", symbol, index)
