"""Tables of a critical-values file (``stabmap critical``): one row per stable interval, boundary and undecided gap.

A critical-values Dataset stores its intervals padded along ``interval``, ``boundary`` and ``gap`` (NaN pads;
docs/critical.md), so a plain ``ds.to_dataframe()`` would cross every padded slot of every dimension with every
other. The functions here read the padded arrays line by line (a *line* is one point of the other grid axes) and
keep only the real entries:

- :func:`intervals_frame` (``ds.stabmap.to_dataframe()``): one row per stable interval;
- :func:`critical_table`: the stable intervals, the boundaries, the undecided gaps and the lines with no stable
  interval, one row each, in order along the scanned axis (what ``stabmap query FILE`` prints);
- :func:`critical_summary` (``ds.stabmap.summary()``): counts, per line and in total;
- :func:`render_table`: the table as the text, CSV or JSON of ``stabmap query``.
"""

from __future__ import annotations

import io

import numpy as np
import pandas as pd
import xarray as xr

from .. import systems
from ..errors import StabmapError
from ..store.dataset import CRITICAL_KIND as KIND
from ..store.dataset import is_critical
from . import shown

ROWS = ("boundary", "stable_interval", "undecided_gap", "no_stable_interval")  # the ``row`` kinds, in this order at equal lower ends


def check_critical(ds: xr.Dataset, question: str) -> str:
    """The scanned axis of a critical-values Dataset; a StabmapError naming what to use instead for anything else."""
    if not is_critical(ds):
        raise StabmapError(
            f"{question} tabulates the stable intervals of a critical-values file (stabmap critical); this Dataset is "
            "an atlas: ask it with ds.stabmap.boundaries(AXIS) or ds.stabmap.smallest_stable(AXIS), whose answers have "
            "their own .to_dataframe() (docs/query.md), or make critical values with 'stabmap critical SCENE --along AXIS'"
        )
    return str(ds.attrs["critical_along"])


def _lines(ds: xr.Dataset) -> tuple[list[str], dict[str, np.ndarray]]:
    """The other grid axes and their values on every line, lines in C order (the order of a reshape)."""
    dims = list(ds["n_stable_intervals"].dims)
    grids = np.meshgrid(*(ds[d].values for d in dims), indexing="ij") if dims else []
    return dims, {d: g.ravel() for d, g in zip(dims, grids, strict=True)}


def _flat(ds: xr.Dataset, name: str, dims: list[str], slot: str | None = None) -> np.ndarray:
    """A variable as (line, slot) or (line,): the other axes flattened in the order of :func:`_lines`."""
    var = ds[name].transpose(*dims, *([slot] if slot else []))
    values = np.asarray(var.values)
    return values.reshape(-1, values.shape[-1]) if slot else values.reshape(-1)


def _shape(ds: xr.Dataset, dims: list[str]) -> tuple[int, ...]:
    return tuple(ds.sizes[d] for d in dims)


def _units(ds: xr.Dataset, name: str) -> str:
    units = str(ds[name].attrs.get("units", "")) if name in ds.variables else ""
    return "" if units == "1" else units


def _intervals(ds: xr.Dataset, along: str, dims: list[str]) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """(line, interval number, columns) of every stable interval: its ends, outer values and flags."""
    names = [f"{along}_stable_{end}" for end in ("lower", "upper", "lower_outer", "upper_outer")]
    lo, hi, olo, ohi = (_flat(ds, n, dims, "interval") for n in names)
    line, k = np.nonzero(np.isfinite(lo))
    whole_name = f"{along}_stable_whole"
    # files made before box proofs have no <along>_stable_whole: their intervals were not proved between scan values
    whole = _flat(ds, whole_name, dims, "interval")[line, k] == 1 if whole_name in ds else np.zeros(line.size, dtype=bool)
    columns = {n: v[line, k] for n, v in zip(names, (lo, hi, olo, ohi), strict=True)}
    columns.update({"from_scan_start": np.isnan(olo[line, k]), "to_scan_end": np.isnan(ohi[line, k]), "proved_throughout": whole})
    return line, k, columns


