"""Scenes: a chain or a tree of bodies, its support and the grid to scan, read from TOML.

A scene is data: frozen dataclasses here, a TOML file on disk, and the same
TOML text stored back into every atlas so the file says how it was made.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from . import liquid, topology
from .errors import StabmapError
from .liquid import Cavity
from .parameters import BASE, BODY, EVERY_BODY, GLOBAL, JOINT, POSITION, SCANNABLE_CAVITY, ParameterInfo, check_value, parse_name
from .topology import Topology

SUPPORTS = ("fixed", "free")
DEFAULT_G = 9.81
_TOP_KEYS = {"title", "support", "g", "omega", "joints", "K_0", "topology", "bodies", "grid"}
_TOPOLOGY_KEYS = {"parent", "at"}
_BODY_KEYS = {"m", "A", "C", "c", "s", "omega", "fluid", "cavity"}
_FLUID_KEYS = {"E", "kappa"}
_AXIS_KEYS = {"start", "stop", "num", "scale", "values"}
_KAPPA = ParameterInfo("kappa", "1", "", None, False)
_E = ParameterInfo("E", "kg m2", "", 0.0, False)


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
class Axis:
    """One scanned parameter: its name (the Dataset dimension) and its values."""

    name: str
    values: tuple[float, ...]
    scale: str = "linear"  # "linear" | "log" | "values" (listed explicitly)

    @property
    def array(self) -> np.ndarray:
        return np.asarray(self.values, dtype=np.float64)


@dataclass(frozen=True)
class Scene:
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

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(a.values) for a in self.grid)

    def joint_stiffness(self) -> tuple[float, ...]:
        """K_1..K_{n-1}, zeros where the scene leaves them out."""
        return tuple(self.joints) if self.joints else (0.0,) * (self.n - 1)

    def to_toml(self) -> str:
        """The scene as TOML text that ``loads`` reads back to an equal Scene."""
        out = [f"title = {_toml_str(self.title)}", f"support = {_toml_str(self.support)}"]
        if not self.free:
            out.append(f"g = {self.g!r}")
        if self.omega is not None:
            out.append(f"omega = {self.omega!r}")
        out.append(f"joints = {_toml_list(self.joint_stiffness())}")
        if not self.free:
            out.append(f"K_0 = {self.K_0!r}")
        if self.topology is not None:
            parents = ", ".join(str(p) for p in self.topology.parent)
            out += ["", "[topology]", f"parent = [{parents}]", f"at = {_toml_list(self.topology.at)}"]
        for b in self.bodies:
            out += ["", "[[bodies]]", f"m = {b.m!r}", f"A = {b.A!r}", f"C = {b.C!r}", f"c = {b.c!r}"]
            if self.topology is None:
                out.append(f"s = {b.s!r}")
            if b.omega is not None:
                out.append(f"omega = {b.omega!r}")
            if b.E:
                out.append(f"fluid = {{ E = {_toml_list(b.E)}, kappa = {_toml_list(b.kappa)} }}")
            if b.cavity is not None:
                out.append(b.cavity.to_toml())
        if self.grid:
            out += ["", "[grid]"]
            for a in self.grid:
                out.append(f"{a.name} = {{ values = {_toml_list(a.values)}, scale = {_toml_str(a.scale)} }}")
        return "\n".join(out) + "\n"


def _toml_str(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def _toml_list(xs) -> str:
    return "[" + ", ".join(repr(float(x)) for x in xs) + "]"


def load(path: str | Path) -> Scene:
    """Read and validate a scene file; every problem is a StabmapError naming the key."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise StabmapError(f"scene file {str(path)!r} does not exist") from None
    except (IsADirectoryError, PermissionError, UnicodeDecodeError) as exc:
        raise StabmapError(f"cannot read scene file {str(path)!r}: {exc}") from None
    return loads(text, source=str(path), base_dir=path.parent)


