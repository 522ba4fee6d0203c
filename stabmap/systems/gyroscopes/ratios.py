"""Axes that scan a combination of parameters: a projectile's S_g, a body's C/A and a cavity's aspect ratio h/a.

Each such axis moves one underlying quantity (two for a cavity of fixed volume) and holds the others, as the
scene's ``[hold]`` table says (docs/projectile.md).  ``underlying`` turns the axis values into the values of the
quantities they move, before anything else reads the point; the kernels and the exact path then see ordinary
inputs, and every label is proved for those inputs (rounded once or twice from the ratio, as a cavity's tail is
from its size).  ``coordinates`` gives the atlas the moved quantities, and S_g wherever M_alpha acts, as auxiliary
coordinates over the grid axes they depend on.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...errors import StabmapError
from ...scene.values import no_unknown
from .parameters import PROJECTILE, parse_name

CHOICES = {
    "S_g": ("M_alpha", "omega"),
    "C_over_A": ("A", "C"),
    "aspect": ("radius", "half_height", "volume"),
}


@dataclass(frozen=True)
class Hold:
    """What a ratio axis holds: the first choice of each is the default.

    S_g = C^2 omega^2 / (4 A M_alpha) holds M_alpha (moves omega) or omega (moves M_alpha); C_over_A_k holds A_k
    (moves C_k) or C_k (moves A_k); aspect_k = 2 half_height_k / radius_k holds the radius (moves the half height),
    the half height (moves the radius) or the cavity's volume (moves both).
    """

    S_g: str = "M_alpha"
    C_over_A: str = "A"
    aspect: str = "radius"

    def __post_init__(self):
        for key, choices in CHOICES.items():
            value = getattr(self, key)
            if value not in choices:
                raise StabmapError(f"hold.{key} must be one of {', '.join(repr(c) for c in choices)}, got {value!r}")

    def to_dict(self) -> dict:
        return {key: getattr(self, key) for key in CHOICES}


def parse_hold(raw) -> Hold:
    no_unknown(raw, set(CHOICES), "hold")
    return Hold(**raw)


def _omega_1(scene) -> str:
    """The name of body 1's spin: its own omega_1, or the common omega it shares."""
    return "omega_1" if scene.bodies[0].omega is not None else "omega"


def moved(scene, name: str, hold: Hold | None = None) -> tuple[str, ...]:
    """The parameter names a ratio axis ``name`` moves (empty for an ordinary axis), under ``hold`` (default: the
    scene's)."""
    hold = scene.hold if hold is None else hold
    parsed = parse_name(name, scene.n, scene.support)
    if parsed.symbol == "S_g":
        return (_omega_1(scene),) if hold.S_g == "M_alpha" else ("M_alpha",)
    if parsed.kind != "ratio":
        return ()
    k = parsed.index
    if parsed.symbol == "C_over_A":
        return (f"C_{k}",) if hold.C_over_A == "A" else (f"A_{k}",)
    return {"radius": (f"half_height_{k}",), "half_height": (f"radius_{k}",)}.get(hold.aspect, (f"radius_{k}", f"half_height_{k}"))


def projectile(scene) -> bool:
    """True where an aerodynamic moment acts: M_alpha given or scanned, or an S_g axis."""
    names = {a.name for a in scene.grid}
    return scene.M_alpha is not None or bool(names & set(PROJECTILE))


