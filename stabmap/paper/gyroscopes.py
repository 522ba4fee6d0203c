"""The gyroscope paper's cases n = 1, 2, 3 recomputed and checked (``stabmap paper gyroscopes``).

Each case is a bundled scene (``stabmap atlas --example NAME``) with two grid axes. For each one:

1. The atlas is computed by the engine and drawn (``stabmap.read.plot.atlas_figure``).
2. On a few rows of the second axis the engine locates every change of N_c along the case's
   ``along`` axis to 1e-10 relative (``stabmap.critical``).
3. Where the paper gives a closed form (``stabmap.systems.gyroscopes.paper.factors``: (23) without liquid is
   Maievskii's condition; (23) and (24) with one liquid mode, (33), (34) and the split
   (23) x (24) x (24) factor into polynomials of degree <= 3 whose discriminant decides), its
   boundaries are the real roots of the discriminant, as a polynomial in the ``along`` parameter,
   at which the closed-form count changes. They are drawn over the map (dense dotted curve), and
   the check requires the engine's boundaries and the closed form's to pair up one to one with
   the same N_c on either side and to agree to RTOL relative, and every point of the map to have
   the closed form's N_c (exact rational arithmetic).
4. Every case, closed form or not, is checked against the paper's printed determinant
   ((22), (29)-(32), (28); ``stabmap.systems.gyroscopes.paper.paper_polynomial``) in exact rational arithmetic: the N_c
   of every atlas point on the checked rows, and of both ends of every located boundary.

``scripts/paper_cases.py`` is a thin wrapper of this module for a source checkout (``--golden``).
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np

from stabmap.errors import StabmapError, given, param
from stabmap.examples import example
from stabmap.run import atlas
from stabmap.run.critical import critical
from stabmap.scene.grid import Axis, resample
from stabmap.store.files import write_atlas
from stabmap.systems.gyroscopes import paper
from stabmap.systems.gyroscopes.points import point_arrays

RTOL = 1e-8  # engine ends are located to 1e-10 and discriminant roots to ~1e-15; this leaves room for both


@dataclasses.dataclass(frozen=True)
class Case:
    name: str  # bundled example scene
    equation: str
    closed_form: str | None  # stabmap.systems.gyroscopes.paper.factors case, or None where the paper has no closed form
    along: str  # the axis along which boundaries are located


CASES = (
    Case("paper-n1-fixed-dry", "(23) without liquid: Maievskii's condition", "top", "omega"),
    Case("paper-n1-fixed-1mode", "(23), one liquid mode: cubic, discriminant >= 0", "top", "omega"),
    Case("paper-n1-fixed", "(23), two liquid modes (quartic: no closed form)", None, "omega"),
    Case("paper-n1-free", "(24), two liquid modes: lambda x cubic, discriminant >= 0", "free-body", "C_1"),
    Case("paper-n2-fixed", "(31), elastic joint", None, "omega"),
    Case("paper-n2-free", "(32), elastic joint", None, "omega"),
    Case("paper-n2-free-resonance", "(32), elastic joint, liquid near resonance", None, "omega"),
    Case("paper-n3-fixed", "(29), elastic joints", None, "omega"),
    Case("paper-n3-free", "(30), elastic joints", None, "omega"),
    Case("paper-n3-free-resonance", "(30), elastic joints, liquid near resonance", None, "omega"),
    Case("paper-n2-free-identical", "(34): identical free bodies, (F~ - 1/2)(F~ + 1/2)", "identical-free", "C"),
    Case("paper-n3-free-identical", "(33): identical free bodies, (F~ - 2/3)(F~ - 1/3)(F~ + 7/3)", "identical-free", "C"),
    Case("paper-n3-fixed-split", "a_2 = a_3 = 0: F_1 F_2 F_3, (23) x (24) x (24)", "split", "omega"),
)


def _other(scene, along: str) -> str:
    return next(a.name for a in scene.grid if a.name != along)


def _chains(scene, values: dict[str, np.ndarray]):
    """Exact paper.Chain of every point given by broadcast axis values, in C order."""
    pa = point_arrays(scene, values)
    return [paper.chain_from_arrays(pa.body[i], pa.joint[i], pa.g[i], pa.E[i], pa.kappa[i], pa.nmodes, pa.free) for i in range(len(pa.g))]


def closed_form_along(scene, case: Case, row: float) -> list[tuple[float, int, int]]:
    """Closed-form boundaries (value, N_c below, N_c above) along ``case.along`` at ``other = row``."""
    other = _other(scene, case.along)
    scan = next(a.array for a in scene.grid if a.name == case.along)
    chain = _chains(scene, {other: np.array([row]), case.along: np.array([scan[0]])})[0]
    _set_symbolic(chain, case.along)
    lo, hi = sorted((float(scan[0]), float(scan[-1])))
    return paper.closed_form_boundaries(paper.factors(chain, _closed_form(case)), lo, hi)


def _closed_form(case: Case) -> str:
    if case.closed_form is None:
        raise ValueError(f"{case.name}: the paper has no closed form for this case")
    return case.closed_form


def _set_symbolic(chain: paper.Chain, name: str) -> None:
    """Make the parameter ``name`` of ``chain`` the variable T of the closed form."""
    symbol, _, index = name.partition("_")
    columns = getattr(chain, symbol)
    for k in range(chain.n) if not index else (int(index) - 1,):
        columns[k] = paper.T


def closed_form_pairs_at(scene, case: Case, values: dict[str, np.ndarray]) -> np.ndarray:
    """N_c from the closed form at every point (C order of the broadcast values)."""
    return np.array([paper.closed_form_pairs(paper.factors(ch, _closed_form(case))) for ch in _chains(scene, values)])


def grid_values(ds) -> dict[str, np.ndarray]:
    """The atlas' axis values, shaped to broadcast over its grid (C order of ``n_complex_pairs``)."""
    dims = list(ds["n_complex_pairs"].dims)
    return {d: ds[d].values.reshape([-1 if i == j else 1 for j in range(len(dims))]) for i, d in enumerate(dims)}


