"""Closed chains: cost of a point, from the system's ``evaluate`` on one core (docs/closed.md, "Speed").

    PYTHONPATH=. python scripts/bench_closed.py            # about two minutes
    PYTHONPATH=. python scripts/bench_closed.py --quick    # a few seconds; run once by the test suite

Each row times ``SYSTEM.evaluate`` on a block of points, as an atlas task does (the pipeline's chunking, files
and threads left out), best of ``repeat`` runs: a scan of the ratio h2/h1 of each two-length family, a ratio x
c1^2 grid (c2 = c1 at every point, so the labels depend on the ratio only: one proof per ratio), rings over n and
the ratio.  Every block is decided in space (the default ``model = "spatial"``: the planar block and the
out-of-plane block proved); the rows marked "planar" are the same scenes with ``model = "planar"`` (the planar
block alone), so the pair is the cost of the spatial proof against the planar one.  Then blocks that vary
c2^2/c1^2: a ratio x c2sq grid (one proof per point; a planar scene refuses a c2sq axis, since c2sq leaves its labels alone) and
twisted rings (n = 12, 24; twist m = 1) over c2sq, the whole 3n-component spatial Hessian proved at every point.
It also counts the points by how they were decided (``decided_by``, where the system has it).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import stabmap
from stabmap.systems.closed import SYSTEM


def _scenes(num: int) -> list[tuple[str, str]]:
    side = max(2, round(num**0.5))
    rings = max(3, num // 8)  # a twisted ring of 24 bodies costs about 60 ms a point
    # c2sq values of the twisted rings: none on a boundary (n = 12: 1.6074628..., 24: 1.7043790...), where a point
    # is undecided; np.linspace(0.5, 3.0, rings) is not one, and no double equals those algebraic numbers
    spatial = [
        ("figure-eight-6 ratio", f'family = "figure-eight-6"\n[grid]\nratio = {{ start = 3.0, stop = 12.0, num = {num} }}'),
        ("hinge ratio", f'family = "hinge"\n[grid]\nratio = {{ start = 0.2, stop = 2.6, num = {num} }}'),
        ("figure-eight-4 ratio", f'family = "figure-eight-4"\n[grid]\nratio = {{ start = 0.05, stop = 1.2, num = {num} }}'),
        ("hinge ratio x c1sq", (f'family = "hinge"\n[grid]\nratio = {{ start = 0.2, stop = 2.6, num = {side} }}\n'
                                f'c1sq = {{ start = 0.5, stop = 4.0, num = {side} }}')),
        ("ring n x ratio", (f'family = "ring"\n[grid]\nn = {{ values = [5, 6, 7, 8, 9, 10] }}\n'
                            f'ratio = {{ start = 0.5, stop = 2.0, num = {max(2, num // 6)} }}')),
    ]
    planar = [(f"{name}, planar", 'model = "planar"\n' + body) for name, body in spatial if name != "hinge ratio x c1sq"]
    ring = 'family = "ring"\nn = {1}\ntwist = 1\n[grid]\nc2sq = {{ start = 0.5, stop = 3.0, num = {0} }}'
    return spatial + planar + [
        ("figure-eight-6 ratio x c2sq", (f'family = "figure-eight-6"\n[grid]\nratio = {{ start = 4.9, stop = 14.0, num = {side} }}\n'
                                         f'c2sq = {{ start = 0.05, stop = 5.0, num = {side}, scale = "log" }}')),
        ("hinge ratio x c2sq", (f'family = "hinge"\n[grid]\nratio = {{ start = 0.2, stop = 2.6, num = {side} }}\n'
                                f'c2sq = {{ start = 0.05, stop = 20.0, num = {side}, scale = "log" }}')),
        ("twisted ring n = 12, m = 1 over c2sq", ring.format(rings, 12)),
        ("twisted ring n = 24, m = 1 over c2sq", ring.format(rings, 24)),
    ]


def measure(body: str, repeat: int) -> dict:
    scene = stabmap.loads_scene('system = "closed"\n' + body + "\n")
    grids = np.meshgrid(*(a.array for a in scene.grid), indexing="ij")
    values = {a.name: g for a, g in zip(scene.grid, grids)}
    points = grids[0].size
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        out = SYSTEM.evaluate(scene, values)
        best = min(best, time.process_time() - t0)
    row = {"points": points, "us_per_point": 1e6 * best / points}
    if SYSTEM.provenance is not None:
        flags = SYSTEM.variable(SYSTEM.provenance)
        values_, counts = np.unique(out[SYSTEM.provenance], return_counts=True)
        row["decided_by"] = {flags.meaning(int(v)): int(c) for v, c in zip(values_, counts)}
    return row


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small blocks, one run each")
    args = parser.parse_args(argv)
    num, repeat = (24, 1) if args.quick else (400, 3)
    rows = []
    print("| block | points | us per point | decided by |")
    print("|---|---|---|---|")
    for name, body in _scenes(num):
        row = {"block": name, **measure(body, repeat)}
        rows.append(row)
        by = ", ".join(f"{k} {v}" for k, v in row.get("decided_by", {}).items()) or "-"
        print(f"| {name} | {row['points']} | {row['us_per_point']:.1f} | {by} |")
    cost = {r["block"]: r["us_per_point"] for r in rows}
    pairs = [(name[: -len(", planar")], name) for name in cost if name.endswith(", planar")]
    print("spatial / planar cost per point: " + ", ".join(f"{space} {cost[space] / cost[plane]:.1f}x"
                                                         for space, plane in pairs if space in cost))
    return rows


if __name__ == "__main__":
    main()