def intervals_frame(ds: xr.Dataset) -> pd.DataFrame:
    """One row per stable interval of a critical-values Dataset (``ds.stabmap.to_dataframe()``).

    Parameters
    ----------
    ds : xarray.Dataset
        Critical values (``stabmap.critical`` or a file of ``stabmap critical``).

    Returns
    -------
    pandas.DataFrame
        Columns: the other grid axes (their values on the interval's line), ``interval`` (its number on the
        line, from 0 upward), ``<along>_stable_lower`` and ``<along>_stable_upper`` (the ends, proved stable
        [units of along]), ``<along>_stable_lower_outer`` and ``<along>_stable_upper_outer`` (the values just
        outside, proved unstable: each boundary lies between an end and its outer value; NaN at the scan
        range's end), ``from_scan_start`` and ``to_scan_end`` (True: the interval meets that end of the scan
        range and may continue beyond it) and ``proved_throughout`` (False: an undecided gap overlaps it, so it
        is proved stable only at its ends and outside the gaps). A line without a stable interval has no row.
        ``.attrs["units"]`` maps every column to its units.
    """
    along = check_critical(ds, "to_dataframe()")
    dims, coords = _lines(ds)
    line, k, columns = _intervals(ds, along, dims)
    frame = pd.DataFrame({**{d: coords[d][line] for d in dims}, "interval": k.astype(np.int64), **columns})
    frame.attrs["units"] = {**{d: _units(ds, d) for d in dims}, **{n: _units(ds, n) for n in columns}}
    frame.attrs["along"] = along
    return frame


def critical_table(ds: xr.Dataset) -> pd.DataFrame:
    """Every stable interval, boundary and undecided gap of a critical-values Dataset, one row each.

    Returns
    -------
    pandas.DataFrame
        ``row`` says what a row is: ``stable_interval``, ``boundary`` (a change of the label, bracketed),
        ``undecided_gap`` (the label is proved at both ends, and the same there, but not inside) or
        ``no_stable_interval`` (a line with no stable value in the scan range). Then the other grid axes;
        ``<along>_lower`` and ``<along>_upper`` (the interval's ends, proved stable; a boundary's bracket; a
        gap's ends); ``<along>_lower_outer`` and ``<along>_upper_outer``, ``from_scan_start``, ``to_scan_end`` and
        ``proved_throughout`` (stable intervals, as in :func:`intervals_frame`); ``<label>_below`` and
        ``<label>_above`` (boundaries: the label at the bracket's ends, a flag label as its meaning). Rows come
        line by line, in order along the scanned axis; a column that does not apply to a row is empty (NaN or
        None). ``.attrs["units"]`` maps columns to units.
    """
    along = check_critical(ds, "the table of critical values")
    system = systems.of_atlas(ds.attrs)
    label = system.variable(system.label)
    lab = label.name
    dims, coords = _lines(ds)
    lower, upper, olo, ohi = f"{along}_lower", f"{along}_upper", f"{along}_lower_outer", f"{along}_upper_outer"
    parts = []

    def rows(kind, line, **columns):
        parts.append(pd.DataFrame({"row": kind, "line": line, **{d: coords[d][line] for d in dims}, **columns}))

    line, _, iv = _intervals(ds, along, dims)
    stable = dict(zip((lower, upper, olo, ohi), (iv[f"{along}_stable_{e}"] for e in ("lower", "upper", "lower_outer", "upper_outer")), strict=True))
    rows("stable_interval", line, **stable, **{k: iv[k].astype(object) for k in ("from_scan_start", "to_scan_end", "proved_throughout")})
    b_lo, b_hi = _flat(ds, "boundary_lower", dims, "boundary"), _flat(ds, "boundary_upper", dims, "boundary")
    below, above = _flat(ds, f"{lab}_below", dims, "boundary"), _flat(ds, f"{lab}_above", dims, "boundary")
    line, k = np.nonzero(np.isfinite(b_lo))
    meanings = dict(label.flags)
    shown = (lambda v: pd.Series(v).map(meanings).to_numpy(dtype=object)) if label.flags else (lambda v: v.astype(np.int64))
    rows("boundary", line, **{lower: b_lo[line, k], upper: b_hi[line, k],
                              f"{lab}_below": shown(below[line, k]), f"{lab}_above": shown(above[line, k])})
    if "undecided_lower" in ds:  # critical files made before box proofs have no gaps
        g_lo, g_hi = _flat(ds, "undecided_lower", dims, "gap"), _flat(ds, "undecided_upper", dims, "gap")
        line, k = np.nonzero(np.isfinite(g_lo))
        rows("undecided_gap", line, **{lower: g_lo[line, k], upper: g_hi[line, k]})
    rows("no_stable_interval", np.flatnonzero(_flat(ds, "n_stable_intervals", dims) == 0))
    columns = ["row", *dims, lower, upper, olo, ohi, "from_scan_start", "to_scan_end", "proved_throughout", f"{lab}_below", f"{lab}_above"]
    table = pd.concat([p for p in parts if len(p)] or [pd.DataFrame(columns=["row", "line", lower])], ignore_index=True)
    table["order"] = table["row"].map({r: i for i, r in enumerate(ROWS)})
    table = table.sort_values(["line", lower, "order"], kind="stable", na_position="first").reindex(columns=columns)
    table = table.reset_index(drop=True)
    for name in ("from_scan_start", "to_scan_end", "proved_throughout"):
        table[name] = table[name].astype("boolean")  # empty (pd.NA) on the rows they do not apply to
    if not label.flags:
        table[[f"{lab}_below", f"{lab}_above"]] = table[[f"{lab}_below", f"{lab}_above"]].astype("Int64")
    units = _units(ds, "boundary_lower")
    table.attrs["units"] = {**{d: _units(ds, d) for d in dims}, lower: units, upper: units, olo: units, ohi: units}
    table.attrs["along"] = along
    table.attrs["label"] = lab
    return table


