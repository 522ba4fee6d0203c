"""Certified labels against the float peer, per degree and body kind, in one run.

    python scripts/bench_kernel.py            # degree 2..64 (n = 1..16) and n = 24, 32 (about 15 minutes)
    python scripts/bench_kernel.py --quick    # seconds; run once by the test suite
    python scripts/bench_kernel.py --corners  # only the structural corners below (a few minutes)
    python scripts/bench_kernel.py --many     # many bodies: n = 12, 16, 24, 32, 0-4 modes, degree <= 128 (~15 minutes)
    python scripts/bench_kernel.py --density  # the same chains on lines of 50, 100, 200, 400 points (~10 minutes)

Point sets, for every (n, modes): random chains (realistic ranges, joints and
liquid modes as given), each scanned along omega over a line of points in grid
order, as an atlas computes them (every point a grid neighbour of the one
before).  Kinds:
  mixed      every body its own random parameters;
  identical  one random body repeated n times (exactly repeated roots);
  scattered  mixed bodies, every point a new random chain (no neighbours: the
             cost without warm starts).
Structural corners (issue 32), each a modification of mixed chains that random draws never produce:
  kappa2      kappa = 2 (the sphere's mode, beta = 0: a root at lambda = 0, no pole) in every other body;
  sameshape   every body's cavity the same shape (kappa shared by all, E scaled per body);
  someshape   the same shape in half of the bodies;
  halfsame    the upper half of the chain identical bodies;
  free        free chains;
  omega0      lines through omega = 0 exactly;
  ideal       every joint ideal (K = 0);
  tinyE       E -> 0 (E scaled by 1e-9);
  tree        a binary tree instead of a chain.
stabmap: ``kernels.decide_block`` on one thread, then exact arithmetic for the
points it leaves (timed on a sample, extrapolated); throughput on every core.
Float peer: what a user would write, batched ``numpy.linalg.eigvals`` of the
D x D first-order linearisation (built by stabmap's kernel, so its build costs
the peer nothing), a pair counted where |Im z| > 1e-7 max(1, |z|).  Its wrong
labels are counted against stabmap's certified ones.
Both are timed in CPU seconds of the process (time.process_time: other work on
the machine does not move the ratio; a peer using several BLAS threads is
charged for all of them); the all-cores throughput in wall-clock seconds.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from stabmap import kernels
from stabmap.kernels import layout
from stabmap.systems.gyroscopes import exact
from stabmap.systems.gyroscopes.points import PointArrays

EXACT_SAMPLE = 10  # undecided points timed in exact arithmetic (the rest extrapolated)
PEER_TOL = 1e-7
STATUSES = (
    (kernels.DECIDED_FLOAT, "Sturm"),
    (kernels.DECIDED_INCLUSION, "coeff. disks"),
    (kernels.DECIDED_INERTIA, "inertia"),
    (kernels.DECIDED_DISKS, "inertia+disks"),
    (getattr(kernels, "DECIDED_ALLATONCE", -99), "all at once"),  # getattr: the script also times older trees
    (kernels.UNDECIDED, "exact"),
)


def random_points(rng: np.random.Generator, npts: int, n: int, modes: int) -> PointArrays:
    """npts independent random fixed-support chains of n bodies with ``modes`` liquid modes each."""
    body = np.empty((npts, n, 6))
    body[..., layout.M] = rng.uniform(0.2, 3.0, (npts, n))
    body[..., layout.A] = rng.uniform(0.005, 0.1, (npts, n))
    body[..., layout.C] = rng.uniform(0.0, 0.1, (npts, n))
    body[..., layout.CM] = rng.uniform(-0.2, 0.4, (npts, n))
    body[..., layout.S] = rng.uniform(0.05, 0.6, (npts, n))
    body[..., layout.OMEGA] = rng.uniform(-100, 100, (npts, 1))
    joint = rng.uniform(0, 200, (npts, n)) * (rng.random((npts, n)) < 0.7)
    lmax = max(1, modes)
    E = rng.uniform(1e-5, 3e-3, (npts, n, lmax))
    kappa = rng.choice([-1, 1], (npts, n, lmax)) * rng.uniform(1.05, 4.0, (npts, n, lmax))
    return PointArrays(body, joint, np.full(npts, 9.81), E, kappa, np.full(n, modes, np.int64), False)


def point_set(rng, kind: str, lines: int, per_line: int, n: int, modes: int) -> PointArrays:
    """``lines`` random chains, each scanned along omega in [-150, 150] over ``per_line`` points."""
    if kind == "scattered":
        return random_points(rng, lines * per_line, n, modes)
    base = random_points(rng, lines, n, modes)
    if kind == "identical":
        base.body[:] = base.body[:, :1]
        base.E[:] = base.E[:, :1]
        base.kappa[:] = base.kappa[:, :1]
        base.joint[:, 1:] = base.joint[:, 1:2]
        base.at = None
        base.parent = None
        base.__post_init__()

    def rep(x):
        return np.repeat(x, per_line, axis=0)

    body = rep(base.body)
    body[..., layout.OMEGA] = np.tile(np.linspace(-150.0, 150.0, per_line), lines)[:, None]
    return PointArrays(body, rep(base.joint), rep(base.g), rep(base.E), rep(base.kappa), base.nmodes, base.free)


CORNERS = ("kappa2", "sameshape", "someshape", "halfsame", "free", "omega0", "ideal", "tinyE", "tree")


def corner_set(rng, corner: str, lines: int, per_line: int, n: int, modes: int) -> PointArrays:
    """Mixed chains scanned along omega, changed into one structural corner (module docstring)."""
    pts = point_set(rng, "mixed", lines, per_line + (corner == "omega0" and per_line % 2 == 0), n, modes)
    body, joint, E, kappa = pts.body, pts.joint, pts.E, pts.kappa
    free, parent, at = False, None, None
    h = n // 2
    if corner == "kappa2" and modes:
        kappa[:, ::2, 0] = 2.0
    elif corner in ("sameshape", "someshape") and modes:
        upto = n if corner == "sameshape" else max(h, 1)
        kappa[:, :upto] = kappa[:, :1]
        E[:, :upto] = E[:, :1] * rng.uniform(0.2, 2.0, (1, upto, 1))
    elif corner == "halfsame":
        for x in (body, E, kappa):
            x[:, h:] = x[:, h : h + 1]
        joint[:, h:] = joint[:, h : h + 1]
    elif corner == "free":
        free = True
        joint[:, 0] = 0.0
    elif corner == "ideal":
        joint[:] = 0.0
    elif corner == "tinyE":
        E *= 1e-9
    elif corner == "tree":
        parent = np.array([-1] + [(k - 1) // 2 for k in range(1, n)], dtype=np.int64)
        at = np.zeros(body.shape[:2])
        at[:, 1:] = rng.uniform(-0.2, 0.6, (1, n - 1))
    # omega0: per_line made odd, so the line's linspace(-150, 150) passes through omega = 0 exactly
    return PointArrays(body, joint, pts.g, E, kappa, pts.nmodes, free, parent, at)


def any_set(rng, kind: str, lines: int, per_line: int, n: int, modes: int) -> PointArrays:
    """``corner_set`` for a structural corner (CORNERS), else ``point_set``."""
    if kind in CORNERS:
        return corner_set(rng, kind, lines, per_line, n, modes)
    return point_set(rng, kind, lines, per_line, n, modes)


def _subset(pts: PointArrays, sl) -> PointArrays:
    return PointArrays(pts.body[sl], pts.joint[sl], pts.g[sl], pts.E[sl], pts.kappa[sl], pts.nmodes, pts.free, pts.parent,
                       pts.at[sl])


def decide_threads(pts: PointArrays, threads: int):
    """decide_block over ``threads`` contiguous slices at once (the kernels release the GIL)."""
    npts = pts.body.shape[0]
    nc = np.empty(npts, np.int16)
    st = np.empty(npts, np.int8)
    edges = np.linspace(0, npts, threads + 1).astype(int)

    def run(i):
        sl = slice(edges[i], edges[i + 1])
        kernels.decide_block(*_subset(pts, sl).kernel_args(), nc[sl], st[sl])

    with ThreadPoolExecutor(threads) as pool:
        list(pool.map(run, range(threads)))
    return nc, st


def timed(f, *args, clock=time.perf_counter):
    """(f(*args), seconds it took by ``clock``)."""
    t0 = clock()
    out = f(*args)
    return out, clock() - t0


def float_peer(pts: PointArrays) -> tuple[np.ndarray, float]:
    """(N_c by eigenvalues with a tolerance, seconds for the eigenvalues and the count)."""
    npts = pts.body.shape[0]
    degree = int((pts.nmodes + 2).sum())
    C = np.empty((npts, degree, degree))
    kernels.linearise_block(*pts.kernel_args(), C)
    t0 = time.process_time()
    z = np.linalg.eigvals(C)
    nc = (np.abs(z.imag) > PEER_TOL * np.maximum(1.0, np.abs(z))).sum(axis=1) // 2
    return nc, time.process_time() - t0


def run(n: int, modes: int, kind: str, lines: int, per_line: int, rng) -> dict:
    degree = n * (2 + modes)
    pts = any_set(rng, kind, lines, per_line, n, modes)
    npts = pts.body.shape[0]
    threads = os.cpu_count() or 1
    decide_threads(_subset(pts, slice(0, 4)), 1)  # compile outside the timed calls
    (nc, st), t1 = timed(decide_threads, pts, 1, clock=time.process_time)
    _, tn = timed(decide_threads, pts, threads)
    undecided = np.flatnonzero(st == kernels.UNDECIDED)
    t_exact = 0.0
    if undecided.size:
        sample = undecided[:EXACT_SAMPLE]
        exact_nc, t_exact = timed(exact.decide_points, *pts.kernel_args(), sample, clock=time.process_time)
        t_exact /= sample.size
        nc[sample] = exact_nc
    labelled = st != kernels.UNDECIDED
    labelled[undecided[:EXACT_SAMPLE]] = True
    peer_nc, t_peer = float_peer(pts)
    certified_us = 1e6 * (t1 + t_exact * undecided.size) / npts
    peer_us = 1e6 * t_peer / npts
    return {
        "n": n, "modes": modes, "degree": degree, "kind": kind, "points": npts,
        "certified_us": certified_us, "peer_us": peer_us, "ratio": certified_us / peer_us,
        "pts_per_s_1": npts / t1, "pts_per_s_all": npts / tn, "threads": threads,
        "shares": {name: 100.0 * (st == code).mean() for code, name in STATUSES},
        "undecided_pct": 100.0 * undecided.size / npts, "exact_ms": 1e3 * t_exact,
        "peer_wrong": int((peer_nc != nc)[labelled].sum()), "compared": int(labelled.sum()),
        "stable_pct": 100.0 * (nc[labelled] == 0).mean(),
    }


# --density: the ratio against the spacing of the grid line (2 lines from -150 to 150 rad/s, the same chains at
# every spacing): neighbours 6.1 rad/s apart (50 points, the other sets) down to 0.75 rad/s (400 points)
DENSITY_ROWS = ((6, 4, "mixed"), (8, 3, "ideal"), (8, 3, "kappa2"), (8, 4, "mixed"), (12, 3, "mixed"), (16, 2, "mixed"),
                (24, 1, "mixed"), (32, 0, "identical"))
DENSITIES = (50, 100, 200, 400)


def density_cases(quick: bool):
    """(n, modes, kind, lines, points per line, seed): each chain drawn from its own seed, so only the spacing
    changes along a row's densities."""
    if quick:
        return [(3, 2, "mixed", 1, per, 1) for per in (8, 16)]
    return [(n, m, k, 2, per, 1000 + i) for i, (n, m, k) in enumerate(DENSITY_ROWS) for per in DENSITIES]