def paper_pairs_at(scene, values: dict[str, np.ndarray]) -> np.ndarray:
    """N_c of the paper's printed determinant, exactly, at every point (C order)."""
    return np.array([paper.complex_pairs(paper.paper_polynomial(ch)) for ch in _chains(scene, values)])


def engine_boundaries(crit, other: str, row: float) -> list[tuple[float, float, int, int]]:
    """(lower, upper, N_c below, N_c above) of every located change at ``other = row``."""
    r = crit.sel({other: row})
    lo, hi = np.asarray(r["boundary_lower"]), np.asarray(r["boundary_upper"])
    below, above = np.asarray(r["n_complex_pairs_below"]), np.asarray(r["n_complex_pairs_above"])
    return [(float(lo[i]), float(hi[i]), int(below[i]), int(above[i])) for i in range(lo.size) if np.isfinite(lo[i])]


FINE = 65  # values of the re-scan of a step that hides a closed-form window


def _pair_up(found, closed):
    """Pairs (engine bracket, closed-form boundary) that agree to RTOL, then the closed-form boundaries and engine
    brackets left without a partner."""
    pairs, left = [], list(found)
    missed = []
    for c in closed:
        hit = next((f for f in left if abs((f[0] + f[1]) / 2 - c[0]) <= RTOL * max(abs(c[0]), 1e-300)), None)
        if hit is None:
            missed.append(c)
        else:
            left.remove(hit)
            pairs.append((hit, c))
    return pairs, missed, left


def _by_scan_step(boundaries, scan: np.ndarray):
    """The closed-form ``boundaries`` grouped by the scan step [scan[i], scan[i + 1]] they lie in: (i, group)."""
    steps: dict[int, list] = {}
    for b in boundaries:
        i = int(np.clip(np.searchsorted(scan, b[0]) - 1, 0, scan.size - 2))
        steps.setdefault(i, []).append(b)
    return sorted(steps.items())


def _one_step(row_scene, along: str, other: str, row: float, lo: float, hi: float):
    """``row_scene`` at ``other = row`` alone, with ``along`` scanned finely over [lo, hi]."""
    axes = {along: Axis(along, tuple(float(v) for v in np.linspace(lo, hi, FINE)), "values", discrete=False),
            other: Axis(other, (float(row),), "values")}
    return dataclasses.replace(row_scene, grid=tuple(axes.get(a.name, a) for a in row_scene.grid))


