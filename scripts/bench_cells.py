"""Atlases decided cell by cell (stabmap.run.cells) against node by node and the float peer, in one run.

    python scripts/bench_cells.py             # degrees 6-48 on 1000 x 1000, paper-n3-fixed end to end on 4000 x 4000,
                                              # the narrow-band stress set (about 40 minutes)
    python scripts/bench_cells.py --quick     # seconds (two ladder rungs on 24 x 24, one stress E); run once by the test suite
    python scripts/bench_cells.py --size 400  # the degree ladder on another grid, no 4000 x 4000 run
    python scripts/bench_cells.py --end-to-end  # only paper-n3-fixed end to end on 4000 x 4000 (minutes)

Three ways over the same grid, all cores, kernels loaded before any timing:
  float peer     scripts/float_peer.py: float64 coefficients and a plain float Sturm count at every node (what a
                 researcher writes by hand: nothing proved; its labels are compared with the proved ones);
  node by node   ``compute_atlas(prove_cells=False)``: every node proved on its own, every cell node_only;
  cells          ``compute_atlas()``, the default: boxes proved first, nodes computed only where no box proves.
Columns: seconds of each, node proofs per cell (nodes computed, and labels at the faces of cells beside a change)
and box proofs per cell of the cells way, the share of cells in each class, and the peer's labels that differ from
the proved ones.

The bundled scenes paper-n2-fixed and paper-n3-fixed on the same grid, and the README's scene (omega x m_2 x the
listed K_1 = [0, 10, 120], a discrete axis) on 300 x 100 x 3 points.

Scenes of the degree ladder: a seeded random fixed chain of n bodies with ``modes`` liquid modes each (the
parameter ranges of scripts/bench_kernel.py), scanned over omega in [1, 100] x K_1 in [0, 40] (c_1 for n = 1).

Stress set (quick mode: E = 1e-6 only): the two-body chain of the narrow-window case, `WINDOW` in tests/systems.py with its liquid's E from 1e-3 down to 1e-8
(unstable bands down to 1e-6 rad/s wide), scanned along omega at STRESS_POINTS = 1000 values: every boundary (critical values,
located to 1e-10 and checked against the exact discriminant by tests/test_boxes.py) must lie in a cell that is
not whole_cell, and whole cells must hold their label at random interior points in exact arithmetic.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import threading
import time
import tomllib
from collections import Counter
from pathlib import Path

import numpy as np

import stabmap
from stabmap.run import cells
from stabmap.scene.grid import resample
from stabmap.store.dataset import edges
from stabmap.store.variables import CELL
from stabmap.systems.gyroscopes.scene import from_dict

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_critical import REGIONS  # noqa: E402  (the narrow-window case of tests/systems.py)
from float_peer import float_atlas  # noqa: E402

STRESS_POINTS = 1000  # values of omega on the stress scene: bands far narrower than a step, cells that boxes prove
LADDER = [(3, 0), (2, 1), (3, 2), (4, 2), (6, 2), (6, 4), (8, 4)]  # degrees 6, 6, 12, 16, 24, 36, 48
QUICK_LADDER = [(2, 1), (3, 2)]


def random_scene(n: int, modes: int, num: int, seed: int):
    """A random fixed chain (bench_kernel's ranges) over omega x K_1 (c_1 for one body), num x num points."""
    rng = np.random.default_rng(seed)
    bodies = []
    for _ in range(n):
        body = {"m": float(rng.uniform(0.2, 3.0)), "A": float(rng.uniform(0.005, 0.1)), "C": float(rng.uniform(0.0, 0.1)),
                "c": float(rng.uniform(-0.2, 0.4)), "s": float(rng.uniform(0.05, 0.6))}
        if modes:
            body["fluid"] = {"E": [float(x) for x in rng.uniform(1e-5, 3e-3, modes)],
                             "kappa": [float(x) for x in rng.choice([-1, 1], modes) * rng.uniform(1.05, 4.0, modes)]}
        bodies.append(body)
    other = ("K_1", 0.0, 40.0) if n > 1 else ("c_1", -0.2, 0.4)
    return from_dict({
        "title": f"random fixed chain, n = {n}, {modes} modes a body", "support": "fixed", "g": 9.81, "bodies": bodies,
        "joints": [float(x) for x in rng.uniform(0, 200, n - 1)],
        "grid": {"omega": {"start": 1.0, "stop": 100.0, "num": num}, other[0]: {"start": other[1], "stop": other[2], "num": num}},
    })


class Tally:
    """Node and box proofs made by the cells way (its functions wrapped for the run; threads share the counts)."""

    def __init__(self):
        self.counts = Counter()
        self.lock = threading.Lock()

    def __enter__(self):
        self.saved = (cells._Chunk._prove, cells._Chunk.classify, cells._Chunk.afford)
        prove, classify, afford = self.saved
        tally = self

        def counted_prove(chunk, lower, upper, tile):
            out = prove(chunk, lower, upper, tile)
            _, proved, tried, _ = out
            with tally.lock:
                tally.counts["boxes"] += int(tried.sum())
                tally.counts["proved boxes"] += int(proved.sum())
            return out

        def counted_classify(chunk, nodes, label, sub_boxes):
            with tally.lock:
                tally.counts["nodes"] += nodes.shape[0]
            return classify(chunk, nodes, label, sub_boxes)

        def counted_afford(chunk, tile, cost, keep=None):
            paid = afford(chunk, tile, cost, keep)
            if cost == 1.0:  # labels at the faces of cells beside a change, one node proof each
                with tally.lock:
                    tally.counts["faces"] += int(paid.sum())
            return paid

        cells._Chunk._prove, cells._Chunk.classify, cells._Chunk.afford = counted_prove, counted_classify, counted_afford
        return self

    def __exit__(self, *exc):
        cells._Chunk._prove, cells._Chunk.classify, cells._Chunk.afford = self.saved


def _timed(f, *args, **kwargs):
    t0 = time.perf_counter()
    out = f(*args, **kwargs)
    return out, time.perf_counter() - t0


def readme_scene():
    """The scene of the README's walkthrough (its scene.toml): omega x m_2 x the listed K_1 = [0, 10, 120]."""
    import re

    text = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    return stabmap.loads_scene(re.search(r"<!-- doc-test: file scene.toml -->\n```toml\n(.*?)```", text, re.S).group(1))


def compare(scene, label: str) -> dict:
    """The three ways on ``scene``'s grid (module docstring)."""
    small = resample(scene, **{a.name: 4 for a in scene.grid})
    stabmap.compute_atlas(small, progress=False)
    float_atlas(small)
    peer, t_peer = _timed(float_atlas, scene)
    nodes, t_nodes = _timed(stabmap.compute_atlas, scene, progress=False, prove_cells=False)
    with Tally() as tally:
        ds, t_cells = _timed(stabmap.compute_atlas, scene, progress=False)
    label_nodes, label_cells = nodes["n_complex_pairs"].values, ds["n_complex_pairs"].values
    if not np.array_equal(label_nodes, label_cells):
        raise AssertionError(f"{label}: cells and node by node disagree at {(label_nodes != label_cells).sum()} nodes")
    npts = label_cells.size
    cell = ds["cell"].values
    return {
        "scene": label, "degree": scene.degree, "points": npts, "peer_s": t_peer, "nodes_s": t_nodes, "cells_s": t_cells,
        "node_proofs_per_cell": (tally.counts["nodes"] + tally.counts["faces"]) / npts,
        "box_proofs_per_cell": tally.counts["boxes"] / npts,
        "shares": {m: float((cell == v).mean()) for v, m in CELL.flags},
        "peer_wrong": int((peer != label_cells).sum()),
    }


def end_to_end(name: str, num: int, workdir: str) -> dict:
    """``stabmap atlas`` of a bundled scene on num x num points to a file, cells against the peer (in memory)."""
    scene = resample(stabmap.example(name), **{a.name: num for a in stabmap.example(name).grid})
    small = resample(scene, **{a.name: 4 for a in scene.grid})
    stabmap.compute_atlas(small, progress=False)
    float_atlas(small)
    peer, t_peer = _timed(float_atlas, scene)
    path = os.path.join(workdir, "big.nc")
    _, t_cells = _timed(stabmap.compute_to_file, scene, path, progress=False)
    with stabmap.open_atlas(path, lazy=True) as ds:
        cell = ds["cell"].values
        wrong = int((ds["n_complex_pairs"].values != peer).sum())
    return {"scene": name, "points": num * num, "peer_s": t_peer, "cells_s": t_cells, "file_mb": os.path.getsize(path) / 1e6,
            "shares": {m: float((cell == v).mean()) for v, m in CELL.flags}, "peer_wrong": wrong}


def stress(E: float, rng) -> dict:
    """False whole cells on the stress scene with liquid E (module docstring)."""
    from stabmap.run.critical import critical
    from stabmap.systems.gyroscopes import exact
    from stabmap.systems.gyroscopes.points import point_arrays

    table = tomllib.loads(REGIONS)
    table["bodies"] = [dict(b, fluid=dict(b["fluid"], E=[E])) for b in table["bodies"]]
    scene = resample(from_dict(table), omega=STRESS_POINTS)
    ds = stabmap.compute_atlas(scene, progress=False)
    crit = critical(scene, "omega", rtol=1e-10, progress=False)
    keep = np.isfinite(crit["boundary_lower"].values)
    e = edges(scene.grid[0].array)
    cell = ds["cell"].values
    false_whole = 0
    for a, b in zip(crit["boundary_lower"].values[keep], crit["boundary_upper"].values[keep]):
        hit = np.flatnonzero((e[:-1] <= b) & (a <= e[1:]))
        false_whole += int((cell[hit] == CELL.value("whole_cell")).sum())
    whole = np.flatnonzero(cell == CELL.value("whole_cell"))
    x = rng.uniform(e[whole], e[whole + 1])
    pts = point_arrays(scene, {"omega": x})
    wrong = int((exact.decide_points(*pts.kernel_args(), np.arange(x.size)) != ds["n_complex_pairs"].values[whole]).sum())
    narrowest = float(np.min(np.diff(np.sort(0.5 * (crit["boundary_lower"].values[keep] + crit["boundary_upper"].values[keep]))))) if keep.sum() > 1 else float("nan")
    return {"E": E, "boundaries": int(keep.sum()), "narrowest": narrowest, "false_whole": false_whole, "checked": int(whole.size),
            "wrong_interior": wrong, "shares": {m: float((cell == v).mean()) for v, m in CELL.flags}}


def _shares(s: dict) -> str:
    return ", ".join(f"{m.replace('_', ' ')} {100 * v:.2f}" for m, v in s.items() if v)


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, for the test suite")
    ap.add_argument("--size", type=int, help="grid points per axis of the degree ladder (default 1000; quick 24)")
    ap.add_argument("--end-to-end", action="store_true", help="only paper-n3-fixed end to end on 4000 x 4000")
    args = ap.parse_args(argv)
    num = args.size or (24 if args.quick else 1000)
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    out = {"ladder": []}
    if args.end_to_end:
        return {"end_to_end": _end_to_end_row()}
    print("\n| scene | degree | points | float peer s | node by node s | cells s | cells / peer | cells / node by node "
          "| node proofs per cell | box proofs per cell | cells (%) | peer wrong labels |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for n, modes in QUICK_LADDER if args.quick else LADDER:
        r = compare(random_scene(n, modes, num, seed=100 * n + modes), f"random n={n}, {modes} modes")
        out["ladder"].append(r)
        print(f"| {r['scene']} | {r['degree']} | {r['points']:,} | {r['peer_s']:.2f} | {r['nodes_s']:.2f} | {r['cells_s']:.2f} "
              f"| {r['cells_s'] / r['peer_s']:.2f} | {r['cells_s'] / r['nodes_s']:.2f} | {r['node_proofs_per_cell']:.3f} "
              f"| {r['box_proofs_per_cell']:.3f} | {_shares(r['shares'])} | {r['peer_wrong']} |", flush=True)
    bundled = [(name, resample(stabmap.example(name), **{a.name: num for a in stabmap.example(name).grid}))
               for name in ("paper-n2-fixed", "paper-n3-fixed")]
    readme = readme_scene()
    bundled.append(("README scene", resample(readme, omega=24, m_2=16) if args.quick else resample(readme, omega=300, m_2=100)))
    for name, scene in bundled:
        r = compare(scene, name)
        out["ladder"].append(r)
        print(f"| {r['scene']} | {r['degree']} | {r['points']:,} | {r['peer_s']:.2f} | {r['nodes_s']:.2f} | {r['cells_s']:.2f} "
              f"| {r['cells_s'] / r['peer_s']:.2f} | {r['cells_s'] / r['nodes_s']:.2f} | {r['node_proofs_per_cell']:.3f} "
              f"| {r['box_proofs_per_cell']:.3f} | {_shares(r['shares'])} | {r['peer_wrong']} |", flush=True)
    rng = np.random.default_rng(2026)
    print("\n| liquid E | boundaries | narrowest gap between boundaries [rad/s] | whole cells holding a boundary "
          "| whole cells checked exactly | wrong | cells (%) |")
    print("|---|---|---|---|---|---|---|")
    out["stress"] = []
    for E in (1e-6,) if args.quick else (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
        r = stress(E, rng)
        out["stress"].append(r)
        print(f"| {E:g} | {r['boundaries']} | {r['narrowest']:.3g} | {r['false_whole']} | {r['checked']} | {r['wrong_interior']} "
              f"| {_shares(r['shares'])} |", flush=True)
    if not args.quick and args.size is None:
        out["end_to_end"] = _end_to_end_row()
    return out


def _end_to_end_row() -> dict:
    with tempfile.TemporaryDirectory() as work:
        r = end_to_end("paper-n3-fixed", 4000, work)
    print(f"\nend to end, paper-n3-fixed on 4000 x 4000 = {r['points']:,} points: cells (file written, {r['file_mb']:.1f} MB) "
          f"{r['cells_s']:.1f} s, float peer (in memory) {r['peer_s']:.1f} s: peer / cells = {r['peer_s'] / r['cells_s']:.2f}; "
          f"cells: {_shares(r['shares'])}; peer wrong labels {r['peer_wrong']:,}", flush=True)
    return r


if __name__ == "__main__":
    main()