MANY = ((12, 0), (12, 2), (12, 4), (16, 0), (16, 2), (16, 4), (24, 0), (24, 1), (24, 3), (32, 0), (32, 1), (32, 2))


def cases(quick: bool, max_degree: int, corners: bool = False, many: bool = False):
    """(n, modes, kind, lines, points per line) of every row."""
    if many:  # issue 32: many bodies, mixed and identical, 2 lines of 50 points (quick: one small row)
        rows = [(n, m, k, 2, 50) for n, m in MANY for k in ("mixed", "identical")]
        return [r for r in rows if r[0] * (2 + r[1]) <= max_degree]
    if quick:
        return [(n, m, k, 2, 12) for n, m in ((1, 0), (2, 1), (3, 2)) for k in ("mixed", "identical")] + [
            (3, 2, c, 1, 6) for c in CORNERS] + [(12, 0, "mixed", 1, 6)]
    corner_rows = [(n, m, c, 10, 50) for n, m in ((3, 2), (6, 3), (8, 3)) for c in CORNERS]
    if os.environ.get("STABMAP_CORNERS"):  # a subset while developing, e.g. STABMAP_CORNERS=tinyE
        corner_rows = [r for r in corner_rows if r[2] in os.environ["STABMAP_CORNERS"].split(",")]
    if corners:
        return corner_rows
    ladder = [(1, 0), (2, 1), (3, 2), (4, 2), (6, 2), (6, 4), (8, 4), (12, 3), (16, 2)]
    out = []
    for n, m in ladder:
        d = n * (2 + m)
        lines, per = (20, 100) if d <= 24 else (10, 100) if d <= 48 else (4, 50)
        for kind in ("mixed", "identical"):
            out.append((n, m, kind, lines, per))
        if (n, m) in ((3, 2), (6, 4), (8, 4)):
            out.append((n, m, "scattered", lines, per))
    out += [(24, 0, "mixed", 2, 20), (32, 0, "mixed", 2, 20), (32, 1, "mixed", 1, 10)]
    return [c for c in out + corner_rows if c[0] * (2 + c[1]) <= max_degree]


