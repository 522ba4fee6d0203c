"""The ``stabmap`` command: one thin subcommand per job, each calling the Python API."""

from __future__ import annotations

import argparse
import signal
import sys
import threading
import time

import numpy as np

from . import __version__
from .errors import StabmapError


def _pairs(items: list[str], what: str) -> dict[str, float]:
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise StabmapError(f"{what} {item!r}: write NAME=VALUE, e.g. omega=42.5")
        try:
            out[key.strip()] = float(value)
        except ValueError:
            raise StabmapError(f"{what} {item!r}: {value!r} is not a number") from None
    return out


def _scene_for_run(args):
    """The scene of an ``atlas`` or ``critical`` run, after every check that can fail before the work."""
    from .cluster import check_threads
    from .examples import example
    from .io import check_writable
    from .scene import load

    if (args.scene is None) == (args.example is None):
        raise StabmapError("give a scene file or --example NAME (not both); see 'stabmap examples'")
    check_writable(args.output)
    if args.png:
        check_writable(args.png)
    scene = load(args.scene) if args.scene else example(args.example)
    for option in ("threads", "workers"):
        if getattr(args, option, None) is not None:
            check_threads(getattr(args, option), f"--{option}")
    return scene


def _cmd_atlas(args) -> None:
    from .atlas import compute_to_file
    from .io import write_atlas
    from .plot import plot_atlas

    refine = _refine_options(args)
    where = _where_to_run(args)
    scene = _scene_for_run(args)
    t0 = time.perf_counter()
    if refine is None:
        with _cluster(where) as client:
            report = compute_to_file(
                scene, args.output, client=client, threads=args.threads, progress=not args.quiet,
                chunk_points=args.chunk_points, resume=args.resume,
            )
        stats = _summary_line(report.counts)
        if report.reused:
            stats += f"; resumed: {report.reused} of {report.chunks} chunks were already done, {report.computed} computed now"
        ds = None
    else:
        from .refine import compute_refined

        ds = compute_refined(scene, threads=args.threads, progress=not args.quiet, **refine)
        write_atlas(ds, args.output)
        stats = _summary_line(None, ds)
    print(f"wrote {args.output}: {stats} in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    if args.png:
        if ds is None:
            from .io import open_atlas

            ds = open_atlas(args.output)
        plot_atlas(ds, args.png)
        print(f"wrote {args.png}", file=sys.stderr)


def _where_to_run(args) -> str | int | None:
    """--scheduler ADDRESS, --workers N (a local cluster) or None (threads here), checked before any work."""
    from .chunks import check_chunk_points

    if args.scheduler is not None and args.workers is not None:
        raise StabmapError("give --scheduler ADDRESS (an existing cluster) or --workers N (a local one), not both")
    cluster = args.scheduler if args.scheduler is not None else args.workers
    if cluster is not None and args.threads is not None:
        raise StabmapError("--threads sets the threads of an in-process run; on a cluster each worker has its own (dask worker --nthreads)")
    if cluster is not None and args.refine:
        raise StabmapError("--refine runs in this process only; drop --scheduler/--workers, or drop --refine for a dense atlas on the cluster")
    check_chunk_points(args.chunk_points, "--chunk-points")
    if args.refine and (args.resume or args.chunk_points is not None):
        raise StabmapError(f"{'--resume' if args.resume else '--chunk-points'} applies to dense atlases; drop --refine or the option")
    return cluster


def _cluster(where):
    """A context giving the client argument of ``compute_to_file``: None, an address, or a local cluster's Client."""
    import contextlib

    if isinstance(where, int):
        from .cluster import local_cluster

        return local_cluster(where)
    return contextlib.nullcontext(where)


def _refine_options(args) -> dict | None:
    """Keyword arguments of compute_refined (None: a dense atlas), checked before any work starts."""
    from .refine import DEFAULT_MARGIN, check_coarse_stride, check_margin

    if not args.refine:
        given = [opt for opt, v in (("--coarse-stride", args.coarse_stride), ("--margin", args.margin)) if v is not None]
        if given:
            raise StabmapError(f"{given[0]} applies to adaptive atlases only; add --refine")
        return None
    margin = DEFAULT_MARGIN if args.margin is None else args.margin
    return {"coarse_stride": check_coarse_stride(args.coarse_stride, "--coarse-stride"), "margin": check_margin(margin, "--margin")}


def _summary_line(counts: dict | None, ds=None) -> str:
    from .query import summary

    s = counts if counts is not None else summary(ds)
    exact = s["decided_by"]["exact_rational_arithmetic"]
    line = f"{s['points']} points, {100 * s['stable_fraction']:.1f} % stable, {exact} decided in exact arithmetic"
    evaluated = None if ds is None else ds.attrs.get("n_evaluated_points")
    if evaluated is not None:
        evaluated = int(evaluated)
        line += (
            f"; refined: {evaluated:,} polynomials evaluated instead of {s['points']:,} "
            f"({s['points'] / max(1, evaluated):.1f}x fewer), the other points inferred from cell corners"
        )
    return line


def _cmd_info(args) -> None:
    from .io import open_atlas
    from .query import summary
    from .variables import N_COMPLEX_PAIRS

    ds = open_atlas(args.atlas)
    if ds.attrs.get("stabmap_kind") == "critical values":
        print(f"{args.atlas}: {ds.attrs.get('title', '')}: critical values along {ds.attrs['critical_along']}")
        print(f"  {ds.attrs['comment']}")
        _print_intervals(ds)
        return
    s = summary(ds)
    a = ds.attrs
    print(f"{args.atlas}: {a.get('title', '')}")
    print(f"  support {a.get('support')}, {a.get('n_bodies')} bodies, characteristic polynomial of degree <= {a.get('polynomial_degree_bound')}")
    if "topology_parent" in a:
        print(f"  a tree: parent = {[int(p) for p in np.atleast_1d(a['topology_parent'])]} (0: the base; docs/trees.md)")
    print("  axes:")
    for d in ds[N_COMPLEX_PAIRS].dims:
        c = ds[d]
        print(f"    {d:<10} {c.size:>7} points  {float(c.min()):.6g} .. {float(c.max()):.6g} {c.attrs.get('units', '')}  ({c.attrs.get('scale', '')})  {c.attrs.get('long_name', '')}")
    fixed = [k for k in ds.coords if ds[k].ndim == 0]
    if fixed:
        print("  fixed: " + ", ".join(f"{k} = {float(ds[k]):.6g}" for k in fixed))
    print(f"  points: {s['points']}, stable: {s['stable']} ({100 * s['stable_fraction']:.2f} %)" + (f", degenerate: {s['degenerate']}" if s["degenerate"] else ""))
    print("  complex root pairs: " + ", ".join(f"{k}: {v}" for k, v in s["n_complex_pairs"].items()))
    print("  decided by: " + ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in s["decided_by"].items()))
    print(f"  made by {a.get('source', '?')}; {a.get('history', '')}")


