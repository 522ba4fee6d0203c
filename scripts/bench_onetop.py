"""Degree 2: one top decided by the float filter of kernels/onetop.py, against the float peer (issue 32).

    python scripts/bench_onetop.py            # 100 000 points per row, a few seconds
    python scripts/bench_onetop.py --quick    # the test suite's run

CPU seconds (``time.process_time``), medians of 5 runs: ``decide_block`` (the proof), ``charpoly_block`` (the
double-double enclosure of p that the filter skips) and batched ``numpy.linalg.eigvals`` of the same 2 x 2
linearisations (the float peer).
"""
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_kernel as bk  # noqa: E402

from stabmap.kernels import block  # noqa: E402
from stabmap.kernels.status import UNDECIDED  # noqa: E402


def main(quick: bool = False) -> list[str]:
    lines, runs = (10, 1) if quick else (1000, 5)
    rows = []
    for kind, free in (("mixed", False), ("identical", False), ("mixed", True)):
        rng = np.random.default_rng(1)
        pts = bk.point_set(rng, kind, lines, 100, 1, 0)
        args = (pts.body, pts.joint, pts.g, pts.E, pts.kappa, pts.nmodes, free, pts.parent, pts.at)
        N = pts.body.shape[0]
        nc = np.empty(N, np.int16)
        st = np.empty(N, np.int8)
        out = np.empty((N, 3, 3))
        C = np.empty((N, 2, 2))
        block.decide_block(*args, nc, st)
        block.charpoly_block(*args, out)
        block.linearise_block(*args, C)

        def t(f):
            times = []
            for _ in range(runs):
                t0 = time.process_time()
                f()
                times.append(time.process_time() - t0)
            return float(np.median(times)) / N * 1e6

        d = t(lambda: block.decide_block(*args, nc, st))
        c = t(lambda: block.charpoly_block(*args, out))
        e = t(lambda: np.linalg.eigvals(C))
        rows.append(f"| {kind} | {'free' if free else 'fixed'} | {N} | {d:.3f} | {c:.3f} | {e:.3f} | {d / e:.2f} | "
                    f"{int((st == UNDECIDED).sum())} |")
    head = ["| kind | support | points | decide_block us/pt | charpoly_block us/pt | eigvals us/pt | ratio | undecided |",
            "|---|---|---|---|---|---|---|---|"]
    return head + rows


if __name__ == "__main__":
    print("\n".join(main("--quick" in sys.argv)))
