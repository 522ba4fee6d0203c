"""Scenes of gyroscopes: a chain or a tree of bodies, its support and the grid to scan.

``Scene`` validates itself when it is made (``__post_init__``), so a scene
built in Python gets the same checks and messages as one read from TOML;
``from_dict`` only turns the TOML layout into the dataclasses, and ``to_dict``
turns them back.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ...errors import StabmapError
from ...scene.grid import Axis, check_axes, parse_axes
from ...scene.values import Parameter, check_value, no_unknown
from ..base import SceneBase
from . import liquid, ratios
from .liquid import Cavity
from .parameters import BASE, BODY, EVERY_BODY, GLOBAL, JOINT, PROJECTILE, SCANNABLE_CAVITY, parse_name
from .ratios import Hold
from .topology import Topology

SUPPORTS = ("fixed", "free")
DEFAULT_G = 9.81
_G_FREE = 'g: gravity exerts no torque about a free system\'s centre of mass and would be ignored; remove g or use support = "fixed"'
_TOP_KEYS = {"title", "support", "g", "omega", "joints", "K_0", "M_alpha", "hold", "topology", "bodies", "grid", "growth_rate", "frequencies"}
_TOPOLOGY_KEYS = {"parent", "at"}
_BODY_KEYS = {"m", "A", "C", "c", "s", "omega", "fluid", "cavity"}
_FLUID_KEYS = {"E", "kappa"}
_KAPPA = Parameter("kappa", "1", "")
_E = Parameter("E", "kg m2", "", 0.0, False)


@dataclass(frozen=True)
class Body:
    """One Lagrange gyroscope; lengths [m], masses [kg], inertias [kg m^2], rates [rad/s]."""

    m: float
    A: float
    C: float
    c: float
    s: float = 0.0
    omega: float | None = None  # None: the scene's common omega
    E: tuple[float, ...] = ()  # retained liquid modes [kg m^2]
    kappa: tuple[float, ...] = ()  # their frequency parameters [1]; lambda_l = 2 omega / kappa_l
    cavity: Cavity | None = None  # modes from geometry or a table, after the explicit ones


@dataclass(frozen=True)
class Scene(SceneBase):
    """n bodies and the grid of parameters to scan.

    Without ``topology`` the bodies form a chain, body 1 at the bottom, body k + 1
    on body k at s_k.  With it they form a tree (docs/trees.md): body k is mounted
    on body parent[k - 1] at at[k - 1] on that body's axis, and s is not used.
    Either way K_0 is the joint of body 1 with the base and K_k (k >= 1) the joint
    of body k + 1 with the body it is mounted on.
    """

    bodies: tuple[Body, ...]
    support: str = "fixed"
    omega: float | None = None
    g: float = DEFAULT_G
    joints: tuple[float, ...] = ()  # K_1..K_{n-1} [N m/rad]; empty = ideal joints
    K_0: float = 0.0  # base stiffness (fixed support)
    title: str = ""
    grid: tuple[Axis, ...] = field(default=())
    topology: Topology | None = None  # None: a chain
    M_alpha: float | None = None  # aerodynamic overturning moment on body 1 about its centre of mass [N m/rad]
    hold: Hold = field(default_factory=Hold)  # what the ratio axes (S_g, C_over_A_k, aspect_k) hold
    growth_rate: bool = True  # store growth_rate and its kin per point (docs/rates.md)
    frequencies: bool = False  # store every root's real part on a ``root`` dimension (docs/rates.md)

    def __post_init__(self):
        _validate(self)

    @property
    def system(self) -> str:
        """A scene whose liquid is viscous belongs to the ``viscous`` system (docs/viscous.md): its label differs."""
        return "viscous" if self.viscous else "gyroscopes"

    @property
    def viscous(self) -> bool:
        return any(b.cavity is not None and b.cavity.viscous for b in self.bodies)

    @property
    def n(self) -> int:
        return len(self.bodies)

    @property
    def free(self) -> bool:
        return self.support == "free"

    @property
    def nmodes(self) -> np.ndarray:
        return np.array([len(b.E) + liquid.n_modes(b.cavity) for b in self.bodies], dtype=np.int64)

    @property
    def degree(self) -> int:
        """Degree bound sum_k (2 + L_k) of the characteristic polynomial."""
        return int(2 * self.n + self.nmodes.sum())

    def joint_stiffness(self) -> tuple[float, ...]:
        """K_1..K_{n-1}, zeros where the scene leaves them out."""
        return tuple(self.joints) if self.joints else (0.0,) * (self.n - 1)

    def parameter(self, name: str) -> Parameter:
        """The parameter a grid axis called ``name`` scans, or a StabmapError saying why it cannot be scanned."""
        return _axis_name(name, self.n, self.support, self.topology is not None).parameter

    @classmethod
    def from_dict(cls, table: dict, base_dir: str | Path | None = None) -> Scene:
        return from_dict(table, base_dir)

    def fixed_values(self) -> dict[str, float]:
        return fixed_values(self)

    def notes(self) -> list[tuple[str, str]]:
        """The liquid of each body for ``stabmap info``, as (``"body k"``, text): the modes given (E [kg m^2],
        kappa [1]) and what a cavity chose for itself that the file does not state (the modes it keeps)."""
        out = []
        for k, b in enumerate(self.bodies, start=1):
            if b.E:
                n = len(b.E)
                out.append((f"body {k}", f"liquid, {n} mode{'s' if n > 1 else ''} given: E = {', '.join(f'{e:g}' for e in b.E)} "
                                         f"kg m2, \u03ba = {', '.join(f'{v:g}' for v in b.kappa)}"))
            if b.cavity is not None:
                out.append((f"body {k}", liquid.describe(b.cavity)))
        return out

    def unused(self) -> list[str]:
        """Notes on values the scene gives that the model does not use: ``s`` on the top body of a chain (it has no
        joint above it; docs/model.md).  Not refused: a chain of identical bodies is naturally written with s on each."""
        top = self.bodies[-1]
        if self.topology is not None or top.s == 0.0 or "s" in {a.name for a in self.grid}:
            return []
        n = self.n
        what = "a single body has" if n == 1 else f"body {n} is the top of the chain and has"
        return [f"note: bodies[{n}].s = {top.s:g} is not used: {what} no joint above it (s is the distance from a body's "
                "lower joint to the joint of the body above it)"]

    def with_grid(self, grid: tuple[Axis, ...]) -> Scene:
        # modes = "auto" chose its count from this grid's extremes; a subset keeps that count, and so its labels.
        bodies = tuple(b if b.cavity is None or b.cavity.modes != liquid.AUTO
                       else replace(b, cavity=replace(b.cavity, modes=b.cavity.kept, mode_tolerance=None)) for b in self.bodies)
        return replace(self, bodies=bodies, grid=tuple(grid))

    def to_dict(self) -> dict:
        out: dict[str, object] = {"title": self.title, "support": self.support}
        if not self.free:
            out["g"] = self.g
        if self.omega is not None:
            out["omega"] = self.omega
        out["joints"] = list(self.joint_stiffness())
        if not self.free:
            out["K_0"] = self.K_0
        if self.M_alpha is not None:
            out["M_alpha"] = self.M_alpha
        if self.hold != Hold():
            out["hold"] = self.hold.to_dict()
        if self.topology is not None:
            out["topology"] = {"parent": list(self.topology.parent), "at": list(self.topology.at)}
        bodies = []
        for b in self.bodies:
            body: dict[str, object] = {"m": b.m, "A": b.A, "C": b.C, "c": b.c}
            if self.topology is None:
                body["s"] = b.s
            if b.omega is not None:
                body["omega"] = b.omega
            if b.E:
                body["fluid"] = {"E": list(b.E), "kappa": list(b.kappa)}
            if b.cavity is not None:
                body["cavity"] = b.cavity.to_dict()
            bodies.append(body)
        out["bodies"] = bodies
        if self.grid:
            out["grid"] = {a.name: a.to_dict() for a in self.grid}
        if not self.growth_rate:
            out["growth_rate"] = False
        if self.frequencies:
            out["frequencies"] = True
        return out


# ---------------------------------------------------------------------------------------------------- TOML layout
def from_dict(data: dict, base_dir: str | Path | None = None) -> Scene:
    """The scene of a TOML table; the layout is checked here, every value by ``Scene`` itself."""
    no_unknown(data, _TOP_KEYS, "scene")
    raw_bodies = data.get("bodies")
    if not isinstance(raw_bodies, list) or not raw_bodies:
        raise StabmapError("bodies is missing: add at least one [[bodies]] table (body 1 at the bottom)")
    n = len(raw_bodies)
    tree = _topology(data["topology"], n) if "topology" in data else None
    base_dir = None if base_dir is None else Path(base_dir)
    bodies = tuple(_body(raw, k + 1, n, base_dir, tree is not None) for k, raw in enumerate(raw_bodies))
    joints = data.get("joints", [])
    if not isinstance(joints, list):
        raise StabmapError(f"joints must be a list of stiffnesses K_1..K_{n - 1}, got {joints!r}")
    support = data.get("support", "fixed")
    tree_flag = tree is not None
    grid = parse_axes(data.get("grid", {}), lambda name: _axis_name(name, n, support, tree_flag).parameter)
    if support == "free" and "g" in data:
        raise StabmapError(_G_FREE)
    scalars = {k: data[k] for k in ("support", "omega", "g", "K_0", "M_alpha", "title", "growth_rate", "frequencies") if k in data}
    if "hold" in data:
        scalars["hold"] = ratios.parse_hold(data["hold"])
    return Scene(bodies=bodies, joints=tuple(joints), grid=grid, topology=tree, **scalars)


def _topology(raw: dict, n: int) -> Topology:
    """The ``[topology]`` table: the parent of each body and the position of its joint on the parent's axis."""
    no_unknown(raw, _TOPOLOGY_KEYS, "topology")
    for key, example in (("parent", "parent = [0, 1, 1] (0: the base)"), ("at", "at = [0.0, 0.3, 0.3] (0 for body 1)")):
        if key not in raw:
            what = "the parent of each body" if key == "parent" else "the position of each body's joint on its parent's axis [m]"
            raise StabmapError(f"topology.{key} is missing: give {what}, one per [[bodies]] table, e.g. {example}")
        if not isinstance(raw[key], list) or len(raw[key]) != n:
            got = f"{len(raw[key])} values" if isinstance(raw[key], list) else repr(raw[key])
            raise StabmapError(f"topology.{key} must be a list with one value per body ({n} [[bodies]] tables), got {got}")
    return Topology(parent=tuple(raw["parent"]), at=tuple(raw["at"]))


