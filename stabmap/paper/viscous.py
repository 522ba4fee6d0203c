"""The paper's cases n = 1, 2, 3 with a viscous liquid, checked (``stabmap paper viscous``; docs/viscous.md).

Kononov's seed 003 gives the viscous model's equations but no worked cases, so its cases n = 1, 2, 3 (the bundled
``paper-*`` scenes) are run again with every liquid made viscous, through the same pipeline as any atlas, and each
label is compared with the classical criterion that holds for one spin rate and a liquid in every body
(Kelvin-Tait-Chetaev; Rumyantsev for the top): with a dissipation that reaches every coordinate, the uniform
rotation is asymptotically stable exactly when the potential in the frame spinning with the bodies,
V = -Phi(-omega) = K + omega G - omega^2 M, is positive definite.  For one top that is (C - A') omega^2 > m g c;
for a free system its rigid tilt gives the major-axis rule.  V is formed in exact rational arithmetic
(``gyroscopes.exact.char_matrix``) and its definiteness decided by its leading principal minors.

The paper's bodies are prolate (C < A), and so they never settle; each case is also run with every C four times as
large (``oblate``), where both classes occur.  Points labelled undecided are counted, not compared.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any

import flint
import numpy as np

CASES = ("paper-n1-fixed", "paper-n1-free", "paper-n2-fixed", "paper-n2-free", "paper-n3-fixed", "paper-n3-free",
         "paper-n3-fixed-split")
# A viscous liquid in every body, given by its tensor: the label does not depend on its size (docs/viscous.md)
LIQUID: dict[str, Any] = {"shape": "table", "tensor": (1e-9, 1e-9), "radius": 0.01, "density": 1000.0, "viscosity": 0.1}


def viscous(scene, oblate: bool = False):
    """``scene`` with every liquid replaced by a viscous one (and every C times 4 if ``oblate``)."""
    from ..systems.gyroscopes.liquid import Cavity

    cav = Cavity(**LIQUID)
    bodies = tuple(dataclasses.replace(b, E=(), kappa=(), cavity=cav, C=b.C * (4.0 if oblate else 1.0)) for b in scene.bodies)
    return dataclasses.replace(scene, bodies=bodies, title=scene.title + (", viscous, oblate" if oblate else ", viscous"))


def settles(points, i: int) -> bool | None:
    """The criterion at point i of ``points`` (None where the bodies spin at different rates)."""
    from ..kernels import layout
    from ..systems.gyroscopes import exact

    w = points.body[i, :, layout.OMEGA]
    if not np.all(w == w[0]):
        return None
    P, _ = exact.char_matrix(points.body[i], points.joint[i], points.g[i], points.E[i], points.kappa[i], points.nmodes,
                             points.free, points.parent, points.at[i])
    V = -P(-exact._q(float(w[0])))
    n = V.nrows()
    return all(flint.fmpq_mat([[V[r, c] for c in range(k)] for r in range(k)]).det() > 0 for k in range(1, n + 1))


def run(*, out: Path | None = None, quick: bool = False) -> dict:
    """Every case, as stated and oblate, on a grid of 25 (quick) or 60 points per axis; figures into ``out``."""
    from ..examples import example
    from ..run import atlas
    from ..scene.grid import resample
    from ..systems.gyroscopes.points import point_arrays
    from ..systems.viscous.outputs import ASYMPTOTICALLY_STABLE, UNDECIDED

    t0 = time.perf_counter()
    num = 25 if quick else 60
    rows, problems = [], []
    for name in CASES:
        for oblate in (False, True):
            scene = viscous(example(name), oblate)
            scene = resample(scene, **{a.name: num for a in scene.grid if len(a.array) > num})
            ds = atlas.compute(scene, progress=False)
            label = ds["asymptotic_stability"].values.reshape(-1)
            axes = [a.name for a in scene.grid]
            grids = np.meshgrid(*(ds[k].values for k in axes), indexing="ij")
            points = point_arrays(scene, {k: g.reshape(-1) for k, g in zip(axes, grids, strict=True)})
            agree = wrong = 0
            for i in np.flatnonzero(label >= 0):
                expected = settles(points, int(i))
                if expected is None:
                    continue
                if expected == (label[i] == ASYMPTOTICALLY_STABLE):
                    agree += 1
                else:
                    wrong += 1
                    point = dict(zip(axes, (float(g.reshape(-1)[i]) for g in grids), strict=True))
                    problems.append(f"{name}{' oblate' if oblate else ''}: point {point} "
                                    f"labelled {int(label[i])}, the criterion says {'settles' if expected else 'grows'}")
            case = f"{name}{' (C x 4)' if oblate else ''}"
            rows.append(f"| {case} | {label.size} | {100 * np.mean(label == ASYMPTOTICALLY_STABLE):.1f} % | "
                        f"{int(np.sum(label == UNDECIDED))} | {agree} | {wrong} |")
            if out is not None:
                from ..read.plot import plot_atlas

                out.mkdir(parents=True, exist_ok=True)
                plot_atlas(ds, out / f"{name}{'-oblate' if oblate else ''}-viscous.png")
    lines = [
        "# viscous: the paper's cases with every liquid viscous, each proved label against the definiteness of",
        "# V = K + omega G - omega^2 M in exact arithmetic (Kelvin-Tait-Chetaev; (C - A') omega^2 > m g c for one top)",
        "",
        "| case | points | asymptotically stable | undecided | agree | disagree |",
        "|---|---|---|---|---|---|",
        *rows,
    ]
    lines += [f"DISAGREES: {m}" for m in problems[:20]]
    lines.append(f"# total {time.perf_counter() - t0:.0f} s")
    return {"results": [], "problems": problems, "text": "\n".join(lines)}
