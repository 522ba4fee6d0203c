"""Every characteristic root at one point, recomputed from a scene or from the scene an atlas stores (docs/query.md).

``roots(scene_or_atlas, omega=..., ...)`` computes the point asked, not the nearest grid point: each root with a
proved enclosure (centre +- radius in the complex plane), its multiplicity, whether it is real or one of a complex
pair (proved), and whether it is a liquid mode or structural (a stated rule, not a proof).  ``stabmap query ATLAS
NAME=VALUE... --roots`` prints it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import xarray as xr

from .. import systems
from ..errors import StabmapError
from ..scene.units import in_si
from . import shown


@dataclass(frozen=True)
class Roots:
    """The roots at ``point`` (every grid axis -> its value) of a scene titled ``title``; ``rule`` says how
    ``origin`` was decided."""

    title: str
    point: dict[str, float]
    units: dict[str, str]
    roots: list
    rule: str
    display: dict[str, str] = field(default_factory=dict)  # a spin-rate axis's display unit (rpm, Hz): shown first

    @property
    def n_complex_pairs(self) -> int:
        return sum(r.multiplicity for r in self.roots if r.kind != "real") // 2

    @property
    def growth_rate(self) -> float:
        """The largest |Im lambda| [1/s] (0 where every root is real)."""
        return max((r.growth_rate for r in self.roots), default=0.0)

    def text(self) -> str:
        at = ", ".join(f"{k} = {shown.value_text(v, self.units.get(k, ''), self.display.get(k, ''), 6)}" for k, v in self.point.items())
        lines = [f"{self.title}: roots of p(lambda) at {at} (computed at this point; solutions ~ exp(i lambda t))" if at else
                 f"{self.title}: roots of p(lambda) (solutions ~ exp(i lambda t))"]
        nc = self.n_complex_pairs
        lines.append(f"N_c = {nc}: " + ("stable (every root real)" if nc == 0 else
                                         f"unstable, growth rate {self.growth_rate:.6g} 1/s, e-folding time {1 / self.growth_rate:.6g} s"))
        lines.append(f"{'lambda [rad/s]':>36}  {'radius':>9}  mult  {'kind':<12}  {'origin':<10}  liquid share")
        for r in self.roots:
            z = r.value
            value = f"{z.real:.12g}" if r.kind == "real" else f"{z.real:.12g} {'+-'[z.imag < 0]} {abs(z.imag):.12g}i"
            lines.append(f"{value:>36}  {r.radius:9.2e}  {r.multiplicity:>4}  {r.kind:<12}  {r.origin:<10}  {r.liquid_share:.3f}")
        lines.append("enclosures and kinds: proved (exact polynomial, roots isolated by FLINT/Arb); each root lies within "
                     "its radius of the value shown")
        lines.append(f"origin: {self.rule}")
        return "\n".join(lines)

    def to_json(self) -> str:
        rows = [{"real": r.value.real, "imag": r.value.imag, "radius": r.radius, "multiplicity": r.multiplicity, "kind": r.kind,
                 "origin": r.origin, "liquid_share": r.liquid_share} for r in self.roots]
        return json.dumps({"title": self.title, "point": self.point, "n_complex_pairs": self.n_complex_pairs,
                           "growth_rate": self.growth_rate, "roots": rows, "origin_rule": self.rule}, indent=1)


def roots(source, /, **point: float) -> Roots:
    """Every root at ``point`` of a scene, or of the scene an atlas Dataset stores.

    ``point`` gives a number for every grid axis (the other parameters keep the scene's values); the point itself
    is computed, not the nearest grid point.
    """
    if isinstance(source, xr.Dataset):
        if "scene" not in source.attrs:
            raise StabmapError("this Dataset holds no scene (attribute 'scene'), so its roots cannot be recomputed; "
                               "pass the scene itself: stabmap.roots(scene, omega=...)")
        scene = systems.loads_scene(str(source.attrs["scene"]), "the atlas's scene")
        units = {d: str(source[d].attrs.get("units", "")) for d in source.dims if d in point}
        display = {d: shown.display_unit(source, d) for d in units if shown.display_unit(source, d)}
    else:
        scene = source
        units, display = {}, {}
    system = systems.of(scene)
    axes = [a.name for a in scene.grid]
    unknown = [k for k in point if k not in axes]
    if unknown:
        raise StabmapError(f"{unknown[0]!r} is not a grid axis of this scene; its axes are: {', '.join(axes) or '(none)'}")
    missing = [a for a in axes if a not in point]
    if missing:
        example = f"{missing[0]}={scene.grid[axes.index(missing[0])].values[0]:g}"
        raise StabmapError(f"give a value for every axis; missing: {', '.join(missing)} (e.g. {example})")
    values = {}
    for k, v in point.items():
        try:
            values[k] = float(in_si(k, v, system.parameter(scene, k).units))  # "14000 rpm" -> rad/s
        except (TypeError, ValueError):
            raise StabmapError(f"{k} must be a number, got {v!r}") from None
    found = system.roots(scene, values)
    if found is None:
        raise StabmapError(f"the {system.name} system has no characteristic roots to list (--roots applies to gyroscopes)")
    return Roots(scene.title or system.title, values, units, *found, display=display)