def loads(text: str, source: str = "<scene>", base_dir: str | Path | None = None) -> Scene:
    """Parse and validate scene TOML text; relative file names in it are taken from ``base_dir``."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise StabmapError(f"{source}: TOML syntax error: {exc}") from None
    return from_dict(data, base_dir)


def from_dict(data: dict, base_dir: str | Path | None = None) -> Scene:
    """Validate a scene given as a dict with the TOML layout."""
    _no_unknown(data, _TOP_KEYS, "scene")
    support = data.get("support", "fixed")
    if support not in SUPPORTS:
        raise StabmapError(f'support must be "fixed" or "free", got {support!r}')
    raw_bodies = data.get("bodies")
    if not isinstance(raw_bodies, list) or not raw_bodies:
        raise StabmapError("bodies is missing: add at least one [[bodies]] table (body 1 at the bottom)")
    n = len(raw_bodies)
    tree = _topology(data["topology"], n) if "topology" in data else None
    base_dir = None if base_dir is None else Path(base_dir)
    bodies = tuple(_body(raw, k + 1, n, base_dir, tree is not None) for k, raw in enumerate(raw_bodies))
    title = data.get("title", "")
    if not isinstance(title, str):
        raise StabmapError(f"title must be a string, got {title!r}")
    omega = data.get("omega")
    if omega is not None:
        omega = check_value("omega", omega, GLOBAL["omega"])
    g = DEFAULT_G
    if "g" in data:
        g = check_value("g", data["g"], GLOBAL["g"])
    joints = data.get("joints", [])
    if not isinstance(joints, list):
        raise StabmapError(f"joints must be a list of stiffnesses K_1..K_{n - 1}, got {joints!r}")
    if joints and len(joints) != n - 1:
        if tree is not None:
            raise StabmapError(
                f"joints has {len(joints)} values; a tree of {n} bodies has {n - 1} joints between bodies "
                f"(K_1..K_{n - 1}, K_k the joint of body k+1 with its parent)"
            )
        raise StabmapError(
            f"joints has {len(joints)} values; a chain of {n} bodies has {n - 1} joints (K_1..K_{n - 1})"
        )
    joints = tuple(check_value(f"joints[{i + 1}] (K_{i + 1})", v, JOINT) for i, v in enumerate(joints))
    K_0 = 0.0
    if "K_0" in data:
        if support == "free":
            raise StabmapError('K_0: a free system has no base joint; remove K_0 or use support = "fixed"')
        K_0 = check_value("K_0", data["K_0"], BASE)
    grid = _grid(data.get("grid", {}), n, support, tree is not None)
    scene = Scene(
        bodies=bodies, support=support, omega=omega, g=g, joints=joints, K_0=K_0, title=title, grid=grid, topology=tree
    )
    _check_omega(scene)
    _check_cavities(scene)
    return scene


def _no_unknown(table: dict, allowed: set, where: str) -> None:
    if not isinstance(table, dict):
        raise StabmapError(f"{where} must be a table, got {table!r}")
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise StabmapError(f"{where}: unknown key {unknown[0]!r}; allowed keys are {', '.join(sorted(allowed))}")


def _topology(raw: dict, n: int) -> Topology:
    """The ``[topology]`` table: the parent of each body and the position of its joint on the parent's axis."""
    _no_unknown(raw, _TOPOLOGY_KEYS, "topology")
    for key, example in (("parent", "parent = [0, 1, 1] (0: the base)"), ("at", "at = [0.0, 0.3, 0.3] (0 for body 1)")):
        if key not in raw:
            what = "the parent of each body" if key == "parent" else "the position of each body's joint on its parent's axis [m]"
            raise StabmapError(f"topology.{key} is missing: give {what}, one per [[bodies]] table, e.g. {example}")
        if not isinstance(raw[key], list) or len(raw[key]) != n:
            got = f"{len(raw[key])} values" if isinstance(raw[key], list) else repr(raw[key])
            raise StabmapError(f"topology.{key} must be a list with one value per body ({n} [[bodies]] tables), got {got}")
    parent = topology.check_parent(raw["parent"], "topology.parent")
    at = tuple(check_value(f"topology.at[{k + 1}]", v, POSITION) for k, v in enumerate(raw["at"]))
    if at[0] != 0.0:
        raise StabmapError(
            f"topology.at[1] must be 0, got {at[0]}: body 1's joint is the base point (or a free system's "
            "reference point), not a place on another body"
        )
    return Topology(parent=parent, at=at)


