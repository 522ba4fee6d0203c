"""What the exact fallback costs a point, per degree, and where the time goes.

    python scripts/bench_exact.py            # degree 6..64 (about a minute)
    python scripts/bench_exact.py --quick    # seconds; run once by the test suite

Scattered random fixed chains (the point sets of ``bench_kernel.py``).  For
each point, ``exact.char_poly`` splits into the deg + 1 rational determinants
and the interpolation through them; ``count_real_roots`` isolates the roots.
In the same run, the interpolation by rational divided differences that the
exact path used before issue 18 (kept here only as the reference) on the same
determinants; both must give the same polynomial.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import flint
import numpy as np

from stabmap.systems.gyroscopes import exact

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_kernel import point_set  # noqa: E402

HEADER = "| n | modes | degree | points | determinants ms | interpolation ms | divided differences ms (before) | roots ms | total ms |"


def divided_differences(ys: list) -> flint.fmpq_poly:
    """The former interpolation: Newton divided differences in rational arithmetic at x = 0..d."""
    xs = [flint.fmpq(i) for i in range(len(ys))]
    coef = list(ys)
    for j in range(1, len(xs)):
        for i in range(len(xs) - 1, j - 1, -1):
            coef[i] = (coef[i] - coef[i - 1]) / (xs[i] - xs[i - j])
    poly = flint.fmpq_poly([coef[-1]])
    for i in range(len(xs) - 2, -1, -1):
        poly = poly * flint.fmpq_poly([-xs[i], 1]) + coef[i]
    return poly


def _determinants(args, p: int) -> list:
    """The deg + 1 determinants exact.char_poly interpolates (captured by wrapping its interpolation)."""
    seen = {}
    real = exact._interpolate

    def capture(ys):
        seen["ys"] = ys
        return real(ys)

    exact._interpolate = capture
    try:
        body, joint, g, E, kappa, nmodes, free, parent, at = args
        exact.char_poly(body[p], joint[p], g[p], E[p], kappa[p], nmodes, free, parent, at[p])
    finally:
        exact._interpolate = real
    return seen["ys"]


def run(n: int, modes: int, npts: int, rng) -> dict:
    args = point_set(rng, "scattered", 1, npts, n, modes).kernel_args()
    body, joint, g, E, kappa, nmodes, free, parent, at = args
    t = {"total": 0.0, "interp": 0.0, "before": 0.0, "roots": 0.0}
    for p in range(npts):
        t0 = time.perf_counter()
        poly = exact.char_poly(body[p], joint[p], g[p], E[p], kappa[p], nmodes, free, parent, at[p])
        t1 = time.perf_counter()
        exact.count_real_roots(poly)
        t2 = time.perf_counter()
        ys = _determinants(args, p)
        t3 = time.perf_counter()
        new = exact._interpolate(ys)
        t4 = time.perf_counter()
        old = divided_differences(ys)
        t5 = time.perf_counter()
        if new != old or new != poly:
            raise AssertionError(f"interpolations disagree at n={n}, modes={modes}, point {p}")
        t["total"] += t2 - t0
        t["roots"] += t2 - t1
        t["interp"] += t4 - t3
        t["before"] += t5 - t4
    ms = {k: 1e3 * v / npts for k, v in t.items()}
    ms["dets"] = ms["total"] - ms["roots"] - ms["interp"]
    return {"n": n, "modes": modes, "degree": n * (2 + modes), "points": npts, **ms}


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, for the test suite")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(2026)
    ladder = [(2, 1, 2), (3, 2, 2)] if args.quick else [(2, 1, 20), (3, 2, 20), (6, 2, 10), (6, 4, 10), (8, 4, 10), (12, 3, 5), (16, 2, 3)]
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    print(HEADER)
    print("|" + "---|" * (HEADER.count("|") - 1))
    rows = []
    for n, modes, npts in ladder:
        r = run(n, modes, npts, rng)
        rows.append(r)
        print(f"| {n} | {modes} | {r['degree']} | {npts} | {r['dets']:.1f} | {r['interp']:.1f} | {r['before']:.1f} "
              f"| {r['roots']:.1f} | {r['total']:.1f} |", flush=True)
    return rows


if __name__ == "__main__":
    main()