def _body(raw: dict, k: int, n: int, base_dir: Path | None, tree: bool) -> Body:
    where = f"bodies[{k}]"
    if isinstance(raw, dict) and "M_alpha" in raw:
        raise StabmapError(f"{where}.M_alpha: M_alpha is a top-level key and acts on body 1, about its centre of mass "
                           "(the fixed point); move it out of [[bodies]]")
    no_unknown(raw, _BODY_KEYS, where)
    values = {}
    for key in ("m", "A", "C", "c", "s"):
        if key in raw:
            values[key] = raw[key]
        elif key != "s" or not (k == n or tree):  # the top body has no upper joint; a tree's joints sit at topology.at
            raise StabmapError(f"{where}.{key} is missing ({BODY[key].long_name.format(k=k)} [{BODY[key].units}])")
    if "omega" in raw:
        values["omega"] = raw["omega"]
    if "fluid" in raw:
        fluid = raw["fluid"]
        no_unknown(fluid, _FLUID_KEYS, f"{where}.fluid")
        E, kappa = fluid.get("E", []), fluid.get("kappa", [])
        if not isinstance(E, list) or not isinstance(kappa, list):
            raise StabmapError(f"{where}.fluid: E and kappa must be lists of numbers")
        values["E"], values["kappa"] = tuple(E), tuple(kappa)
    if "cavity" in raw:
        values["cavity"] = liquid.parse(raw["cavity"], f"{where}.cavity", base_dir)
    return Body(**values)


