"""The figures of docs/reactions.md, and the speed behind the reactions system's task sizes.

    python scripts/reactions_figure.py            # writes docs/figures/reactions-square-plate.png and
                                                  # reactions-spinning-stage.png (the two bundled examples)
    python scripts/reactions_figure.py --bench    # CPU seconds per point: load axes, node axes, ties, collinear
                                                  # (--quick: small grids; tests/test_reactions_atlas.py runs both)

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
    """CPU seconds per point of ``evaluate`` (the best of three; CPU time, so that other work on the machine does
    not count): a grid over the load only (one layout), over one node coordinate (one layout per value of it) and
    over two (one per point), none of them through a tie; then the bundled plate, whose axes are exact ties, and a
    collinear shaft, where every point is decided in exact arithmetic. Each line says how many points the float
    bound decided and how many exact arithmetic did."""
    from stabmap.run.tasks import evaluate_block
    from stabmap.scene.grid import resample

    nodes = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]
    side = int(np.sqrt(points))
    scenes = {}
    for label, (a, b) in {
        "load axes only (c_x, c_y)": ("c_x", "c_y"),
        "one node coordinate scanned (x_0, c_y)": ("x_0", "c_y"),
        "two node coordinates scanned (x_0, y_1)": ("x_0", "y_1"),
    }.items():
        # an even number of points: c_y = 0, where nodes 0 and 3 tie, is not on the grid
        grid = (Axis(a, tuple(np.linspace(-0.45, -0.05, side))), Axis(b, tuple(np.linspace(-0.4, 0.4, 2 * (side // 2)))))
        scenes[label] = Scene(nodes=nodes, body=Body(mass=10.0), grid=grid)
    odd = 2 * (side // 2) + 1
    scenes["square plate example (ties on its axes)"] = resample(stabmap.example("reactions-square-plate"), c_x=odd, c_y=odd)
    shaft = Scene(nodes=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.5, 0.0, 0.0]], body=Body(mass=10.0, centre=(1.0, 0.0, 0.2)),
                  grid=(Axis("c_x", tuple(np.linspace(-1.0, 3.0, max(2, side // 10)))), Axis("g_elevation", tuple(np.linspace(-90.0, 0.0, max(2, side // 10))))))
    scenes["collinear shaft (all exact, 1 % of the points)"] = shaft  # gravity in the shaft's plane: compatible
    for label, scene in scenes.items():
        shape = scene.shape
        location = tuple((0, k) for k in shape)
        evaluate_block(scene, tuple((0, min(2, k)) for k in shape))  # warm up
        seconds = np.inf
        for _ in range(3):  # the best of three
            t0 = time.process_time()
            out = evaluate_block(scene, location)
            seconds = min(seconds, (time.process_time() - t0) / int(np.prod(shape)))
        exact = int(np.sum(out["decided_by"] == 1))
        print(f"{label:<48} {seconds * 1e6:7.2f} us per point ({int(np.prod(shape)):,} points, {exact:,} exact)")


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
