"""How many digits the certified Sturm count needs: its decided share as the coefficients blur.

    python scripts/bench_conditioning.py            # 4000 points per degree (about a minute)
    python scripts/bench_conditioning.py --quick    # seconds; run once by the test suite

For random chains (ranges of scripts/bench_kernel.py) the kernel's own enclosures
of p(lambda) are counted by the interval Sturm sequence as they are (about 30
digits), then with every coefficient known only to a relative 1e-15 and 1e-13,
i.e. as accurate as any float64 computation of them could be.  The share of
points still decided says whether a float64 (vectorised, lock-step) kernel could
carry a certified decision at that degree.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
from pathlib import Path

import numba
import numpy as np

from stabmap import kernels
from stabmap.kernels.sturm import count_complex_pairs

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_kernel import random_points  # noqa: E402

BLUR = (0.0, 1e-15, 1e-13)


@numba.njit(nogil=True)
def _decided(c, W):
    out = 0
    for p in range(c.shape[0]):
        out += count_complex_pairs(c[p], W)[1] == kernels.DECIDED_FLOAT
    return out


def decided_share(coeffs: np.ndarray, blur: float) -> float:
    c = coeffs.copy()
    if blur:
        mid = c[..., 0] + c[..., 1]
        c[..., 0], c[..., 1] = mid, 0.0
        c[..., 2] = np.abs(mid) * blur + c[..., 2]
    W = np.zeros((2, c.shape[1], 3))
    return _decided(c, W) / len(c)


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, for the test suite")
    args = ap.parse_args(argv)
    npts = 200 if args.quick else 4000
    cases = [(2, 1), (3, 2)] if args.quick else [(3, 0), (2, 2), (3, 1), (3, 2), (4, 2)]
    rng = np.random.default_rng(7)
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    print("| n | modes | degree | decided, kernel enclosures | decided, coefficients to 1e-15 | decided, to 1e-13 |")
    print("|---|---|---|---|---|---|")
    rows = []
    for n, modes in cases:
        pts = random_points(rng, npts, n, modes)
        coeffs = np.zeros((npts, n * (2 + modes) + 1, 3))
        kernels.charpoly_block(*pts.kernel_args(), coeffs)
        shares = [decided_share(coeffs, b) for b in BLUR]
        rows.append({"n": n, "modes": modes, "degree": n * (2 + modes), "shares": shares})
        print(f"| {n} | {modes} | {n * (2 + modes)} | " + " | ".join(f"{100 * s:.1f} %" for s in shares) + " |", flush=True)
    return rows


if __name__ == "__main__":
    main()
