"""Before/after pictures of each figure kind, for docs/plots.md ("Before and after").

    python scripts/figure_gallery.py                   # docs/figures/compare-<kind>.png; "before" is d307004
    python scripts/figure_gallery.py --before REV      # another "before" version (any git revision)
    python scripts/figure_gallery.py --quick --out DIR # only the "after" side, tiny grids, no git (tests run this)

Every figure is drawn twice by the same command line (``stabmap atlas SCENE -o A.nc --png A.png``, ``stabmap plot``,
``stabmap critical``): once by the version at REV, checked out into a temporary ``git worktree`` that is removed at
the end, and once by this checkout. The two PNGs are put side by side, with a line on what changed. The "before"
version compiles its kernels on first use, which takes a minute or two.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import textwrap
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.image import imread
from matplotlib.patches import Rectangle

ROOT = Path(__file__).resolve().parents[1]
BEFORE = "d307004"  # the parent of e3bf716, where issue 22 changed the figures

CHAIN = """
title = "three free bodies, elastic joints, liquid near resonance"
support = "free"
omega = 50.0
joints = [120.0, 10.0]
""" + """
[[bodies]]
m = 1.0
A = 0.02
C = 0.004
c = 0.10
s = 0.25
fluid = { E = [1.0e-4, 2.0e-5], kappa = [2.7, 1.31] }
""" * 2 + """
[[bodies]]
m = 1.0
A = 0.02
C = 0.004
c = 0.10
fluid = { E = [1.0e-4, 2.0e-5], kappa = [2.7, 1.31] }

[grid]
omega = { start = 1.0, stop = 200.0, num = 120 }
K_1 = { start = 0.0, stop = 20.0, num = 80 }
"""

MASSES = """
title = "two tops on a fixed point, elastic joint: six masses of the top body"
support = "fixed"
g = 9.81
omega = 30.0
joints = [20.0]

[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25
fluid = { E = [1.0e-3], kappa = [1.31] }

[[bodies]]
m = 0.5
A = 0.01
C = 0.015
c = 0.08
fluid = { E = [5.0e-4], kappa = [1.31] }

[grid]
omega = { start = 1.0, stop = 150.0, num = 100 }
K_1 = { start = 0.0, stop = 40.0, num = 80 }
m_2 = { values = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0] }
"""

LOG_MASS = """
title = "two tops on a fixed point: mass of the top body on a log axis"
support = "fixed"
joints = [50.0]

[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25

[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
fluid = { E = [1e-4], kappa = [1.31] }

[grid]
omega = { start = 1.0, stop = 120.0, num = 80 }
m_2 = { start = 0.1, stop = 10.0, num = 60, scale = "log" }
"""

# The bundled example paper-n2-free-resonance as this checkout has it: both versions read the same text.
RESONANCE = (ROOT / "stabmap" / "examples" / "paper-n2-free-resonance.toml").read_text()

HINGE = """
title = "closed chain: two loops on a shared joint (hinge) against h2/h1"
system = "closed"
family = "hinge"
h1 = 1.0
c1sq = 1.0

[grid]
ratio = { start = 0.05, stop = 2.5, num = 120 }
"""

PLATE = """
system = "reactions"
title = "square plate on four corner supports: the most loaded corner as the centre of mass moves"
nodes = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]]

[body]
mass = 10.0
centre = [0.0, 0.0, 0.0]
gravity = [0.0, 0.0, -9.81]