# ------------------------------------------------------------------------------------------------------ the checks
def _validate(scene: Scene) -> None:
    """Check every value of ``scene`` and store the normalised ones (floats, tuples); errors name the TOML key."""

    def put(name, value):
        object.__setattr__(scene, name, value)

    if scene.support not in SUPPORTS:
        raise StabmapError(f'support must be "fixed" or "free", got {scene.support!r}')
    if not isinstance(scene.bodies, (tuple, list)) or not scene.bodies or not all(isinstance(b, Body) for b in scene.bodies):
        raise StabmapError("bodies is missing: add at least one [[bodies]] table (body 1 at the bottom)")
    n, tree = len(scene.bodies), scene.topology
    if tree is not None and (not isinstance(tree, Topology) or tree.n != n):
        raise StabmapError(f"topology must be a Topology with one parent and one position per body ({n} bodies)")
    put("bodies", tuple(_checked_body(b, k + 1, tree is not None) for k, b in enumerate(scene.bodies)))
    if not isinstance(scene.title, str):
        raise StabmapError(f"title must be a string, got {scene.title!r}")
    for key in ("growth_rate", "frequencies"):
        if not isinstance(getattr(scene, key), bool):
            raise StabmapError(f"{key} must be true or false (whether the atlas stores it; docs/rates.md), got {getattr(scene, key)!r}")
    if scene.omega is not None:
        put("omega", check_value("omega", scene.omega, GLOBAL["omega"]))
    put("g", check_value("g", scene.g, GLOBAL["g"]))
    if scene.free and scene.g != DEFAULT_G:
        raise StabmapError(_G_FREE)
    joints = tuple(scene.joints)
    if joints and len(joints) != n - 1:
        raise StabmapError(_joints_count(len(joints), n, tree is not None))
    put("joints", tuple(check_value(f"joints[{i + 1}] (K_{i + 1})", v, JOINT) for i, v in enumerate(joints)))
    K_0 = check_value("K_0", scene.K_0, BASE)
    if K_0 and scene.free:
        raise StabmapError('K_0: a free system has no base joint; remove K_0 or use support = "fixed"')
    put("K_0", K_0)
    if scene.M_alpha is not None:
        put("M_alpha", check_value("M_alpha", scene.M_alpha, PROJECTILE["M_alpha"]))
    if not isinstance(scene.hold, Hold):
        raise StabmapError(f"hold must be a Hold (a [hold] table), got {scene.hold!r}")
    put("grid", tuple(scene.grid))
    check_axes(scene.grid, scene.parameter)
    ratios.check(scene)
    _check_omega(scene)
    _check_one_liquid_model(scene)
    put("bodies", _check_cavities(scene))