def check(scene) -> None:
    """Errors for the combinations a projectile or a ratio axis cannot take, each naming the fix."""
    names = {a.name for a in scene.grid}
    if projectile(scene):
        _check_projectile(scene, names)
    for axis in scene.grid:
        taken = [m for m in moved(scene, axis.name) if m in names or _every(m) in names]
        name = parse_name(axis.name, scene.n, scene.support)
        if taken:
            what = "S_g" if name.symbol == "S_g" else name.symbol
            # the other hold that leaves the clashing quantity alone (volume moves both of a cavity's sizes)
            other = next(c for c in CHOICES[what] if c != getattr(scene.hold, what)
                         and taken[0] not in moved(scene, axis.name, replace(scene.hold, **{what: c})))
            clash = taken[0] if taken[0] in names else _every(taken[0])
            raise StabmapError(
                f"grid axes {axis.name!r} and {clash!r}: {axis.name} moves {taken[0]} (hold.{what} = "
                f"{getattr(scene.hold, what)!r}), so {clash} cannot be scanned with it; remove {clash!r} or set "
                f'hold.{what} = "{other}"'
            )
        if name.symbol == "aspect":
            cav = scene.bodies[name.index - 1].cavity
            if cav is None or not cav.geometric:
                raise StabmapError(
                    f"grid axis {axis.name!r}: body {name.index} has no spheroid or cylinder cavity; add "
                    f'bodies[{name.index}].cavity = {{ shape = "cylinder", ... }} or remove the axis'
                )
        if name.symbol == "C_over_A" and scene.hold.C_over_A == "C" and min(axis.values) <= 0.0:
            raise StabmapError(f"grid.{axis.name}: with hold.C_over_A = \"C\" the ratio sets A = C / ratio, so it must be > 0")


def _every(name: str) -> str:
    """The axis that sets this column of every body (``C`` for ``C_2``), or the name itself."""
    head, _, index = name.rpartition("_")
    return head if index.isdigit() and head in ("m", "A", "C", "c", "s") else name


def _check_projectile(scene, names: set[str]) -> None:
    if scene.free:
        raise StabmapError(
            'M_alpha acts about a fixed point at body 1\'s centre of mass; use support = "fixed" with bodies[1].c = 0 '
            "(a single body in flight moves about its centre of mass as on a fixed point there)"
        )
    if scene.K_0 != 0.0 or "K_0" in names:
        raise StabmapError("K_0 and M_alpha both act at body 1's fixed point; a projectile has no base joint: remove K_0")
    b = scene.bodies[0]
    if b.c != 0.0 or names & {"c_1", "c"}:
        raise StabmapError(
            "M_alpha is the overturning moment about body 1's centre of mass, which is the fixed point: set "
            "bodies[1].c = 0 and do not scan c_1 or c"
        )
    if b.cavity is not None and b.cavity.geometric and not b.cavity.liquid_in_body:
        raise StabmapError(
            "bodies[1].cavity.liquid_in_body = false with M_alpha: S_g needs A and C with the liquid frozen; give body 1's "
            "m, A and C with the liquid (liquid_in_body = true)"
        )
    if "S_g" not in names:
        return
    if scene.hold.S_g == "omega":
        return
    values = [scene.M_alpha] if "M_alpha" not in names else list(next(a for a in scene.grid if a.name == "M_alpha").values)
    if values == [None]:
        raise StabmapError('grid axis \'S_g\' needs M_alpha: set M_alpha [N m/rad], or hold.S_g = "omega" to let S_g move M_alpha')
    if min(values) <= 0.0:
        raise StabmapError(f"grid axis 'S_g' moves the spin, omega = 2 sqrt(A M_alpha S_g) / C: M_alpha must be > 0, got {min(values):g}")


def _value(scene, values: dict, name: str):
    """The value of ``name`` at the points: a grid axis (or the axis of every body), else the scene's."""
    if name in values:
        return values[name]
    every = _every(name)
    if every in values:
        return values[every]
    if name == "M_alpha":
        return scene.M_alpha
    if name == "omega":
        return scene.omega
    parsed = parse_name(name, scene.n, scene.support)
    b = scene.bodies[parsed.index - 1]
    if parsed.symbol == "omega":
        return b.omega if b.omega is not None else _value(scene, values, "omega")
    return getattr(b.cavity if parsed.kind == "cavity" else b, parsed.symbol)


