"""The figures of docs/reactions.md, and the speed behind the reactions system's task sizes.

    python scripts/reactions_figure.py            # writes docs/figures/reactions-square-plate.png and
                                                  # reactions-spinning-stage.png (the two bundled examples)
    python scripts/reactions_figure.py --bench    # seconds per point, load axes only and node axes scanned
                                                  # (--quick: a small grid; tests/test_reactions_atlas.py runs both)

The square plate's map is stabmap's own picture of the atlas (which corner carries the most), with the stored
R_max drawn over it as contours in units of the weight: a quarter of the weight at the centre, where all four
corners tie.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import stabmap
from stabmap.read.plot import save_figure
from stabmap.scene.grid import Axis
from stabmap.systems.reactions import Body, Scene

ROOT = Path(__file__).resolve().parents[1]


def plate_figure(out: Path) -> None:
    scene = stabmap.example("reactions-square-plate")
    ds = stabmap.compute_atlas(scene, progress=False)
    fig = stabmap.atlas_figure(ds)
    ax = fig.axes[0]
    weight = scene.body.mass * float(np.linalg.norm(scene.body.gravity))
    share = ds["R_max"].transpose("c_y", "c_x") / weight
    lines = ax.contour(ds["c_x"], ds["c_y"], share, levels=[0.3, 0.4, 0.5, 0.6, 0.75], colors="k", linewidths=0.7, zorder=5)
    ax.clabel(lines, fmt=lambda v: f"{v:g} G", fontsize=8)
    ax.plot([-0.5, 0.5, 0.5, -0.5, -0.5], [-0.5, -0.5, 0.5, 0.5, -0.5], color="0.2", lw=1.2, ls="--", zorder=6)
    for k, (x, y, _) in enumerate(scene.nodes):
        ax.plot(x, y, "ko", ms=5, zorder=7)
        ax.annotate(f"node {k}", (x, y), xytext=(x * 0.8, y * 0.88), ha="center", va="center", fontsize=8, zorder=7)
    ax.text(0.0, 0.0, "G/4 each", ha="center", va="bottom", fontsize=8, zorder=7)
    ax.set_title(ax.get_title() + "\ncontours: R_max in units of the weight G; dashed: the plate", fontsize=10)
    save_figure(fig, out / "reactions-square-plate.png")


def bench(points: int = 200_000) -> None:
    """Seconds per point of ``evaluate`` on one core: a grid over the load only (one SVD in all), over one node
    coordinate (one SVD per grid value of it), and over two (one SVD per point)."""
    from stabmap.run.tasks import evaluate_block

    nodes = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]
    side = int(np.sqrt(points))
    cases = {
        "load axes only (c_x, c_y)": ("c_x", "c_y"),
        "one node coordinate scanned (x_0, c_y)": ("x_0", "c_y"),
        "two node coordinates scanned (x_0, y_1)": ("x_0", "y_1"),
    }
    for label, (a, b) in cases.items():
        grid = (Axis(a, tuple(np.linspace(-0.45, -0.05, side))), Axis(b, tuple(np.linspace(-0.4, 0.4, side))))
        scene = Scene(nodes=nodes, body=Body(mass=10.0), grid=grid)
        location = ((0, side), (0, side))
        evaluate_block(scene, ((0, 2), (0, 2)))  # warm up
        t0 = time.perf_counter()
        evaluate_block(scene, location)
        seconds = (time.perf_counter() - t0) / side**2
        print(f"{label:<40} {seconds * 1e6:7.2f} us per point ({side**2:,} points)")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "figures")
    parser.add_argument("--bench", action="store_true", help="measure seconds per point instead of drawing")
    parser.add_argument("--quick", action="store_true", help="with --bench: a small grid (the test suite runs it)")
    args = parser.parse_args(argv)
    if args.bench:
        bench(2_500 if args.quick else 200_000)
        return
    args.out.mkdir(parents=True, exist_ok=True)
    plate_figure(args.out)
    stabmap.plot_atlas(stabmap.compute_atlas(stabmap.example("reactions-spinning-stage"), progress=False),
                       args.out / "reactions-spinning-stage.png")
    print(f"wrote {args.out / 'reactions-square-plate.png'} and {args.out / 'reactions-spinning-stage.png'}")


if __name__ == "__main__":
    main()