def _joints_count(given: int, n: int, tree: bool) -> str:
    """What is wrong with ``given`` joint stiffnesses for ``n`` bodies, in words that count right."""
    values = f"joints has {given} value{'s' if given != 1 else ''}"
    if n == 1:
        return f"{values}, but one body has no joint between bodies (its base joint is K_0); remove joints"
    names = "K_1" if n == 2 else f"K_1..K_{n - 1}"
    what = "tree" if tree else "chain"
    whose = ", K_k the joint of body k+1 with its parent" if tree else ""
    return (f"{values}; a {what} of {n} bodies has {n - 1} joint{'s' if n > 2 else ''} between bodies ({names}{whose}); "
            "give one stiffness per joint")


def _checked_body(b: Body, k: int, tree: bool) -> Body:
    where = f"bodies[{k}]"
    # A dry shell may be massless when the engine adds the liquid (Kelvin's spinning shell).
    dry = b.cavity is not None and not b.cavity.liquid_in_body
    values = {}
    for key in ("m", "A", "C", "c", "s"):
        info = BODY[key]
        if dry and key in ("m", "A"):
            info = Parameter(info.symbol, info.units, info.long_name, 0.0, False)
        values[key] = check_value(f"{where}.{key}", getattr(b, key), info)
    if tree and values["s"] != 0.0:
        raise StabmapError(
            f"{where}.s is not used in a scene with [topology]: the joints' positions are topology.at "
            "(where each body's joint sits on its parent's axis); remove s"
        )
    omega = None if b.omega is None else check_value(f"{where}.omega", b.omega, BODY["omega"])
    if len(b.E) != len(b.kappa):
        raise StabmapError(f"{where}.fluid: E has {len(b.E)} values but kappa has {len(b.kappa)}; give one kappa per mode")
    E = tuple(check_value(f"{where}.fluid.E[{i + 1}]", v, _E) for i, v in enumerate(b.E))
    kappa = tuple(check_value(f"{where}.fluid.kappa[{i + 1}]", v, _KAPPA) for i, v in enumerate(b.kappa))
    for i, v in enumerate(kappa):
        # An inertial wave of a liquid spinning at omega has a frequency below 2 omega in the rotating frame
        # (Greenspan 1968, 2.7), and lambda = 2 omega / kappa is that frequency: so |kappa| > 1, as a cavity's table.
        if abs(v) <= 1.0:
            raise StabmapError(f"{where}.fluid.kappa[{i + 1}] = {v:g}: a liquid mode has |kappa| > 1 (its frequency in the body, "
                               "2 omega / kappa, is below 2 omega; docs/cavities.md)")
    cavity = None if b.cavity is None else liquid.check(b.cavity, f"{where}.cavity")
    return Body(omega=omega, E=E, kappa=kappa, cavity=cavity, **values)


