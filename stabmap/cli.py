"""The ``stabmap`` command: one thin click command per job, each calling ``stabmap.jobs``."""

from __future__ import annotations

import os
import signal
import sys
import threading

import click

from .errors import StabmapError, cli_spelling
from .version import __version__

# library parameters whose flag is not the parameter's name with "--" and dashes (stabmap.errors.cli_spelling)
FLAGS = {"cases": "--case", "client": "--scheduler"}


class Interrupted(click.ClickException):
    """Ctrl-C or SIGTERM: exit status 130 and what the interrupted command left behind."""

    exit_code = 130

    def show(self, file=None) -> None:
        click.echo(f"stabmap: interrupted; {self.message}", err=True)


def _report(done) -> None:
    for line in done.notes:
        click.echo(line, err=True)
    if done.text:
        click.echo(done.text)


def _where(scheduler, workers, threads) -> dict:
    return {"client": scheduler, "workers": workers, "threads": threads}


_scene_source = [
    click.argument("scene", required=False, type=click.Path(dir_okay=False)),
    click.option("--example", metavar="NAME", help="a bundled example scene (see 'stabmap examples')"),
]
_overwrite = click.option("--overwrite", is_flag=True, help="replace output files that exist (without it, an existing output is an error)")
_cluster = [
    click.option("--threads", type=int, help="threads of an in-process run (default: all cores)"),
    click.option("--workers", type=int, metavar="N", help="start a local dask cluster of N worker processes for the run"),
    click.option("--scheduler", metavar="ADDRESS", help="run on an existing dask.distributed cluster, e.g. tcp://HOST:8786 (docs/cluster.md)"),
    click.option("--chunk-points", type=int, metavar="P", help="points per task (default: about half a second of work each)"),
]


def _options(options):
    def decorate(f):
        for option in reversed(options):
            f = option(f)
        return f

    return decorate


@click.group(context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 110})
@click.version_option(__version__, prog_name="stabmap", message="%(prog)s %(version)s")
def cli() -> None:
    """Stability atlases of spinning multibody systems, every label proved."""


@cli.command(short_help="Compute an atlas from a scene: netCDF4 or Zarr, here or on a dask cluster.")
@_options(_scene_source)
@click.option("-o", "--output", required=True, help="file to write: atlas.nc (netCDF4) or atlas.zarr (Zarr)")
@click.option("--png", metavar="FILE", help="also draw the atlas to this PNG/PDF")
@_options(_cluster)
@click.option("--resume", is_flag=True, help="finish an interrupted run from OUTPUT.partial/, computing only the missing chunks")
@click.option("--refine", is_flag=True, help="opt-in, not proved: a coarse lattice, the other points inferred from their cell's corners "
              "and marked so (docs/refine.md)")
@click.option("--coarse-stride", type=int, metavar="S", help="with --refine: grid steps between coarse nodes, a power of two")
@click.option("--margin", type=int, metavar="M", help="with --refine: cells split around every disagreeing cell (default 2)")
@click.option("--node-by-node", is_flag=True, help="prove every grid node on its own, no box proofs: every cell node_only (docs/cells.md)")
@_overwrite
@click.option("-q", "--quiet", is_flag=True, help="no progress line")
def atlas(scene, example, output, png, threads, workers, scheduler, chunk_points, resume, refine, coarse_stride, margin, node_by_node,
          overwrite, quiet):
    """Compute an atlas from a scene and write netCDF4 or Zarr, here or on a dask cluster."""
    from . import jobs
    from .run.runner import quiet_dask_logs

    try:
        with quiet_dask_logs(scheduler is not None or workers is not None):
            _report(jobs.atlas(
                jobs.scene(scene, example), output, png=png, refine=refine, coarse_stride=coarse_stride, margin=margin,
                prove_cells=not node_by_node, resume=resume, overwrite=overwrite, chunk_points=chunk_points, progress=not quiet,
                **_where(scheduler, workers, threads),
            ))
    except KeyboardInterrupt:
        raise Interrupted(jobs.interrupted(output)) from None


