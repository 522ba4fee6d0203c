"""What each ``stabmap`` command does, as a Python function: every check first, then the work.

The CLI (``stabmap.cli``) only reads its options and calls these; each returns
what the command reports (and a script may call them alike).  Every check that
can fail runs before any work starts, so bad input leaves no file.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from .errors import StabmapError, given, param


@dataclass
class Done:
    """What a command reports: ``notes`` (files written, notes; standard error) and ``text`` (standard output)."""

    notes: list[str] = field(default_factory=list)
    text: str = ""


def scene(path: str | Path | None = None, example: str | None = None):
    """The scene of a command: a scene file or a bundled example, exactly one of the two."""
    from .examples import example as bundled
    from .systems import load_scene

    if path is not None and example is None:
        return load_scene(path)
    if example is not None and path is None:
        return bundled(example)
    raise StabmapError("give a scene file or --example NAME (not both); see 'stabmap examples'")


def check_grid(scene, source: str = "the scene") -> None:
    """An atlas scans at least one parameter: a scene without ``[grid]`` is an error, not a one-point atlas.

    A scene with no grid axes is almost always a forgotten or misspelt ``[grid]`` table; a single point is asked
    for explicitly with a one-value axis, ``NAME = {values = [VALUE]}``.
    """
    if not scene.grid:
        from . import systems

        axis = systems.of(scene).default_axis  # the example names the axis the system scans first
        raise StabmapError(
            f"{source} has no [grid]: an atlas scans at least one parameter of the scene, e.g. "
            f"[grid] {axis} = {{ start = ..., stop = ..., num = 201 }}; for the label at one point, give that point "
            f"as one-value axes, e.g. {axis} = {{ values = [...] }}"
        )


def atlas(
    scene,
    output: str | Path,
    *,
    png: str | Path | None = None,
    refine: bool = False,
    coarse_stride: int | None = None,
    margin: int | None = None,
    prove_cells: bool = True,
    resume: bool = False,
    overwrite: bool = False,
    client=None,
    workers: int | None = None,
    threads: int | None = None,
    chunk_points: int | None = None,
    progress: bool | None = None,
) -> Done:
    """``stabmap atlas``: compute the atlas of ``scene`` into ``output`` (and draw it to ``png``).

    An existing ``output`` or ``png`` is an error unless ``overwrite``; ``resume`` finishes an interrupted run
    (its checkpoint ``OUTPUT.partial/``), which left no ``output`` behind.
    """
    from . import systems
    from .read.plot import check_figure_path, plot_atlas
    from .read.summary import summary
    from .run import costs, sizes
    from .run import refine as refining
    from .run.atlas import compute_to_file
    from .run.chunks import check_chunk_points
    from .store.files import check_atlas_output, check_new_output, open_atlas, write_atlas

    check_atlas_output(output, overwrite)
    if png is not None:
        check_figure_path(png)
        check_new_output(png, overwrite, param("png"))
    check_grid(scene)
    check_chunk_points(chunk_points)
    if refine:  # written at the end, so its disk is checked here; compute_refined checks the memory, compute_to_file a dense run's disk
        sizes.check_disk(sizes.of(scene), output)
    if not refine:
        extra = [name for name, v in (("coarse_stride", coarse_stride), ("margin", margin)) if v is not None]
        if extra:
            raise StabmapError(f"{param(extra[0])} applies to adaptive atlases only; add {param('refine')}")
    elif resume:
        raise StabmapError(f"{param('resume')} applies to dense atlases; an adaptive atlas ({param('refine')}) has no checkpoint to resume")
    elif not prove_cells:
        raise StabmapError("--node-by-node and --refine are two ways to decide an atlas; give one of them")
    system = systems.of(scene)
    t0 = time.perf_counter()
    where = {"client": client, "workers": workers, "threads": threads, "progress": progress, "chunk_points": chunk_points}
    if refine:
        stride = refining.check_coarse_stride(coarse_stride)
        cells = refining.check_margin(refining.DEFAULT_MARGIN if margin is None else margin)
        with _no_checkpoint():
            ds = refining.compute_refined(scene, coarse_stride=stride, margin=cells, **where)
        write_atlas(ds, output)
        stats = summary_line(system, summary(ds), ds.attrs.get("n_evaluated_points"))
        note = costs.note(system, scene, costs.from_attrs(ds.attrs))
    else:
        report = compute_to_file(scene, output, resume=resume, prove_cells=prove_cells, note=False, **where)
        with open_atlas(output, lazy=True) as ds:
            stats = summary_line(system, summary(ds))
        if report.reused:
            stats += f"; resumed: {report.reused} of {report.chunks} chunks were already done, {report.computed} computed now"
        note = report.note
    lines = [f"wrote {output} in {time.perf_counter() - t0:.1f} s: {stats}"]
    if png is not None:
        with open_atlas(output, lazy=True) as ds:
            plot_atlas(ds, png)
        lines.append(f"wrote {png}")
    return Done(lines + scene.unused() + ([note] if note else []))  # last: what the user may change before the next run


@contextlib.contextmanager
def _no_checkpoint():
    """A lost scheduler in a run that keeps no checkpoint (--refine, critical): say that it must start over."""
    from .run.runner import SchedulerLost

    try:
        yield
    except SchedulerLost as exc:
        raise SchedulerLost(f"{exc}; nothing was written (this kind of run keeps no checkpoint): run it again") from None


def summary_line(system, s: dict, evaluated=None) -> str:
    """One line about a finished atlas: its headline (:mod:`stabmap.read.headline`), who decided, the saving of
    refinement."""
    line = s["headline"]
    if system.stable_label is None:  # a system without stability: how often each class of its label occurs
        line += "; " + ", ".join(f"{system.class_name(v)}: {c}" for v, c in s[system.label].items())
    if system.provenance in s:
        line += "; decided by " + ", ".join(f"{m.replace('_', ' ')} {c}" for m, c in s[system.provenance].items() if c)
    if evaluated is not None and int(evaluated) >= s["points"]:
        line += ("; refined: nothing to infer, every point computed (the grid is too coarse to refine: the default "
                 "stride is 1 along axes of fewer than 129 points; --coarse-stride sets it, docs/refine.md)")
    elif evaluated is not None:
        evaluated = int(evaluated)
        line += (
            f"; refined: {evaluated:,} polynomials evaluated instead of {s['points']:,} "
            f"({s['points'] / max(1, evaluated):.1f}x fewer), the other points inferred from cell corners"
        )
    return line


def critical(
    scene,
    output: str | Path,
    *,
    along: str | None = None,
    rtol: float | None = None,
    png: str | Path | None = None,
    client=None,
    workers: int | None = None,
    threads: int | None = None,
    chunk_points: int | None = None,
    progress: bool | None = None,
    listing: bool = True,
    overwrite: bool = False,
) -> Done:
    """``stabmap critical``: the stable intervals of ``along`` (None: the system's ``default_axis``) into ``output``
    (and drawn to ``png``).

    An existing ``output`` or ``png`` is an error unless ``overwrite``.
    """
    from . import systems
    from .read.info import intervals
    from .read.plot import check_figure_path, plot_critical
    from .run import critical as located
    from .store.files import check_atlas_output, check_new_output, write_atlas

    check_atlas_output(output, overwrite)
    axis = systems.of(scene).default_axis if along is None else along
    if png is not None:
        check_figure_path(png)
        check_new_output(png, overwrite, param("png"))
        others = [a.name for a in scene.grid if a.name != axis]
        if len(others) > 1 and axis in {a.name for a in scene.grid}:
            # A picture shows one other axis; fail before the work rather than after it.
            raise StabmapError(
                f"--png draws one other axis, but this scene has {len(others)} ({', '.join(others)}); drop --png and draw "
                f"the file afterwards with 'stabmap plot {output} -o PNG --sel {others[-1]}=VALUE'"
            )
    t0 = time.perf_counter()
    rtol = located.DEFAULT_RTOL if rtol is None else rtol
    with _no_checkpoint():
        ds = located.critical(scene, along, rtol=rtol, client=client, workers=workers, threads=threads, progress=progress,
                              chunk_points=chunk_points)
    write_atlas(ds, output)
    lines = [f"wrote {output} in {time.perf_counter() - t0:.1f} s"]
    if png is not None:
        plot_critical(ds, png)
        lines.append(f"wrote {png}")
    return Done(lines, "\n".join(intervals(ds)) if listing else "")


def info(path: str | Path, limit: int = 8) -> str:
    """``stabmap info``: what an atlas file holds; ``limit``: points of critical values listed (0: all)."""
    from .read.info import describe
    from .store.files import open_atlas

    if limit < 0:
        raise StabmapError(f"{given('limit', limit)}: must be >= 0 (0 lists every point)")
    with open_atlas(path, lazy=True) as ds:
        return describe(ds, str(path), limit)


def query(
    path: str | Path,
    items: Sequence[str] = (),
    *,
    fraction: bool = False,
    boundaries: str | None = None,
    smallest_stable: str | None = None,
    over: str | None = None,
    locate: bool = False,
    roots: bool = False,
    fmt: str | None = None,
    limit: int = 40,
    progress: bool | None = None,
    output: str | Path | None = None,
    overwrite: bool = False,
    nearest_edge: bool = False,
) -> str | None:
    """``stabmap query``: the label at a point, or the answer to one question about a slice (docs/query.md).

    ``items`` are ``NAME=VALUE`` or ``NAME=LO:HI``; a question's axis may also come first among them.
    ``smallest_stable`` ``""``: along the system's ``default_axis``.
    ``locate``: answer --boundaries and --smallest-stable with critical values of the atlas's scene (complete,
    located to 1e-10: ``stabmap.read.located``) instead of the grid.
    A critical-values file answers with its table (``stabmap.read.table``): every stable interval, boundary and gap.
    ``output``: write the answer to this file (atomically; an existing one only if ``overwrite``) instead of returning it;
    without ``fmt``, its suffix chooses the format (``.csv``: CSV). ``nearest_edge``: a value outside the scan takes its
    nearest end (otherwise an error). ``fmt="csv"`` with no point and no question: every grid point, one row each
    (``stabmap.read.export``), streamed to ``output`` or to standard output (then None is returned).
    """
    from .read import query as q
    from .read.report import output_format, render
    from .store.dataset import is_critical
    from .store.files import check_new_output, open_atlas

    items = list(items)
    asked = [opt for opt, v in (("--fraction", fraction or None), ("--boundaries", boundaries), ("--smallest-stable", smallest_stable),
                                ("--roots", roots or None)) if v is not None]
    if len(asked) > 1:
        raise StabmapError(f"ask one question at a time: {' and '.join(asked)} were both given")
    if limit < 0:
        raise StabmapError(f"{given('limit', limit)}: must be >= 0 (0 shows every row)")
    if locate and boundaries is None and smallest_stable is None:
        raise StabmapError("--locate applies to --boundaries and --smallest-stable, e.g. --boundaries AXIS --locate NAME=VALUE")
    if over is not None and smallest_stable is None:
        raise StabmapError("--over applies to --smallest-stable only, e.g. --smallest-stable AXIS --over NAME")
    for option, axis in (("--boundaries", boundaries), ("--smallest-stable", smallest_stable)):
        if axis is not None and "=" in axis:  # NAME=VALUE right after the option: the axis was left out
            if option == "--boundaries":
                raise StabmapError(f"{option}: name the axis to search along first, e.g. {option} omega K_1=3")
            items.insert(0, axis)
            smallest_stable = ""  # the system's default axis
    if output is not None:
        check_new_output(output, overwrite)
    fmt = output_format(fmt, output)
    ds = open_atlas(path, lazy=True)  # read chunk by chunk: bounded memory at any size
    sel = q.parse_selection(items)
    if fmt == "csv" and not items and not asked and not is_critical(ds):  # the whole atlas, one row per grid point
        from .read import export

        if output is None:
            import sys

            export.write_csv(ds, sys.stdout)
            return None
        _, rows = export.save_csv(ds, output)
        return f"wrote {output}: {rows} rows, one per grid point"
    if is_critical(ds):
        from .read.table import render_table, select_lines

        if asked or locate or over is not None:
            question = asked[0] if asked else "--locate" if locate else "--over"
            raise StabmapError(f"{path} holds critical values, not an atlas, and {question} asks an atlas; 'stabmap query {path}' "
                               "(--csv or --json; NAME=VALUE picks lines) lists its stable intervals and boundaries")
        return _answer(render_table(select_lines(ds, sel, nearest_edge=nearest_edge), fmt, limit=limit), output)
    if roots:
        from .read.roots import roots as roots_at

        if fmt == "csv":
            raise StabmapError(f"{param('roots')} prints text or JSON, not {fmt.upper()}")
        found = roots_at(ds, **sel)
        return _answer(found.to_json() if fmt == "json" else found.text(), output)
    if locate:
        from .read import located

        if boundaries is not None:
            result = located.located_boundaries(ds, boundaries, progress=progress, nearest_edge=nearest_edge, **sel)
        else:
            result = located.located_smallest_stable(ds, smallest_stable or None, over, progress=progress, nearest_edge=nearest_edge, **sel)
    elif boundaries is not None:
        result = q.boundaries(ds, boundaries, nearest_edge=nearest_edge, **sel)
    elif smallest_stable is not None:
        result = q.smallest_stable(ds, smallest_stable or None, over, nearest_edge=nearest_edge, **sel)
    elif fraction:
        result = q.stable_fraction(ds, nearest_edge=nearest_edge, **sel)
    else:
        if not items:
            axes = " ".join(f"{d}=VALUE" for d in q.grid_axes(ds))
            raise StabmapError(
                f"give the point: {axes} (nearest grid point), or ask --fraction, --boundaries AXIS or "
                "--smallest-stable [AXIS], or --csv for every grid point; see 'stabmap query --help'"
            )
        result = q.label_at(ds, nearest_edge=nearest_edge, **sel)
    return _answer(render(result, fmt, limit=limit, atlas=ds), output)


def _answer(text: str, output: str | Path | None) -> str:
    """The answer, or, with ``output``, the answer written there (atomically) and a line saying so."""
    if output is None:
        return text
    from .store.files import write_text

    write_text(text + "\n", output)
    return f"wrote {output}"


def plot(
    path: str | Path,
    output: str | Path,
    *,
    x: str | None = None,
    y: str | None = None,
    sel: Sequence[str] = (),
    facet: str | None = None,
    max_panels: int | None = None,
    max_mb: float | None = None,
    overwrite: bool = False,
    var: str | None = None,
    campbell: bool = False,
) -> Done:
    """``stabmap plot``: draw an atlas (or critical values) to a PNG or PDF file, or write its interactive page (.html);
    an existing output only if ``overwrite``. ``var``: draw that float variable of the atlas instead of its classes;
    ``campbell``: the Campbell diagram of an atlas with frequencies."""
    from .read import plot as figures
    from .store.dataset import is_critical
    from .store.files import check_new_output, open_atlas

    if campbell:
        return _campbell(path, output, x=x, y=y, sel=sel, facet=facet, max_panels=max_panels, max_mb=max_mb, var=var, overwrite=overwrite)
    page = Path(output).suffix.lower() in (".html", ".htm")
    if var is not None and page:
        raise StabmapError(f"{param('var')} draws PNG and PDF figures; an .html page shows the classes (use a .png or .pdf name)")
    figures.check_value_options(var, facet, max_panels is not None)
    if page:
        from .read import explore

        explore.check_page_path(output)
        extra = [name for name, v in (("facet", facet), ("max_panels", max_panels)) if v is not None]
        if extra:
            raise StabmapError(f"{param(extra[0])} applies to PNG and PDF figures; an .html page has a slider for every further axis "
                               f"(fix one with {param('sel')})")
    else:
        figures.check_figure_path(output)
        if max_mb is not None:
            raise StabmapError(f"{param('max_mb')} applies to .html pages; {output} is a figure (use a .html name for a page)")
    check_new_output(output, overwrite)
    ds = _derived_axes(open_atlas(path, lazy=True), x, y)  # read chunk by chunk: bounded memory at any size
    chosen = _selection(ds, sel)
    if page:
        if is_critical(ds) and x is not None:
            raise StabmapError(f"{param('x')} applies to atlases; along x a critical-values page shows the scanned axis")
        from .run.progress import ProgressLine, wanted

        bound = explore.MAX_MB if max_mb is None else max_mb
        line = ProgressLine(wanted(None))  # on a terminal, once a page has taken two seconds

        def read(done: int, total: int) -> None:
            line.show(f"page: {done} of {total} slider settings read")

        try:
            made = (explore.critical_page(ds, y=y, sel=chosen, max_mb=bound, progress=read) if is_critical(ds)
                    else explore.atlas_page(ds, x=x, y=y, sel=chosen, max_mb=bound, progress=read))
            made.save(output)
        finally:
            line.close()
        return Done([f"note: {note}" for note in made.notes] + [f"wrote {output} ({Path(output).stat().st_size / 1e6:.1f} MB)"])
    if is_critical(ds):
        extra = [name for name, v in (("var", var), ("x", x), ("y", y), ("facet", facet), ("max_panels", max_panels)) if v is not None]
        if extra:
            raise StabmapError(f"{param(extra[0])} applies to atlases; {path} holds critical values (fix other axes with {param('sel')})")
        figures.plot_critical(ds, output, sel=chosen)
        return Done([f"wrote {output}"])
    panels = figures.MAX_PANELS if max_panels is None else max_panels
    figures.plot_atlas(ds, output, x=x, y=y, sel=chosen, facet=facet, max_panels=panels, var=var)
    plan = figures.plan_figure(ds, x=x, y=y, sel=chosen, facet=facet, max_panels=panels)
    return Done([f"note: {note}" for note in plan.notes] + [f"wrote {output}"])


def _derived_axes(ds, *axes: str | None):
    """``ds`` with each of ``axes`` that is a derived quantity (a projectile's S_g) as the index of the grid axis it is
    monotone along, so a figure can be drawn against it; one line naming it where it is not (``read.derived``)."""
    from .read import derived

    for name in axes:
        if name is not None and name not in ds.dims and name in ds.coords:
            ds = derived.as_axis(ds, name)
    return ds


def _campbell(path, output, *, x, y, sel, facet, max_panels, max_mb, var, overwrite) -> Done:
    """``stabmap plot --campbell``: the checks, then the figure or page (``plot``)."""
    from .read import plot as figures
    from .store.dataset import is_critical
    from .store.files import check_new_output, open_atlas

    extra = [name for name, v in (("y", y), ("facet", facet), ("max_panels", max_panels), ("max_mb", max_mb), ("var", var))
             if v is not None]
    if extra:
        raise StabmapError(f"{param(extra[0])} does not apply to {param('campbell')}: a Campbell diagram draws frequencies "
                           f"against one spin axis ({param('x')}), other axes fixed with {param('sel')}")
    if Path(output).suffix.lower() not in (".html", ".htm"):
        figures.check_figure_path(output)
    check_new_output(output, overwrite)
    ds = open_atlas(path, lazy=True)
    if is_critical(ds):
        raise StabmapError(f"{param('campbell')} needs an atlas computed with frequencies = true; {path} holds critical values")
    figures.plot_campbell(ds, output, x=x, sel=_selection(ds, sel))
    return Done([f"wrote {output}"])


def _selection(ds, sel: Sequence[str]) -> dict:
    """``--sel NAME=VALUE`` items as numbers, a spin rate given with its unit (``omega="14000 rpm"``) in the file's
    units, rad/s."""
    from .read.query import parse_selection
    from .scene.units import in_si

    chosen = parse_selection(list(sel), ranges=False, option="--sel")
    return {k: in_si(f"--sel {k}", v, str(ds[k].attrs.get("units", ""))) if k in ds.coords else v for k, v in chosen.items()}


def examples(show: str | None = None) -> list[str]:
    """``stabmap examples``: the bundled scenes and their titles, or with ``show`` the TOML text of that one."""
    from importlib import resources

    from .examples import example, example_names

    names = example_names()
    if show is not None:
        if show not in names:
            raise StabmapError(f"unknown example {show!r}; choose one of: {', '.join(names)}")
        text = resources.files("stabmap.examples").joinpath(show + ".toml").read_text(encoding="utf-8")
        return text.rstrip("\n").split("\n")
    width = max(map(len, names))
    return [f"{name:<{width}}  {example(name).title}" for name in names]


def interrupted(output: str | Path | None) -> str:
    """What an interrupted command leaves: no output file, and the finished chunks a --resume will use."""
    from .store.checkpoint import Checkpoint, partial_dir

    if output is None:
        return "no output file was written"
    saved = partial_dir(output)
    if not saved.is_dir():
        return f"{output} was not written"
    try:
        chunks = len(Checkpoint.open(saved).done())
    except StabmapError:
        return f"{output} was not written"
    done = "1 finished chunk is" if chunks == 1 else f"{chunks} finished chunks are"
    return f"{output} was not written; {done} saved in {saved}: run the same command with --resume to finish"