def check_case(case: Case, *, quick: bool, rows: int, out: Path | None) -> dict:
    """Atlas, located boundaries, closed form and exact paper determinant for one case; the disagreements found."""
    scene = example(case.name)
    other = _other(scene, case.along)
    if quick:
        scene = resample(scene, **{case.along: 60, other: 40})
    t0 = time.perf_counter()
    ds = atlas.compute(scene, progress=False)
    t_atlas = time.perf_counter() - t0
    grid_rows = next(a.array for a in scene.grid if a.name == other)
    picks = grid_rows[np.linspace(0, grid_rows.size - 1, rows + 2).round().astype(int)[1:-1]]
    row_axis = Axis(other, tuple(float(v) for v in picks), "values")
    row_scene = dataclasses.replace(scene, grid=tuple(a if a.name != other else row_axis for a in scene.grid))
    crit = critical(row_scene, case.along, progress=False)
    problems, notes, matched, worst = [], [], 0, 0.0
    if case.closed_form is not None:
        # The whole map against the closed form, point by point, in exact arithmetic.
        expected = closed_form_pairs_at(scene, case, grid_values(ds)).reshape(ds["n_complex_pairs"].shape)
        wrong = np.argwhere(expected != ds["n_complex_pairs"].values)
        dims = ds["n_complex_pairs"].dims
        for idx in wrong[:5]:
            at = ", ".join(f"{d} = {ds[d].values[i]:.10g}" for d, i in zip(dims, idx, strict=True))
            problems.append(f"{case.name}: {at}: engine N_c = {ds['n_complex_pairs'].values[tuple(idx)]}, closed form {expected[tuple(idx)]}")
        if len(wrong) > 5:
            problems.append(f"{case.name}: {len(wrong)} points of the map disagree with the closed form in all")
    scan = next(a.array for a in scene.grid if a.name == case.along)
    for row in picks:
        found = engine_boundaries(crit, other, row)
        where = f"{case.name}: {other} = {row:.6g}"
        # The paper's determinant, exactly: every atlas point on the row and both ends of every bracket.
        line = ds["n_complex_pairs"].sel({other: row}).values
        exact = paper_pairs_at(scene, {case.along: scan, other: np.array([row])})
        for v, e, x in zip(scan, line, exact, strict=True):
            if e != x:
                problems.append(f"{where}, {case.along} = {v:.10g}: engine N_c = {e}, paper's determinant {x}")
        ends = np.array([[lo, hi] for lo, hi, _, _ in found]).ravel()
        if ends.size:
            exact_ends = paper_pairs_at(scene, {case.along: ends, other: np.array([row])}).reshape(-1, 2)
            for (lo, hi, below, above), (xb, xa) in zip(found, exact_ends, strict=True):
                if (xb, xa) != (below, above):
                    problems.append(f"{where}: bracket [{lo:.12g}, {hi:.12g}] has N_c {below} -> {above}, paper's determinant {xb} -> {xa}")
        if case.closed_form is None:
            continue
        closed = closed_form_along(scene, case, row)
        pairs, missed, extra = _pair_up(found, closed)
        for step, hidden in _by_scan_step(missed, scan):
            # Two changes inside one scan step with one N_c at both its ends cannot be seen by the scan
            # (docs/critical.md): re-scanning that step finely must find exactly them, else the engine is wrong.
            fine = critical(_one_step(row_scene, case.along, other, row, scan[step], scan[step + 1]), case.along, progress=False)
            again = engine_boundaries(fine, other, row)
            more_pairs, still_missed, more_extra = _pair_up(again, hidden)
            if len(hidden) % 2 or still_missed or more_extra:
                problems.append(f"{where}: closed form {[round(t, 8) for t, _, _ in hidden]} inside the scan step "
                                f"[{scan[step]:.8g}, {scan[step + 1]:.8g}]; a {FINE}-value scan of it finds "
                                f"{[round((a + b) / 2, 8) for a, b, _, _ in again]}")
            else:
                pairs += more_pairs
                notes.append(f"{where}: a window narrower than the scan step [{scan[step]:.8g}, {scan[step + 1]:.8g}] "
                             f"({', '.join(f'{t:.10g}' for t, _, _ in hidden)}): found by a {FINE}-value scan of that step")
        for lo, hi, below, above in extra:
            problems.append(f"{where}: engine boundary {(lo + hi) / 2:.12g} (N_c {below} -> {above}) has no closed-form match")
        for (lo, hi, below, above), (t, cb, ca) in pairs:
            mid = (lo + hi) / 2
            err = abs(mid - t) / max(abs(t), 1e-300)
            worst = max(worst, err)
            matched += 1
            if (below, above) != (cb, ca):
                problems.append(f"{where}: engine boundary {mid:.12g} (N_c {below} -> {above}), "
                                f"closed form {t:.12g} ({cb} -> {ca}), rel. diff {err:.1e}")
    if out is not None:
        _figure(case, scene, ds, crit, picks, out / f"{case.name}.png")
    return {
        "case": case, "points": int(ds["n_complex_pairs"].size), "atlas_s": t_atlas, "rows": len(picks),
        "boundaries": sum(len(engine_boundaries(crit, other, r)) for r in picks), "matched": matched,
        "worst_rel": worst, "problems": problems, "notes": notes,
        "map_agree": None if case.closed_form is None else int(ds["n_complex_pairs"].size - len(wrong)),
    }


