"""What an atlas file holds, as the text ``stabmap info`` prints."""

from __future__ import annotations

import numpy as np
import xarray as xr

from .. import systems
from ..errors import StabmapError
from .summary import summary


def describe(ds: xr.Dataset, name: str = "") -> str:
    """The scene, axes, fixed parameters, counts and provenance of an atlas (or the intervals of critical values)."""
    if ds.attrs.get("stabmap_kind") == "critical values":
        head = f"{name}: {ds.attrs.get('title', '')}: critical values along {ds.attrs['critical_along']}"
        return "\n".join([head, f"  {ds.attrs['comment']}", *intervals(ds)])
    system = systems.of_atlas(ds.attrs)
    s = summary(ds)
    a = ds.attrs
    lines = [f"{name}: {a.get('title', '')}"]
    lines += [f"  {line}" for line in system.describe(a)]
    lines += [f"  {line}" for line in scene_notes(a)]
    lines.append("  axes:")
    for d in ds[system.label].dims:
        c = ds[d]
        lines.append(
            f"    {d:<10} {c.size:>7} points  {float(c.min()):.6g} .. {float(c.max()):.6g} {c.attrs.get('units', '')}  "
            f"({c.attrs.get('scale', '')})  {c.attrs.get('long_name', '')}"
        )
    fixed = [k for k in ds.coords if ds[k].ndim == 0]
    if fixed:
        lines.append("  fixed: " + ", ".join(f"{k} = {float(ds[k]):.6g}" for k in fixed))
    if system.stable_label is not None:
        degenerate = f", degenerate: {s['degenerate']}" if s["degenerate"] else ""
        absent = f", absent: {s['absent']}" if s["absent"] else ""
        undecided = f", undecided (not proved): {s['undecided']}" if s["undecided"] else ""
        lines.append(f"  points: {s['points']}, stable: {s['stable']} ({100 * s['stable_fraction']:.2f} %)" + degenerate + absent + undecided)
    else:
        lines.append(f"  points: {s['points']}")
    flags = system.variable(system.label).flags
    name = (lambda k: system.variable(system.label).meaning(k)) if flags else str  # a flag label: its meanings
    lines.append(f"  {system.label} ({system.label_symbol}): " + ", ".join(f"{name(k)}: {v}" for k, v in s[system.label].items()))
    if system.provenance in s:
        lines.append("  decided by: " + ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in s[system.provenance].items()))
    lines.append(f"  made by {a.get('source', '?')}; {a.get('history', '')}")
    return "\n".join(lines)


def scene_notes(attrs: dict) -> list[str]:
    """What the stored scene chose for itself (its ``notes()``, if it has them), such as the liquid modes kept.

    The scene is read back from the atlas, so the lines say what that scene chooses;
    a scene this version no longer reads is reported, not fatal: the atlas is still described.
    """
    if "scene" not in attrs:
        return []
    try:
        scene = systems.loads_scene(str(attrs["scene"]), "the atlas's scene")
    except StabmapError as exc:
        return [f"(the stored scene does not load in this version: {exc})"]
    notes = getattr(scene, "notes", None)
    return list(notes()) if notes is not None else []


def intervals(ds: xr.Dataset, limit: int = 8) -> list[str]:
    """Stable intervals of a critical-values Dataset, for the first ``limit`` points of the other axes."""
    along = ds.attrs["critical_along"]
    names = [f"{along}_stable_{end}" for end in ("lower", "upper", "lower_outer", "upper_outer")]
    dims = [d for d in ds[names[0]].dims if d != "interval"]
    table = ds[names].stack(point=dims) if dims else ds[names].expand_dims(point=[0])
    lo, hi, olo, ohi = (table[n].transpose("point", "interval").values for n in names)
    units = ds[names[0]].attrs.get("units", "")
    lines = []
    for p, label in enumerate(table["point"].values[:limit]):
        where = ", ".join(f"{d} = {v:g}" for d, v in zip(dims, label)) if dims else "the scene"
        parts = [
            f"{lo[p, k]:.10g} ({'scan end' if np.isnan(olo[p, k]) else 'boundary'}) to "
            f"{hi[p, k]:.10g} ({'scan end' if np.isnan(ohi[p, k]) else 'boundary'})"
            for k in range(lo.shape[1])
            if np.isfinite(lo[p, k])
        ]
        lines.append(f"{where}: stable {along} [{units}] " + ("; ".join(parts) if parts else "nowhere in the scan"))
    if lo.shape[0] > limit:
        lines.append(f"... and {lo.shape[0] - limit} more points in the file")
    return lines
