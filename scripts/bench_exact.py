"""What the exact fallback costs a point, per degree, before and after issue 32's disks, in one run.

    python scripts/bench_exact.py            # degree 6..64 (a minute or two)
    python scripts/bench_exact.py --quick    # seconds; run once by the test suite
    python scripts/bench_exact.py --corners  # also the E -> 0 corner points the kernels leave undecided

Scattered random fixed chains (the point sets of ``bench_kernel.py``).  For each point:

- before: the exact path as it was (kept here only as the reference): the deg + 1 rational determinants of
  ``char_matrix``'s P(x), the interpolation, and FLINT/Arb's isolation of every root;
- now, the exact polynomial alone (what a point the disks leave costs before its root isolation): the
  row-cleared integer matrices (``exact.int_matrix``) and deg + 1 integer determinants;
- now, ``exact.decide_points``: inclusion disks from ball values of det A(z) (``exact_disks``), the exact
  polynomial only where they do not prove.

Both paths must give the same N_c, and both polynomials must be equal; the script stops otherwise.  Times are
CPU seconds of this process (python-flint is single-threaded), so other load on the machine matters less.
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

from stabmap.systems.gyroscopes import exact, exact_disks

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_kernel import corner_set, point_set  # noqa: E402

HEADER = ("| set | n | modes | degree | points | before: rational dets ms | before: roots ms | before: total ms "
          "| now: exact polynomial ms | now: proved by disks | now: total ms | speed-up |")


def before(*args) -> tuple[flint.fmpq_poly, int, float]:
    """(p, N_c, seconds in the root isolation) by the path before issue 32's disks."""
    P, degree = exact.char_matrix(*args)
    poly = exact._interpolate([P(flint.fmpq(i)).det() for i in range(degree + 1)])
    t = time.process_time()
    real = sum(mult for root, mult in poly.numer().complex_roots() if root.imag.is_zero())
    return poly, (poly.degree() - real) // 2, time.process_time() - t


def undecided(n: int, modes: int, rng, corner: str = "tinyE", most: int = 20):
    """(kernel args, indices): the points of a ``bench_kernel`` corner set that the kernels leave to the exact path."""
    from stabmap import kernels
    from stabmap.systems.gyroscopes.decide import kernel_args

    pts = corner_set(rng, corner, 10, 50, n, modes)
    nc = np.empty(pts.body.shape[0], np.int16)
    st = np.empty(pts.body.shape[0], np.int8)
    kernels.decide_block(*kernel_args(pts), nc, st)
    return pts.kernel_args(), np.flatnonzero(st == kernels.UNDECIDED)[:most]


def split_chain(omega: float = 40.0):
    """(kernel args, [0]): a fixed chain of 8 bodies, 4 modes each, whose 7 identical upper bodies have their joints
    at their centres of mass, so p = F_1 F_2^7 (docs/model.md): a repeated factor no disk separates."""
    from stabmap.systems.gyroscopes.points import point_arrays
    from stabmap.systems.gyroscopes.scene import from_dict

    fluid = {"E": [1e-3, 5e-4, 2e-4, 1e-4], "kappa": [1.31, 2.7, -1.9, 3.3]}
    low = {"m": 2.0, "A": 0.05, "C": 0.06, "c": 0.1, "s": 0.3, "fluid": dict(fluid, kappa=[1.5, 2.5, 3.5, -1.7])}
    upper = {"m": 1.0, "A": 0.02, "C": 0.03, "c": 0.0, "s": 0.0, "fluid": fluid}
    scene = {"support": "fixed", "g": 9.81, "omega": omega, "bodies": [low] + [dict(upper) for _ in range(7)]}
    return point_arrays(from_dict(scene), {}).kernel_args(), [0]


def run(n: int, modes: int, npts: int, rng, corner: str | None = None) -> dict:
    if corner == "split":
        args, index = split_chain()
        npts = 1
    elif corner:
        args, index = undecided(n, modes, rng, corner)
        npts = len(index)
    else:
        args, index = point_set(rng, "scattered", 1, npts, n, modes).kernel_args(), range(npts)
    body, joint, g, E, kappa, nmodes, free, parent, at = args
    t = {"before": 0.0, "roots": 0.0, "poly": 0.0, "now": 0.0}
    proved = 0
    for p in index:
        point = (body[p], joint[p], g[p], E[p], kappa[p], nmodes, free, parent, at[p])
        t0 = time.process_time()
        old, nc_old, roots = before(*point)
        t1 = time.process_time()
        nc = int(exact.decide_points(*args, [p])[0])
        t2 = time.process_time()
        new = exact.char_poly(*point)
        t3 = time.process_time()
        if nc != nc_old or new != old:
            raise AssertionError(f"the exact paths disagree at n={n}, modes={modes}, point {p}")
        coefs, _, degrees = exact.int_matrix(*point)
        proved += exact_disks.count(coefs, degrees) is not None
        t["before"] += t1 - t0
        t["roots"] += roots
        t["now"] += t2 - t1
        t["poly"] += t3 - t2
    ms = {k: 1e3 * v / max(npts, 1) for k, v in t.items()}
    return {"n": n, "modes": modes, "degree": n * (2 + modes), "points": npts, "proved": proved, "set": corner or "scattered", **ms}


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes, for the test suite")
    ap.add_argument("--corners", action="store_true",
                    help="also the points the kernels leave undecided in bench_kernel's E -> 0 corner (n = 6, 8; 3 modes) "
                         "and a split chain with a repeated factor (n = 8, 4 modes), which the disks leave")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(2026)
    ladder = [(2, 1, 2), (3, 2, 2)] if args.quick else [(2, 1, 20), (3, 2, 20), (6, 2, 10), (6, 4, 10), (8, 4, 10), (12, 3, 5), (16, 2, 3)]
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}, "
          f"python-flint {flint.__version__}")
    print(HEADER)
    print("|" + "---|" * (HEADER.count("|") - 1))
    rows = []
    ladder = [(n, modes, npts, None) for n, modes, npts in ladder]
    if args.corners:
        ladder += [(6, 3, 0, "tinyE"), (8, 3, 0, "tinyE"), (8, 4, 1, "split")]
    for n, modes, npts, corner in ladder:
        r = run(n, modes, npts, rng, corner)
        rows.append(r)
        npts = r["points"]
        if not npts:
            continue
        print(f"| {r['set']} | {n} | {modes} | {r['degree']} | {npts} | {r['before'] - r['roots']:.1f} | {r['roots']:.1f} | {r['before']:.1f} "
              f"| {r['poly']:.1f} | {r['proved']} of {npts} | {r['now']:.1f} | {r['before'] / r['now']:.1f}x |", flush=True)
    return rows


if __name__ == "__main__":
    main()
