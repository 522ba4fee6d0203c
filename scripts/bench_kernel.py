"""Throughput of the certified kernel against numpy.roots and batched companion eigenvalues.

    python scripts/bench_kernel.py            # n = 1..8, 0..4 liquid modes (about 10 minutes)
    python scripts/bench_kernel.py --quick    # seconds; run once by the test suite

Points are random fixed-support chains (realistic ranges, joints and liquid
modes as given).  For each (n, modes): warm kernel throughput on one thread and
on every core (points/s), the share of points the kernel leaves to exact
arithmetic and what that costs, and in the same run the cost of the two usual
float methods on the same polynomials.  Those are not references: where they
disagree with the certified label (1e-7 tolerance on imaginary parts), the
certified label is right.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from stabmap import kernels
from stabmap.systems.gyroscopes import exact
from stabmap.systems.gyroscopes.points import PointArrays

EXACT_SAMPLE = 20  # undecided points timed in exact arithmetic (the rest extrapolated)


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


def _subset(pts: PointArrays, sl) -> PointArrays:
    return PointArrays(pts.body[sl], pts.joint[sl], pts.g[sl], pts.E[sl], pts.kappa[sl], pts.nmodes, pts.free)


def count_threads(pts: PointArrays, threads: int):
    """count_block over ``threads`` contiguous slices at once (the kernels release the GIL)."""
    npts = pts.body.shape[0]
    nc = np.empty(npts, np.int16)
    st = np.empty(npts, np.int8)
    edges = np.linspace(0, npts, threads + 1).astype(int)

    def run(i):
        sl = slice(edges[i], edges[i + 1])
        kernels.count_block(*_subset(pts, sl).kernel_args(), nc[sl], st[sl])

    with ThreadPoolExecutor(threads) as pool:
        list(pool.map(run, range(threads)))
    return nc, st


def timed(f, *args):
    """(f(*args), seconds it took)."""
    t0 = time.perf_counter()
    out = f(*args)
    return out, time.perf_counter() - t0


def companion_pairs(coeffs: np.ndarray, tol: float) -> np.ndarray:
    d = coeffs.shape[1] - 1
    comp = np.zeros((len(coeffs), d, d))
    comp[:, 1:, :-1] = np.eye(d - 1)
    comp[:, :, -1] = -coeffs[:, :d] / coeffs[:, d : d + 1]
    z = np.linalg.eigvals(comp)
    return (np.abs(z.imag) > tol * np.maximum(np.abs(z), 1e-300)).sum(axis=1) // 2


def roots_pairs(coeffs: np.ndarray, tol: float) -> np.ndarray:
    out = np.empty(len(coeffs), np.int64)
    for p, c in enumerate(coeffs):
        z = np.roots(c[::-1])
        out[p] = (np.abs(z.imag) > tol * np.maximum(1, np.abs(z))).sum() // 2
    return out


def points_for(degree: int, quick: bool) -> int:
    if quick:
        return 200
    return 40000 if degree <= 8 else 20000 if degree <= 12 else 4000 if degree <= 24 else 600


def run(n: int, modes: int, rng, quick: bool) -> dict:
    degree = n * (2 + modes)
    npts = points_for(degree, quick)
    pts = random_points(rng, npts, n, modes)
    threads = os.cpu_count() or 1
    count_threads(_subset(pts, slice(0, 2 * threads)), threads)  # compile outside the timed calls
    (nc, st), t1 = timed(count_threads, pts, 1)
    _, tn = timed(count_threads, pts, threads)
    undecided = np.flatnonzero(st == kernels.UNDECIDED)
    sample = undecided[:EXACT_SAMPLE]
    t_exact = 0.0
    if sample.size:
        _, t_exact = timed(exact.decide_points, *pts.kernel_args(), sample)
        t_exact /= sample.size
    coeffs = np.zeros((npts, degree + 1, 3))
    kernels.charpoly_block(*pts.kernel_args(), coeffs)
    c = coeffs[..., 0] + coeffs[..., 1]
    m = min(npts, 2000)
    nc_np, t_np = timed(roots_pairs, c[:m], 1e-7)
    nc_eig, t_eig = timed(companion_pairs, c[:m], 1e-7)
    decided = st[:m] != kernels.UNDECIDED
    certified_us = 1e6 * t1 / npts + 1e6 * t_exact * undecided.size / npts
    return {
        "n": n, "modes": modes, "degree": degree, "points": npts,
        "kernel_us": 1e6 * t1 / npts,
        "pts_per_s_1": npts / t1, "pts_per_s_all": npts / tn, "threads": threads,
        "undecided_pct": 100 * undecided.size / npts, "exact_ms": 1e3 * t_exact,
        "certified_us": certified_us,
        "numpy_roots_us": 1e6 * t_np / m, "companion_us": 1e6 * t_eig / m,
        "roots_disagree": int((nc_np != nc[:m])[decided].sum()),
        "companion_disagree": int((nc_eig != nc[:m])[decided].sum()),
        "compared": int(decided.sum()),
    }


HEADER = (
    "| n | modes | degree | points/s, 1 thread | points/s, all cores | undecided % | exact ms/pt "
    "| certified us/pt | numpy.roots us/pt | companion eig us/pt | roots / companion disagree |"
)


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, for the test suite")
    ap.add_argument("--max-degree", type=int, default=48, help="skip larger (n, modes) cases")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(2026)
    if args.quick:
        cases = [(1, 0), (2, 1), (3, 2)]
    else:
        cases = [(n, m) for n in range(1, 9) for m in range(5) if n * (2 + m) <= args.max_degree]
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    print(HEADER)
    print("|" + "---|" * (HEADER.count("|") - 1))
    rows = []
    for n, modes in cases:
        r = run(n, modes, rng, args.quick)
        rows.append(r)
        print(
            f"| {r['n']} | {r['modes']} | {r['degree']} | {r['pts_per_s_1']:,.0f} | {r['pts_per_s_all']:,.0f} "
            f"| {r['undecided_pct']:.2f} | {r['exact_ms']:.1f} | {r['certified_us']:.2f} | {r['numpy_roots_us']:.1f} "
            f"| {r['companion_us']:.1f} | {r['roots_disagree']} / {r['companion_disagree']} of {r['compared']} |",
            flush=True,
        )
    return rows


if __name__ == "__main__":
    main()