@cli.command(short_help="What an atlas file holds: scene, axes, stable fraction, who decided.")
@click.argument("atlas")
@click.option("--limit", type=int, default=8, show_default=True, metavar="N", help="critical values: points of the other axes listed (0: all)")
@click.option("--all", "every", is_flag=True, help="critical values: list every point and every undecided gap (--limit 0)")
def info(atlas, limit, every):
    """What an atlas file holds: scene, axes, stable fraction, who decided; critical values: the stable intervals."""
    from . import jobs

    click.echo(jobs.info(atlas, limit=0 if every else limit))


@cli.command(
    short_help="Ask a saved atlas: a label, a stable fraction, boundaries, the smallest stable value.",
    epilog="""\b
examples:
  stabmap query a.nc omega=42.5 K_1=3                      label at the nearest grid point
  stabmap query a.nc --fraction K_1=3                      stable fraction over every omega at K_1 ~ 3
  stabmap query a.nc --fraction omega=20:60                stable fraction of a range, every K_1
  stabmap query a.nc --boundaries omega K_1=0:10           where N_c changes along omega (grid brackets)
  stabmap query a.nc --smallest-stable omega --over K_1    smallest stable omega for each K_1
  stabmap query a.nc --smallest-stable omega=0: --csv      ... of positive spin rates only, as CSV
  stabmap query a.nc --boundaries omega K_1=3 --locate     every change, however narrow, located to 1e-10
  stabmap query crit.nc --csv -o crit.csv                  critical values: every stable interval and boundary
  stabmap query a.nc --csv -o a.csv                        the whole atlas: one row per grid point
  stabmap query a.nc omega=42.5 K_1=3 --roots              every root there, enclosed, with kind and origin
\b
Without --locate, boundaries are known to grid resolution only; --locate computes critical values of the
atlas's scene along the selected lines: complete, and located to 1e-10 (docs/critical.md)."""
)
@click.argument("atlas")
@click.argument("items", nargs=-1, metavar="[NAME=VALUE | NAME=LO:HI]...")
@click.option("--fraction", is_flag=True, help="the stable fraction of the slice; axes not named are counted whole")
@click.option("--boundaries", metavar="AXIS", help="every change of the label along AXIS, between two neighbouring grid values")
@click.option("--smallest-stable", is_flag=False, flag_value="", default=None, metavar="[AXIS]",
              help="the smallest stable grid value of AXIS (default: the system's, e.g. omega), for every point of the other axes")
@click.option("--over", metavar="NAME", help="with --smallest-stable: the one axis that labels the answer")
@click.option("--locate", is_flag=True, help="with --boundaries or --smallest-stable: critical values of the atlas's scene, "
              "every change located to 1e-10, undecided stretches listed (computes)")
@click.option("--roots", is_flag=True, help="every characteristic root at the point (computed there, not the nearest grid point): "
              "proved enclosure, multiplicity, real or complex pair, liquid mode or structural (docs/rates.md)")
@click.option("--csv", "fmt", flag_value="csv", help="print CSV (every row)")
@click.option("--json", "fmt", flag_value="json", help="print JSON (every row)")
@click.option("--limit", type=int, default=40, metavar="N", help="rows of a text table (default 40; 0: all)")
@click.option("-o", "--output", metavar="FILE", help="write the answer to FILE (atomically) instead of printing it; "
              "its suffix picks the format (.txt, .csv, .json)")