def _axis_name(name: str, n: int, support: str, tree: bool):
    """The parsed name of a grid axis, with the rules that depend on the layout (chain or tree)."""
    parsed = parse_name(name, n, support)
    if tree and parsed.symbol == "s":
        raise StabmapError(
            f"grid axis {name!r} has no effect in a scene with [topology]: joints sit at topology.at; "
            "scan at_k, the position of body k's joint on its parent's axis"
        )
    if not tree and parsed.symbol == "s" and parsed.kind == "body" and parsed.index == n:
        raise StabmapError(
            f"grid axis {name!r} has no effect: s_k is the distance to the joint of the body above body k, and body {n} "
            "is the top of the chain; scan s_k of a lower body"
        )
    if not tree and parsed.kind == "position":
        raise StabmapError(
            f"grid axis {name!r}: at_k places a joint in a scene with [topology]; in a chain body {parsed.index} "
            f"hangs at s_{parsed.index - 1} on body {parsed.index - 1}, so scan s_{parsed.index - 1}"
        )
    return parsed


def _check_omega(scene: Scene) -> None:
    names = {a.name for a in scene.grid} | {m for a in scene.grid for m in ratios.moved(scene, a.name)}
    own = [b.omega is not None or f"omega_{k + 1}" in names for k, b in enumerate(scene.bodies)]
    if "omega" in names and all(own):
        raise StabmapError("grid axis 'omega' has no effect: every body sets its own omega (scan omega_k instead)")
    if scene.omega is None and "omega" not in names and not all(own):
        k = own.index(False) + 1
        raise StabmapError(f"omega is missing: set the common rate omega, bodies[{k}].omega, or scan omega in [grid]")


def _check_one_liquid_model(scene: Scene) -> None:
    """A scene is either ideal (modes) or viscous (Chernousko's first order): the two models do not combine."""
    names = {a.name for a in scene.grid}
    for k, b in enumerate(scene.bodies, start=1):
        if f"viscosity_{k}" in names and (b.cavity is None or not b.cavity.viscous):
            raise StabmapError(f"grid axis 'viscosity_{k}': body {k} has no viscous cavity; add viscosity to its cavity or remove the axis")
    if not scene.viscous:
        return
    for k, b in enumerate(scene.bodies, start=1):
        ideal = "fluid modes (E, kappa)" if b.E else "an ideal-liquid cavity (no viscosity)" if b.cavity is not None and not b.cavity.viscous else ""
        if ideal:
            raise StabmapError(
                f"bodies[{k}] has {ideal} but another body's cavity holds a viscous liquid: one scene takes one liquid model "
                f"(docs/viscous.md); give bodies[{k}].cavity a viscosity, or remove viscosity everywhere for the ideal model")
    if scene.frequencies:
        raise StabmapError("frequencies: a viscous scene stores the frequency of its slowest-decaying mode (variable frequency); "
                           "remove frequencies = true")
    for k, b in enumerate(scene.bodies, start=1):
        if b.cavity is not None and not b.cavity.geometric and ({f"half_height_{k}", f"aspect_{k}"} & names):
            raise StabmapError(f"grid axis of body {k}'s cavity size: its tensor is given as a table, so no size moves it; "
                               "give the cavity's shape and sizes to scan them")