def critical_summary(ds: xr.Dataset) -> dict:
    """Counts that describe a critical-values Dataset (``ds.stabmap.summary()`` and ``stabmap info`` of one).

    Returns
    -------
    dict
        ``kind`` (``"critical values"``), ``along`` and ``units``, ``scan_range`` (first and last scan value);
        ``lines`` (points of the other grid axes), ``stable_intervals`` (in all), ``n_stable_intervals`` (a
        histogram: how many lines have 0, 1, 2, ... intervals), ``boundaries``, ``undecided_gaps``,
        ``lines_with_gaps`` and ``intervals_with_gap_inside`` (intervals not proved stable throughout);
        ``stable_length`` (the intervals' lengths summed over every line [units]; an interval with a gap inside
        counts whole) and ``stable_length_proved`` (only the intervals proved stable throughout),
        ``stable_share`` (``stable_length`` over the scan range's length times ``lines``); ``smallest_stable``
        (the lowest stable value on any line: ``value``, ``outer`` (proved unstable just below it, None at the
        scan start) and the line's axes; None if nothing is stable) and ``per_line``, an xarray.Dataset on the
        other axes with ``n_stable_intervals``, ``stable_length``, ``smallest_stable``, ``smallest_stable_outer``,
        ``n_boundaries`` and ``n_undecided``.
    """
    along = check_critical(ds, "the summary of critical values")
    dims, coords = _lines(ds)
    units = _units(ds, f"{along}_stable_lower")
    line, k, iv = _intervals(ds, along, dims)
    nlines = int(np.prod(_shape(ds, dims))) if dims else 1
    length = iv[f"{along}_stable_upper"] - iv[f"{along}_stable_lower"]
    per_length = np.bincount(line, weights=length, minlength=nlines)
    first = k == 0  # intervals are stored in increasing order on each line
    smallest = np.full(nlines, np.nan)
    smallest_outer = np.full(nlines, np.nan)
    smallest[line[first]] = iv[f"{along}_stable_lower"][first]
    smallest_outer[line[first]] = iv[f"{along}_stable_lower_outer"][first]
    n_int = _flat(ds, "n_stable_intervals", dims).astype(np.int64)
    n_bound = np.isfinite(_flat(ds, "boundary_lower", dims, "boundary")).sum(axis=1)
    n_gaps = _flat(ds, "n_undecided", dims).astype(np.int64) if "n_undecided" in ds else np.zeros(nlines, dtype=np.int64)
    scan = [float(v) for v in np.ravel(ds.attrs.get("critical_scan_range", [np.nan, np.nan]))]
    out = {
        "kind": KIND, "along": along, "units": units, "scan_range": tuple(scan), "lines": nlines,
        "stable_intervals": int(line.size),
        "n_stable_intervals": dict(sorted(zip(*(v.tolist() for v in np.unique(n_int, return_counts=True)), strict=True))),
        "boundaries": int(n_bound.sum()), "undecided_gaps": int(n_gaps.sum()), "lines_with_gaps": int(np.count_nonzero(n_gaps)),
        "intervals_with_gap_inside": int(np.count_nonzero(~iv["proved_throughout"])),
        "stable_length": float(length.sum()), "stable_length_proved": float(length[iv["proved_throughout"]].sum()),
        "stable_share": float(length.sum() / (nlines * (scan[1] - scan[0]))) if scan[1] > scan[0] else float("nan"),
        "smallest_stable": None,
    }
    if line.size:
        i = int(np.argmin(iv[f"{along}_stable_lower"]))
        outer = iv[f"{along}_stable_lower_outer"][i]
        out["smallest_stable"] = {"value": float(iv[f"{along}_stable_lower"][i]), "outer": None if np.isnan(outer) else float(outer),
                                  **{d: float(coords[d][line[i]]) for d in dims}}

    def var(values, long_name, units="1", **attrs):
        return (dims, np.asarray(values).reshape(_shape(ds, dims)), {"long_name": long_name, "units": units, **attrs})

    out["per_line"] = xr.Dataset(
        {
            "n_stable_intervals": var(n_int, "number of stable intervals in the scan range"),
            "stable_length": var(per_length, f"total length of the stable intervals of {along}", units,
                                 comment="an interval with an undecided gap inside counts whole"),
            "smallest_stable": var(smallest, f"lowest stable {along} (lower end of the first stable interval)", units,
                                   comment="NaN: nothing stable in the scan range"),
            "smallest_stable_outer": var(smallest_outer, f"{along} just below smallest_stable, proved unstable", units,
                                         comment="NaN where smallest_stable is the first scan value (it may continue below) or nothing is stable"),
            "n_boundaries": var(n_bound, "number of located changes of the label"),
            "n_undecided": var(n_gaps, "number of undecided gaps"),
        },
        coords={d: ds[d].variable for d in dims},
    )
    return out


