"""Scenes of closed chains: a family, its lengths (explicit, or h1 and the ratio h2/h1 of its pattern), c1^2, h,
the ring's n and winding j, and the grid to scan.

``Scene`` validates itself when it is made, so a scene built in Python gets the same checks and messages as one
read from TOML.  Every grid point is checked too: lengths that cannot close and windings out of range are
errors before any work starts; a family without an equilibrium at valid lengths is data (``exists = 0``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from ...errors import StabmapError
from ...scene.grid import Axis, check_axes, parse_axes
from ...scene.values import Parameter, check_value, did_you_mean, no_unknown
from ..base import SceneBase
from . import checks
from .families import FAMILIES

PARAMETERS = {
    "ratio": Parameter("h_2/h_1", "1", "length ratio of the family's pattern (h2 over h1)", 0.0, True),
    "h1": Parameter("h_1", "m", "length of the bodies marked h1 in the family's pattern", 0.0, True),
    "n": Parameter("n", "1", "number of bodies of the ring", 3.0, False),
    "j": Parameter("j", "1", "winding number of the ring", 1.0, False),
    "c1sq": Parameter("c_1^2", "N m2", "bending stiffness c1^2 of the joints", 0.0, True),
    "c2sq": Parameter("c_2^2", "N m2", "torsional stiffness c2^2 of the joints (default c1^2)", 0.0, True),
    "twist": Parameter("m", "1", "twist of the ring: turns m of the bodies' frames about their axes around the ring", 0.0, False),
    "h": Parameter("h", "m", "step h of the discrete curvature", 0.0, True),
}
_KEYS = {"title", "family", "model", "lengths", "ratio", "h1", "n", "j", "twist", "c1sq", "c2sq", "h", "grid"}
_RING_ONLY = ("n", "j", "twist")
_PATTERN_ONLY = ("ratio", "h1", "n")  # names that build the lengths: not with explicit lengths


@dataclass(frozen=True)
class Scene(SceneBase):
    """A closed chain of one family and the grid of parameters to scan (docs/closed.md).

    Lengths are either ``lengths`` (h_1..h_n [m], in the family's pattern) or built from ``h1`` [m] (default 1)
    and ``ratio`` = h2/h1 (default 1 for the ring, whose pattern alternates h1, h2).  ``n`` (ring only) is the
    number of bodies; ``j`` (ring only, default 1) its winding; ``c1sq`` (default 1) the bending stiffness c1^2 [N m^2];
    ``h`` (default min h_k at each point) the step of the discrete curvature; ``c2sq`` (default c1^2 at each
    point) the torsional stiffness c2^2 [N m^2]; ``twist`` (ring only, default 0) the ring's twist m, whole turns
    of the bodies' frames about their axes around the ring (equal lengths only).  ``model`` is "spatial" (the
    default: stability against every motion, out of the plane and twist included) or "planar" (the chain
    confined to its plane, the paper's section 3).
    """

    system: ClassVar[str] = "closed"

    family: str = "ring"
    model: str = "spatial"
    lengths: tuple[float, ...] = ()
    ratio: float | None = None
    h1: float | None = None
    n: int | None = None
    j: int | None = None
    twist: int | None = None
    c1sq: float | None = None
    c2sq: float | None = None
    h: float | None = None
    title: str = ""
    grid: tuple[Axis, ...] = field(default=())

    def __post_init__(self):
        _validate(self)

    @property
    def fam(self):
        return FAMILIES[self.family]

    @property
    def ring(self) -> bool:
        return self.family == "ring"

    @property
    def spatial(self) -> bool:
        return self.model == "spatial"

    def axis(self, name: str) -> np.ndarray | None:
        for a in self.grid:
            if a.name == name:
                return a.array
        return None

    def values_of(self, name: str) -> np.ndarray:
        """Every value ``name`` takes in this scene: its grid axis, or its fixed value."""
        on_grid = self.axis(name)
        return on_grid if on_grid is not None else np.array([float(fixed_values(self, all_names=True)[name])])

    @property
    def n_values(self) -> np.ndarray:
        if self.lengths:
            return np.array([len(self.lengths)])
        return self.values_of("n").astype(np.int64) if self.ring else np.array([self.fam.n])

    @property
    def n_max(self) -> int:
        return int(self.n_values.max())

    def parameter(self, name: str) -> Parameter:
        """The parameter a grid axis called ``name`` scans, or a StabmapError saying why it cannot be scanned."""
        return _parameter(name, self.family, bool(self.lengths))

    @classmethod
    def from_dict(cls, table: dict, base_dir: str | Path | None = None) -> Scene:
        return from_dict(table, base_dir)

    def fixed_values(self) -> dict[str, float]:
        return fixed_values(self)

    def to_dict(self) -> dict:
        out: dict[str, object] = {"title": self.title, "family": self.family}
        if self.model != "spatial":
            out["model"] = self.model
        if self.lengths:
            out["lengths"] = list(self.lengths)
        for key in ("ratio", "h1", "n", "j", "twist", "c1sq", "c2sq", "h"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        if self.grid:
            out["grid"] = {a.name: a.to_dict() for a in self.grid}
        return out


def _parameter(name: str, family: str, explicit: bool) -> Parameter:
    if name not in PARAMETERS:
        raise StabmapError(f"unknown parameter name {name!r}; {did_you_mean(name, PARAMETERS)}a closed chain scans {', '.join(PARAMETERS)}")
    if name in _RING_ONLY and family != "ring":
        n = FAMILIES[family].n
        what = "no twisted equilibrium (twist applies to rings)" if name == "twist" else "no winding"
        raise StabmapError(f"grid axis {name!r} applies to family = \"ring\" only; family {family!r} has n = {n} bodies and {what}")
    if name in _PATTERN_ONLY and explicit:
        raise StabmapError(f"grid axis {name!r} builds the lengths from the family's pattern; remove lengths = [...] to scan it")
    return PARAMETERS[name]


def from_dict(data: dict, base_dir: str | Path | None = None) -> Scene:
    """The scene of a TOML table; the layout is checked here, every value by ``Scene`` itself."""
    no_unknown(data, _KEYS, "scene")
    family = data.get("family", "ring")
    checks.family(family)
    lengths = data.get("lengths", [])
    if not isinstance(lengths, list):
        raise StabmapError(f"lengths must be a list of lengths h_1..h_n [m], e.g. lengths = [1.0, 0.5, 1.0, 0.5]; got {lengths!r}")
    grid = parse_axes(data.get("grid", {}), lambda name: _parameter(name, family, bool(lengths)))
    scalars = {k: data[k] for k in ("title", "model", "ratio", "h1", "n", "j", "twist", "c1sq", "c2sq", "h") if k in data}
    return Scene(family=family, lengths=tuple(lengths), grid=grid, **scalars)


def fixed_values(scene: Scene, all_names: bool = False) -> dict[str, float]:
    """The scalar parameters that are not grid axes (``all_names``: the grid's too, at their fixed defaults)."""
    out = {}
    if not scene.lengths:
        out["ratio"] = 1.0 if scene.ratio is None else scene.ratio
        out["h1"] = 1.0 if scene.h1 is None else scene.h1
    if scene.ring:
        if scene.lengths:
            out["n"] = float(len(scene.lengths))
        elif scene.n is not None:
            out["n"] = float(scene.n)
        out["j"] = float(1 if scene.j is None else scene.j)
        out["twist"] = float(0 if scene.twist is None else scene.twist)
    out["c1sq"] = 1.0 if scene.c1sq is None else scene.c1sq
    if scene.c2sq is not None:
        out["c2sq"] = scene.c2sq
    if scene.h is not None:
        out["h"] = scene.h
    if all_names:
        return out
    names = {a.name for a in scene.grid}
    return {k: v for k, v in out.items() if k not in names}


# ------------------------------------------------------------------------------------------------------ the checks
def _validate(scene: Scene) -> None:
    """Check every value of ``scene`` (and every grid point) and store the normalised ones; errors name the key."""

    def put(name, value):
        object.__setattr__(scene, name, value)

    fam = checks.family(scene.family)
    checks.model(scene.model)
    if not isinstance(scene.title, str):
        raise StabmapError(f"title must be a string, got {scene.title!r}")
    put("grid", tuple(scene.grid))
    explicit = bool(scene.lengths)
    if explicit:
        for key in _PATTERN_ONLY:
            if getattr(scene, key) is not None:
                raise StabmapError(f"{key}: give either lengths = [...] or h1, ratio (and the ring's n), not both; remove {key}")
        put("lengths", tuple(checks.lengths(fam, scene.lengths).tolist()))
    for key in ("ratio", "h1", "c1sq", "c2sq", "h"):
        if getattr(scene, key) is not None:
            put(key, check_value(key, getattr(scene, key), PARAMETERS[key]))
    for key in _RING_ONLY:
        if getattr(scene, key) is not None and not scene.ring:
            if key == "n":
                checks.body_count(fam, checks.whole("n", scene.n, 3))  # says what n the family has (and why odd n fails)
            raise StabmapError(f"{key} applies to family = \"ring\" only; remove {key} for family {fam.name!r}")
    if scene.n is not None:
        put("n", checks.whole("n", scene.n, 3))
    if scene.j is not None:
        put("j", checks.whole("j", scene.j, 1))
    if scene.twist is not None:
        put("twist", checks.whole("twist", scene.twist, 0))
    check_axes(scene.grid, scene.parameter)
    names = {a.name for a in scene.grid}
    for key in _RING_ONLY:
        if key in names:
            for i, v in enumerate(scene.values_of(key)):
                checks.whole(f"grid.{key}.values[{i + 1}]", v, {"n": 3, "j": 1, "twist": 0}[key])
    if scene.ring and not explicit and scene.n is None and "n" not in names:
        raise StabmapError("n is missing: a ring needs its number of bodies; set n = 6 (say), scan n in [grid], or give lengths = [...]")
    if scene.ratio is None and not explicit and not scene.ring and "ratio" not in names:
        raise StabmapError(
            f"ratio is missing: family {fam.name!r} has lengths {checks.pattern_text(fam)}; set ratio = h2/h1, scan it in [grid], "
            "or give lengths = [...]"
        )
    for key in ("n", "j", "twist"):
        if key in names and getattr(scene, key) is not None:
            raise StabmapError(f"{key} is both fixed and a grid axis; remove one of them")
    for key in ("ratio", "h1", "c1sq", "c2sq", "h"):
        if key in names and getattr(scene, key) is not None:
            raise StabmapError(f"{key} is both fixed and a grid axis; remove one of them")
    if scene.ring:
        _check_windings(scene)
        _check_twist(scene)
    if not scene.spatial and "c2sq" in names:
        raise StabmapError("grid axis 'c2sq' with model = \"planar\": the torsional stiffness acts out of the plane only; "
                           "remove the axis or use model = \"spatial\"")
    _check_closing(scene)


def _check_windings(scene: Scene) -> None:
    n_min = int(scene.n_values.min())
    j = scene.values_of("j")
    where = "grid.j" if scene.axis("j") is not None else "j"
    if scene.axis("n") is not None:
        where += f" (with the grid's smallest n = {n_min})"
    checks.winding(int(j.max()), n_min, where)


def _check_twist(scene: Scene) -> None:
    """The largest twist of the grid, checked at its smallest n, on every length the grid builds (``checks.twist``)."""
    where = "grid.twist" if scene.axis("twist") is not None else "twist"
    lengths = np.asarray(scene.lengths) if scene.lengths else None
    equal = bool((lengths == lengths[0]).all()) if lengths is not None else bool((scene.values_of("ratio") == 1.0).all())
    checks.twist(int(scene.values_of("twist").max()), int(scene.n_values.min()), where, equal, scene.spatial)


def _check_closing(scene: Scene) -> None:
    """Every grid point's lengths must close (the ring's odd n with ratio != 1 is the only pattern that may not)."""
    if scene.lengths:
        return
    ratios = scene.values_of("ratio")
    for n in np.unique(scene.n_values):
        lengths = scene.fam.lengths(1.0, ratios, int(n))
        try:
            checks.can_close(lengths)
        except StabmapError:
            bad = ratios[np.argmax(lengths.max(-1) > (lengths.sum(-1) - lengths.max(-1)) * (1 + checks.PATTERN_RTOL))]
            raise StabmapError(
                f"ratio = {bad:g} with n = {n}: the lengths {checks.pattern_text(scene.fam)} cannot close (one body is longer "
                "than all the others together); narrow the ratio range or choose an even n"
            ) from None


def point_values(scene: Scene, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Every parameter at every point, as flat arrays of the points' broadcast shape (fixed values filled in)."""
    fixed = fixed_values(scene, all_names=True)
    shape = np.broadcast_shapes(*(np.shape(v) for v in values.values())) if values else ()
    out = {}
    for name in PARAMETERS:
        if name in values:
            out[name] = np.broadcast_to(np.asarray(values[name], dtype=float), shape).ravel()
        elif name in fixed:
            out[name] = np.full(int(np.prod(shape, dtype=np.int64)), float(fixed[name]))
    if "c2sq" not in out:  # the default torsional stiffness: c1^2 at each point, where the paper's law has an energy
        out["c2sq"] = out["c1sq"]
    return out


def combinations(*arrays: np.ndarray):
    """Unique combinations of values of equal-length arrays, with the points of each."""
    stacked = np.stack(arrays, axis=-1)
    keys, inverse = np.unique(stacked, axis=0, return_inverse=True)
    for i, key in enumerate(keys):
        yield tuple(key), np.flatnonzero(inverse.ravel() == i)


__all__ = ["PARAMETERS", "Scene", "fixed_values", "from_dict"]
