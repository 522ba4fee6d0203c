"""Growth rates against the labels they annotate: the default atlas against ``growth_rate = false``, same run.

    python scripts/bench_rate_price.py            # the scenes below, then every row of bench_kernel.py's ladder and corners
    python scripts/bench_rate_price.py --quick    # small grids and the quick ladder; run once by the test suite

(scripts/bench_rates.py measures what rates and frequencies cost in time and memory on the paper scenes, one thread;
this one measures the ratio to the labels on the scenes where rates cost most, and per point on the kernel's sets.)

Scenes (``compute_atlas``, both cores, wall seconds, minimum of two alternating runs each):
- paper-n3-fixed (3 bodies, degree 12) and paper-n2-fixed (degree 6), 300 x 300;
- the README scene (omega x m_2 x K_1 = 300 x 100 x 3);
- six identical bodies with four liquid modes each (degree 36) over omega x K_1, 80 x 50: clustered real roots.
Each row gives both times, their ratio, the rate methods (growth_rate_method) over the unstable points, the share
of them that went to exact arithmetic and the largest relative enclosure width (upper - lower) / upper.

Point sets (``--ladder``; on by default): the sets of bench_kernel.py, one thread, CPU seconds: ``decide_block``
(the label) against the label plus ``rates.growth_only`` on the unstable points, and the same widths and shares;
and at every unstable point an independent float solver (numpy's eigenvalues of the first-order linearisation)
against the proved bounds (``peer_check``).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

import stabmap
from stabmap.scene.grid import resample
from stabmap.systems.gyroscopes import rates

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_kernel
from bench_cells import readme_scene

METHODS = dict(zip(("all_roots_real", "inclusion_disks", "exact_arb_roots", "not_computed", "degenerate", "newton_pairs"),
                   (rates.ALL_REAL, rates.DISKS, rates.EXACT, rates.NOT_COMPUTED, rates.DEGENERATE, rates.PAIRS), strict=True))

SIX = """
title = "six identical tops, four liquid modes each (degree 36)"
g = 9.81
joints = [120.0, 120.0, 120.0, 120.0, 120.0]
""" + """
[[bodies]]
m = 1.0
A = 0.02
C = 0.03
c = 0.10
s = 0.25
fluid = { E = [1.0e-4, 5.0e-5, 2.0e-5, 1.0e-5], kappa = [1.31, 2.7, 4.8, 8.1] }
""" * 6 + """
[grid]
omega = { start = 1.0, stop = 200.0, num = 80 }
K_1 = { start = 20.0, stop = 200.0, num = 50 }
"""


def _min_of_two(f):
    best = np.inf
    out = None
    for _ in range(2):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return out, best


def _widths(lower, upper, unstable) -> float:
    lo, hi = lower[unstable].astype(np.float64), upper[unstable].astype(np.float64)
    return float(np.max((hi - lo) / hi)) if lo.size else 0.0


def scene_row(label: str, scene) -> dict:
    """Default atlas against growth_rate = false on ``scene``'s grid (module docstring)."""
    small = resample(scene, **{a.name: 3 for a in scene.grid})
    stabmap.compute_atlas(small, progress=False)
    plain = dataclasses.replace(scene, growth_rate=False)
    t_rates, t_plain = np.inf, np.inf
    ds = None
    for _ in range(2):  # alternating, so a busy spell of the machine hits both
        t0 = time.perf_counter()
        ds = stabmap.compute_atlas(scene, progress=False)
        t_rates = min(t_rates, time.perf_counter() - t0)
        t0 = time.perf_counter()
        base = stabmap.compute_atlas(plain, progress=False)
        t_plain = min(t_plain, time.perf_counter() - t0)
    assert ds is not None
    if not np.array_equal(ds["n_complex_pairs"].values, base["n_complex_pairs"].values):
        raise AssertionError(f"{label}: the rates changed a label")
    unstable = ds["n_complex_pairs"].values > 0
    method = ds["growth_rate_method"].values[unstable]
    return {"scene": label, "degree": scene.degree, "points": int(unstable.size), "unstable": int(unstable.sum()),
            "rates_s": t_rates, "labels_s": t_plain, "ratio": t_rates / t_plain,
            "methods": {m: int((method == v).sum()) for m, v in METHODS.items() if (method == v).any()},
            "exact_pct": 100.0 * float((method == rates.EXACT).mean()) if method.size else 0.0,
            "width": _widths(ds["growth_rate_lower"].values, ds["growth_rate_upper"].values, unstable)}