def _cmd_query(args) -> None:
    from .io import open_atlas
    from .query import boundaries, label_at, smallest_stable, stable_fraction
    from .report import render

    ds = open_atlas(args.atlas)
    if ds.attrs.get("stabmap_kind") == "critical values":
        raise StabmapError(f"{args.atlas} holds critical values, not an atlas; 'stabmap info {args.atlas}' lists its intervals")
    fmt = "csv" if args.csv else "json" if args.json else "text"
    if args.limit < 0:
        raise StabmapError(f"--limit must be >= 0 (0 shows every row), got {args.limit}")
    over, after_over = (None, []) if args.over is None else _query_axis(args.over, "--over", None)
    if over is not None and args.smallest_stable is None:
        raise StabmapError("--over applies to --smallest-stable only, e.g. --smallest-stable omega --over K_1")
    if args.boundaries is not None:
        along, extra = _query_axis(args.boundaries, "--boundaries", None)
        result = boundaries(ds, along, **_query_selection(args.point + extra))
    elif args.smallest_stable is not None:
        along, extra = _query_axis(args.smallest_stable, "--smallest-stable", "omega")
        result = smallest_stable(ds, along, over, **_query_selection(args.point + extra + after_over))
    elif args.fraction is not None:
        result = stable_fraction(ds, **_query_selection(args.point + args.fraction))
    else:
        if not args.point:
            axes = " ".join(f"{d}=VALUE" for d in ds["n_complex_pairs"].dims)
            raise StabmapError(
                f"give the point: {axes} (nearest grid point), or ask --fraction, --boundaries AXIS or "
                "--smallest-stable [AXIS]; see 'stabmap query --help'"
            )
        result = label_at(ds, **_query_selection(args.point))
    print(render(result, fmt, limit=args.limit, atlas=ds))