def _body(raw: dict, k: int, n: int, base_dir: Path | None, tree: bool = False) -> Body:
    where = f"bodies[{k}]"
    _no_unknown(raw, _BODY_KEYS, where)
    if tree and "s" in raw:
        raise StabmapError(
            f"{where}.s is not used in a scene with [topology]: the joints' positions are topology.at "
            "(where each body's joint sits on its parent's axis); remove s"
        )
    cavity = liquid.parse(raw["cavity"], f"{where}.cavity", base_dir) if "cavity" in raw else None
    # A dry shell may be massless when the engine adds the liquid (Kelvin's spinning shell).
    dry = cavity is not None and not cavity.liquid_in_body
    values = {}
    for key in ("m", "A", "C", "c", "s"):
        if key not in raw:
            if key == "s" and (k == n or tree):
                values[key] = 0.0  # the top body has no upper joint; a tree's joints are placed by topology.at
                continue
            raise StabmapError(f"{where}.{key} is missing ({BODY[key].long_name.format(k=k)} [{BODY[key].units}])")
        info = BODY[key]
        if dry and key in ("m", "A"):
            info = ParameterInfo(info.symbol, info.units, info.long_name, 0.0, False)
        values[key] = check_value(f"{where}.{key}", raw[key], info)
    omega = raw.get("omega")
    if omega is not None:
        omega = check_value(f"{where}.omega", omega, BODY["omega"])
    E, kappa = (), ()
    if "fluid" in raw:
        fluid = raw["fluid"]
        _no_unknown(fluid, _FLUID_KEYS, f"{where}.fluid")
        E = fluid.get("E", [])
        kappa = fluid.get("kappa", [])
        if not isinstance(E, list) or not isinstance(kappa, list):
            raise StabmapError(f"{where}.fluid: E and kappa must be lists of numbers")
        if len(E) != len(kappa):
            raise StabmapError(f"{where}.fluid: E has {len(E)} values but kappa has {len(kappa)}; give one kappa per mode")
        E = tuple(check_value(f"{where}.fluid.E[{i + 1}]", v, _E) for i, v in enumerate(E))
        kappa = tuple(check_value(f"{where}.fluid.kappa[{i + 1}]", v, _KAPPA) for i, v in enumerate(kappa))
        for i, v in enumerate(kappa):
            if v == 0.0:
                raise StabmapError(f"{where}.fluid.kappa[{i + 1}] must be nonzero (lambda = 2 omega / kappa)")
    return Body(omega=omega, E=E, kappa=kappa, cavity=cavity, **values)


def _grid(raw: dict, n: int, support: str, tree: bool = False) -> tuple[Axis, ...]:
    if not isinstance(raw, dict):
        raise StabmapError(f"grid must be a table of axes, got {raw!r}")
    axes = []
    for name, spec in raw.items():
        parsed = parse_name(name, n, support)
        where = f"grid.{name}"
        if tree and parsed.symbol == "s":
            raise StabmapError(
                f"grid axis {name!r} has no effect in a scene with [topology]: joints sit at topology.at; "
                "scan at_k, the position of body k's joint on its parent's axis"
            )
        if not tree and parsed.kind == "position":
            raise StabmapError(
                f"grid axis {name!r}: at_k places a joint in a scene with [topology]; in a chain body {parsed.index} "
                f"hangs at s_{parsed.index - 1} on body {parsed.index - 1}, so scan s_{parsed.index - 1}"
            )
        _no_unknown(spec, _AXIS_KEYS, where)
        if "values" in spec:
            extra = set(spec) - {"values", "scale"}
            if extra:
                raise StabmapError(f"{where}: give either values or start/stop/num, not both (remove {sorted(extra)[0]!r})")
            values = spec["values"]
            if not isinstance(values, list) or not values:
                raise StabmapError(f"{where}.values must be a non-empty list of numbers")
            values = [check_value(f"{where}.values[{i + 1}]", v, parsed.info) for i, v in enumerate(values)]
            scale = spec.get("scale", "values")
            if scale not in ("linear", "log", "values"):
                raise StabmapError(f'{where}.scale must be "linear", "log" or "values", got {scale!r}')
        else:
            for key in ("start", "stop", "num"):
                if key not in spec:
                    raise StabmapError(f"{where}.{key} is missing (or give values = [...])")
            num = spec["num"]
            if isinstance(num, bool) or not isinstance(num, int) or num < 1:
                raise StabmapError(f"{where}.num must be a whole number >= 1, got {num!r}")
            start = check_value(f"{where}.start", spec["start"], parsed.info)
            stop = check_value(f"{where}.stop", spec["stop"], parsed.info)
            scale = spec.get("scale", "linear")
            if scale == "linear":
                values = np.linspace(start, stop, num)
            elif scale == "log":
                if start <= 0 or stop <= 0:
                    raise StabmapError(f'{where}: scale = "log" needs start > 0 and stop > 0, got {start} and {stop}')
                values = np.geomspace(start, stop, num)
            else:
                raise StabmapError(f'{where}.scale must be "linear" or "log", got {scale!r}')
            values = [check_value(f"{where}", float(v), parsed.info) for v in values]
        diffs = np.diff(values)
        if len(values) > 1 and not (np.all(diffs > 0) or np.all(diffs < 0)):
            raise StabmapError(f"{where}: values must be distinct and sorted (increasing or decreasing)")
        axes.append(Axis(name, tuple(float(v) for v in values), scale))
    return tuple(axes)


