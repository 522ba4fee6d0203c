"""What an atlas file holds, as the text ``stabmap info`` prints."""

from __future__ import annotations

import textwrap

import numpy as np
import xarray as xr

from .. import systems
from ..errors import StabmapError, given
from ..run import costs
from ..scene import units
from ..scene.units import unit_suffix
from ..store.dataset import is_critical
from ..systems.stages import CELLS, LABELS
from . import shown as in_units
from .summary import summary

WIDTH = 100  # characters a line of ``stabmap info`` may take


def plural(n: int, word: str, many: str | None = None) -> str:
    """``1 point``, ``2 points`` (``many``: an irregular plural, ``body`` -> ``bodies``)."""
    return f"{n} {word if n == 1 else (many or word + 's')}"


def wrapped(head: str, items: list[str], indent: str = "  ", width: int = WIDTH, whole: bool = False) -> list[str]:
    """``head`` then ``items`` joined by ", ", wrapped at ``width`` with the continuation lines under the first item;
    ``whole``: an item (``density = 1000 kg m-3``) is never broken across lines."""
    first = f"{indent}{head}"
    text = ", ".join(i.replace(" ", "\u00a0") if whole else i for i in items)  # textwrap does not break at U+00A0
    lines = textwrap.wrap(text, width=width, initial_indent=first, subsequent_indent=" " * len(first),
                          break_long_words=False, break_on_hyphens=False) or [first.rstrip()]
    return [line.replace("\u00a0", " ") for line in lines]


def display_range(c: xr.DataArray) -> str:
    """`` (= 5000 .. 20000 rpm)`` for an axis with ``display_units`` (a spin rate the scene gave in rpm or Hz), else ""."""
    unit = c.attrs.get("display_units")
    if not unit:
        return ""
    k = units.factor(str(unit))
    return f" (= {float(c.min()) / k:.6g} .. {float(c.max()) / k:.6g} {unit})"


def fixed_parameters(ds: xr.Dataset, system, item=None) -> list[tuple[str, list[str]]]:
    """The atlas's fixed parameters (scalar coordinates) grouped as the system groups them, as text with units.

    Returns (heading, ["m = 1 kg", ...]): inside a heading such as ``body 2`` a name loses its index (``m_2`` -> ``m``).
    ``item(name, value, units)`` writes one entry (a figure's caption writes symbols and units in mathtext).
    """
    item = item or (lambda name, value, units: f"{name} = {value:.6g}{unit_suffix(units)}")
    names = [str(k) for k in ds.coords if ds[k].ndim == 0 and np.issubdtype(ds[k].dtype, np.number)]
    out = []
    for head, group in system.fixed_groups(names):
        suffix = "_" + head.rpartition(" ")[2] if head.rpartition(" ")[2].isdigit() else None
        items = []
        for k in group:
            units = ds[k].attrs.get("units", "")
            shown = k[: -len(suffix)] if suffix and k.endswith(suffix) else k
            items.append(item(shown, float(ds[k]), units))
        out.append((head, items))
    return out