def _figure(case: Case, scene, ds, crit, picks, path: Path) -> None:
    """The engine's map, the closed-form boundary (dense) and the located boundaries on the checked rows."""
    from stabmap.read.plot import atlas_figure, save_figure

    fig = atlas_figure(ds)
    ax = fig.axes[0]
    other = _other(scene, case.along)
    x_is_along = list(ds["n_complex_pairs"].dims)[0] == case.along

    def draw(alongs, others, **kw):
        xs, ys = (alongs, others) if x_is_along else (others, alongs)
        ax.plot(xs, ys, linestyle="none", **kw)

    if case.closed_form is not None:
        lo, hi = float(ds[other].min()), float(ds[other].max())
        dense = np.geomspace(lo, hi, 200) if ds[other].attrs.get("scale") == "log" else np.linspace(lo, hi, 200)
        pts = [(t, r) for r in dense for t, _, _ in closed_form_along(scene, case, r)]
        if pts:
            t, r = np.array(pts).T
            draw(t, r, marker=".", ms=2.0, color="black", label="closed form (paper)")
    located = [((lo + hi) / 2, r) for r in picks for lo, hi, _, _ in engine_boundaries(crit, other, r)]
    if located:
        t, r = np.array(located).T
        draw(t, r, marker="o", ms=6, mfc="none", mec="white", mew=1.6, label="engine, located to 1e-10")
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        ax.legend(handles, labels, loc="best", fontsize=8, framealpha=0.85)
    save_figure(fig, path)


def write_golden(directory: Path) -> list[Path]:
    """Small atlases of every case (41 x 21 points) for tests/test_paper_cases.py to pin."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for case in CASES:
        scene = example(case.name)
        scene = resample(scene, **{case.along: 41, _other(scene, case.along): 21})
        ds = atlas.compute(scene, progress=False)
        ds.attrs["history"] = f"golden atlas of the paper case {case.name}: python scripts/paper_cases.py --golden {directory}"
        paths.append(write_atlas(ds, directory / f"{case.name}.nc"))
    return paths


def run(cases=None, *, quick: bool = False, rows: int | None = None, out: Path | None = None) -> dict:
    """Check the paper cases named ``cases`` (default all); figures into ``out`` (None: none). Returns results,
    problems, text."""
    names = cases
    rows = rows or (3 if quick else 15)
    if rows < 1:
        raise StabmapError(f"{given('rows', rows)}: must be >= 1")
    known = {c.name: c for c in CASES}
    unknown = [n for n in names or () if n not in known]
    if unknown:
        raise StabmapError(f"unknown paper case {unknown[0]!r} ({param('cases')}); choose one of: {', '.join(known)}")
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    cases = [c for c in CASES if not names or c.name in names]
    t0 = time.perf_counter()
    results = [check_case(c, quick=quick, rows=rows, out=out) for c in cases]
    return {"results": results, "problems": [m for r in results for m in r["problems"]], "text": table(results, time.perf_counter() - t0)}


def table(results: list[dict], seconds: float | None = None) -> str:
    """The Markdown table of ``run``'s results."""
    lines = [
        f"# boundaries located to 1e-10 relative by stabmap.critical; closed form must agree to {RTOL:g}; every label on",
        "# the checked rows and both ends of every boundary are compared with the paper's determinant in exact arithmetic",
        "",
        "| case | paper | points | map points = closed form | rows | boundaries located | closed form: matched, worst rel. diff | disagreements |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        c = r["case"]
        cf = f"{r['matched']}, {r['worst_rel']:.1e}" if c.closed_form else "none exists"
        agree = "-" if r["map_agree"] is None else f"{r['map_agree']}"
        lines.append(f"| {c.name} | {c.equation} | {r['points']} | {agree} | {r['rows']} | {r['boundaries']} | {cf} | {len(r['problems'])} |")
    lines += [f"DISAGREES: {m}" for r in results for m in r["problems"]]
    lines += [f"NOTE: {m}" for r in results for m in r.get("notes", ())]
    if seconds is not None:
        lines.append(f"# total {seconds:.0f} s")
    return "\n".join(lines)
