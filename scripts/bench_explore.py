"""Interactive pages: the size of ``stabmap plot atlas.nc -o atlas.html`` and the time to write and to open it, for
100², 1000² and 100² × 10 × 10 atlases, and a page thinned by a small ``--max-mb``.

    python scripts/bench_explore.py                 # the three atlases, a thinned page, a page of many small frames (3 minutes)
    python scripts/bench_explore.py --quick         # tiny shapes, seconds; run once by the test suite
    python scripts/bench_explore.py --no-browser    # without the time to open the pages in headless Chromium

Atlases of 10⁶ points are not computed (that would take far too long): :func:`synthetic_atlas` writes them
with the global, coordinate and variable attributes of a real tiny atlas of ``paper-n1-fixed-dry`` (Maievskii's
top) computed first over the same axes, and the values a real atlas of that top holds: N_c from Maievskii's
condition C² ω² ≥ 4 (A + m c²) m c g decided exactly (:func:`maievskii_stable`; stable N_c = 0, else 1), the growth
rate from the roots of (A + m c²) λ² − C ω λ + m c g, every point ``decided_by`` the interval Sturm sequence, every
``cell`` proved whole but those the boundary crosses, which hold a change.  Before any timing the synthetic values
are checked against the real tiny atlas, point for point.  The atlases are chunked as ``stabmap atlas`` chunks them
(``MAX_CHUNK_POINTS`` points, the spin axis whole) and written with ``stabmap.write_atlas``.

Per atlas (median of ``--runs`` runs each):
  plot s        ``python -m stabmap plot atlas.nc -o atlas.html`` end to end, a fresh process (imports included);
  make s, save s  in one warm process, ``atlas_page(open_atlas(path, lazy=True))`` and then ``.save(path)``;
  in memory     the same make with the atlas read into memory first (``open_atlas(path)``, not timed);
  open s        headless Chromium (tests/browser.py) from loading the file until BokehJS has drawn every view;
  model MB      1.7 MB + frames × (blocks + 20 B × boundary segments) × 4/3, from the frames, blocks and segments
                counted in the page's own data, against the file's size.  Bokeh gzips every array before its base64
                (a map of wide regions packs well), but the hover texts and each frame's title and ten small arrays
                (about 2 kB a frame) are not in it.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]
AXES = {"omega": (1.0, 60.0), "c_1": (0.02, 0.30), "m_1": (0.5, 2.0), "A_1": (0.01, 0.04)}  # ranges (all positive)
# (name, points per axis, page size bound [MB] or None for the default)
FULL = [("100²", {"omega": 100, "c_1": 100}, None), ("1000²", {"omega": 1000, "c_1": 1000}, None),
        ("100² × 10 × 10", {"omega": 100, "c_1": 100, "m_1": 10, "A_1": 10}, None),
        ("100² × 10 × 10", {"omega": 100, "c_1": 100, "m_1": 10, "A_1": 10}, 2.5),
        ("10² × 20 × 20", {"omega": 10, "c_1": 10, "m_1": 20, "A_1": 20}, 2.0)]  # many small frames
# Quick: a map whose omega is finer than the map (blocks of 3 grid values), a map with two sliders, and it thinned.
QUICK = [("1300 × 20", {"omega": 1300, "c_1": 20}, None), ("60 × 40 × 8 × 8", {"omega": 60, "c_1": 40, "m_1": 8, "A_1": 8}, None),
         ("60 × 40 × 8 × 8", {"omega": 60, "c_1": 40, "m_1": 8, "A_1": 8}, 1.8)]
BASE_MB = 1.7  # the model's fixed part: BokehJS inlined


# ---------------------------------------------------------------------------------------------------- the atlases
def maievskii_stable(omega, c, m, A, C: float, g: float) -> np.ndarray:
    """Maievskii's condition C² ω² ≥ 4 (A + m c²) m c g at every point, exact on the binary values of the numbers.

    Floats decide where the two sides differ by far more than their rounding (a few ulps each: every term is
    positive, nothing cancels); the points within 1e-12 of equality are decided again in rationals.
    """
    omega, c, m, A = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (omega, c, m, A)))
    if min(v.min(initial=1.0) for v in (omega, c, m, A)) <= 0 or C <= 0 or g <= 0:
        raise ValueError("maievskii_stable needs positive ω, c, m, A, C and g (the float bound relies on it)")
    lhs = C * C * omega * omega
    rhs = 4.0 * (A + m * c * c) * m * c * g
    stable = lhs >= rhs
    for i in zip(*np.nonzero(np.abs(lhs - rhs) <= 1e-12 * np.maximum(lhs, rhs)), strict=True):
        w, cc, mm, a = (Fraction(float(v[i])) for v in (omega, c, m, A))
        stable[i] = Fraction(C) ** 2 * w * w >= 4 * (a + mm * cc * cc) * mm * cc * Fraction(g)
    return stable


def _on_grid(dims: list[str], arrays: dict[str, np.ndarray], fixed: dict[str, float]) -> dict[str, np.ndarray]:
    """Each parameter as an array that broadcasts over the grid ``dims`` (a fixed one as a scalar)."""
    out = {}
    for name in ("omega", "c_1", "m_1", "A_1"):
        if name in dims:
            shape = [1] * len(dims)
            shape[dims.index(name)] = -1
            out[name] = np.asarray(arrays[name], dtype=np.float64).reshape(shape)
        else:
            out[name] = np.float64(fixed[name])
    return out


def maievskii_values(dims: list[str], grid: dict[str, np.ndarray], fixed: dict[str, float], flags: dict[str, dict[str, int]]) -> dict:
    """The variables of an atlas of Maievskii's top on ``grid`` (values per axis of ``dims``): N_c, stability, growth
    rates, provenance and cells, the flag values taken from ``flags`` (variable -> meaning -> value)."""
    from stabmap.store.dataset import edges

    C, g = fixed["C_1"], fixed["g"]
    p = _on_grid(dims, grid, fixed)
    shape = tuple(len(grid[d]) for d in dims)
    stable = np.broadcast_to(maievskii_stable(p["omega"], p["c_1"], p["m_1"], p["A_1"], C, g), shape)
    # The cell's most and least stable corners: the left side grows with ω, the right side with c, m and A.
    lo = _on_grid(dims, {d: edges(grid[d])[:-1] for d in dims}, fixed)
    hi = _on_grid(dims, {d: edges(grid[d])[1:] for d in dims}, fixed)
    best = maievskii_stable(hi["omega"], lo["c_1"], lo["m_1"], lo["A_1"], C, g)
    worst = maievskii_stable(lo["omega"], hi["c_1"], hi["m_1"], hi["A_1"], C, g)
    change = np.broadcast_to(best & ~worst, shape)

    inertia = p["A_1"] + p["m_1"] * p["c_1"] ** 2
    gap = 4.0 * inertia * p["m_1"] * p["c_1"] * g - (C * p["omega"]) ** 2
    rate = np.where(stable, 0.0, np.sqrt(np.maximum(gap, 0.0)) / (2.0 * inertia))
    rate32 = rate.astype(np.float32)
    with np.errstate(divide="ignore"):
        efold = np.where(rate32 > 0, np.float32(1) / np.where(rate32 > 0, rate32, 1), np.float32(np.inf)).astype(np.float32)
    zero = np.float32(0)
    return {
        "n_complex_pairs": np.where(stable, 0, 1).astype(np.int16),
        "stability": np.where(stable, flags["stability"]["stable"], flags["stability"]["unstable"]).astype(np.int8),
        "decided_by": np.full(shape, flags["decided_by"]["interval_sturm_sequence"], dtype=np.int8),
        "growth_rate": rate32,
        "growth_rate_lower": np.where(rate32 > 0, np.nextafter(rate32, zero), zero).astype(np.float32),
        "growth_rate_upper": np.where(rate32 > 0, np.nextafter(rate32, np.float32(np.inf)), zero).astype(np.float32),
        "efolding_time": efold,
        "growth_rate_method": np.where(stable, flags["growth_rate_method"]["all_roots_real"],
                                       flags["growth_rate_method"]["newton_pairs"]).astype(np.int8),
        "cell": np.where(change, flags["cell"]["contains_change"], flags["cell"]["whole_cell"]).astype(np.int8),
    }


def _flags(ds: xr.Dataset) -> dict[str, dict[str, int]]:
    """Every flag variable's meaning -> value, as the file declares them."""
    return {k: dict(zip(str(v.attrs["flag_meanings"]).split(), (int(x) for x in v.attrs["flag_values"]), strict=True))
            for k, v in ds.data_vars.items() if "flag_meanings" in v.attrs}