[grid]
c_x = { start = -0.6, stop = 0.6, num = 61 }
c_y = { start = -0.6, stop = 0.6, num = 61 }
"""

ATLAS = [["atlas", "{scene}", "-o", "{nc}", "--png", "{png}", "-q"]]


@dataclass
class Kind:
    name: str  # the picture is docs/figures/compare-<name>.png
    caption: str  # what changed, in a sentence
    scene: str  # TOML
    commands: list[list[str]]  # stabmap arguments; {scene}, {nc}, {png} are filled in
    zoom: tuple[int, int, int, int] | None = None  # (left, top, right, bottom) [px] of both PNGs, shown magnified


KINDS = [
    Kind("map", "a caption under the map lists the fixed parameters per body, symbols and units in mathtext, "
         "with each body's liquid modes", CHAIN, ATLAS),
    Kind("facets", "small multiples get the same caption of fixed parameters, under all the panels",
         MASSES, [["atlas", "{scene}", "-o", "{nc}", "-q"], ["plot", "{nc}", "-o", "{png}", "--facet", "m_2"]]),
    Kind("log-axis", "a log axis is labelled at 2 and 5 between the decades, as 0.1 ... 10 rather than $10^{-1}$ ... $10^{1}$",
         LOG_MASS, ATLAS),
    # The map's lower left: a tongue of one complex pair and a stable strip, each one grid cell high.
    Kind("thin-bands", "a band one cell wide keeps its class colour between two thinner lines instead of becoming "
         "a black bar", RESONANCE, ATLAS, zoom=(90, 630, 370, 705)),
    Kind("critical", "critical values put the scanned parameter (ω) on x as the atlas maps do, "
         "each stretch in its class's colour as on the maps, a labelled log axis and the caption of fixed parameters", LOG_MASS,
         [["critical", "{scene}", "--along", "omega", "-o", "{nc}", "--png", "{png}", "-q"]]),
    Kind("closed", "closed chains: one axis is a line of the class over its colours; fixed parameters captioned", HINGE, ATLAS),
    Kind("reactions", "reactions maps: only the caption of fixed parameters is new", PLATE, ATLAS),
]


def tiny(scene: str) -> str:
    """The scene on a grid of a few points per axis (lists of values are kept)."""
    return re.sub(r"num = \d+", "num = 6", scene)


def render(tree: Path, kinds: list[Kind], work: Path, quick: bool = False) -> dict[str, Path]:
    """Run every kind's commands with the stabmap found at ``tree``; the PNG of each kind, by name."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    work.mkdir(parents=True, exist_ok=True)
    out = {}
    for kind in kinds:
        scene = work / f"{kind.name}.toml"
        scene.write_text(tiny(kind.scene) if quick else kind.scene)
        names = {"scene": str(scene), "nc": str(work / f"{kind.name}.nc"), "png": str(work / f"{kind.name}.png")}
        for args in kind.commands:
            args = [a.format(**names) for a in args]
            run = subprocess.run([sys.executable, "-m", "stabmap", *args], env=env, cwd=work, capture_output=True, text=True, check=False)
            if run.returncode:
                raise SystemExit(f"stabmap {' '.join(args)} (at {tree}) failed:\n{run.stderr}")
        out[kind.name] = Path(names["png"])
    return out


