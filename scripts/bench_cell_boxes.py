"""Share of one-cell boxes of two grid axes that the box kernels prove, on examples regridded to 300 x 300.

    python scripts/bench_cell_boxes.py          # every cell: 90000 boxes per example (about a minute)
    python scripts/bench_cell_boxes.py 2000     # a random sample of 2000 cells each

Cells: edges midway between neighbouring grid values (``store.dataset.edges``).  paper-n3-fixed omega x m_2 (three
identical bodies and cavities: spin and a mass on the tensor grid) and paper-n2-fixed omega x K_1
(docs/certification.md, section 6, "Measured": 92.7 % and 97.7 % of every cell).
"""

from __future__ import annotations

import sys
import time

import numpy as np

import stabmap
from stabmap.scene.grid import resample
from stabmap.store.dataset import edges
from stabmap.systems.gyroscopes.decide import prove_boxes

CASES = (("paper-n3-fixed", "omega", "m_2"), ("paper-n2-fixed", "omega", "K_1"))


def share(example: str, a: str, b: str, num: int = 300, sample: int | None = None, seed: int = 0) -> tuple[int, int, float]:
    """(proved, tried, seconds) for the one-cell a x b boxes of ``example`` regridded to num x num."""
    scene = resample(stabmap.example(example), **{a: num, b: num})
    values = {x.name: x.array for x in scene.grid}
    ea, eb = edges(values[a]), edges(values[b])
    i, j = (x.ravel() for x in np.meshgrid(np.arange(num), np.arange(num), indexing="ij"))
    if sample:
        k = np.random.default_rng(seed).choice(i.size, sample, replace=False)
        i, j = i[k], j[k]
    t0 = time.perf_counter()
    _, proved = prove_boxes(scene, {a: ea[i], b: eb[j]}, {a: ea[i + 1], b: eb[j + 1]})
    return int(proved.sum()), proved.size, time.perf_counter() - t0


if __name__ == "__main__":
    sample = int(sys.argv[1]) if len(sys.argv) > 1 else None
    for example, a, b in CASES:
        k, n, seconds = share(example, a, b, sample=sample)
        print(f"{example} {a} x {b}: {k}/{n} = {100 * k / n:.2f} % proved ({seconds:.0f} s)", flush=True)