def _scene(points: dict[str, int]):
    """``paper-n1-fixed-dry`` over the axes ``points`` names, that many evenly spaced values each (:data:`AXES`)."""
    import stabmap
    from stabmap.systems.gyroscopes.scene import Axis

    axes = tuple(Axis(name, tuple(float(v) for v in np.linspace(*AXES[name], n))) for name, n in points.items())
    return stabmap.example("paper-n1-fixed-dry").with_grid(axes)


def template(dims: list[str]) -> xr.Dataset:
    """A real atlas of Maievskii's top over ``dims``, tiny (3 values an axis), computed by stabmap."""
    import stabmap

    return stabmap.compute_atlas(_scene(dict.fromkeys(dims, 3)))


def _fixed(ds: xr.Dataset, scene) -> dict[str, float]:
    body = scene.bodies[0]
    return {"g": float(scene.g), "C_1": float(body.C), "m_1": float(body.m), "A_1": float(body.A),
            **{k: float(ds[k]) for k in ds.coords if ds[k].ndim == 0}}


def check_template(real: xr.Dataset) -> None:
    """The synthetic values on the real atlas's own grid must be the real atlas's: N_c and stability exactly, the
    growth rate to float32 rounding; raises ``AssertionError`` where they differ."""
    from stabmap.systems import loads_scene

    scene = loads_scene(str(real.attrs["scene"]), "the template's scene")
    dims = list(real["n_complex_pairs"].dims)
    mine = maievskii_values(dims, {d: real[d].values for d in dims}, _fixed(real, scene), _flags(real))
    if set(mine) != set(real.data_vars):
        raise AssertionError(f"the synthetic atlas has {sorted(mine)}, a real one {sorted(real.data_vars)}")
    for name in ("n_complex_pairs", "stability", "growth_rate_method"):
        if not np.array_equal(mine[name], real[name].values):
            raise AssertionError(f"{name} differs from the real atlas: {mine[name].ravel()} against {real[name].values.ravel()}")
    if not np.allclose(mine["growth_rate"], real["growth_rate"].values, rtol=1e-5, atol=0):
        raise AssertionError(f"growth_rate differs from the real atlas: {mine['growth_rate'].ravel()} against {real['growth_rate'].values.ravel()}")


