"""Where the all-at-once certificate (docs/certification.md, section 4b) spends its time, per point.

    python scripts/bench_allatonce.py           # the many-body rows of bench_kernel.py --many (a few minutes)
    python scripts/bench_allatonce.py --quick   # seconds; run once by the test suite
    python scripts/bench_allatonce.py --lines 32:0:identical:400 16:0:identical:200   # cold starts per line set

The points are those of ``bench_kernel.py --many`` (same seed and order: 2 lines of 50 points along omega per
row).  Each point is certified as ``certify.certify_point`` does it, one step at a time from Python, timed in CPU
seconds (time.process_time): warm (the neighbours' decomposition extrapolated and refined by Newton steps, the
proof tried between them by ``allatonce.proof_due``), else cold (the float linearisation, LAPACK dgeev with eigenvectors, the inverse of B X, the proof).
The float peer's eigenvalues of the same linearisations are timed alongside.  Run it with
OPENBLAS_NUM_THREADS=1 as in BENCHMARKS.md: the kernels' products are many small ones.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from stabmap import kernels
from stabmap.kernels import allatonce, certify, pencil

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_kernel import any_set, cases, float_peer, point_set  # noqa: E402


def split(pts) -> dict:
    """Time per point of each part, the share of warm points, the mean Newton steps of a warm point."""
    body, joint, g, E, kappa, nmodes, free, parent, at = pts.kernel_args()
    npts, n = body.shape[:2]
    ws = certify.allocate(n, nmodes, parent)
    pws, C, Mo, aw = ws[0], ws[1], ws[2], ws[-1]
    state = aw[-1]
    t = {"refine": 0.0, "proof": 0.0, "eigenvectors": 0.0, "peer": 0.0}
    warm = steps = decided = 0
    clock = time.process_time
    for p in range(npts):
        m = pencil.prepare(body[p], joint[p], at[p], g[p], E[p], kappa[p], nmodes, parent, free, pws, False)
        allatonce.pencil_balls(body[p], E[p], nmodes, pws, aw)
        nonreal = -1
        if state[0] == 1:
            # allatonce.certify's warm start, with its own stopping and proof rules
            t0 = clock()
            allatonce.extrapolate(aw)
            moved, last, tried = allatonce.refine(aw), np.inf, np.inf
            t["refine"] += clock() - t0
            for k in range(1, allatonce.REFINE_STEPS + 1):
                stop = allatonce.last_step(k, moved, last)
                if allatonce.proof_due(moved, tried, stop):
                    tried, t0 = moved, clock()
                    nonreal = allatonce.verify(m, aw)
                    t["proof"] += clock() - t0
                    if nonreal >= 0:
                        break
                if stop:
                    break
                t0 = clock()
                last, moved = moved, allatonce.refine(aw)
                t["refine"] += clock() - t0
            steps += k
            warm += nonreal >= 0
            state[4] = int(nonreal >= 0) * (1 - state[5])
        else:
            state[4] = 0
        pencil.linearisation(body[p], E[p], nmodes, parent, pws, C, Mo)
        t0 = clock()
        np.linalg.eigvals(C)
        t["peer"] += clock() - t0
        if nonreal < 0:
            t0 = clock()
            state[0] = int(allatonce.decompose(C, aw))
            t1 = clock()
            nonreal = allatonce.verify(m, aw) if state[0] else -1
            t["eigenvectors"] += t1 - t0
            t["proof"] += clock() - t1
        decided += nonreal >= 0
    us = {k: 1e6 * v / npts for k, v in t.items()}
    return {"points": npts, "warm_pct": 100.0 * warm / npts, "decided_pct": 100.0 * decided / npts,
            "steps": steps / max(1, npts - 1), "us": us, "ratio": sum(v for k, v in us.items() if k != "peer") / us["peer"]}


def cold_starts(spec: str) -> dict:
    """``kernels.allatonce_block`` on the point set ``spec`` = n:modes:kind:points per line (2 lines along omega from
    -150 to 150, ``bench_kernel.any_set``, seed 1007): its cold starts, the points it left
    undecided and its CPU time over the float peer's."""
    n, modes, kind, per = spec.split(":")
    n, modes, per = int(n), int(modes), int(per)
    pts = any_set(np.random.default_rng(1007), kind, 2, per, n, modes)
    args = pts.kernel_args()
    npts = args[0].shape[0]
    nc, st = np.zeros(npts, np.int64), np.zeros(npts, np.int8)
    kernels.allatonce_block(*pts.take(np.arange(2)).kernel_args(), nc[:2], st[:2])  # compile outside the timed call
    t0 = time.process_time()
    cold = kernels.allatonce_block(*args, nc, st)
    t = time.process_time() - t0
    _, t_peer = float_peer(pts)
    return {"spec": spec, "points": npts, "cold": int(cold), "undecided": int((st != kernels.DECIDED_ALLATONCE).sum()),
            "ratio": t / t_peer}


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one small row, for the test suite")
    ap.add_argument("--lines", nargs="+", metavar="N:MODES:KIND:PER_LINE",
                    help="only the cold starts of the certificate alone on these point sets (2 lines each)")
    args = ap.parse_args(argv)
    if args.lines:
        print("| spec | points | cold starts | undecided | ratio to the float peer |")
        print("|---|---|---|---|---|")
        out = []
        for spec in args.lines:
            r = cold_starts(spec)
            print(f"| {spec} | {r['points']} | {r['cold']} | {r['undecided']} | {r['ratio']:.2f} |", flush=True)
            out.append(r)
        return out
    rng = np.random.default_rng(2026)
    rows = cases(False, 128, many=True)
    if args.quick:
        rows = [(12, 0, "mixed", 1, 8)]
    print("| n | modes | degree | kind | points | decided % | warm % | Newton steps | refine us/pt | proof us/pt "
          "| eigenvectors us/pt | all-at-once us/pt | float peer us/pt | ratio |")
    print("|" + "---|" * 14)
    split(point_set(np.random.default_rng(0), "mixed", 1, 3, 2, 1))  # compile outside the timed rows
    out = []
    for n, modes, kind, lines, per in rows:
        r = split(point_set(rng, kind, lines, per, n, modes))
        u = r["us"]
        print(f"| {n} | {modes} | {n * (2 + modes)} | {kind} | {r['points']} | {r['decided_pct']:.0f} | {r['warm_pct']:.0f} "
              f"| {r['steps']:.1f} | {u['refine']:.0f} | {u['proof']:.0f} | {u['eigenvectors']:.0f} "
              f"| {u['refine'] + u['proof'] + u['eigenvectors']:.0f} | {u['peer']:.0f} | {r['ratio']:.2f} |", flush=True)
        out.append(r)
    return out


if __name__ == "__main__":
    main()