def underlying(scene, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """``values`` (grid-axis names -> arrays that broadcast together) with every ratio axis replaced by the
    quantities it moves.  C/A first, then the aspect ratios, then S_g (which reads A_1 and C_1)."""
    ratios = [k for k in values if moved(scene, k)]
    if not ratios:
        return values
    out = {k: v for k, v in values.items() if k not in ratios}
    for key in sorted(ratios, key=lambda k: ("C_over_A" not in k, "aspect" not in k)):
        r = np.asarray(values[key], dtype=np.float64)
        name = parse_name(key, scene.n, scene.support)
        k = name.index
        if name.symbol == "C_over_A":
            if scene.hold.C_over_A == "A":
                out[f"C_{k}"] = r * _value(scene, out, f"A_{k}")
            else:
                out[f"A_{k}"] = _value(scene, out, f"C_{k}") / r
        elif name.symbol == "aspect":
            hold = scene.hold.aspect
            a, c = _value(scene, out, f"radius_{k}"), _value(scene, out, f"half_height_{k}")
            if hold == "radius":
                out[f"half_height_{k}"] = 0.5 * r * a
            elif hold == "half_height":
                out[f"radius_{k}"] = 2.0 * c / r
            else:  # the volume, proportional to a^2 c for a cylinder and a spheroid alike
                a_new = np.cbrt(2.0 * a * a * c / r)
                out[f"radius_{k}"], out[f"half_height_{k}"] = a_new, 0.5 * r * a_new
        else:
            A, C = _value(scene, out, "A_1"), _value(scene, out, "C_1")
            if scene.hold.S_g == "M_alpha":
                out[_omega_1(scene)] = 2.0 * np.sqrt(A * _value(scene, out, "M_alpha") * r) / C
            else:
                w = _value(scene, out, _omega_1(scene))
                out["M_alpha"] = C * C * w * w / (4.0 * A * r)
    return out


def stability_factor(scene, values: dict[str, np.ndarray]):
    """S_g = C_1^2 omega_1^2 / (4 A_1 M_alpha) at the points ``values`` (grid-axis names, ratios resolved), with the
    scene's A_1 and C_1 (liquid frozen, the tail not taken off)."""
    A, C = _value(scene, values, "A_1"), _value(scene, values, "C_1")
    w, M = _value(scene, values, "omega_1"), _value(scene, values, "M_alpha")
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(C * C * w * w / (4.0 * A * M), dtype=np.float64)


def _open_grid(scene) -> dict[str, np.ndarray]:
    d = len(scene.grid)
    return {a.name: a.array.reshape([-1 if i == j else 1 for j in range(d)]) for i, a in enumerate(scene.grid)}


def coordinates(scene, parameter) -> dict[str, tuple]:
    """Auxiliary coordinates of an atlas: each quantity a ratio axis moves and, where M_alpha acts and S_g is not
    an axis, S_g; each over the grid axes it varies along: ``{name: (dims, values, attrs)}``."""
    names = [a.name for a in scene.grid]
    wanted = [m for k in names for m in moved(scene, k)]
    sg = projectile(scene) and "S_g" not in names
    if not wanted and not sg:
        return {}
    grid = _open_grid(scene)
    values = underlying(scene, grid)
    out = {}
    for name in wanted + (["S_g"] if sg else []):
        v = stability_factor(scene, values) if name == "S_g" else np.asarray(values[name], dtype=np.float64)
        axes = [i for i in range(v.ndim) if v.shape[i] > 1]
        v = v.reshape([v.shape[i] for i in axes]) if v.ndim else v
        info = PROJECTILE["S_g"] if name == "S_g" else parameter(name)
        long_name = info.long_name if name != "S_g" else info.long_name + ", A and C of body 1 with its liquid frozen"
        by = [n for n in names if moved(scene, n) and name in moved(scene, n)]
        comment = (f"not scanned: set at every grid point by {by[0]} with the scene's [hold]" if by
                   else "computed at every grid point from the scene and the grid axes")
        out[name] = (tuple(names[i] for i in axes), v, {"units": info.units, "long_name": long_name, "comment": comment})
    return out


def grid_values(scene) -> dict[str, np.ndarray]:
    """Every value the moved quantities take on the grid (flattened), for the checks of the extremes."""
    names = [a.name for a in scene.grid]
    wanted = [m for k in names for m in moved(scene, k)]
    if not wanted:
        return {}
    values = underlying(scene, _open_grid(scene))
    return {m: np.unique(np.asarray(values[m], dtype=np.float64)) for m in wanted}


__all__ = ["Hold", "check", "coordinates", "grid_values", "moved", "parse_hold", "projectile", "stability_factor", "underlying"]
