"""Answers of stabmap.read.query as the text, CSV or JSON that ``stabmap query`` prints."""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np
import xarray as xr

from .. import systems
from ..errors import StabmapError
from ..scene.units import unit_suffix
from . import shown
from .query import CRITICAL_HINT, Label, StableFraction

FORMATS = ("text", "csv", "json")
SUFFIXES = {".csv": "csv", ".json": "json", ".txt": "text", ".text": "text", "": "text"}  # what -o FILE's suffix asks for


def output_format(fmt: str | None, output) -> str:
    """The format of an answer: ``fmt`` (--csv, --json) if given, else the one ``output``'s suffix names (``frac.csv``:
    CSV), else text. A suffix that names no format, or another one than ``fmt``, is a StabmapError: a file named
    .csv holds CSV."""
    if output is None:
        return fmt or "text"
    from pathlib import Path

    suffix = Path(output).suffix.lower()
    named = SUFFIXES.get(suffix)
    if named is None:
        raise StabmapError(f"-o {output}: stabmap query writes text (.txt), CSV (.csv) or JSON (.json); name the file with one of "
                           "these suffixes")
    if fmt is not None and fmt != named and suffix:
        raise StabmapError(f"-o {output}: the suffix {suffix} names {named} but --{fmt} was given; name the file "
                           f"{Path(output).stem}.{fmt}, or leave out --{fmt}")
    return fmt or named


def render(result, fmt: str = "text", *, limit: int = 40, atlas: xr.Dataset | None = None) -> str:
    """The text, CSV or JSON of an answer (a Label, a StableFraction, or a boundaries/smallest_stable Dataset).

    ``limit`` caps the rows of a text table (0: all); CSV and JSON are always complete. ``atlas`` supplies the
    units of a Label's axes.
    """
    if fmt not in FORMATS:
        raise StabmapError(f"format {fmt!r}: choose one of {', '.join(FORMATS)}")
    if isinstance(result, Label):
        return {"text": _label_text, "csv": _label_csv, "json": _label_json}[fmt](result, atlas)
    if isinstance(result, StableFraction):
        return {"text": _fraction_text, "csv": _fraction_csv, "json": _fraction_json}[fmt](result)
    kind = result.attrs.get("stabmap_query") if isinstance(result, xr.Dataset) else None
    if kind not in ("boundaries", "smallest_stable"):
        raise StabmapError(f"cannot render {type(result).__name__}: not an answer of stabmap.read.query")
    frame = _frame(result)
    if fmt == "csv":
        buf = io.StringIO()
        frame.to_csv(buf, index=False, lineterminator="\n")
        return buf.getvalue().rstrip("\n")
    if fmt == "json":
        head = {k: result.attrs[k] for k in ("stabmap_query", "along", "along_units", "selection", "comment")}
        if result.attrs.get("along_display_units"):
            head["along_display_units"] = result.attrs["along_display_units"]
        head["fixed"] = {k: float(result[k]) for k in _fixed_axes(result)}
        head["rows"] = frame.to_dict(orient="records")
        if "undecided_lower" in result:
            gaps = zip(result["undecided_lower"].values, result["undecided_upper"].values, strict=True)
            head["undecided"] = [[float(a), float(b)] for a, b in gaps]
        return json_text(head)
    return (_boundaries_text if kind == "boundaries" else _smallest_text)(result, frame, limit)


def _units(ds: xr.Dataset | None, name: str) -> str:
    """`` s-1`` after a value of ``name`` (its ``units`` attribute), ``""`` for none, a flag or a count."""
    if ds is None or name not in ds.variables or "flag_values" in ds[name].attrs:
        return ""
    return unit_suffix(ds[name].attrs.get("units"))