def _check_cavities(scene: Scene) -> tuple[Body, ...]:
    """The bodies, each cavity checked against the grid and its number of modes chosen for it."""
    axes = {a.name: a.array for a in scene.grid}
    axes.update(ratios.grid_values(scene))  # what the ratio axes move (C_k, A_k, a cavity's sizes)
    bodies = []
    for k, b in enumerate(scene.bodies, start=1):
        cav = b.cavity
        for key in SCANNABLE_CAVITY:
            # a viscous table keeps its density and the radius of its Reynolds number scannable
            if f"{key}_{k}" in axes and (cav is None or not cav.geometric) and not (cav is not None and cav.viscous and key != "half_height"):
                raise StabmapError(
                    f"grid axis '{key}_{k}': body {k} has no spheroid or cylinder cavity to size; "
                    f'add bodies[{k}].cavity = {{ shape = "cylinder", ... }} or remove the axis'
                )
        if cav is None:
            bodies.append(b)
            continue
        values = {}
        for key in ("m", "A", "C") + (SCANNABLE_CAVITY if cav.geometric else ()):
            fixed = getattr(b, key) if key in BODY else getattr(cav, key)
            values[key] = axes.get(f"{key}_{k}", axes.get(key, np.array([fixed])) if key in EVERY_BODY else np.array([fixed]))
        extremes = {key: (float(v.min()), float(v.max())) for key, v in values.items()}
        liquid.check_body(cav, f"bodies[{k}]", extremes)
        if cav.viscous and cav.shape == "cylinder":  # its tensor is tabulated: refuse the grid now, not mid-run
            from .stokes import cylinder_range

            low, high = cylinder_range()
            q = (extremes["half_height"][0] / extremes["radius"][1], extremes["half_height"][1] / extremes["radius"][0])
            if q[0] < low or q[1] > high:
                raise StabmapError(
                    f"bodies[{k}].cavity: half_height / radius runs from {q[0]:.4g} to {q[1]:.4g} on this grid; the viscous "
                    f"cylinder's tensor is tabulated for {low:g} <= half_height / radius <= {high:g} (docs/viscous-tensors.md): "
                    "narrow the grid, or give the tensor directly (shape = \"table\", tensor = [P_t, P_a])")
        if cav.geometric and not cav.viscous:
            inertia = extremes["A"][0]
            if not cav.liquid_in_body:  # the engine adds the frozen liquid, at least its inertia at the smallest sizes
                inertia += float(liquid.cavity.frozen_inertia(cav.shape, *(extremes[key][0] for key in SCANNABLE_CAVITY))[0])
            cav = liquid.choose(cav, f"bodies[{k}].cavity", values, inertia)
        bodies.append(replace(b, cavity=cav))
    return tuple(bodies)


def fixed_values(scene: Scene) -> dict[str, float]:
    """Every scalar parameter of the scene that is not a grid axis, by its scannable name."""
    names = {a.name for a in scene.grid}
    out = {}
    own = all(b.omega is not None or f"omega_{k}" in names for k, b in enumerate(scene.bodies, start=1))
    if scene.omega is not None and "omega" not in names and not own:  # in force only where a body does not set its own
        out["omega"] = scene.omega
    if not scene.free and "g" not in names:
        out["g"] = scene.g
    for k, b in enumerate(scene.bodies, start=1):
        for key in EVERY_BODY:
            # s places the joint above: a tree places its joints by topology.at, and a chain's top body has none
            if key not in names and not (key == "s" and (scene.topology is not None or k == len(scene.bodies))):
                out[f"{key}_{k}"] = getattr(b, key)
        if scene.topology is not None and k > 1:
            out[f"at_{k}"] = scene.topology.at[k - 1]
        if b.omega is not None:
            out[f"omega_{k}"] = b.omega
        if b.cavity is not None and (b.cavity.geometric or b.cavity.viscous):
            for key in SCANNABLE_CAVITY if b.cavity.geometric else ("radius", "density"):
                out[f"{key}_{k}"] = getattr(b.cavity, key)
            if b.cavity.viscosity is not None:  # the cavity is viscous
                out[f"viscosity_{k}"] = b.cavity.viscosity
    if not scene.free and not ratios.projectile(scene):  # M_alpha takes the base joint's place
        out["K_0"] = scene.K_0
    if scene.M_alpha is not None and "M_alpha" not in names:
        out["M_alpha"] = scene.M_alpha
    if "K" not in names:
        for j, K in enumerate(scene.joint_stiffness(), start=1):
            out[f"K_{j}"] = K
    return {k: v for k, v in out.items() if k not in names}


__all__ = ["Body", "Scene", "from_dict", "fixed_values", "SUPPORTS"]