HEADER = (
    "| n | modes | degree | kind | points | stable % | stabmap us/pt | float peer us/pt | ratio "
    "| points/s, 1 thread | points/s, all cores | decided by (%) | exact ms/pt | peer wrong labels |"
)


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, for the test suite")
    ap.add_argument("--max-degree", type=int, default=96, help="skip larger (n, modes) cases")
    ap.add_argument("--corners", action="store_true", help="only the structural corners (module docstring)")
    ap.add_argument("--many", action="store_true", help="only many bodies: n = 12..32, degree <= --max-degree")
    ap.add_argument("--density", action="store_true", help="the ratio against the grid spacing (DENSITY_ROWS)")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(2026)
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    print(HEADER)
    print("|" + "---|" * (HEADER.count("|") - 1))
    rows = []
    if args.density:
        todo = [(n, m, k, lines, per, np.random.default_rng(seed)) for n, m, k, lines, per, seed in density_cases(args.quick)]
    else:
        todo = [(n, m, k, lines, per, rng) for n, m, k, lines, per in cases(args.quick, args.max_degree, args.corners, args.many)]
    for n, modes, kind, lines, per, row_rng in todo:
        r = run(n, modes, kind, lines, per, row_rng)
        rows.append(r)
        shares = ", ".join(f"{name} {v:.1f}" for name, v in r["shares"].items() if v)
        print(
            f"| {n} | {modes} | {r['degree']} | {kind} | {r['points']} | {r['stable_pct']:.0f} | {r['certified_us']:.1f} "
            f"| {r['peer_us']:.1f} | {r['ratio']:.2f} | {r['pts_per_s_1']:,.0f} | {r['pts_per_s_all']:,.0f} | {shares} "
            f"| {r['exact_ms']:.1f} | {r['peer_wrong']} of {r['compared']} |",
            flush=True,
        )
    return rows


if __name__ == "__main__":
    main()