def _check_omega(scene: Scene) -> None:
    names = {a.name for a in scene.grid}
    own = [b.omega is not None or f"omega_{k + 1}" in names for k, b in enumerate(scene.bodies)]
    if "omega" in names and all(own):
        raise StabmapError("grid axis 'omega' has no effect: every body sets its own omega (scan omega_k instead)")
    if scene.omega is None and "omega" not in names and not all(own):
        k = own.index(False) + 1
        raise StabmapError(f"omega is missing: set the common rate omega, bodies[{k}].omega, or scan omega in [grid]")


def _check_cavities(scene: Scene) -> None:
    axes = {a.name: a.array for a in scene.grid}
    for k, b in enumerate(scene.bodies, start=1):
        cav = b.cavity
        for key in SCANNABLE_CAVITY:
            if f"{key}_{k}" in axes and (cav is None or not cav.geometric):
                raise StabmapError(
                    f"grid axis '{key}_{k}': body {k} has no spheroid or cylinder cavity to size; "
                    f'add bodies[{k}].cavity = {{ shape = "cylinder", ... }} or remove the axis'
                )
        if cav is None:
            continue
        extremes = {}
        for key in ("m", "A", "C") + (SCANNABLE_CAVITY if cav.geometric else ()):
            fixed = getattr(b, key) if key in BODY else getattr(cav, key)
            values = axes.get(f"{key}_{k}", axes.get(key, np.array([fixed])) if key in EVERY_BODY else np.array([fixed]))
            extremes[key] = (float(values.min()), float(values.max()))
        liquid.check_body(cav, f"bodies[{k}]", extremes)


def resample(scene: Scene, **nums: int) -> Scene:
    """The scene with the named grid axes resampled to ``nums[name]`` points over the same range and scale."""
    unknown = set(nums) - {a.name for a in scene.grid}
    if unknown:
        raise StabmapError(f"resample: {sorted(unknown)[0]!r} is not a grid axis of this scene")
    axes = []
    for a in scene.grid:
        if a.name in nums:
            lo, hi = a.values[0], a.values[-1]
            values = np.geomspace(lo, hi, nums[a.name]) if a.scale == "log" else np.linspace(lo, hi, nums[a.name])
            a = Axis(a.name, tuple(float(v) for v in values), a.scale)
        axes.append(a)
    return replace(scene, grid=tuple(axes))


def fixed_values(scene: Scene) -> dict[str, float]:
    """Every scalar parameter of the scene that is not a grid axis, by its scannable name."""
    names = {a.name for a in scene.grid}
    out = {}
    if scene.omega is not None and "omega" not in names:
        out["omega"] = scene.omega
    if not scene.free and "g" not in names:
        out["g"] = scene.g
    for k, b in enumerate(scene.bodies, start=1):
        for key in EVERY_BODY:
            if key not in names and not (key == "s" and scene.topology is not None):
                out[f"{key}_{k}"] = getattr(b, key)
        if scene.topology is not None and k > 1:
            out[f"at_{k}"] = scene.topology.at[k - 1]
        if b.omega is not None:
            out[f"omega_{k}"] = b.omega
        if b.cavity is not None and b.cavity.geometric:
            for key in SCANNABLE_CAVITY:
                out[f"{key}_{k}"] = getattr(b.cavity, key)
    if not scene.free:
        out["K_0"] = scene.K_0
    if "K" not in names:
        for j, K in enumerate(scene.joint_stiffness(), start=1):
            out[f"K_{j}"] = K
    return {k: v for k, v in out.items() if k not in names}


__all__ = ["Axis", "Body", "Scene", "load", "loads", "from_dict", "fixed_values", "resample", "SUPPORTS"]