def synthetic_atlas(points: dict[str, int], real: xr.Dataset) -> xr.Dataset:
    """An atlas of Maievskii's top over ``points`` (values per axis) with ``real``'s attributes, its variables'
    and coordinates' attributes, its scene on the new grid, chunked as ``stabmap atlas`` chunks (lazy: dask)."""
    from stabmap.run.chunks import MAX_CHUNK_POINTS, chunk_shape
    from stabmap.run.tasks import point_order
    from stabmap.store.dataset import BOUNDS_DIM, bounds

    scene = _scene(points)
    dims = [a.name for a in scene.grid]
    if dims != list(real["n_complex_pairs"].dims):
        raise ValueError(f"the template's axes are {real['n_complex_pairs'].dims}, not {dims}")
    grid = {a.name: a.array for a in scene.grid}
    values = maievskii_values(dims, grid, _fixed(real, scene), _flags(real))
    coords = {}
    for d in dims:
        coords[d] = (d, grid[d], real[d].attrs)
        coords[f"{d}_bounds"] = ((d, BOUNDS_DIM), bounds(grid[d]), real[f"{d}_bounds"].attrs)
    coords.update({k: ((), real[k].values, real[k].attrs) for k in real.coords if real[k].ndim == 0})
    attrs = {**real.attrs, "scene": scene.to_toml(),
             "history": f"{real.attrs['history']}; synthetic values of Maievskii's condition written by scripts/bench_explore.py"}
    ds = xr.Dataset({k: (dims, np.ascontiguousarray(values[k]), real[k].attrs) for k in real.data_vars}, coords=coords, attrs=attrs)
    chunks = chunk_shape(scene.shape, MAX_CHUNK_POINTS, point_order(scene))
    return ds.chunk(dict(zip(dims, chunks, strict=True)))