def describe(ds: xr.Dataset, name: str = "", limit: int = 8) -> str:
    """The scene, axes, fixed parameters, counts and provenance of an atlas (or the intervals of critical values).

    Every line fits in :data:`WIDTH` characters but for a single word longer than that (a path); fixed parameters
    come in the system's groups (per body for gyroscopes), each group's scene notes (liquid modes) beside it.
    ``limit``: lines of critical values listed (0: every line, and every gap of each; an atlas lists nothing per line).
    """
    if is_critical(ds):
        head = f"{name}: {ds.attrs.get('title', '')}: critical values along {ds.attrs['critical_along']}"
        comment = textwrap.wrap(ds.attrs["comment"], width=WIDTH, initial_indent="  ", subsequent_indent="  ")
        from .table import counts_line, critical_summary

        dims = list(ds["n_stable_intervals"].dims)
        line = counts_line(critical_summary(ds), dims, in_units.display_unit(ds, str(ds.attrs["critical_along"])))
        counts = textwrap.wrap(line, width=WIDTH, initial_indent="  ", subsequent_indent="    ")
        return "\n".join([head, *comment, *counts, *intervals(ds, limit)])
    system = systems.of_atlas(ds.attrs)
    s = summary(ds)
    a = ds.attrs
    lines = textwrap.wrap(f"{name}: {a.get('title', '')}", width=WIDTH, subsequent_indent="    ")
    for line in system.describe(a):
        lines += textwrap.wrap(line, width=WIDTH, initial_indent="  ", subsequent_indent="    ")
    lines += textwrap.wrap(s["headline"], width=WIDTH, initial_indent="  ", subsequent_indent="    ")  # before the details
    notes = scene_notes(a)
    lines.append("  axes:")
    dims = ds[system.label].dims
    name_width = max([10, *map(len, dims)])
    for d in dims:
        c = ds[d]
        shown = display_range(c)
        lines.append(
            f"    {d:<{name_width}} {plural(c.size, 'point'):>11}  "
            f"{float(c.min()):.6g} .. {float(c.max()):.6g}{unit_suffix(c.attrs.get('units'))}{shown}  "
            f"({c.attrs.get('scale', '')})  {c.attrs.get('long_name', '')}"
        )
    # auxiliary coordinates: what a ratio axis (S_g, C/A, h/a) moves, and S_g where M_alpha acts (docs/projectile.md)
    derived = [k for k, c in ds.coords.items() if c.ndim and k not in ds.dims and not str(k).endswith("_bounds")]
    if derived:
        lines.append("  set by the axes:")
    for k in derived:
        c = ds[k]
        lines += textwrap.wrap(f"{k:<{name_width}} over {', '.join(c.dims)}: {float(c.min()):.6g} .. {float(c.max()):.6g}"
                               f"{unit_suffix(c.attrs.get('units'))}  {c.attrs.get('long_name', '')}", width=WIDTH,
                               initial_indent="    ", subsequent_indent="      ")
    groups = fixed_parameters(ds, system)
    if groups:
        lines.append("  fixed:")
    for head, items in groups:
        lines += wrapped(f"{head}: " if head else "", items, indent="    ", whole=True)
        for text in notes.pop(head, []):  # e.g. the liquid of this body, under its parameters
            lines += wrapped(" " * (len(head) + 2) if head else "", [text], indent="    ")
    for head, texts in notes.items():  # notes of a group with no fixed parameter (every one scanned)
        for text in texts:
            lines += wrapped(f"{head}: " if head else "", [text], indent="  ")
    if system.stable_label is not None:
        degenerate = f", degenerate: {s['degenerate']}" if s["degenerate"] else ""
        absent = f", absent: {s['absent']}" if s["absent"] else ""
        undecided = f", undecided (not proved): {s['undecided']}" if s["undecided"] else ""
        stable = f"{system.stable_word}: {s['stable']} ({100 * s['stable_fraction']:.2f} %)"
        lines.append(f"  points: {s['points']}, {stable}" + degenerate + absent + undecided)
    else:
        lines.append(f"  points: {s['points']}")
    flags = system.variable(system.label).flags
    meaning = (lambda k: system.variable(system.label).meaning(k)) if flags else str  # a flag label: its meanings
    lines += wrapped(f"{system.label} ({system.label_symbol}): ", [f"{meaning(k)}: {v}" for k, v in s[system.label].items()])
    if system.provenance in s:
        lines += wrapped("decided by: ", [f"{k.replace('_', ' ')} {v}" for k, v in s[system.provenance].items() if v])
    if "growth_rate" in s:
        g = s["growth_rate"]
        top = f"largest {g['max']:.6g} s-1 (proved <= {g['max_upper']:.6g})"
        if not g["max"] > 0:
            top = "none grows" if g["max"] == 0 else f"every mode decays, the slowest at {g['max']:.6g} s-1 (proved <= {g['max_upper']:.6g})"
        lines += wrapped("growth rate: ", [top, *(f"{m.replace('_', ' ')} {n}" for m, n in g["method"].items() if n)])
    lines += modes(ds)
    for line in system.caveats(ds):
        lines += textwrap.wrap(line, width=WIDTH, initial_indent="  ", subsequent_indent="    ")
    if "cell" in s:  # their shares of the region are in the headline
        counts = [f"{m.replace('_', ' ')} {n}" for m, n in s["cell"].items() if n]
        lines += wrapped("cells: ", counts[:-1] + [counts[-1] + " (docs/cells.md)"])
    lines += times(a)
    lines += provenance(a)
    return "\n".join(lines)