@click.option("--nearest-edge", is_flag=True, help="a value outside the scan takes its nearest end (otherwise an error)")
@_overwrite
def query(atlas, items, fraction, boundaries, smallest_stable, over, locate, roots, fmt, limit, output, nearest_edge, overwrite):
    """Ask a saved atlas: the label at a point, the stable fraction, boundaries, the smallest stable value.

    NAME=VALUE selects the grid value of NAME nearest to VALUE (the value used is printed); NAME=LO:HI keeps the
    grid values in [LO, HI] (LO: and :HI are open-ended); axes not named are kept whole (docs/query.md).
    """
    from . import jobs

    # a question's axis is the library's along: name the flag that gave it
    with cli_spelling({**FLAGS, "along": "--boundaries" if boundaries is not None else "--smallest-stable"}):
        text = jobs.query(atlas, items, fraction=fraction, boundaries=boundaries, smallest_stable=smallest_stable, over=over,
                          locate=locate, roots=roots, fmt=fmt, limit=limit, output=output, overwrite=overwrite, nearest_edge=nearest_edge)
    if text is not None:  # None: every grid point was streamed to standard output
        click.echo(text)


@cli.command(short_help="Draw an atlas (or critical values) to a PNG or PDF file, or an interactive HTML page.")
@click.argument("atlas")
@click.argument("items", nargs=-1, metavar="[NAME=VALUE]...")
@click.option("-o", "--output", required=True, help="PNG or PDF file, or an .html page (interactive: a slider per further axis)")
@click.option("--x", help="axis along x (default: the first axis not fixed or faceted)")
@click.option("--y", help="axis along y (default: the next one)")
@click.option("--sel", multiple=True, metavar="NAME=VALUE", help="fix an axis at this value (nearest grid value); also NAME=VALUE after the atlas")
@click.option("--facet", metavar="NAME", help="axis drawn as one panel per value (default: the third axis; a fourth gives rows)")
@click.option("--max-panels", type=int, metavar="N", help="at most N panels, evenly spaced values (default 12)")
@click.option("--max-mb", type=float, metavar="MB",
              help="an .html page's size bound: slider values beyond it are left out, evenly spaced ones kept (default 20)")
@click.option("--var", metavar="NAME", help="draw this float variable instead of the classes, e.g. growth_rate: a map with a colour "
              "bar, or a line along one axis (docs/plots.md)")
@click.option("--campbell", is_flag=True,
              help="the Campbell diagram: every mode's frequency against the spin rate, critical speeds, growth rate "
                   "(an atlas computed with frequencies = true; docs/rates.md)")
@_overwrite
def plot(atlas, items, output, x, y, sel, facet, max_panels, max_mb, var, overwrite, campbell):
    """Draw an atlas: a map of its classes, small multiples for 3 or 4 axes (docs/plots.md); or write an interactive
    page (.html, no server needed: docs/explore.md). --campbell: its Campbell diagram (docs/rates.md)."""
    from . import jobs

    _report(jobs.plot(atlas, output, x=x, y=y, sel=[*sel, *items], facet=facet, max_panels=max_panels, max_mb=max_mb,
                      overwrite=overwrite, var=var, campbell=campbell))


@cli.command(short_help="Stable intervals of one parameter (the critical spin rates, say), ends to 1e-10.")
@_options(_scene_source)
@click.option("--along", default=None, help="the scanned grid axis (default: the system's, e.g. omega for gyroscopes)")
@click.option("-o", "--output", required=True, help="netCDF file to write, e.g. critical.nc")
@click.option("--png", metavar="FILE", help="also draw the stable intervals to this PNG/PDF")
@click.option("--rtol", type=float, default=1e-10, show_default=True, help="relative width of the located ends")
@_options(_cluster)
@_overwrite
@click.option("-q", "--quiet", is_flag=True, help="no interval listing")
def critical(scene, example, along, output, png, rtol, threads, workers, scheduler, chunk_points, overwrite, quiet):
    """Stable intervals of one parameter (e.g. the critical spin rates), ends to 1e-10."""
    from . import jobs
    from .run.runner import quiet_dask_logs

    try:
        with quiet_dask_logs(scheduler is not None or workers is not None):
            _report(jobs.critical(
                jobs.scene(scene, example), output, along=along, rtol=rtol, png=png, chunk_points=chunk_points,
                listing=not quiet, progress=not quiet, overwrite=overwrite, **_where(scheduler, workers, threads),
            ))
    except KeyboardInterrupt:
        raise Interrupted("no output file was written") from None


