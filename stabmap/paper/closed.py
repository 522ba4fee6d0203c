"""The closed-chain paper's families checked against their closed forms (``stabmap paper closed``).

The paper's model is planar (its section 3 puts every axis in one plane), so its results are checked in the
planar model (scene ``model = "planar"``).  The bundled scenes ``closed-hinge`` and ``closed-figure-eight-6``
scan the length ratio h2/h1. Along it, ``stabmap.critical`` locates every change of class to 1e-10 relative;
each must be one that docs/closed.md's table (docs/closed.md, section 2) gives in closed form, with the same
classes on either side:

- hinge: stable below h2/h1 = sqrt 2, unstable (index 1) above, absent beyond h2/h1 = 2 (the hinge is then a
  folded loop, degenerate, at exactly 2);
- six-body figure-eight: absent below 2/(sqrt 2 - 1), unstable (index 1) until 5.98605461610344, stable above.

Then it says in words which of the paper's shapes are stable in space at c2 = c1 (the one value where the
paper's law (11) has an energy): the two families' classes in space along h2/h1 (``stabmap.critical`` in the
spatial model), the plane ring (27) and the twisted ring (26) for n = 4 .. 16 (``closed.solve``).
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path

import numpy as np

RTOL = 1e-9  # ends located to 1e-10; the closed forms are known to ~1e-15

# (example, [(boundary, class below, class above), ...]) from docs/closed.md's table of families
CASES = (
    ("closed-hinge", [(math.sqrt(2.0), "stable", "unstable"), (2.0, "unstable", "degenerate"), (2.0, "degenerate", "absent")]),
    ("closed-figure-eight-6", [(2.0 / (math.sqrt(2.0) - 1.0), "absent", "unstable"), (5.98605461610344, "unstable", "stable")]),
)


def _meanings(ds) -> dict[int, str]:
    from ..systems import of_atlas

    flags = of_atlas(ds.attrs).variable("stability").flags
    return {int(v): name for v, name in flags}


def check_case(name: str, expected, out: Path | None = None) -> dict:
    """Locate the boundaries of one bundled family along ``ratio`` and compare them with the closed form."""
    from ..examples import example
    from ..run.critical import critical

    scene = dataclasses.replace(example(name), model="planar")
    ds = critical(scene, "ratio", progress=False)
    meaning = _meanings(ds)
    lo, hi = ds["boundary_lower"].values, ds["boundary_upper"].values
    found = [((a + b) / 2, meaning.get(int(s), str(s)), meaning.get(int(t), str(t)), b - a)
             for a, b, s, t in zip(lo, hi, ds["stability_below"].values, ds["stability_above"].values, strict=True) if np.isfinite(a)]
    problems = []
    if len(found) != len(expected):
        problems.append(f"{name}: located {len(found)} boundaries {[(round(t, 10), b, a) for t, b, a, _ in found]}, "
                        f"the closed form has {len(expected)}")
    worst = 0.0
    for (t, below, above, _), (x, xb, xa) in zip(found, expected, strict=False):  # a count mismatch is reported above
        err = abs(t - x) / abs(x)
        worst = max(worst, err)
        if err > RTOL or (below, above) != (xb, xa):
            problems.append(f"{name}: boundary {t:.12g} ({below} -> {above}), closed form {x:.12g} ({xb} -> {xa}), rel. diff {err:.1e}")
    if out is not None:
        from ..read.plot import plot_critical

        plot_critical(ds, out / f"{name}.png")
    return {"case": name, "boundaries": len(found), "expected": len(expected), "worst_rel": worst, "problems": problems}


def run(*, out: Path | None = None) -> dict:
    """Check every family of ``CASES``; figures of the located intervals into ``out`` (None: none)."""
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    results = [check_case(name, expected, out) for name, expected in CASES]
    lines = [
        f"# closed chains: boundaries along h2/h1 located to 1e-10 by stabmap.critical; the closed forms of docs/closed.md must agree to {RTOL:g}",
        "",
        "| case | boundaries located | closed form | worst rel. diff | disagreements |",
        "|---|---|---|---|---|",
    ]
    for r in results:
        lines.append(f"| {r['case']} | {r['boundaries']} | {r['expected']} | {r['worst_rel']:.1e} | {len(r['problems'])} |")
    problems = [m for r in results for m in r["problems"]]
    lines += [f"DISAGREES: {m}" for m in problems]
    lines += ["", "# in space, at c2 = c1 (the paper's model is planar; docs/closed.md, section 1b)", ""] + in_space()
    lines.append(f"# total {time.perf_counter() - t0:.0f} s")
    return {"results": results, "problems": problems, "text": "\n".join(lines)}


def in_space() -> list[str]:
    """Which of the paper's shapes are stable in space at c2 = c1, in words: the families' stretches along h2/h1
    from ``critical`` in the spatial model, and the paper's rings (27) and (26) from ``closed.solve``."""
    from .. import closed
    from ..examples import example
    from ..run.critical import critical

    lines = []
    for name, family in (("closed-hinge", "hinge"), ("closed-figure-eight-6", "six-body figure-eight")):
        scene = example(name)
        ds = critical(scene, "ratio", progress=False)
        meaning = _meanings(ds)
        scan = next(a.array for a in scene.grid if a.name == "ratio")
        lo, hi = ds["boundary_lower"].values, ds["boundary_upper"].values
        ends = [(a + b) / 2 for a, b in zip(lo, hi, strict=True) if np.isfinite(a)]
        classes = [meaning.get(int(ds["stability_at_scan_start"]), "?")]
        classes += [meaning.get(int(t), str(t)) for t, a in zip(ds["stability_above"].values, lo, strict=True) if np.isfinite(a)]
        start = float(scan[0])
        stops = ends + [float(scan[-1])]
        stretches = []
        left = start
        for cls, right in zip(classes, stops, strict=True):
            stretches.append(f"{cls} for h2/h1 in [{left:.10g}, {right:.10g}]" if abs(right - left) > 1e-9 * right else f"{cls} at {right:.10g}")
            left = right
        lines.append(f"- {family}: " + "; ".join(stretches) + ".")
    for twist, what in ((0, "plane ring (27), j = 1"), (1, "twisted ring (26), one turn of twist (m = 1)")):
        by_n = {n: closed.solve("ring", [1.0] * n, twist=twist).stability for n in range(4 if not twist else 3, 17)}
        stable = [n for n, c in by_n.items() if c == "stable"]
        other = {n: c for n, c in by_n.items() if c != "stable"}
        text = f"stable in space for n = {', '.join(map(str, stable))}" if stable else "stable in space for no n"
        if other:
            text += "; " + ", ".join(f"{c} for n = {n}" for n, c in other.items())
        lines.append(f"- {what}, equal bodies: {text}.")
    return lines