def _label_text(label: Label, atlas: xr.Dataset | None) -> str:
    lines = []
    for k, v in label.requested.items():
        note = " (outside the scan: nearest edge, as asked)" if k in label.outside else ""
        asked = (f"{label.via[k]}\n{k}" if k in label.via
                 else f"{k} = {shown.value_text(v, shown.stored_units(atlas, k), shown.display_unit(atlas, k), 6)}")
        lines.append(f"{asked} -> nearest grid point {shown.axis_value(atlas, k, label.grid_point[k])}" + note)
    for k, v in label.derived.items():  # functions of the grid axes (S_g, a moved half height): at the grid point used
        on = " and ".join(map(str, atlas[k].dims)) if atlas is not None and k in atlas.variables else "the grid"
        lines.append(f"{k} = {shown.axis_value(atlas, k, v)} at that grid point (derived from {on})")
    # NAME_lower and NAME_upper, a proved enclosure of NAME, are shown on NAME's line
    bounds = {k for k in label.values for end in ("_lower", "_upper") if k.endswith(end) and k[: -len(end)] in label.values}
    shown_values = [(k, v) for k, v in label.values.items() if k != label.provenance and k not in bounds]
    lines += [f"{k} = {_value(v)}{_units(atlas, k)}" + (f" ({CELL_TEXT[v]})" if k == "cell" and v in CELL_TEXT else "")
              + (f" (proved in [{_value(label.values[k + '_lower'])}, {_value(label.values[k + '_upper'])}]{_units(atlas, k)})"
                 if k + "_lower" in bounds else "")
              for k, v in shown_values]
    if label.provenance is not None:
        how = str(label.values[label.provenance])  # a flag's meaning
        # How the point was decided qualifies its verdict (stability, else the label: the critical node), not
        # whichever variable happens to be last.
        names = [k for k, _ in shown_values]
        main = "stability" if "stability" in names else systems.of_atlas(atlas.attrs).label if atlas is not None else None
        at = len(lines) - len(shown_values) + names.index(main) if main in names else -1
        lines[at] += (
            " (not computed: inferred from the agreeing corners of its grid cell; docs/refine.md)"
            if label.inferred
            else " (not proved: the class is undecided)"
            if how == "undecided"
            else f" (decided by {how.replace('_', ' ')})"
        )
    return "\n".join(lines)


CELL_TEXT = {  # what the cell flag says about the requested point, which lies in the grid point's cell
    "whole_cell": "the label is proved at every point of this grid cell, the requested point included",
    "contains_change": "this grid cell is proved to hold a change of label: at the requested point it may differ",
    "node_only": "the label is proved at the grid point only; at the requested point it is not decided",
    "not_proved": "not proved even at the grid point",
}


def _value(v) -> str:
    if isinstance(v, float):
        return f"{v:.8g}"
    return np.array2string(v, precision=8) if isinstance(v, np.ndarray) else str(v)


def _label_record(label: Label) -> dict:
    return {**label.grid_point, **label.derived, **{k: plain_value(v) for k, v in label.values.items()}}


def _label_csv(label: Label, atlas) -> str:
    return _csv([_label_record(label)])


def _label_json(label: Label, atlas) -> str:
    return json_text({
        "stabmap_query": "label_at", "requested": label.requested, "grid_point": label.grid_point,
        "outside": list(label.outside), **({"derived": label.derived} if label.derived else {}),
        **({"via": label.via} if label.via else {}), **label.values, "inferred": label.inferred,
    })


def _fraction_text(f: StableFraction) -> str:
    lines = [
        f"stable fraction {f.fraction:.6g}: {f.stable} of {f.points} grid points stable ({100 * f.fraction:.2f} %), "
        f"{f.unstable} unstable" + (f", {f.degenerate} degenerate" if f.degenerate else "") + (f", {f.absent} absent" if f.absent else "")
        + (f", {f.undecided} undecided (not proved)" if f.undecided else "")
    ]
    lines += [f"  {a.describe()}" for a in f.axes.values()]
    if f.inferred:
        lines.append(
            f"  inferred: {f.inferred} of these points were not computed but inferred from their grid cell's corners "
            f"({f.inferred_stable} of them stable); among the computed points the stable fraction is {f.computed_fraction:.6g}"
        )
    else:
        lines.append("  inferred: 0 (every point was computed)")
    return "\n".join(lines)


def _fraction_record(f: StableFraction) -> dict:
    row = {k: getattr(f, k) for k in ("fraction", "stable", "points", "unstable", "degenerate", "inferred", "inferred_stable")}
    if f.absent is not None:
        row["absent"] = f.absent
    if f.undecided is not None:
        row["undecided"] = f.undecided
    for name, a in f.axes.items():
        row[f"{name}_lo"], row[f"{name}_hi"] = a.bounds
        row[f"{name}_n"] = len(a.values)
    return row


def _fraction_csv(f: StableFraction) -> str:
    return _csv([_fraction_record(f)])


def _fraction_json(f: StableFraction) -> str:
    out = {"stabmap_query": "stable_fraction", **{k: v for k, v in _fraction_record(f).items() if not k.startswith(tuple(f.axes))}}
    out["axes"] = {
        name: {"units": a.units, "requested": list(a.requested) if isinstance(a.requested, tuple) else a.requested,
               "grid_lo": a.bounds[0], "grid_hi": a.bounds[1], "grid_values": len(a.values), "outside": a.outside}
        for name, a in f.axes.items()
    }
    return json_text(out)