# ---------------------------------------------------------------------------------------------------- measuring
def page_counts(page) -> dict:
    """Frames, and per frame the blocks, the rectangles that draw them and the boundary segments, counted in the
    page's own bokeh models."""
    from bokeh.models import ColumnDataSource, CustomJS, Slider

    refs = page.layout.references()
    frames = math.prod(1 if s.disabled else int(s.end - s.start) + 1 for s in refs if isinstance(s, Slider))
    swaps = [m for m in refs if isinstance(m, CustomJS) and "frames" in m.args]
    if swaps:  # each frame: its rectangles, its blocks' states, its two tables of boundary segments
        table = swaps[0].args["frames"]
        blocks = [len(f[1]) for f in table]
        rects = [len(f[0]["c0"]) for f in table]
        segments = [len(f[2]["x0"]) + len(f[3]["x0"]) for f in table]
    else:
        sources = [m for m in refs if isinstance(m, ColumnDataSource)]
        blocks = [len(s.data["state"]) for s in sources if "state" in s.data]
        rects = [len(s.data["c0"]) for s in sources if "c0" in s.data]
        segments = [sum(len(s.data["x0"]) for s in sources if "x0" in s.data)]
    if not (len(blocks) == len(rects) == len(segments) == frames):
        raise AssertionError(f"the page holds {len(blocks)} block arrays and {len(segments)} segment tables for {frames} frames")
    return {"frames": frames, "blocks": blocks, "rects": rects, "segments": segments}


def model_bytes(counts: dict) -> float:
    """The size model of docs/explore.md, before bokeh's compression: 1.7 MB + every frame's blocks (a byte each),
    rectangles (9 B each) and segments (20 B each), base64 (4/3)."""
    return BASE_MB * 1e6 + sum(b + 9 * r + 20 * s for b, r, s in zip(counts["blocks"], counts["rects"], counts["segments"], strict=True)) * 4 / 3