def select_lines(ds: xr.Dataset, sel: dict, *, nearest_edge: bool = False) -> xr.Dataset:
    """The lines of a critical-values Dataset that ``sel`` selects: ``{axis: number}`` keeps the grid value nearest
    to it (outside the scan an error, unless ``nearest_edge``), ``{axis: (lo, hi)}`` (None: open) the grid values in
    [lo, hi]; every axis stays a dimension."""
    from .derived import within
    from .query import outside_error, requested_value

    along = check_critical(ds, "a selection of critical values")
    dims = list(ds["n_stable_intervals"].dims)
    index = {}
    for name, value in sel.items():
        if name not in dims:
            what = "the scanned axis: every stable interval along it is listed" if name == along else "not a grid axis of this file"
            raise StabmapError(f"{name}: {what}; select the lines by their other axes: {', '.join(dims) or '(none: one line)'}")
        requested = requested_value(name, value)
        grid = np.asarray(ds[name].values, dtype=np.float64)
        if isinstance(requested, tuple):
            lo, hi = (-np.inf if requested[0] is None else requested[0]), (np.inf if requested[1] is None else requested[1])
            keep = np.flatnonzero((grid >= lo) & (grid <= hi))
            if not keep.size:
                raise StabmapError(f"{name} in [{lo:g}, {hi:g}] holds no grid value; the {grid.size} values of {name} run from "
                                   f"{grid.min():.8g} to {grid.max():.8g} {_units(ds, name)}".rstrip())
            index[name] = keep
        else:
            if not nearest_edge and not within(requested, float(grid.min()), float(grid.max())):
                raise outside_error(ds, name, requested, grid)
            index[name] = [int(np.argmin(np.abs(grid - requested)))]
    return ds.isel(index) if index else ds