def modes(ds: xr.Dataset) -> list[str]:
    """The modes of an atlas that stores every root on a ``mode`` dimension: how many, the axis they are followed
    along, and how the links between neighbouring points went (``mode_tracking``, docs/rates.md)."""
    if "mode_tracking" not in ds or "mode" not in ds.dims:
        return []
    from .blocks import counts

    along = ds["mode"].attrs.get("followed_along")
    head = f"modes: {ds.sizes['mode']}, " + (f"followed along {along}" if along else "by ascending real part (no spin axis)")
    var = ds["mode_tracking"]
    by = counts(var.data)
    names = dict(zip(var.attrs.get("flag_values", []), str(var.attrs.get("flag_meanings", "")).split(), strict=False))
    links = [f"{names.get(k, k)} {n:,}" for k, n in sorted(by.items()) if names.get(k) in ("followed", "ambiguous") and n]
    return wrapped(head + ("; links " if links else ""), links[:-1] + [links[-1] + " (mode_tracking)"] if links else [])


def times(attrs: dict) -> list[str]:
    """The seconds the run that made the atlas spent, by stage (``stabmap.run.costs``); nothing for an atlas
    written before they were kept."""
    seconds = costs.from_attrs(attrs)
    if not seconds:
        return []
    threads = int(attrs.get(costs.THREADS, 1))
    stages = [k for k in seconds if k not in (costs.WRITE, costs.WALL)]
    stages.sort(key=lambda k: (k != LABELS, k != CELLS, k))
    shown = [f"{'cells (box proofs)' if k == CELLS else k} {_seconds(seconds[k])}" for k in stages if k == LABELS or seconds[k] > 0]
    on = f" (CPU-seconds on {plural(threads, 'thread')})" if threads > 1 else ""
    text = f"work {_seconds(costs.work(seconds))} summed over tasks{on}: {', '.join(shown)}"
    if costs.WRITE in seconds:
        text += f"; writing {_seconds(seconds[costs.WRITE])}"
    if costs.WALL in seconds:
        text += f"; wall {_seconds(seconds[costs.WALL])}"
    lines = wrapped("time: ", [text])
    timed = attrs.get(costs.TIMED)
    if timed and timed != costs.WHOLE:
        lines += wrapped("", [f"timed: {timed}"], indent="    ")
    return lines


def _seconds(x: float) -> str:
    return f"{x:.2g} s" if x < 0.1 else f"{x:.2f} s" if x < 1 else f"{x:.1f} s" if x < 1000 else f"{x:,.0f} s"


def provenance(attrs: dict) -> list[str]:
    """Who made the atlas and what was done to it, each step once: ``history`` lines, and ``source`` only when no
    history line names it already."""
    source = str(attrs.get("source", "?"))
    history = [h.strip() for h in str(attrs.get("history", "")).splitlines() if h.strip()]
    lines = [] if any(source in h for h in history) else [f"  made by {source}"]
    for k, h in enumerate(history):
        lines += textwrap.wrap(h, width=WIDTH, initial_indent="  history: " if k == 0 else " " * 11, subsequent_indent=" " * 13)
    return lines


