"""Krein boxes (kernels/kreinbox.py) against today's tensor-grid box proof (block.nodes_box_block), same boxes, one process.

    python scripts/bench_kreinbox.py            # 3000 random boxes of each size, then every tile of the grid
    python scripts/bench_kreinbox.py --quick    # 300 random boxes of each size, then the tiles of a 64 x 64-cell patch
    python scripts/bench_kreinbox.py --atlas    # whole atlases, the default (Krein boxes first) against no Krein boxes
    python scripts/bench_kreinbox.py --atlas --quick   # the same on small grids; run once by the test suite

paper-n3-fixed regridded to 300 x 300 (omega 1-200 x m_2 0.1-10, log), cell edges midway between grid values
(``store.dataset.edges``, as scripts/bench_cell_boxes.py).  Boxes of 1 x 1, 4 x 4 and 16 x 16 cells at random
positions, each proved cold (no warm start: ``krein_box_block(..., warm=False)``); then the grid tiled by boxes of
each size, swept along omega row by row of m_2, where each Krein box first tries its predecessor's separators and
pairs (``warm=True``, as an atlas would).  For each kernel: the share proved and the microseconds per box of the
kernel call alone (inputs formed before the clock starts; each kernel called once first, so compilation is not
timed).  Where both prove a box they must agree on N_c (checked).

``--atlas``: ``compute_atlas()`` (the default, cells proved) on paper-n3-fixed and paper-n2-fixed (240 x 160) and
random fixed chains of bench_cells.py's ladder (omega x K_1, 200 x 200 up to 4 bodies, 100 x 100 beyond), with the Krein boxes (the default) and
without them (``cheap_box_cost`` 0: the cells' boxes go to the tensor-grid proof alone), alternating, minimum of two;
the labels of both must be equal (checked), and the shares of whole cells are counted.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import stabmap
from stabmap.kernels import UNDECIDED, ZERO_POLYNOMIAL, nodes_box_block
from stabmap.kernels.kreinbox import NINFO, krein_box_block
from stabmap.scene.grid import resample
from stabmap.store.dataset import edges
from stabmap.systems.gyroscopes.boxes import boxes
from stabmap.systems.gyroscopes.decide import kernel_args
from stabmap.systems.gyroscopes.kreinboxes import krein_arrays
from stabmap.systems.gyroscopes.nodes import NodeBoxes


def cell_boxes(num: int, size: int, count: int, seed: int = 0, example: str = "paper-n3-fixed", axis: str = "m_2"):
    scene = resample(stabmap.example(example), **{"omega": num, axis: num})
    values = {x.name: x.array for x in scene.grid}
    ew, em = edges(values["omega"]), edges(values[axis])
    rng = np.random.default_rng(seed + size)
    i, j = rng.integers(0, num - size + 1, count), rng.integers(0, num - size + 1, count)
    return scene, {"omega": ew[i], axis: em[j]}, {"omega": ew[i + size], axis: em[j + size]}


def tiles(num: int, size: int, cells: int):
    """Every size x size tile of the first ``cells`` x ``cells`` cells, omega fastest."""
    scene = resample(stabmap.example("paper-n3-fixed"), omega=num, m_2=num)
    values = {x.name: x.array for x in scene.grid}
    ew, em = edges(values["omega"]), edges(values["m_2"])
    k = np.arange(0, cells - size + 1, size)
    j, i = (x.ravel() for x in np.meshgrid(k, k, indexing="ij"))
    return scene, {"omega": ew[i], "m_2": em[j]}, {"omega": ew[i + size], "m_2": em[j + size]}


def run_krein(scene, lower, upper, warm=False):
    npts = lower["omega"].size
    nc = np.full(npts, -1, dtype=np.int16)
    rows, part = krein_arrays(scene, lower, upper)
    args = part.kernel_args()
    count = np.empty(rows.size, np.int16)
    status = np.empty(rows.size, np.int8)
    info = np.zeros((rows.size, NINFO), np.int64)
    t0 = time.perf_counter()
    krein_box_block(*args, warm, count, status, info)
    seconds = time.perf_counter() - t0
    ok = status != UNDECIDED
    nc[rows[ok]] = count[ok]
    return nc, seconds, info


def run_nodes(scene, lower, upper):
    npts = lower["omega"].size
    nc = np.full(npts, -1, dtype=np.int16)
    seconds = 0.0
    for rows, part in boxes(scene, lower, upper):
        assert isinstance(part, NodeBoxes)
        args = kernel_args(part)
        count = np.empty(rows.size, np.int16)
        status = np.empty(rows.size, np.int8)
        split = np.empty(rows.size, np.int8)
        t0 = time.perf_counter()
        nodes_box_block(*args, count, status, split)
        seconds += time.perf_counter() - t0
        ok = (status != UNDECIDED) & (status != ZERO_POLYNOMIAL)
        nc[rows[ok]] = count[ok]
    return nc, seconds


def atlases(quick: bool) -> list[dict]:
    """The ``--atlas`` rows (module docstring)."""
    import sys
    from pathlib import Path

    from stabmap.systems.gyroscopes import kreinboxes

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_cells import random_scene

    price = kreinboxes.cheap_box_cost
    num = 40 if quick else 200
    w, t = (40, 40) if quick else (240, 160)
    scenes = [(name, resample(stabmap.example(name), omega=w, **{axis: t})) for name, axis in (("paper-n3-fixed", "m_2"), ("paper-n2-fixed", "K_1"))]
    ladder = ((2, 2, num),) if quick else ((2, 2, num), (3, 2, num), (4, 2, num), (6, 2, num // 2), (8, 4, num // 2))
    scenes += [(f"random n={n}, {m} modes, {k} x {k}", random_scene(n, m, k, seed=10 + n)) for n, m, k in ladder]
    print("| scene | points | seconds: Krein first / without | ratio | whole cells %: Krein first / without | change % |")
    print("|---|---|---|---|---|---|")
    rows = []
    try:
        for way in ("krein", "without"):  # compile (or load) the kernels before any clock
            kreinboxes.cheap_box_cost = price if way == "krein" else (lambda scene: 0.0)
            stabmap.compute_atlas(resample(scenes[0][1], omega=8, m_2=8))
        for name, scene in scenes:
            best, cells, labels = {}, {}, {}
            for _ in range(1 if quick else 2):
                for way in ("krein", "without"):
                    kreinboxes.cheap_box_cost = price if way == "krein" else (lambda scene: 0.0)
                    t = time.perf_counter()
                    ds = stabmap.compute_atlas(scene)
                    best[way] = min(best.get(way, np.inf), time.perf_counter() - t)
                    cells[way] = ds["cell"].values
                    labels[way] = ds["n_complex_pairs"].values
            assert np.array_equal(labels["krein"], labels["without"]), f"{name}: the labels differ"
            whole = {w: 100.0 * float(np.mean(c == 1)) for w, c in cells.items()}
            row = {"scene": name, "points": int(labels["krein"].size), "seconds": best, "whole_pct": whole,
                   "change_pct": 100.0 * float(np.mean(cells["krein"] == 2))}
            rows.append(row)
            print(f"| {name} | {row['points']} | {best['krein']:.2f} / {best['without']:.2f} | {best['krein'] / best['without']:.2f} "
                  f"| {whole['krein']:.1f} / {whole['without']:.1f} | {row['change_pct']:.1f} |", flush=True)
    finally:
        kreinboxes.cheap_box_cost = price
    return rows


def main(argv=None) -> list:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes (the test suite runs --atlas --quick)")
    ap.add_argument("--count", type=int, default=None, help="random boxes of each size")
    ap.add_argument("--atlas", action="store_true", help="whole atlases with and without the Krein boxes")
    args = ap.parse_args(argv)
    if args.atlas:
        return atlases(args.quick)
    count = args.count or (300 if args.quick else 3000)
    for example, axis in (("paper-n3-fixed", "m_2"), ("paper-n2-fixed", "K_1")):  # compile (or load) before any clock
        warm = cell_boxes(300, 1, 4, example=example, axis=axis)
        run_krein(*warm)
        run_nodes(*warm)
    for example, axis in (("paper-n3-fixed", "m_2"), ("paper-n2-fixed", "K_1")):
        print(f"{example} 300 x 300, omega x {axis}, {count} random boxes of each size (cold)")
        print("cells    krein: proved   us/box  (N_c = 0 / pairs)   nodes_box_block: proved   us/box   both   disagree")
        for size in (1, 4, 16):
            scene, lower, upper = cell_boxes(300, size, count, example=example, axis=axis)
            kn, ks, info = run_krein(scene, lower, upper)
            nn, ns = run_nodes(scene, lower, upper)
            both = (kn >= 0) & (nn >= 0)
            disagree = int(np.sum(both & (kn != nn)))
            print(f"{size:2d}x{size:<2d}   {100 * np.mean(kn >= 0):6.1f} %  {1e6 * ks / count:7.1f}   "
                  f"({int(np.sum(kn == 0))} / {int(np.sum(kn > 0))})          {100 * np.mean(nn >= 0):6.1f} %   "
                  f"{1e6 * ns / count:7.1f}   {int(both.sum()):5d}   {disagree}", flush=True)
            assert disagree == 0, "the two box proofs disagree"
    cells = 64 if args.quick else 300
    print(f"tiles of the first {cells} x {cells} cells, swept along omega; Krein boxes warm from their predecessor")
    print("cells   boxes   krein: proved   us/box  (warm)         nodes_box_block: proved   us/box   disagree")
    for size in (1, 4, 16):
        scene, lower, upper = tiles(300, size, cells)
        nb = lower["omega"].size
        kn, ks, info = run_krein(scene, lower, upper, warm=True)
        nn, ns = run_nodes(scene, lower, upper)
        both = (kn >= 0) & (nn >= 0)
        disagree = int(np.sum(both & (kn != nn)))
        print(f"{size:2d}x{size:<2d}  {nb:6d}   {100 * np.mean(kn >= 0):6.1f} %  {1e6 * ks / nb:7.1f}  ({int(np.sum(info[:, 3] == 7))})"
              f"          {100 * np.mean(nn >= 0):6.1f} %   {1e6 * ns / nb:7.1f}   {disagree}", flush=True)
        assert disagree == 0, "the two box proofs disagree"
    return []


if __name__ == "__main__":
    main()