@cli.command(short_help="List the bundled example scenes, or print one's TOML (--show NAME).")
@click.option("--show", metavar="NAME", help="print the scene file of this example (a start for your own scene)")
def examples(show):
    """List the bundled example scenes; with --show NAME, print that example's scene (TOML).

    \b
    stabmap examples --show paper-n1-fixed > my-scene.toml    a scene file of your own to edit
    stabmap atlas my-scene.toml -o my-atlas.nc                 its atlas
    """
    from . import jobs

    for line in jobs.examples(show):
        click.echo(line)


@cli.command(short_help="Recompute the source papers' results and check them: determinants, closed forms, figures.")
@click.argument("systems", nargs=-1, metavar="[gyroscopes|closed|reactions|viscous]...")
@click.option("--out", metavar="DIR", help="write the figures to DIR/<system>/ (default: no figures)")
@click.option("--quick", is_flag=True, help="gyroscopes: coarse grids (60 x 40) and 3 checked rows per case; viscous: 25 points per axis")
@click.option("--case", "cases", multiple=True, metavar="NAME", help="gyroscopes: only this paper case (repeatable; e.g. paper-n1-fixed-dry)")
@click.option("--rows", type=int, metavar="N", help="gyroscopes: rows checked per case (default 15, --quick 3)")
def paper(systems, out, quick, cases, rows):
    """Recompute the papers' cases and check them; exit status 1 on any disagreement (docs/paper-cases.md).

    gyroscopes: the cases n = 1, 2, 3 against the printed determinants (exact arithmetic) and closed forms;
    closed: the families' boundaries along h2/h1 against docs/closed.md; reactions: the square plate's G/4;
    viscous: the cases n = 1, 2, 3 with a viscous liquid against the Kelvin-Tait-Chetaev criterion.
    """
    from . import paper as papers

    done = papers.check(systems, out=out, quick=quick, cases=cases, rows=rows)
    click.echo(done["text"])
    if done["problems"]:
        raise click.ClickException(f"{len(done['problems'])} disagreements with the papers (DISAGREES lines above)")


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (2: bad input, 130: interrupted)."""
    # 'kill' (SIGTERM) stops a run as Ctrl-C does: temporary files removed, finished chunks kept for --resume.
    previous = signal.signal(signal.SIGTERM, _interrupt) if threading.current_thread() is threading.main_thread() else None
    try:
        with cli_spelling(FLAGS):  # library errors name the flags of the command line (stabmap.errors)
            cli.main(args=argv, prog_name="stabmap", standalone_mode=False)
    except StabmapError as exc:
        click.echo(f"stabmap: error: {exc}", err=True)
        return getattr(exc, "exit_status", 2)  # 2: bad input; 3: the dask scheduler was lost
    except click.ClickException as exc:
        exc.show()
        return _leave(exc.exit_code, argv)
    except (KeyboardInterrupt, click.Abort):
        click.echo("stabmap: interrupted", err=True)
        return _leave(130, argv)
    except BrokenPipeError:  # output piped into e.g. head, which stopped reading
        sys.stdout = None
        return 0
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    return 0


def _leave(status: int, argv) -> int:
    """After Ctrl-C: the command's process (``argv`` None: run as ``stabmap ...``) exits now, even while a thread
    still runs a task it cannot stop (every finished chunk is already saved); a call from Python returns."""
    if status == 130 and argv is None:
        others = [t for t in threading.enumerate() if t is not threading.main_thread() and not t.daemon and t.is_alive()]
        if others:
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(status)
    return status


def _interrupt(signum, frame):
    raise KeyboardInterrupt


if __name__ == "__main__":
    sys.exit(main())