def ladder_row(n: int, modes: int, kind: str, lines: int, per_line: int, rng) -> dict:
    """decide_block against decide_block + growth_only on one of bench_kernel.py's point sets, one thread."""
    pts = bench_kernel.any_set(rng, kind, lines, per_line, n, modes)
    D = int((pts.nmodes + 2).sum())
    first = bench_kernel._subset(pts, slice(0, 4))
    nc0, _ = bench_kernel.decide_threads(first, 1)
    rates.growth_only(first, np.flatnonzero(nc0 > 0), nc0[nc0 > 0], D)  # compile outside the clock
    (nc, st), t_label = bench_kernel.timed(bench_kernel.decide_threads, pts, 1, clock=time.process_time)
    at = np.flatnonzero(nc > 0)
    (lower, upper, _, method), t_rate = bench_kernel.timed(rates.growth_only, pts, at, nc[at].astype(np.int64), D,
                                                            clock=time.process_time)
    npts = nc.size
    outside, off = peer_check(bench_kernel._subset(pts, at), lower, upper)
    return {"n": n, "modes": modes, "degree": D, "kind": kind, "points": npts, "unstable": int(at.size),
            "peer_outside": outside, "peer_off": off,
            "label_us": 1e6 * t_label / npts, "rate_us": 1e6 * t_rate / npts, "ratio": (t_label + t_rate) / t_label,
            "methods": {m: int((method == v).sum()) for m, v in METHODS.items() if (method == v).any()},
            "exact_pct": 100.0 * float((method == rates.EXACT).mean()) if at.size else 0.0,
            "width": float(np.max((upper - lower) / upper)) if at.size else 0.0}


def peer_check(pts, lower: np.ndarray, upper: np.ndarray) -> tuple[int, float]:
    """An independent float solver against the proved bounds: max |Im z| over the eigenvalues (numpy's LAPACK dgeev) of
    the first-order linearisation, at every unstable point.  Returns the points where it lies outside [lower, upper]
    by more than PEER_RTOL relative, and the largest such distance (relative): the float solver's own error on a
    simple eigenvalue is about its condition number times 1e-16, so a point counted is either an ill-conditioned
    float answer or a wrong bound, and is to be looked at."""
    if not lower.size:
        return 0, 0.0
    D = int((pts.nmodes + 2).sum())
    C = np.empty((lower.size, D, D))
    stabmap.kernels.linearise_block(*pts.kernel_args(), C)
    peer = np.abs(np.linalg.eigvals(C).imag).max(axis=1)
    off = np.maximum(lower - peer, peer - upper) / np.maximum(upper, 1e-300)
    return int((off > PEER_RTOL).sum()), float(max(0.0, off.max()))


PEER_RTOL = 1e-8


def _methods(m: dict) -> str:
    return ", ".join(f"{k.replace('_', ' ')} {v:,}" for k, v in m.items())


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small grids and the quick ladder, for the test suite")
    ap.add_argument("--no-ladder", action="store_true", help="the scenes only")
    ap.add_argument("--max-degree", type=int, default=48, help="ladder rows up to this degree (default 48)")
    args = ap.parse_args(argv)
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    q = args.quick
    scenes = [
        ("paper-n3-fixed", resample(stabmap.example("paper-n3-fixed"), omega=24 if q else 300, m_2=16 if q else 300)),
        ("paper-n2-fixed", resample(stabmap.example("paper-n2-fixed"), **{a.name: 16 if q else 300 for a in stabmap.example("paper-n2-fixed").grid})),
        ("README scene", resample(readme_scene(), omega=24 if q else 300, m_2=12 if q else 100)),
        ("6 identical bodies, 4 modes", resample(stabmap.loads_scene(SIX), omega=6 if q else 80, K_1=4 if q else 50)),
    ]
    out = {"scenes": [], "ladder": []}
    print("\n| scene | degree | points | unstable | default s | growth_rate = false s | ratio | rate methods (unstable points) "
          "| exact % | widest enclosure (relative) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for label, scene in scenes:
        r = scene_row(label, scene)
        out["scenes"].append(r)
        print(f"| {r['scene']} | {r['degree']} | {r['points']:,} | {r['unstable']:,} | {r['rates_s']:.2f} | {r['labels_s']:.2f} "
              f"| {r['ratio']:.2f} | {_methods(r['methods'])} | {r['exact_pct']:.2f} | {r['width']:.1e} |", flush=True)
    if args.no_ladder:
        return out
    print("\n| n | modes | degree | kind | points | unstable | label us/pt | rate us/pt | (label + rate) / label "
          "| rate methods | exact % | widest enclosure | float eigvals outside the bounds (largest, relative) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    rng = np.random.default_rng(2026)
    for case in bench_kernel.cases(q, args.max_degree):
        r = ladder_row(*case, rng)
        out["ladder"].append(r)
        print(f"| {r['n']} | {r['modes']} | {r['degree']} | {r['kind']} | {r['points']:,} | {r['unstable']:,} "
              f"| {r['label_us']:.1f} | {r['rate_us']:.1f} | {r['ratio']:.2f} | {_methods(r['methods'])} "
              f"| {r['exact_pct']:.2f} | {r['width']:.1e} | {r['peer_outside']} ({r['peer_off']:.0e}) |", flush=True)
    return out


if __name__ == "__main__":
    main()