def _fixed_axes(result: xr.Dataset) -> list[str]:
    """The atlas axes that a number in the selection fixed (scalar coordinates of the answer)."""
    return result.attrs.get("fixed_axes", "").split()


def _frame(result: xr.Dataset):
    """A pandas table of a boundaries/smallest_stable answer: varying axes, fixed axes, then the variables."""
    scalars = [k for k in result.coords if result[k].ndim == 0]
    fixed = _fixed_axes(result)
    gaps = [k for k in result.variables if "gap" in result[k].dims]  # located boundaries' undecided stretches: apart
    table = result.drop_vars(scalars + gaps)
    if not table.sizes:  # smallest_stable of a one-axis atlas: one row
        frame = table.expand_dims("row").to_dataframe().reset_index(drop=True)
    elif result.attrs["stabmap_query"] == "boundaries":
        frame = table.to_dataframe().reset_index(drop=True)
    else:
        frame = table.to_dataframe().reset_index()
    for i, k in enumerate(fixed):
        frame.insert(i, k, float(result[k]))
    axes = fixed + [c for c in frame.columns if c in result.coords and c not in fixed]
    return frame[axes + [c for c in frame.columns if c not in axes]]


def short_number(v) -> str:
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (float, np.floating)):
        return "-" if np.isnan(v) else f"{v:.8g}"
    return str(v)


def text_table(header: list[str], rows: list[list[str]]) -> list[str]:
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(header)]
    return ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in [header, *rows]]


def _column(result: xr.Dataset, name: str) -> str:
    """A table's header for an axis: its name and units, a spin rate's display unit first (``omega [rpm (rad s-1)]``)."""
    return name + shown.header_units(str(result[name].attrs.get("units", "")), shown.display_unit(result, name))


def _cell(result: xr.Dataset, name: str, value) -> str:
    """A table cell of the axis ``name``: a spin rate in its display unit, SI beside (``_along_cell``)."""
    return _along_cell(value, shown.display_unit(result, name))


def _along_cell(value, disp: str) -> str:
    return shown.cell(float(value), disp) if disp and not _missing(value) else short_number(value)


def _missing(value) -> bool:
    return isinstance(value, (float, np.floating)) and bool(np.isnan(value))


def _head(result: xr.Dataset) -> list[str]:
    lines = [f"  {item}" for item in result.attrs["selection"].split("; ") if item]
    return lines


def more_rows_line(n: int, limit: int) -> list[str]:
    return [f"... and {n - limit} more rows (--limit 0 shows all; --csv or --json for every row)"] if limit and n > limit else []


def _boundaries_text(b: xr.Dataset, frame, limit: int) -> str:
    along, units, disp = b.attrs["along"], b.attrs["along_units"], b.attrs.get("along_display_units", "")
    lab, sym = b.attrs["label"], b.attrs["label_symbol"]
    u = shown.header_units(units, disp)
    n, lines_total = b.sizes["boundary"], b.attrs["n_lines"]
    lines = [
        f"boundaries along {along}{u}: {n} change{'s' if n != 1 else ''} of {sym} on {b.attrs['n_lines_with_boundary']} "
        f"of {lines_total} line{'s' if lines_total != 1 else ''}, "
        + ("each located to 1e-10 relative" if b.attrs.get("located") else "each between two neighbouring grid values")
    ]
    lines += _head(b)
    others = [c for c in frame.columns if c in b.coords and b[c].ndim == 1]
    header = [_column(b, d) for d in others]
    header += [f"{along} lower", f"{along} upper", f"{sym} below", f"{sym} above"]
    rows = []
    visible = frame if not limit else frame.iloc[:limit]
    star = False
    for r in visible.to_dict(orient="records"):
        nb = f"{r[lab + '_below']}" + ("*" if r["inferred_below"] else "")
        na = f"{r[lab + '_above']}" + ("*" if r["inferred_above"] else "")
        star |= bool(r["inferred_below"] or r["inferred_above"])
        rows.append([_cell(b, d, r[d]) for d in others] + [_along_cell(r["boundary_lower"], disp), _along_cell(r["boundary_upper"], disp), nb, na])
    if rows:
        lines += text_table(header, rows)
    else:
        lines.append(f"{sym} does not change between neighbouring grid values of {along} anywhere in this selection")
    lines += more_rows_line(len(frame), limit)
    if star:
        lines.append("* not computed: inferred from the agreeing corners of its grid cell (docs/refine.md)")
    if b.attrs.get("located"):
        lines += _gaps_text(b, along)
        return "\n".join(lines)
    located = b.attrs.get("located_by", f"{CRITICAL_HINT.format(along=along)}.")
    lines.append("Each change lies between the two grid values, not at either" + (f"; {located}" if located else "."))
    return "\n".join(lines)


