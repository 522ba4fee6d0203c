"""Run time against error: every way of labelling a point, on the same point sets, against exact labels.

    python scripts/bench_accuracy.py            # full tables (about ten minutes)
    python scripts/bench_accuracy.py --quick    # seconds; run once by the test suite

Point sets (all fixed or free chains with liquid, see the functions below):
  random-12     n = 3, two modes per body (degree 12), realistic random parameters
  random-24     n = 6, two modes per body (degree 24)
  boundary      n = 2, one mode, spin rates 1e-4 .. 1e-12 relative from a located stability boundary
  repeated      identical upper bodies on a split chain, identical free bodies: exactly repeated roots
Methods: plain float64 Sturm (no tolerance, and a 1e-10 relative remainder tolerance), numpy.roots
with a tolerance on |Im z| / |z|, batched companion-matrix eigenvalues (one LAPACK call per set),
batched eigenvalues of the first-order linearisation (no coefficients), stabmap's certified kernel (and with its exact fallback), and the exact path alone.  Every method is
scored against the exact label of the same binary point.

A second table gives, for the bundled example atlases, the share of points each path decided and the
cost of the exact fallback.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from stabmap import kernels  # noqa: E402
from stabmap.kernels import layout  # noqa: E402
from bench_kernel import random_points, timed  # noqa: E402
from stabmap.systems.gyroscopes import exact  # noqa: E402
from stabmap.run.atlas import compute  # noqa: E402
from stabmap.systems.gyroscopes.decide import decided_by_from_status  # noqa: E402
from stabmap.systems.gyroscopes.outputs import BY_DISKS, BY_EXACT, BY_INCLUSION, BY_INERTIA, BY_STURM  # noqa: E402
from stabmap.examples import example  # noqa: E402
from stabmap.systems.gyroscopes.points import PointArrays  # noqa: E402


# --- float methods ------------------------------------------------------------------------------


def companion_pairs(coeffs: np.ndarray, tol: float) -> np.ndarray:
    """N_c from batched eigenvalues of the companion matrices of the float coefficients."""
    d = coeffs.shape[1] - 1
    comp = np.zeros((len(coeffs), d, d))
    comp[:, 1:, :-1] = np.eye(d - 1)
    comp[:, :, -1] = -coeffs[:, :d] / coeffs[:, d : d + 1]
    z = np.linalg.eigvals(comp)
    return (np.abs(z.imag) > tol * np.maximum(np.abs(z), 1e-300)).sum(axis=1) // 2


def linearisation_pairs(pts: PointArrays, tol: float) -> np.ndarray:
    """N_c from batched eigenvalues of the D x D first-order linearisation (the float peer of bench_kernel)."""
    degree = int((pts.nmodes + 2).sum())
    C = np.empty((pts.body.shape[0], degree, degree))
    kernels.linearise_block(*pts.kernel_args(), C)
    z = np.linalg.eigvals(C)
    return (np.abs(z.imag) > tol * np.maximum(1.0, np.abs(z))).sum(axis=1) // 2


# --- point sets ---------------------------------------------------------------------------------


def _take(pts: PointArrays, idx) -> PointArrays:
    return PointArrays(pts.body[idx], pts.joint[idx], pts.g[idx], pts.E[idx], pts.kappa[idx], pts.nmodes, pts.free)


def _exact_labels(pts: PointArrays) -> np.ndarray:
    return exact.decide_points(*pts.kernel_args(), np.arange(pts.body.shape[0]))


def boundary_points(rng, nsys: int) -> PointArrays:
    """Points at relative distances 1e-4 .. 1e-12 on both sides of an exactly located spin-rate boundary."""
    rels = [s * 10.0**-k for k in (4, 6, 8, 10, 12) for s in (-1, 1)]
    chosen = []
    grid = 10.0 ** np.linspace(-1, 3, 25)
    while len(chosen) < nsys:
        base = random_points(rng, 1, 2, 1)
        base.body[..., layout.CM] = np.abs(base.body[..., layout.CM])  # top-heavy: unstable when slow, a boundary exists
        def label(w):
            p = _take(base, [0])
            p.body[..., layout.OMEGA] = w
            return int(_exact_labels(p)[0])
        labels = [label(w) for w in grid]
        change = [i for i in range(len(grid) - 1) if labels[i] != labels[i + 1]]
        if not change:
            continue
        lo, hi = grid[change[0]], grid[change[0] + 1]
        a = labels[change[0]]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if label(mid) == a:
                lo = mid
            else:
                hi = mid
        pts = _take(base, [0] * len(rels))
        pts.body[..., layout.OMEGA] = (hi * (1 + np.array(rels)))[:, None]
        chosen.append(pts)
    return PointArrays(*(np.concatenate([getattr(p, f) for p in chosen]) for f in ("body", "joint", "g", "E", "kappa")),
                       chosen[0].nmodes, chosen[0].free)


def repeated_points(rng, npts: int) -> PointArrays:
    """Half split fixed chains with three identical upper bodies (p = F_1 F_2^3), half identical free chains."""
    n = 4
    dy = lambda size: rng.integers(1, 65, size) / 64  # noqa: E731  (dyadic: products stay exact)
    body = np.empty((npts, n, 6))
    body[..., layout.M] = 4 * dy((npts, 1))
    body[..., layout.A] = dy((npts, 1)) / 16
    body[..., layout.C] = dy((npts, 1)) / 16
    body[..., layout.CM] = dy((npts, 1)) / 2
    body[..., layout.S] = dy((npts, 1))
    body[..., layout.OMEGA] = rng.choice([-1, 1], (npts, 1)) * 2.0 ** rng.integers(-2, 9, (npts, 1))
    E = body[..., 1:2] * dy((npts, 1, 1)) / 4 * np.ones((1, n, 1))
    kappa = rng.choice([-3.5, -1.25, 1.5, 3.0], (npts, 1, 1)) * np.ones((1, n, 1))
    half = npts // 2
    body[:half, 0] = np.column_stack([4 * dy(half), dy(half) / 16, dy(half) / 16, dy(half) / 2, dy(half), body[:half, 0, layout.OMEGA]])
    body[:half, 1:, 3:5] = 0.0  # a_k = 0 above the first body: the determinant splits
    joint = np.zeros((npts, n))
    fixed = PointArrays(body[:half], joint[:half], np.full(half, 9.8125), E[:half], kappa[:half], np.full(n, 1, np.int64), False)
    free = PointArrays(body[half:], joint[half:], np.zeros(npts - half), E[half:], kappa[half:], np.full(n, 1, np.int64), True)
    return fixed, free


# --- float methods ------------------------------------------------------------------------------


@numba.njit(cache=False)
def _float_sturm(c, tol):
    """Plain float64 Sturm count of complex pairs; remainder coefficients below tol * max are dropped."""
    top = c.shape[0] - 1
    while top >= 0 and c[top] == 0.0:
        top -= 1
    low = 0
    while c[low] == 0.0:
        low += 1
    a = c[low : top + 1] / np.abs(c[top])
    d = top - low
    b = np.empty(d)
    for i in range(d):
        b[i] = (i + 1) * a[i + 1]
    seq_lead = np.empty(d + 1)
    seq_deg = np.empty(d + 1, np.int64)
    seq_lead[0], seq_deg[0] = a[d], d
    m = 1
    while True:
        db = b.shape[0] - 1
        while db >= 0 and b[db] == 0.0:
            db -= 1
        if db < 0:
            break
        seq_lead[m], seq_deg[m] = b[db], db
        m += 1
        if db == 0:
            break
        r = a.copy()
        for j in range(r.shape[0] - 1, db - 1, -1):
            f = r[j] / b[db]
            for i in range(db + 1):
                r[j - db + i] -= f * b[i]
        r = -r[:db]
        scale = np.abs(r).max()
        if scale == 0.0:
            break
        for i in range(db):
            if abs(r[i]) <= tol * scale:
                r[i] = 0.0
        a, b = b[: db + 1], r / scale
    vp = vm = 0
    for i in range(1, m):
        sp0, sp1 = np.sign(seq_lead[i - 1]), np.sign(seq_lead[i])
        sm0 = sp0 * (-1) ** seq_deg[i - 1]
        sm1 = sp1 * (-1) ** seq_deg[i]
        vp += sp0 != sp1
        vm += sm0 != sm1
    real = low + vm - vp
    return (top - real) // 2


def float_sturm(coeffs, tol):
    return np.array([_float_sturm(c, tol) for c in coeffs])


def numpy_roots(coeffs, tol):
    out = np.empty(len(coeffs), np.int64)
    for p, c in enumerate(coeffs):
        z = np.roots(c[::-1])
        out[p] = int((np.abs(z.imag) > tol * np.maximum(np.abs(z), 1e-300)).sum()) // 2
    return out


# --- the table ----------------------------------------------------------------------------------


def score(name: str, pts_list, rows: list) -> None:
    """Every method on the point set(s), against the exact labels."""
    coeffs, truth, t_exact, certified, t_kernel, t_fallback, by = [], [], 0.0, [], 0.0, 0.0, []
    for pts in pts_list:
        npts = pts.body.shape[0]
        degree = int((pts.nmodes + 2).sum())
        c = np.zeros((npts, degree + 1, 3))
        kernels.charpoly_block(*pts.kernel_args(), c)
        coeffs.append(c[..., 0] + c[..., 1])
        lab, t = timed(_exact_labels, pts)
        truth.append(lab)
        t_exact += t
        nc, st = np.empty(npts, np.int16), np.empty(npts, np.int8)
        _, t = timed(kernels.decide_block, *pts.kernel_args(), nc, st)
        t_kernel += t
        und = np.flatnonzero(st == kernels.UNDECIDED)
        t0 = time.perf_counter()
        nc[und] = exact.decide_points(*pts.kernel_args(), und)
        t_fallback += time.perf_counter() - t0
        certified.append(nc)
        by.append(decided_by_from_status(st))
    truth, certified, by = np.concatenate(truth), np.concatenate(certified), np.concatenate(by)
    npts = truth.size
    per = lambda t: 1e6 * t / npts  # noqa: E731
    def row(method, labels, seconds, note=""):
        wrong = int((np.asarray(labels) != truth).sum())
        rows.append((name, method, per(seconds), wrong, npts, note))
    # Uniform degree inside one list element; the float methods run per element.
    parts = {k: [] for k in ("fs0", "fs10", "nr10", "nr6", "ce", "lin")}
    times = dict.fromkeys(parts, 0.0)
    for c in coeffs:
        for key, f, tol in (("fs0", float_sturm, 0.0), ("fs10", float_sturm, 1e-10),
                            ("nr10", numpy_roots, 1e-10), ("nr6", numpy_roots, 1e-6), ("ce", companion_pairs, 1e-8)):
            out, t = timed(f, c, tol)
            parts[key].append(out)
            times[key] += t
    for pts in pts_list:
        out, t = timed(linearisation_pairs, pts, 1e-7)
        parts["lin"].append(out)
        times["lin"] += t
    fs0, fs10, nr10, nr6, ce = (np.concatenate(parts[k]) for k in ("fs0", "fs10", "nr10", "nr6", "ce"))
    row("float Sturm, no tolerance", fs0, times["fs0"])
    row("float Sturm, 1e-10 remainder tolerance", fs10, times["fs10"])
    row("numpy.roots, tol 1e-10", nr10, times["nr10"])
    row("numpy.roots, tol 1e-6", nr6, times["nr6"])
    row("companion eigvals (batched), tol 1e-8", ce, times["ce"])
    row("linearisation eigvals (batched), tol 1e-7", np.concatenate(parts["lin"]), times["lin"])
    paths = ((BY_STURM, "Sturm"), (BY_INCLUSION, "inclusion"), (BY_INERTIA, "inertia"), (BY_DISKS, "inertia+disks"), (BY_EXACT, "exact"))
    shares = ", ".join(f"{100 * (by == v).mean():.1f} % {k}" for v, k in paths)
    row("stabmap certified kernel alone", np.where(by == BY_EXACT, -2, certified), t_kernel, "undecided points counted as wrong; " + shares)
    row("stabmap certified + exact fallback", certified, t_kernel + t_fallback, shares)
    row("exact path alone (python-flint)", truth, t_exact)


def atlas_shares(names, quick: bool) -> list:
    """Share of each deciding path and cost of the exact fallback on the bundled example atlases."""
    out = []
    for name in names:
        scene = example(name)
        if quick:  # every 12th grid value of each axis
            scene = dataclasses.replace(scene, grid=tuple(dataclasses.replace(a, values=a.values[::12]) for a in scene.grid))
        t0 = time.perf_counter()
        ds = compute(scene, threads=1, progress=False)
        t = time.perf_counter() - t0
        by = ds["decided_by"].values.ravel()
        out.append((name, by.size, 100 * (by == BY_STURM).mean(), 100 * (by == BY_INCLUSION).mean(),
                    100 * (by == BY_EXACT).mean(), t, 100 * np.isin(by, (BY_INERTIA, BY_DISKS)).mean()))
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, for the test suite")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(7)
    n = 20 if args.quick else 1000
    warm = random_points(rng, 2, 1, 1)
    kernels.decide_block(*warm.kernel_args(), np.empty(2, np.int16), np.empty(2, np.int8))
    _float_sturm(np.array([1.0, 0.0, 1.0]), 0.0)
    sets = {
        "random-12": [random_points(rng, n, 3, 2)],
        "random-24": [random_points(rng, max(10, n // 5), 6, 2)],
        "boundary": [boundary_points(rng, 2 if args.quick else 40)],
        "repeated": list(repeated_points(rng, n // 2)),
    }
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, "
          f"python {platform.python_version()}, numba {numba.__version__}, numpy {np.__version__}; one thread")
    print("| point set | method | us/pt | mislabelled | note |")
    print("|---|---|---|---|---|")
    rows: list = []
    for name, pts_list in sets.items():
        start = len(rows)
        score(name, pts_list, rows)
        for r in rows[start:]:
            print(f"| {r[0]} | {r[1]} | {r[2]:.1f} | {r[3]}/{r[4]} | {r[5]} |", flush=True)
    names = ["paper-n1-fixed", "paper-n2-fixed", "paper-n3-fixed"] if args.quick else \
        ["paper-n1-fixed", "paper-n1-free", "paper-n2-fixed", "paper-n2-free", "paper-n3-fixed", "paper-n3-free"]
    print()
    print("| example atlas | points | Sturm % | inclusion % | inertia (+ disks) % | exact % | seconds (1 thread, warm) |")
    print("|---|---|---|---|---|---|---|")
    shares = atlas_shares(names, args.quick)
    for s in shares:
        print(f"| {s[0]} | {s[1]} | {s[2]:.2f} | {s[3]:.2f} | {s[6]:.2f} | {s[4]:.2f} | {s[5]:.2f} |", flush=True)
    return {"rows": rows, "atlases": shares}


if __name__ == "__main__":
    main()