def render_table(ds: xr.Dataset, fmt: str = "text", *, limit: int = 40) -> str:
    """:func:`critical_table` as the text, CSV or JSON that ``stabmap query FILE`` prints.

    CSV and JSON hold every row; their headers carry the units (``omega_lower [rad s-1]``), NaN and the fields that
    do not apply to a row are empty (JSON ``null``). ``limit`` caps the rows of the text (0: all).
    """
    from .report import FORMATS, json_text, more_rows_line, plain_value, text_table

    if fmt not in FORMATS:
        raise StabmapError(f"format {fmt!r}: choose one of {', '.join(FORMATS)}")
    table = critical_table(ds)
    units = table.attrs["units"]
    along, lab = table.attrs["along"], table.attrs["label"]
    if fmt == "csv":
        named = table.rename(columns={c: f"{c} [{units[c]}]" for c in table.columns if units.get(c)})
        buf = io.StringIO()
        named.to_csv(buf, index=False, lineterminator="\n", na_rep="")
        return buf.getvalue().rstrip("\n")
    s = critical_summary(ds)
    if fmt == "json":
        records = [{k: (None if v is pd.NA else plain_value(v)) for k, v in r.items()} for r in table.to_dict(orient="records")]
        head = {"stabmap_query": "critical_values", "along": along, "along_units": s["units"], "label": lab,
                "comment": ds.attrs.get("comment", ""), "units": {k: v for k, v in units.items() if v}, "rows": records}
        return json_text(head)
    system = systems.of_atlas(ds.attrs)
    sym = system.label_symbol
    dims = [c for c in table.columns if c in ds.dims and c in ds.coords]
    disp = shown.display_unit(ds, along)
    u = shown.header_units(s["units"], disp)
    lines = [counts_line(s, dims, disp)]
    shown_in = {d: shown.display_unit(ds, d) for d in dims}
    header = [d + shown.header_units(units.get(d, ""), shown_in[d]) for d in dims]
    header += ["row", f"{along} lower{u}", f"{along} upper{u}", "note"]
    rows = []
    for r in (table if not limit else table.iloc[:limit]).to_dict(orient="records"):
        kind = r["row"]
        if kind == "stable_interval":
            note = (f"from {'scan start' if r['from_scan_start'] else 'a boundary'} to {'scan end' if r['to_scan_end'] else 'a boundary'}"
                    + ("" if r["proved_throughout"] else "; not proved stable inside its gaps"))
        elif kind == "boundary":
            note = f"{sym} {r[lab + '_below']} -> {r[lab + '_above']}"
        elif kind == "undecided_gap":
            note = f"{sym} proved the same at both ends, not proved inside"
        else:
            note = f"nothing stable from {s['scan_range'][0]:.8g} to {s['scan_range'][1]:.8g}"
        ends = [r[f"{along}_lower"], r[f"{along}_upper"]]
        rows.append([shown.cell(r[d], shown_in[d]) for d in dims]
                    + [kind.replace("_", " "), *(shown.cell(v, disp, 10) if v == v else "-" for v in ends), note])
    lines += text_table(header, rows) if rows else ["(no rows)"]
    lines += more_rows_line(len(table), limit)
    lines.append("Stable ends are proved stable, and the boundary lies between each end and the proved-unstable value just "
                 f"outside it (--csv: {along}_lower_outer, {along}_upper_outer); a boundary row is that bracket (docs/critical.md).")
    return "\n".join(lines)


def counts_line(s: dict, dims: list[str], display: str = "") -> str:
    """One line of counts: intervals, boundaries and gaps on how many lines (``display``: the scanned axis's display unit)."""
    u = shown.header_units(s["units"], display)
    on = f"on {s['lines']} line{'s' if s['lines'] != 1 else ''} of {', '.join(dims)}" if dims else "on the one line of the scene"
    gaps = (f"{s['undecided_gaps']} undecided gap{'s' if s['undecided_gaps'] != 1 else ''} (on {s['lines_with_gaps']} "
            f"line{'s' if s['lines_with_gaps'] != 1 else ''})" if s["undecided_gaps"] else "no undecided gap")
    return (f"critical values along {s['along']}{u}: {s['stable_intervals']} stable interval{'s' if s['stable_intervals'] != 1 else ''}"
            f" and {s['boundaries']} boundar{'ies' if s['boundaries'] != 1 else 'y'} {on}; {gaps}")
