"""The sign-aware (Krein-type) real-root count: separators and time per point, by placement, in one run.

    python scripts/bench_krein.py            # bench_kernel.py's rows and paper-n3-fixed at low and high spin (minutes)
    python scripts/bench_krein.py --quick    # seconds; run once by the test suite
    python scripts/bench_krein.py --labels   # decide_block per point on bench_kernel.py's sets (run it in two
                                             # checkouts, alternating, to compare a change)

For every point, the linearisation's eigenvalues (the cold start's approximations, unpolished) place separators
three ways (kernels/certify.py, ``_real_roots_at_least``):
  coarse  between groups of near-real approximations, cut only where the count falls short (the first try);
  fine    between every two near-real approximations;
  poles   fine, and the poles fenced: the placement the earlier bound, |nu(b) - nu(a)| - (poles inside), needed.
Each is counted with the pole-free nu_H.  Reported: separators evaluated a point (a count: no clock), real roots
proved against the most any placement proves, and microseconds a point of the count alone (numba loop, process
time, the three placements interleaved; ratios within one row mean more than the absolute times).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_kernel as bk

import stabmap
from stabmap.kernels import approximations, certify, disks, pencil
from stabmap.systems.gyroscopes.points import PointArrays, point_arrays

PLACEMENTS = (("coarse", certify.COARSE), ("fine", certify.FINE), ("poles", certify.POLES))


@numba.njit(cache=False)
def _approximate(body, joint, g, E, kappa, nmodes, free, parent, at, zs, ms, leads):
    """The cold start's approximations of every point (zs[p, :d]), its exact zero roots and nu of the leading matrix."""
    n = body.shape[1]
    ws = certify.allocate(n, nmodes, parent)
    degree = ws.C.shape[0]
    for p in range(body.shape[0]):
        m = pencil.prepare(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, ws.pws, False)
        ms[p] = -1
        if not pencil.linearisation(body[p], E[p], nmodes, parent, ws.pws, ws.C, ws.Mo):
            continue
        if not approximations.eigenvalues(ws.C, ws.wr, ws.wi, ws.vdummy, ws.z, degree, m):
            continue
        ms[p] = m
        zs[p, : degree - m] = ws.z[: degree - m]
        leads[p] = disks.lead_bound(ws.pws, n, ws.Sm, ws.Sr)[3]


@numba.njit(cache=False)
def _count(body, joint, g, E, kappa, nmodes, free, parent, at, zs, ms, leads, placement, real, evaluated):
    n = body.shape[1]
    ws = certify.allocate(n, nmodes, parent)
    degree = ws.C.shape[0]
    for p in range(body.shape[0]):
        if ms[p] < 0:
            continue
        m = pencil.prepare(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, ws.pws, False)
        d = degree - m
        ws.z[:d] = zs[p, :d]
        real[p], evaluated[p] = certify._real_roots_at_least(ws.z, d, m, leads[p], body[p], E[p], nmodes, parent, ws.pws, ws.feat,
                                                             ws.Sm, ws.Sr, ws.done, placement)


@numba.njit(cache=False)
def _prepare_only(body, joint, g, E, kappa, nmodes, free, parent, at, ms):
    """The same loop without the count: its time is taken off the count's."""
    n = body.shape[1]
    ws = certify.allocate(n, nmodes, parent)
    for p in range(body.shape[0]):
        if ms[p] >= 0:
            pencil.prepare(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, ws.pws, False)


def row(name: str, pts: PointArrays, repeats: int) -> dict:
    args = pts.kernel_args()
    npts = pts.body.shape[0]
    degree = int((pts.nmodes + 2).sum())
    zs = np.zeros((npts, degree), np.complex128)
    ms = np.zeros(npts, np.int64)
    leads = np.full(npts, -1, np.int64)
    _approximate(*args, zs, ms, leads)
    real = {k: np.zeros(npts, np.int64) for k, _ in PLACEMENTS}
    evaluated = {k: np.zeros(npts, np.int64) for k, _ in PLACEMENTS}
    seconds = {k: np.inf for k, _ in PLACEMENTS}
    base = np.inf
    for k, placement in PLACEMENTS:  # compile outside the timed calls
        _count(*args, zs, ms, leads, placement, real[k], evaluated[k])
    for _ in range(repeats):
        t = time.process_time()
        _prepare_only(*args, ms)
        base = min(base, time.process_time() - t)
        for k, placement in PLACEMENTS:
            t = time.process_time()
            _count(*args, zs, ms, leads, placement, real[k], evaluated[k])
            seconds[k] = min(seconds[k], time.process_time() - t)
    ok = ms >= 0
    best = np.max([real[k] for k, _ in PLACEMENTS], axis=0)
    out = {"name": name, "degree": degree, "points": int(ok.sum())}
    for k, _ in PLACEMENTS:
        out[k] = {"separators": float(evaluated[k][ok].mean()), "all_found_pct": 100.0 * float((real[k] == best)[ok].mean()),
                  "us": 1e6 * max(seconds[k] - base, 0.0) / max(1, ok.sum())}
    return out


