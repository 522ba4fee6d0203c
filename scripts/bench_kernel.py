"""Throughput of the certified kernel and cost of the exact fallback, against numpy.roots.

    python scripts/bench_kernel.py            # full table (a few minutes)
    python scripts/bench_kernel.py --quick    # seconds; run once by the test suite

Points are random chains (fixed support, realistic ranges, joints and liquid
modes as given); every label is also checked against numpy.roots with a 1e-7
tolerance on the imaginary parts, and the count of disagreements is reported
(numpy.roots is not a reference: where they disagree, the certified label is right).
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

import kernels
from stabmap import exact
from stabmap.points import PointArrays


def random_points(rng: np.random.Generator, npts: int, n: int, modes: int) -> PointArrays:
    body = np.empty((npts, n, 6))
    body[..., 0] = rng.uniform(0.2, 3.0, (npts, n))
    body[..., 1] = rng.uniform(0.005, 0.1, (npts, n))
    body[..., 2] = rng.uniform(0.0, 0.1, (npts, n))
    body[..., 3] = rng.uniform(-0.2, 0.4, (npts, n))
    body[..., 4] = rng.uniform(0.05, 0.6, (npts, n))
    body[..., 5] = rng.uniform(-100, 100, (npts, 1))
    joint = rng.uniform(0, 200, (npts, n)) * (rng.random((npts, n)) < 0.7)
    lmax = max(1, modes)
    E = rng.uniform(1e-5, 3e-3, (npts, n, lmax))
    kappa = rng.choice([-1, 1], (npts, n, lmax)) * rng.uniform(1.05, 4.0, (npts, n, lmax))
    return PointArrays(body, joint, np.full(npts, 9.81), E, kappa, np.full(n, modes, np.int64), False)


def run(npts: int, n: int, modes: int, rng) -> dict:
    pts = random_points(rng, npts, n, modes)
    nc = np.empty(npts, np.int16)
    st = np.empty(npts, np.int8)
    warm = random_points(rng, 1, n, modes)  # compile outside the timed call
    kernels.count_block(*warm.kernel_args(), nc[:1], st[:1])
    t0 = time.perf_counter()
    kernels.count_block(*pts.kernel_args(), nc, st)
    t_kernel = time.perf_counter() - t0
    undecided = np.flatnonzero(st == kernels.UNDECIDED)
    t0 = time.perf_counter()
    if undecided.size:
        nc[undecided] = exact.decide_points(*pts.kernel_args(), undecided)
    t_exact = time.perf_counter() - t0
    degree = n * (2 + modes)
    coeffs = np.zeros((npts, degree + 1, 3))
    kernels.charpoly_block(*pts.kernel_args(), coeffs)
    sample = min(npts, 2000)
    t0 = time.perf_counter()
    disagree = 0
    for p in range(sample):
        roots = np.roots((coeffs[p, :, 0] + coeffs[p, :, 1])[::-1])
        nc_np = int((np.abs(roots.imag) > 1e-7 * np.maximum(1, np.abs(roots))).sum() // 2)
        disagree += nc_np != nc[p]
    t_np = (time.perf_counter() - t0) / sample
    return {
        "n": n, "modes": modes, "degree": degree, "points": npts,
        "kernel_us": 1e6 * t_kernel / npts, "undecided_pct": 100 * undecided.size / npts,
        "exact_ms": 1e3 * t_exact / max(1, undecided.size), "total_us": 1e6 * (t_kernel + t_exact) / npts,
        "numpy_roots_us": 1e6 * t_np, "numpy_roots_disagree": f"{disagree}/{sample}",
    }


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, for the test suite")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(2026)
    cases = [(1, 0), (2, 1), (3, 2)] if args.quick else [(n, m) for n in (1, 2, 3, 4, 6, 8) for m in (0, 2)]
    npts = 200 if args.quick else 20000
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    print("| n | modes | degree | kernel us/pt | undecided % | exact ms/undecided pt | total us/pt | numpy.roots us/pt | numpy.roots disagrees |")
    print("|---|---|---|---|---|---|---|---|---|")
    rows = []
    for n, modes in cases:
        r = run(npts if n <= 4 else npts // 10, n, modes, rng)
        rows.append(r)
        print(f"| {r['n']} | {r['modes']} | {r['degree']} | {r['kernel_us']:.2f} | {r['undecided_pct']:.2f} | {r['exact_ms']:.2f} | {r['total_us']:.2f} | {r['numpy_roots_us']:.1f} | {r['numpy_roots_disagree']} |", flush=True)
    return rows


if __name__ == "__main__":
    main()