def cli_runs(atlas: Path, out: Path, runs: int, max_mb: float | None) -> tuple[list[float], list[float], list[str]]:
    """Wall-clock and CPU seconds of ``python -m stabmap plot atlas -o out`` in fresh processes, and the notes the
    last run printed."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    command = [sys.executable, "-m", "stabmap", "plot", str(atlas), "-o", str(out), "--overwrite"]
    command += [] if max_mb is None else ["--max-mb", f"{max_mb:g}"]
    seconds, cpu, text = [], [], ""
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        res = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
        seconds.append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
        if res.returncode:
            raise RuntimeError(f"{' '.join(command)} failed: {res.stdout}{res.stderr}")
        text = res.stdout + res.stderr
    return seconds, cpu, [line for line in text.splitlines() if line.startswith("note:")]


def in_process(atlas: Path, out: Path, runs: int, max_mb: float | None, lazy: bool = True) -> dict:
    """Median seconds to make the page of an atlas opened ``lazy`` (else loaded first, not timed) and to save it, in
    this (warm) process; and the last page."""
    from stabmap import open_atlas
    from stabmap.read.explore import MAX_MB, atlas_page

    make, save, cpu = [], [], []
    for _ in range(runs):
        ds = open_atlas(atlas, lazy=lazy)
        try:
            c0, t0 = time.process_time(), time.perf_counter()
            page = atlas_page(ds, max_mb=MAX_MB if max_mb is None else max_mb)
            t1 = time.perf_counter()
            page.save(out)
            c2, t2 = time.process_time(), time.perf_counter()
        finally:
            ds.close()
        make.append(t1 - t0)
        save.append(t2 - t1)
        cpu.append(c2 - c0)
    return {"make_s": statistics.median(make), "save_s": statistics.median(save), "cpu_s": statistics.median(cpu), "page": page}


def open_times(paths: list[Path], runs: int) -> list[float | None]:
    """Median seconds to open each page in headless Chromium until rendered (None for all without Chromium)."""
    import pytest

    sys.path.insert(0, str(ROOT / "tests"))
    try:
        from browser import browser
    finally:
        sys.path.remove(str(ROOT / "tests"))
    try:
        with browser() as new_page:
            out = []
            for path in paths:
                seconds = []
                for _ in range(runs):
                    page = new_page()
                    page.timeout = 600.0
                    t0 = time.perf_counter()
                    page.open(path)
                    seconds.append(time.perf_counter() - t0)
                    errors = page.errors()
                    if errors:
                        raise RuntimeError(f"{path} logged errors in Chromium: {errors}")
                out.append(statistics.median(seconds))
            return out
    except pytest.skip.Exception as why:  # no Chromium here: the other columns still stand
        print(f"no Chromium: {why}", file=sys.stderr)
        return [None] * len(paths)


def empty_page_bytes() -> int:
    """Bytes of a bokeh page of one empty Div, scripts inlined as stabmap's pages inline them: every page's floor."""
    from bokeh.embed import file_html
    from bokeh.models import Div
    from bokeh.resources import INLINE

    return len(file_html(Div(text=""), resources=INLINE, title="").encode("utf-8"))


def machine() -> dict:
    """What the numbers were measured on."""
    import bokeh

    cpu = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines() if line.startswith("model name")),
               platform.processor() or platform.machine()) if Path("/proc/cpuinfo").exists() else platform.machine()
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")  # other work on the machine moves the times
    return {"cores": cores, "cpu": cpu, "python": platform.python_version(), "bokeh": bokeh.__version__, "date": time.strftime("%Y-%m-%d"),
            "load": load}


# ---------------------------------------------------------------------------------------------------- the run
def main(argv: list[str] | None = None) -> dict:
    import stabmap

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="tiny shapes, one run each (seconds)")
    ap.add_argument("--runs", type=int, help="runs per measurement, the median reported (default 3; quick 1)")
    ap.add_argument("--browser", action=argparse.BooleanOptionalAction, default=None,
                    help="time opening the pages in headless Chromium (default: on, off with --quick)")
    ap.add_argument("--dir", default=None, help="keep the atlases and pages here (default: a temporary directory, removed after)")
    args = ap.parse_args(argv)
    cases = QUICK if args.quick else FULL
    runs = args.runs or (1 if args.quick else 3)
    use_browser = (not args.quick) if args.browser is None else args.browser
    work = Path(args.dir) if args.dir else Path(tempfile.mkdtemp(prefix="stabmap-explore-"))
    work.mkdir(parents=True, exist_ok=True)
    rows, templates, atlases = [], {}, {}
    floor = empty_page_bytes()
    load_start = machine()["load"]
    try:
        for name, points, max_mb in cases:
            dims = tuple(points)
            if dims not in templates:
                templates[dims] = template(list(dims))
                check_template(templates[dims])
            key = tuple(points.items())
            if key not in atlases:
                atlases[key] = work / f"atlas-{'x'.join(str(n) for n in points.values())}.nc"
                stabmap.write_atlas(synthetic_atlas(points, templates[dims]), atlases[key])
            atlas = atlases[key]
            tag = "" if max_mb is None else f"-max{max_mb:g}"
            cli_page, py_page = atlas.with_name(f"{atlas.stem}{tag}.html"), atlas.with_name(f"{atlas.stem}{tag}-py.html")
            if not rows:  # imports and kernels loaded before the first in-process timing
                in_process(atlas, py_page, 1, max_mb)
            timed = in_process(atlas, py_page, runs, max_mb)
            loaded = in_process(atlas, py_page, runs, max_mb, lazy=False)  # the same page, the atlas read into memory first
            counts = page_counts(timed["page"])
            seconds, cpu, cli_notes = cli_runs(atlas, cli_page, runs, max_mb)
            size = cli_page.stat().st_size
            frames_all = math.prod(n for d, n in points.items() if d not in ("omega", "c_1"))
            row = {"atlas": name, "points": math.prod(points.values()), "max_mb": max_mb, "nc_mb": atlas.stat().st_size / 1e6,
                   "frames": counts["frames"], "frames_all": frames_all, "blocks": statistics.mean(counts["blocks"]),
                   "segments": statistics.mean(counts["segments"]), "page_mb": size / 1e6, "py_page_mb": py_page.stat().st_size / 1e6,
                   "model_mb": model_bytes(counts) / 1e6,
                   "plot_s": statistics.median(seconds), "plot_runs": seconds, "plot_cpu_s": statistics.median(cpu),
                   "make_s": timed["make_s"], "save_s": timed["save_s"], "inproc_cpu_s": timed["cpu_s"], "make_memory_s": loaded["make_s"],
                   "notes": list(timed["page"].notes), "cli_notes": cli_notes, "page": str(cli_page), "open_s": None}
            row["beyond_kb"] = (size - floor) / 1e3
            row["model_err_pct"] = 100 * (row["page_mb"] - row["model_mb"]) / row["model_mb"]
            rows.append(row)
            print(f"{name:>16} max_mb {max_mb or 'default':>7}: {row['page_mb']:6.2f} MB (model {row['model_mb']:6.2f}), {row['frames']} frames "
                  f"of {row['blocks']:,.0f} blocks, plot {row['plot_s']:5.2f} s, make {row['make_s']:5.2f} s + save {row['save_s']:5.2f} s "
                  f"(in memory: make {row['make_memory_s']:5.2f} s)",
                  flush=True)
        if use_browser:
            for row, seconds in zip(rows, open_times([Path(r["page"]) for r in rows], runs), strict=True):
                row["open_s"] = seconds
        info = machine()
        info["load"] = f"{load_start:.1f} at the start, {info['load']:.1f} at the end"
        command = "python scripts/bench_explore.py" + (" --quick" if args.quick else "") + (f" --runs {args.runs}" if args.runs else "")
        print(table(rows, info, command, runs, floor))
        return {"rows": rows, "machine": info, "command": command, "dir": str(work), "empty_page_mb": floor / 1e6}
    finally:
        if args.dir is None:
            shutil.rmtree(work, ignore_errors=True)


def table(rows: list[dict], info: dict, command: str, runs: int, floor: int) -> str:
    """The markdown table of ``rows``, the command and the machine; ``floor``: bytes of an empty bokeh page."""
    lines = [f"\nCommand: `{command}`. Machine: {info['cores']} cores ({info['cpu']}), Python {info['python']}, bokeh {info['bokeh']}, "
             f"{info['date']}; load average (1 min) {info['load']}; median of {runs} run{'s' if runs > 1 else ''}.", "",
             "| atlas | grid points | max_mb | frames (kept of all) | blocks a frame | boundary segments a frame | .nc MB | page MB "
             "| beyond an empty page, kB | model MB (page − model) | `stabmap plot` s (CPU s) | make + save s (CPU s), in process "
             "| make s, atlas in memory | open in Chromium s |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        opened = "–" if r["open_s"] is None else f"{r['open_s']:.2f}"
        bound = "20 (default)" if r["max_mb"] is None else f"{r['max_mb']:g}"
        lines.append(f"| {r['atlas']} | {r['points']:,} | {bound} | "
                     f"{r['frames']} of {r['frames_all']} | {r['blocks']:,.0f} | {r['segments']:,.0f} | {r['nc_mb']:.2f} | "
                     f"{r['page_mb']:.2f} | {r['beyond_kb']:,.0f} | "
                     f"{r['model_mb']:.2f} ({r['model_err_pct']:+.1f} %) | {r['plot_s']:.2f} ({r['plot_cpu_s']:.2f}) | "
                     f"{r['make_s']:.2f} + {r['save_s']:.2f} ({r['inproc_cpu_s']:.2f}) | "
                     f"{r['make_memory_s']:.2f} | {opened} |")
    notes = list(dict.fromkeys(n for r in rows for n in r["cli_notes"]))
    lines += ["", f"An empty bokeh page (one Div, BokehJS inlined) is {floor / 1e6:.3f} MB.",
              *(f"`stabmap plot` printed: {n}" for n in notes)]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