def _query_axis(items: list[str], option: str, default: str | None) -> tuple[str, list[str]]:
    """The axis named first after ``option`` (or ``default``), and the NAME=VALUE items after it."""
    if items and "=" not in items[0]:
        return items[0], items[1:]
    if default is None:
        raise StabmapError(f"{option}: name the axis to search along first, e.g. {option} omega K_1=3")
    return default, items


def _query_selection(items: list[str]) -> dict:
    """NAME=VALUE (nearest grid value) and NAME=LO:HI (a range; LO: and :HI open) as stabmap.query selections."""
    out = {}
    for item in items:
        key, sep, value = (part.strip() for part in item.partition("="))
        if not sep or not key:
            raise StabmapError(f"{item!r}: write NAME=VALUE (nearest grid value) or NAME=LO:HI (a range), e.g. omega=42.5 or K_1=0:10")
        if key in out:
            raise StabmapError(f"{key} is given twice; give each axis once")
        ends = value.split(":")
        if len(ends) > 2:
            raise StabmapError(f"{item!r}: a range is NAME=LO:HI, e.g. {key}=0:10")
        try:
            numbers = [float(e) if e.strip() else None for e in ends]
        except ValueError:
            raise StabmapError(f"{item!r}: {value!r} is not a number or a range LO:HI; write e.g. {key}=42.5 or {key}=0:10") from None
        if len(numbers) == 1 and numbers[0] is None:
            raise StabmapError(f"{item!r}: no value; write e.g. {key}=42.5 or {key}=0:10")
        out[key] = numbers[0] if len(numbers) == 1 else tuple(numbers)
    return out


def _cmd_plot(args) -> None:
    from .io import open_atlas
    from .plot import MAX_PANELS, plan_figure, plot_atlas

    ds = open_atlas(args.atlas)
    sel = _pairs(args.sel, "--sel")
    if ds.attrs.get("stabmap_kind") == "critical values":
        from .plot import plot_critical

        given = [opt for opt, v in (("--x", args.x), ("--y", args.y), ("--facet", args.facet), ("--max-panels", args.max_panels)) if v is not None]
        if given:
            raise StabmapError(f"{given[0]} applies to atlases; {args.atlas} holds critical values (fix other axes with --sel)")
        plot_critical(ds, args.output, sel=sel)
    else:
        options = {"x": args.x, "y": args.y, "sel": sel, "facet": args.facet, "max_panels": MAX_PANELS if args.max_panels is None else args.max_panels}
        plot_atlas(ds, args.output, **options)
        for note in plan_figure(ds, **options).notes:
            print(f"note: {note}", file=sys.stderr)
    print(f"wrote {args.output}", file=sys.stderr)