def _gaps_text(b: xr.Dataset, along: str) -> list[str]:
    """The completeness of located boundaries: the stretches no proof decided, or that there are none."""
    n = int(b.attrs.get("n_undecided", 0))
    head = f"{b.attrs['located_by']}; "
    if not n:
        return [head + f"the list is complete: every other stretch of {along} is proved to keep its label"]
    stretches: list[str] = []
    if "undecided_lower" in b:
        units, disp = b.attrs.get("along_units", ""), b.attrs.get("along_display_units", "")
        stretches = [shown.span_text(a, c, units, disp, 10)
                     for a, c in zip(b["undecided_lower"].values[:6], b["undecided_upper"].values[:6], strict=True)]
    more = f" and {n - len(stretches)} more" if n > len(stretches) else ""
    return [head + f"complete but for {n} stretch{'es' if n != 1 else ''} not decided, where a change may hide: "
            + "; ".join(stretches) + more]


def _smallest_text(s: xr.Dataset, frame, limit: int) -> str:
    along, units, disp = s.attrs["along"], s.attrs["along_units"], s.attrs.get("along_display_units", "")
    lab, sym = s.attrs["label"], s.attrs["label_symbol"]
    u = shown.header_units(units, disp)
    lo, hi = s.attrs["along_range"]
    lines = [f"smallest stable {along}{u}, searched upward over {s.attrs['along_grid_values']} grid values "
             f"{shown.span_text(lo, hi, units, disp)}"]
    lines += _head(s)
    others = list(s["smallest_stable"].dims)
    header = [_column(s, d) for d in others]
    header += [f"smallest stable {along}", "unstable below", f"{sym} below", "stable to end"]
    rows = []
    visible = frame if not limit else frame.iloc[:limit]
    star = False
    for r in visible.to_dict(orient="records"):
        if np.isnan(r["smallest_stable"]):
            first, below, ncb = "none", "-", "-"
        else:
            first = _along_cell(r["smallest_stable"], disp) + ("*" if r["inferred"] else "")
            below = _along_cell(r["unstable_below"], disp) if not np.isnan(r["unstable_below"]) else "(scan start)"
            below_label = r[lab + "_below"]
            ncb = f"{below_label}" + ("*" if r["inferred_below"] else "") if below_label != s.attrs["label_fill"] else "-"
        star |= bool(r["inferred"] or r["inferred_below"])
        rows.append([_cell(s, d, r[d]) for d in others] + [first, below, ncb, short_number(r["stable_to_scan_end"]) if first != "none" else "-"])
    lines += text_table(header, rows)
    lines += more_rows_line(len(frame), limit)
    if star:
        lines.append("* not computed: inferred from the agreeing corners of its grid cell (docs/refine.md)")
    if s.attrs.get("located"):
        undecided = int(s["undecided_below"].sum()) if "undecided_below" in s else 0
        lines.append(
            f"The threshold is {s.attrs['located_by']}: stable just above it, unstable just below; '(scan start)': "
            "stable from the start of the range. "
            + (f"On {undecided} line{'s' if undecided != 1 else ''} a stretch below it is not decided (a smaller "
               "stable value may lie there)." if undecided else "Below it, every stretch is proved unstable.")
        )
        return "\n".join(lines)
    lines.append(
        f"The threshold lies between 'unstable below' and the smallest stable grid value; "
        f"'(scan start)': stable from the first grid value searched. {CRITICAL_HINT.format(along=along)}."
    )
    return "\n".join(lines)


def plain_value(v):
    if isinstance(v, np.ndarray):  # a variable with dimensions beyond the grid's (e.g. reactions per node)
        return plain_value(v.tolist())
    if isinstance(v, dict):
        return {str(k): plain_value(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [plain_value(x) for x in v]
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return None if math.isnan(v) else float(v)
    return v


def json_text(obj) -> str:
    return json.dumps(plain_value(obj), indent=1)


def _csv(rows: list[dict]) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue().rstrip("\n")