def scene_notes(attrs: dict) -> dict[str, list[str]]:
    """What the stored scene says of itself beyond its parameters (its ``notes()``: the liquid modes kept), by the
    group of :meth:`System.fixed_groups` they belong to (``""``: the whole scene).

    The scene is read back from the atlas, so the lines say what that scene chooses;
    a scene this version no longer reads is reported, not fatal: the atlas is still described.
    """
    if "scene" not in attrs:
        return {}
    try:
        scene = systems.loads_scene(str(attrs["scene"]), "the atlas's scene")
    except StabmapError as exc:
        return {"": [f"(the stored scene does not load in this version: {exc})"]}
    out: dict[str, list[str]] = {}
    for head, text in scene.notes():
        out.setdefault(head, []).append(text)
    return out


def intervals(ds: xr.Dataset, limit: int = 8) -> list[str]:
    """Stable intervals of a critical-values Dataset, for the first ``limit`` points of the other axes (0: all of them,
    and then every undecided gap, not only the first 4 of each point)."""
    if limit < 0:
        raise StabmapError(f"{given('limit', limit)}: must be >= 0 (0 lists every point)")
    gaps_shown = 4 if limit else None
    along = ds.attrs["critical_along"]
    names = [f"{along}_stable_{end}" for end in ("lower", "upper", "lower_outer", "upper_outer")]
    dims = [d for d in ds[names[0]].dims if d != "interval"]
    table = ds[names].stack(point=dims) if dims else ds[names].expand_dims(point=[0])
    lo, hi, olo, ohi = (table[n].transpose("point", "interval").values for n in names)
    units = ds[names[0]].attrs.get("units", "")
    gaps = None
    if "n_undecided" in ds:  # critical files before box proofs have no gaps
        g = ds[["n_undecided", "undecided_lower", "undecided_upper"]]
        g = g.stack(point=dims) if dims else g.expand_dims(point=[0])
        gaps = g["n_undecided"].values, g["undecided_lower"].transpose("point", "gap").values, g["undecided_upper"].transpose("point", "gap").values
    disp = in_units.display_unit(ds, along)

    def end(value: float, what: str) -> str:  # a spin rate in its display unit first, the stored value beside
        if not disp:
            return f"{value:.10g} ({what})"
        return f"{in_units.in_display(value, disp):.10g} {disp} ({value:.10g}{unit_suffix(units)}, {what})"

    lines = []
    for p, label in enumerate(table["point"].values[:limit or None]):
        where = ", ".join(f"{d} = {in_units.axis_value(ds, d, v)}" for d, v in zip(dims, label, strict=True)) if dims else "the scene"
        parts = [
            f"{end(lo[p, k], 'scan start' if np.isnan(olo[p, k]) else 'boundary')} to "
            f"{end(hi[p, k], 'scan end' if np.isnan(ohi[p, k]) else 'boundary')}"
            for k in range(lo.shape[1])
            if np.isfinite(lo[p, k])
        ]
        head = "" if disp else f" [{unit_suffix(units).strip()}]" if unit_suffix(units) else ""
        lines.append(f"{where}: stable {along}{head} " + ("; ".join(parts) if parts else "nowhere in the scan"))
        if gaps is not None and gaps[0][p]:
            n = int(gaps[0][p])
            ends = zip(gaps[1][p, :n][:gaps_shown], gaps[2][p, :n][:gaps_shown], strict=True)
            pieces = [in_units.span_text(a, b, units, disp, 10) if disp else f"{a:.10g} to {b:.10g}" for a, b in ends]
            more = f" and {n - gaps_shown} more (--all lists every one)" if gaps_shown and n > gaps_shown else ""
            lines.append(f"  not proved inside {n} gap{'s' if n > 1 else ''}: " + "; ".join(pieces) + more)
    if limit and lo.shape[0] > limit:
        lines.append(f"... and {lo.shape[0] - limit} more points in the file (--all or --limit 0 lists every one; "
                     "'stabmap query FILE --csv' gives them as a table)")
    return lines