def compose(images: list[tuple[str, Path]], kind: Kind, path: Path, width: float = 12.0, dpi: int = 150) -> Path:
    """The images under their headings, the zoomed region of each under it, the caption at the bottom.

    Side by side, or one above the other when the figures are wide (small multiples, strips), which side by side
    would shrink to unreadable. All are shown at one scale, never enlarged, so that the two versions line up.
    """
    pictures = [np.asarray(imread(p)) for _, p in images]
    n = len(pictures)
    stacked = min(p.shape[1] / p.shape[0] for p in pictures) > 1.6
    gap, head = 0.15, 0.3  # [in]
    column = width - 2 * gap if stacked else (width - gap * (n + 1)) / n
    scale = min(column / max(p.shape[1] for p in pictures), 1.0 / dpi)  # inches per pixel
    column = max(p.shape[1] for p in pictures) * scale
    width = column + 2 * gap if stacked else n * column + (n + 1) * gap  # no blank margin right of small figures
    tall = max(p.shape[0] for p in pictures) * scale
    zoom_tall = 0.0
    if kind.zoom:
        left, top, right, bottom = kind.zoom
        zoom_tall = column * (bottom - top) / (right - left)
    caption = textwrap.fill("What changed: " + kind.caption, int(width * 11))
    foot = 0.15 + 0.2 * (caption.count("\n") + 1)
    block = head + tall + (head + zoom_tall if kind.zoom else 0.0)
    height = (n if stacked else 1) * block + foot
    fig = Figure(figsize=(width, height), dpi=dpi)
    for k, ((heading, _), picture) in enumerate(zip(images, pictures)):
        x = (gap if stacked else gap + k * (column + gap)) / width
        top_of_block = height - (k * block if stacked else 0.0)
        h, w = picture.shape[0] * scale, picture.shape[1] * scale
        ax = fig.add_axes((x, (top_of_block - head - h) / height, w / width, h / height))
        ax.imshow(picture, interpolation="antialiased")
        ax.set_title(heading, fontsize=12, fontweight="bold", loc="left")
        ax.set_axis_off()
        if kind.zoom:
            ax.add_patch(Rectangle((left, top), right - left, bottom - top, fill=False, ec="#CC0066", lw=1.5))
            zx = fig.add_axes((x, (top_of_block - block) / height, column / width, zoom_tall / height))
            zx.imshow(picture[top:bottom, left:right], interpolation="nearest")
            zx.set_title("the framed region, magnified", fontsize=10, loc="left")
            zx.set_xticks([])
            zx.set_yticks([])
            for spine in zx.spines.values():
                spine.set_edgecolor("#CC0066")
    fig.text(gap / width, 0.1 / height, caption, fontsize=11, va="bottom")
    fig.savefig(path, dpi=dpi, facecolor="white")
    return path


def is_png(path: Path) -> bool:
    return path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def main(argv: list[str] | None = None) -> dict[str, Path]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default=BEFORE, help=f"git revision drawn as 'before' (default {BEFORE})")
    parser.add_argument("--out", type=Path, help="directory of the compare-<kind>.png files (default docs/figures; "
                        "with --quick a new temporary directory)")
    parser.add_argument("--quick", action="store_true", help="only the 'after' side, on tiny grids, no git")
    parser.add_argument("--kinds", nargs="+", choices=[k.name for k in KINDS], help="only these kinds")
    args = parser.parse_args(argv)
    kinds = [k for k in KINDS if not args.kinds or k.name in args.kinds]
    out = args.out or (Path(tempfile.mkdtemp(prefix="figure-gallery-")) if args.quick else ROOT / "docs" / "figures")
    out.mkdir(parents=True, exist_ok=True)

    written = {}
    with tempfile.TemporaryDirectory(prefix="figure-gallery-") as tmp:
        tmp = Path(tmp)
        start = time.perf_counter()
        after = render(ROOT, kinds, out / "after" if args.quick else tmp / "after", quick=args.quick)
        print(f"after: {len(after)} figures in {time.perf_counter() - start:.0f} s")
        before = {}
        if not args.quick:
            tree = tmp / "before-tree"
            subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), args.before], check=True, capture_output=True)
            try:
                start = time.perf_counter()
                before = render(tree, kinds, tmp / "before")
                print(f"before ({args.before}): {len(before)} figures in {time.perf_counter() - start:.0f} s")
            finally:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], check=False)
        for kind in kinds:
            images = ([(f"before (stabmap at {args.before})", before[kind.name])] if before else []) + [("after", after[kind.name])]
            written[kind.name] = compose(images, kind, out / f"compare-{kind.name}.png")
    bad = [str(p) for p in [*written.values(), *(after.values() if args.quick else [])] if not is_png(p)]
    if bad:
        raise SystemExit(f"not written or not a PNG: {', '.join(bad)}")
    for p in written.values():
        print(f"wrote {p} ({p.stat().st_size / 1024:.0f} KB)")
    return written


if __name__ == "__main__":
    main()