def scenes(quick: bool):
    """(name, points): bench_kernel.py's rows (cold approximations) and paper-n3-fixed's grid lines."""
    rng = np.random.default_rng(2026)
    sc = stabmap.example("paper-n3-fixed")
    per = 40 if quick else 400
    for lo, hi in ((1.0, 10.0), (60.0, 200.0)):
        om = np.linspace(lo, hi, per)
        yield f"paper-n3-fixed, omega {lo:g}-{hi:g}, m_2 = 1", point_arrays(sc, {"omega": om, "m_2": np.ones_like(om)})
    rows = [(3, 2, "mixed"), (6, 3, "free")] if quick else [
        (3, 2, "mixed"), (3, 2, "identical"), (6, 4, "mixed"), (6, 4, "identical"), (8, 3, "kappa2"), (8, 3, "free"),
        (8, 3, "halfsame"), (8, 3, "tinyE"), (8, 4, "mixed"), (12, 3, "mixed"), (16, 2, "mixed"), (32, 2, "mixed")]
    for n, m, kind in rows:
        lines, per_line = (1, 10) if quick else (4, 50)
        yield f"{n} x {m} {kind}", bk.any_set(rng, kind, lines, per_line, n, m)


LABEL_ROWS = ((3, 2, "identical", 4, 100), (3, 2, "sameshape", 4, 100), (6, 4, "mixed", 4, 100), (6, 4, "identical", 4, 100),
              (8, 4, "mixed", 2, 100), (8, 3, "kappa2", 4, 50), (8, 3, "free", 4, 50), (6, 3, "free", 4, 50), (12, 3, "mixed", 2, 50))


def labels(quick: bool) -> list[dict]:
    """decide_block per point, one thread, process time, minimum of three."""
    rng = np.random.default_rng(7)
    out = []
    for n, m, kind, lines, per in LABEL_ROWS[:1] if quick else LABEL_ROWS:
        pts = bk.any_set(rng, kind, 1 if quick else lines, 8 if quick else per, n, m)
        bk.decide_threads(bk._subset(pts, slice(0, 4)), 1)
        best = np.inf
        for _ in range(1 if quick else 3):
            (_, st), t = bk.timed(bk.decide_threads, pts, 1, clock=time.process_time)
            best = min(best, t)
        us = 1e6 * best / pts.body.shape[0]
        out.append({"name": f"{n} x {m} {kind}", "us": us, "undecided_pct": 100.0 * float(np.mean(st == 1))})
        print(f"| {n} x {m} {kind} | {us:.1f} | {out[-1]['undecided_pct']:.1f} |", flush=True)
    return out


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, for the test suite")
    ap.add_argument("--labels", action="store_true", help="decide_block per point (LABEL_ROWS)")
    args = ap.parse_args(argv)
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    if args.labels:
        print("| points | decide_block us a point | undecided % |\n|---|---|---|")
        return labels(args.quick)
    print("| points | degree | n | separators a point: coarse / fine / poles | all real roots found (%): coarse / fine / poles "
          "| count us a point: coarse / fine / poles |")
    print("|---|---|---|---|---|---|")
    out = []
    for name, pts in scenes(args.quick):
        r = row(name, pts, 1 if args.quick else 3)
        out.append(r)
        c, f, p = r["coarse"], r["fine"], r["poles"]
        print(f"| {name} | {r['degree']} | {r['points']} | {c['separators']:.1f} / {f['separators']:.1f} / {p['separators']:.1f} "
              f"| {c['all_found_pct']:.1f} / {f['all_found_pct']:.1f} / {p['all_found_pct']:.1f} "
              f"| {c['us']:.1f} / {f['us']:.1f} / {p['us']:.1f} |", flush=True)
    return out


if __name__ == "__main__":
    main()