def _cmd_critical(args) -> None:
    from .critical import critical
    from .io import write_atlas
    from .plot import plot_critical

    scene = _scene_for_run(args)
    others = [a.name for a in scene.grid if a.name != args.along]
    if args.png and len(others) > 1 and args.along in {a.name for a in scene.grid}:
        # Fail before the work: a picture shows one other axis, the rest must be fixed with --sel.
        raise StabmapError(
            f"--png draws one other axis, but this scene has {len(others)} ({', '.join(others)}); drop --png and draw "
            f"the file afterwards with 'stabmap plot {args.output} -o PNG --sel {others[-1]}=VALUE'"
        )
    t0 = time.perf_counter()
    ds = critical(scene, args.along, rtol=args.rtol, threads=args.threads)
    write_atlas(ds, args.output)
    print(f"wrote {args.output} in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    if not args.quiet:
        _print_intervals(ds)
    if args.png:
        plot_critical(ds, args.png)
        print(f"wrote {args.png}", file=sys.stderr)


def _print_intervals(ds, limit: int = 8) -> None:
    """Stable intervals for the first ``limit`` points of the other axes."""
    along = ds.attrs["critical_along"]
    names = [f"{along}_stable_{end}" for end in ("lower", "upper", "lower_outer", "upper_outer")]
    dims = [d for d in ds[names[0]].dims if d != "interval"]
    table = ds[names].stack(point=dims) if dims else ds[names].expand_dims(point=[0])
    lo, hi, olo, ohi = (table[n].transpose("point", "interval").values for n in names)
    units = ds[names[0]].attrs.get("units", "")
    for p, label in enumerate(table["point"].values[:limit]):
        where = ", ".join(f"{d} = {v:g}" for d, v in zip(dims, label)) if dims else "the scene"
        parts = [
            f"{lo[p, k]:.10g} ({'scan end' if np.isnan(olo[p, k]) else 'boundary'}) to "
            f"{hi[p, k]:.10g} ({'scan end' if np.isnan(ohi[p, k]) else 'boundary'})"
            for k in range(lo.shape[1])
            if np.isfinite(lo[p, k])
        ]
        print(f"{where}: stable {along} [{units}] " + ("; ".join(parts) if parts else "nowhere in the scan"))
    if lo.shape[0] > limit:
        print(f"... and {lo.shape[0] - limit} more points in the file")


def _cmd_examples(args) -> None:
    from .examples import example, example_names

    names = example_names()
    width = max(map(len, names))
    for name in names:
        print(f"{name:<{width}}  {example(name).title}")


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="stabmap", description="Stability atlases of spinning chains and trees of gyroscopes with liquid-filled cavities.")
    p.add_argument("--version", action="version", version=f"stabmap {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    a = sub.add_parser("atlas", help="compute an atlas from a scene and write netCDF4 or Zarr, here or on a dask cluster")
    a.add_argument("scene", nargs="?", help="scene TOML file")
    a.add_argument("--example", metavar="NAME", help="a bundled example scene (see 'stabmap examples')")
    a.add_argument("-o", "--output", required=True, help="file to write: atlas.nc (netCDF4) or atlas.zarr (Zarr)")
    a.add_argument("--png", metavar="FILE", help="also draw the atlas to this PNG/PDF")
    a.add_argument("--threads", type=int, help="threads of an in-process run (default: all cores)")
    a.add_argument("--workers", type=int, metavar="N", help="start a local dask cluster of N worker processes for the run")
    a.add_argument("--scheduler", metavar="ADDRESS", help="run on an existing dask.distributed cluster, e.g. tcp://HOST:8786 (docs/cluster.md)")
    a.add_argument("--chunk-points", type=int, metavar="P", help="grid points per task (default: about half a second of work each)")
    a.add_argument("--resume", action="store_true", help="finish an interrupted run from OUTPUT.partial/, computing only the missing chunks")
    a.add_argument("--refine", action="store_true", help="adaptive: a coarse lattice, refined only where labels change (docs/refine.md)")
    a.add_argument("--coarse-stride", type=int, metavar="S", help="with --refine: grid steps between coarse nodes, a power of two (default: 64-127 cells per axis)")
    a.add_argument("--margin", type=int, metavar="M", help="with --refine: cells split around every disagreeing cell (default 2)")
    a.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    a.set_defaults(func=_cmd_atlas)

    i = sub.add_parser("info", help="what an atlas file holds")
    i.add_argument("atlas")
    i.set_defaults(func=_cmd_info)

    q = sub.add_parser(
        "query",
        help="ask a saved atlas: the label at a point, the stable fraction, boundaries, the smallest stable value",
        description="Answers about the grid points of a saved atlas (docs/query.md).\n"
        "NAME=VALUE selects the grid value of NAME nearest to VALUE (the value used is printed);\n"
        "NAME=LO:HI keeps the grid values in [LO, HI] (LO: and :HI are open-ended); axes not named are kept whole.\n"
        "Without a question (--fraction, --boundaries, --smallest-stable): the label at one point, a value per axis.",
        epilog="examples:\n"
        "  stabmap query a.nc omega=42.5 K_1=3                      label at the nearest grid point\n"
        "  stabmap query a.nc --fraction K_1=3                      stable fraction over every omega at K_1 ~ 3\n"
        "  stabmap query a.nc --fraction omega=20:60                stable fraction of a range, every K_1\n"
        "  stabmap query a.nc --boundaries omega K_1=0:10           where N_c changes along omega (grid brackets)\n"
        "  stabmap query a.nc --smallest-stable omega --over K_1    smallest stable omega for each K_1\n"
        "  stabmap query a.nc --smallest-stable omega=0: --csv      ... of positive spin rates only, as CSV\n"
        "NAME=VALUE items go after the atlas or after the question (argparse reads none after --csv or --limit N).\n"
        "Boundaries are known to grid resolution only; 'stabmap critical' locates them to 1e-10 (docs/critical.md).",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    q.add_argument("atlas", help="an atlas file (stabmap atlas)")
    q.add_argument("point", nargs="*", metavar="NAME=VALUE", help="the point (no question), or the slice a question is asked of")
    ask = q.add_mutually_exclusive_group()
    ask.add_argument("--fraction", nargs="*", metavar="NAME=VALUE", help="the stable fraction of the slice; axes not named are counted whole")
    ask.add_argument(
        "--boundaries", nargs="+", metavar=("AXIS", "NAME=VALUE"),
        help="every change of N_c along AXIS, for every point of the other axes (or the slice): the two grid values around it, N_c on each side",
    )
    ask.add_argument(
        "--smallest-stable", nargs="*", metavar=("AXIS", "NAME=VALUE"),
        help="the smallest stable grid value of AXIS (default omega) and the unstable one just below it, for every point of the other axes",
    )
    q.add_argument(
        "--over", nargs="+", metavar=("NAME", "NAME=VALUE"),
        help="with --smallest-stable: the one axis that labels the answer (fix the others with NAME=VALUE)",
    )
    out = q.add_mutually_exclusive_group()
    out.add_argument("--csv", action="store_true", help="print CSV (every row) instead of text")
    out.add_argument("--json", action="store_true", help="print JSON (every row) instead of text")
    q.add_argument("--limit", type=int, default=40, metavar="N", help="rows of a text table (default 40; 0: all)")
    q.set_defaults(func=_cmd_query)

    pl = sub.add_parser("plot", help="draw an atlas: a map of N_c, small multiples for 3 or 4 axes (docs/plots.md)")
    pl.add_argument("atlas")
    pl.add_argument("-o", "--output", required=True, help="PNG or PDF file")
    pl.add_argument("--x", help="axis along x (default: the first axis not fixed or faceted)")
    pl.add_argument("--y", help="axis along y (default: the next one)")
    pl.add_argument("--sel", nargs="*", default=[], metavar="NAME=VALUE", help="fix axes at these values (nearest grid value)")
    pl.add_argument("--facet", metavar="NAME", help="axis drawn as one panel per value (default: the third axis; a fourth gives rows)")
    pl.add_argument("--max-panels", type=int, metavar="N", help="at most N panels, evenly spaced values (default 12)")
    pl.set_defaults(func=_cmd_plot)

    c = sub.add_parser("critical", help="stable intervals of one parameter (e.g. the critical spin rates), ends to 1e-10")
    c.add_argument("scene", nargs="?", help="scene TOML file; its grid axis --along is the scan")
    c.add_argument("--example", metavar="NAME", help="a bundled example scene (see 'stabmap examples')")
    c.add_argument("--along", default="omega", help="the scanned grid axis (default: omega)")
    c.add_argument("-o", "--output", required=True, help="netCDF file to write, e.g. critical.nc")
    c.add_argument("--png", metavar="FILE", help="also draw the stable intervals to this PNG/PDF")
    c.add_argument("--rtol", type=float, default=1e-10, help="relative width of the located ends (default 1e-10)")
    c.add_argument("--threads", type=int, help="threads (default: all cores)")
    c.add_argument("-q", "--quiet", action="store_true", help="no interval listing")
    c.set_defaults(func=_cmd_critical)

    e = sub.add_parser("examples", help="list the bundled example scenes")
    e.set_defaults(func=_cmd_examples)
    return p


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    # 'kill' (SIGTERM) stops a run as Ctrl-C does: temporary files removed, finished chunks kept for --resume.
    previous = signal.signal(signal.SIGTERM, _interrupt) if threading.current_thread() is threading.main_thread() else None
    try:
        args.func(args)
    except StabmapError as exc:
        print(f"stabmap: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"stabmap: interrupted; {_interrupted_note(args)}", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into e.g. head, which stopped reading
        sys.stdout = None
        return 0
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    return 0


def _interrupt(signum, frame):
    raise KeyboardInterrupt


def _interrupted_note(args) -> str:
    from .partial import partial_dir

    output = getattr(args, "output", None)
    if output is None or args.func is not _cmd_atlas:
        return "no output file was written"
    saved = partial_dir(output)
    if not saved.is_dir():
        return f"{output} was not written"
    chunks = len(list(saved.glob("chunk-*.npy")))
    return f"{output} was not written; {chunks} finished chunks are saved in {saved}: run the same command with --resume to finish"


if __name__ == "__main__":
    sys.exit(main())
