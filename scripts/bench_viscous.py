"""What the viscous liquid costs a point, how often it stays undecided, and how a float peer fares (docs/viscous.md).

    python scripts/bench_viscous.py           # n = 1, 2, 3, 4, 6; fixed and free; common and distinct spin rates
    python scripts/bench_viscous.py --quick   # n = 1, 2, a few points; run once by the test suite

Every row is a set of random chains of n bodies (seeded), each scanned along a spin rate (``omega``, or
``omega_1`` when every body spins at its own rate), each body carrying a sphere of liquid whose viscosity keeps
Re = omega a^2 / nu below 1 at the fastest spin.  The same chains are evaluated node by node
(``System.evaluate``, what an atlas runs on each chunk; growth rates on, as by default) three ways:

  dry       the bodies alone: the frozen chain, degree 2n (gyroscopes system);
  ideal     the sphere's liquid ideal: one mode per body, degree 3n (gyroscopes system);
  viscous   the liquid viscous: the frozen chain's roots and their first-order growth rates, degree 2n.

Times are CPU seconds of the process (``time.process_time``: other work on the machine moves them less than the
wall clock), the median of ``--repeat`` runs of each way in turn, so the ratios are taken within one run.

The viscous label's provenance (``decided_by``) is counted over every point.  The float peer is what a
researcher would write: numpy's eigenvalues of the companion linearisation (3n x 3n) of the full cubic matrix
polynomial

    Phi_eps(lambda) = lambda^2 M + lambda G - K - i diag(eps_k lambda^2 (lambda + omega_k)),   eps_k = rho_k P_k / nu_k,

with M, G, K built here from the model (docs/model.md; checked against the float peer's characteristic polynomial,
scripts/float_peer.py) and P = 8 pi a^7 / 525 for a sphere.  It drops the n roots of largest modulus (the spurious
ones the singular perturbation creates, |lambda| ~ A_k / eps_k) and the roots within 1e-9 of 0 in relative terms
(a free chain's neutral tilts), and calls the point unstable if any remaining root has -Im lambda > 0.  Its labels
are compared with stabmap's proved ones, and a difference is called "at a boundary" when stabmap's label changes
between that point and a neighbour along the scanned spin rate.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

from stabmap import systems
from stabmap.kernels import layout
from stabmap.scene.grid import Axis, resample
from stabmap.systems.gyroscopes import scene as scene_module
from stabmap.systems.gyroscopes.points import point_arrays
from stabmap.systems.viscous.decide import dissipation
from stabmap.systems.viscous.outputs import ASYMPTOTICALLY_STABLE, BY, UNDECIDED, UNSTABLE

sys.path.insert(0, str(Path(__file__).resolve().parent))
from float_peer import float_charpoly  # noqa: E402  (the ideal model's float peer: its p checks this peer's M, G, K)

RE_MAX = 0.8  # the largest Reynolds number of a scene, at its fastest spin
SPIN = (5.0, 150.0)  # [rad/s] the scanned spin rates
ZERO = 1e-9  # the peer's relative tolerance for a neutral lambda = 0 root


def random_scene(rng: np.random.Generator, n: int, support: str, spin: str, points: int, liquid: str, identical: bool = False):
    """One random chain of n bodies with a sphere of liquid each (``liquid``: "dry", "ideal" or "viscous"), scanned
    along omega (``spin`` = "common") or omega_1 with every other body at its own fixed rate ("distinct");
    ``identical``: one random body repeated, with one joint stiffness (exactly repeated roots)."""
    bodies = []
    seed = int(rng.integers(2**62))
    for k in range(n):
        if identical:
            rng = np.random.default_rng(seed)  # every body the same draws
        a = float(rng.uniform(0.01, 0.04))
        body = {"m": float(rng.uniform(0.5, 3.0)), "A": float(rng.uniform(0.005, 0.05)), "C": float(rng.uniform(0.002, 0.1)),
                "c": float(rng.uniform(-0.05, 0.2))}
        body["s"] = float(rng.uniform(0.1, 0.4))
        if spin == "distinct":
            body["omega"] = float(rng.choice([-1.0, 1.0]) * rng.uniform(*SPIN))
        cavity = {"shape": "spheroid", "radius": a, "half_height": a, "density": 1000.0}
        if liquid == "viscous":
            cavity["viscosity"] = SPIN[1] * a * a / RE_MAX
        if liquid != "dry":
            body["cavity"] = cavity
        bodies.append(body)
    axis = "omega" if spin == "common" else "omega_1"
    joints = [float(x) for x in rng.uniform(0.0, 200.0, n - 1)]
    if identical:
        joints = joints[:1] * (n - 1)
        bodies[-1].pop("s", None)
    table = {"support": support, "bodies": bodies, "joints": joints,
             "grid": {axis: {"start": SPIN[0], "stop": SPIN[1], "num": points}}}
    if spin == "common":
        table["omega"] = 50.0
    return scene_module.from_dict(table)


def row_scenes(seed: int, n: int, support: str, spin: str, kind: str, lines: int, points: int) -> dict[str, list]:
    """The ``lines`` random scenes of one row, the same chains for each liquid."""
    return {liquid: [random_scene(np.random.default_rng([seed, k]), n, support, spin, points, liquid, kind == "identical")
                     for k in range(lines)]
            for liquid in ("dry", "ideal", "viscous")}


def axis_values(scene) -> dict[str, np.ndarray]:
    axis: Axis = scene.grid[0]
    return {axis.name: np.asarray(axis.array, dtype=np.float64)}


def evaluate_all(scenes: list) -> list[dict]:
    return [systems.of(s).evaluate(s, axis_values(s)) for s in scenes]


def cpu_median(f, repeat: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeat):
        t0 = time.process_time()
        out = f()
        times.append(time.process_time() - t0)
    return float(np.median(times)), out


# --- the float peer -------------------------------------------------------------------------------------------------

def chain_matrices(pts) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, G, K (npts, n, n) of chains (docs/model.md, "Linearised equations") from a PointArrays."""
    body, joint, g = pts.body, pts.joint, pts.g
    npts, n = body.shape[:2]
    m, A, C, c, s, omega = (body[..., i] for i in range(6))
    J = np.zeros((npts, n, n))
    for k in range(n):
        J[:, k, k] = c[:, k]
        for i in range(k):
            J[:, k, i] = s[:, i]
    if pts.free:
        J -= (m[:, :, None] * J).sum(axis=1, keepdims=True) / m.sum(axis=1)[:, None, None]
    M = np.einsum("pki,pk,pkj->pij", J, m, J)
    M[:, range(n), range(n)] += A
    G = np.zeros((npts, n, n))
    G[:, range(n), range(n)] = C * omega
    K = np.zeros((npts, n, n))
    for k in range(1, n):
        K[:, k, k] += joint[:, k]
        K[:, k - 1, k - 1] += joint[:, k]
        K[:, k, k - 1] -= joint[:, k]
        K[:, k - 1, k] -= joint[:, k]
    if not pts.free:
        K[:, 0, 0] += joint[:, 0]
        above = np.cumsum(m[:, ::-1], axis=1)[:, ::-1]  # mass of bodies k..n-1
        a = m * c + s * np.concatenate([above[:, 1:], np.zeros((npts, 1))], axis=1)
        K[:, range(n), range(n)] -= g[:, None] * a
    return M, G, K


def check_matrices(pts) -> float:
    """Largest relative difference between det(lambda^2 M + lambda G - K) and scripts/float_peer.py's p at a few
    lambda: the peer's matrices are the model's (dry chains, no modes)."""
    coeffs = float_charpoly(pts)
    M, G, K = chain_matrices(pts)
    worst = 0.0
    for lam in (0.37, -2.9, 11.3, -41.0):
        det = np.linalg.det(lam * lam * M + lam * G - K)
        p = np.polynomial.polynomial.polyval(lam, coeffs.T)
        scale = np.polynomial.polynomial.polyval(abs(lam), np.abs(coeffs).T)
        worst = max(worst, float(np.max(np.abs(det - p) / scale)))
    return worst


def peer_roots(M, G, K, omega, eps) -> np.ndarray:
    """Every root (npts, 3n) of Phi_eps by numpy's eigenvalues of its companion linearisation."""
    npts, n = M.shape[:2]
    inv = 1j / eps  # (-i eps)^-1, the leading coefficient's inverse (diagonal)
    A2 = M - 1j * eps[:, :, None] * np.eye(n) * omega[:, :, None]
    L = np.zeros((npts, 3 * n, 3 * n), np.complex128)
    L[:, :n, n:2 * n] = np.eye(n)
    L[:, n:2 * n, 2 * n:] = np.eye(n)
    L[:, 2 * n:, :n] = -inv[:, :, None] * (-K)
    L[:, 2 * n:, n:2 * n] = -inv[:, :, None] * G
    L[:, 2 * n:, 2 * n:] = -inv[:, :, None] * A2
    return np.linalg.eigvals(L)


def peer_labels(z: np.ndarray, n: int) -> tuple[np.ndarray, float]:
    """(labels, the least ratio of a dropped spurious root's modulus to a kept root's): unstable where a kept root
    has -Im lambda > 0."""
    order = np.argsort(np.abs(z), axis=1)
    z = np.take_along_axis(z, order, axis=1)
    kept, spurious = z[:, : 2 * n], z[:, 2 * n:]
    big = np.abs(kept).max(axis=1)
    gap = float(np.min(np.abs(spurious).min(axis=1) / np.maximum(big, 1e-300)))
    neutral = np.abs(kept) <= ZERO * np.maximum(1.0, big)[:, None]
    grows = ((-kept.imag > 0) & ~neutral).any(axis=1)
    return np.where(grows, UNSTABLE, ASYMPTOTICALLY_STABLE).astype(np.int8), gap


def float_peer(scenes: list) -> tuple[list[np.ndarray], float, float]:
    """(labels per scene, CPU seconds of the peer, least spurious-root gap): inputs built outside the timing."""
    inputs = []
    for scene in scenes:
        values = axis_values(scene)
        pts = point_arrays(scene, values)
        eps, _, liquid, _ = dissipation(scene, values, pts)
        assert list(liquid) == list(range(scene.n))  # one viscous cavity on every body
        inputs.append((*chain_matrices(pts), pts.body[..., layout.OMEGA], eps, scene.n))
    t0 = time.process_time()
    out = [peer_labels(peer_roots(M, G, K, omega, eps), n) for M, G, K, omega, eps, n in inputs]
    seconds = time.process_time() - t0
    return [o[0] for o in out], seconds, min(o[1] for o in out)


def closed_form(scene, omega: np.ndarray) -> np.ndarray:
    """One body's label from the classical criteria (liquid frozen in m, A, C): on a fixed point asymptotically
    stable iff (C - A') omega^2 > m g c, A' = A + m c^2; free, iff C > A (spin about the axis of largest inertia)."""
    b = scene.bodies[0]
    if scene.support == "free":
        ok = np.full(omega.shape, b.C > b.A)
    else:
        ok = (b.C - (b.A + b.m * b.c**2)) * omega**2 > b.m * scene.g * b.c
    return np.where(ok, ASYMPTOTICALLY_STABLE, UNSTABLE)


# --- the rows -------------------------------------------------------------------------------------------------------

def run_row(seed: int, n: int, support: str, spin: str, kind: str, lines: int, points: int, repeat: int) -> dict:
    sc = row_scenes(seed, n, support, spin, kind, lines, points)
    for liquid in sc:  # load every kernel path these scenes take before the timings
        evaluate_all(sc[liquid][:1])
    seconds, outs = {}, {}
    for liquid in ("dry", "ideal", "viscous"):
        seconds[liquid], outs[liquid] = cpu_median(lambda: evaluate_all(sc[liquid]), repeat)
    npts = lines * points
    labels = [o["asymptotic_stability"] for o in outs["viscous"]]
    by = np.concatenate([o["decided_by"] for o in outs["viscous"]])
    reynolds = np.concatenate([o["reynolds"] for o in outs["viscous"]])
    peer, peer_s, gap = float_peer(sc["viscous"])
    differ = at_boundary = compared = 0
    worst = 0.0  # the largest |growth rate| (stabmap's, proved) at a point where the peer differs
    for lab, pl, o in zip(labels, peer, outs["viscous"]):
        decided = lab != UNDECIDED
        bad = decided & (lab != pl) & (lab >= 0)
        compared += int((decided & (lab >= 0)).sum())
        differ += int(bad.sum())
        change = np.zeros(lab.shape, bool)
        change[1:] |= lab[1:] != lab[:-1]
        change[:-1] |= lab[1:] != lab[:-1]
        at_boundary += int((bad & change).sum())
        if bad.any():
            worst = max(worst, float(np.nanmax(np.abs(o["growth_rate"][bad]))))
    allv = np.concatenate(labels)
    closed = None
    if n == 1:  # the classical criteria, independent of stabmap's code
        closed = sum(int(((lab != closed_form(s, axis_values(s)["omega" if spin == "common" else "omega_1"])) & (lab != UNDECIDED)).sum())
                     for lab, s in zip(labels, sc["viscous"]))
    return {
        "n": n, "support": support, "spin": spin, "kind": kind, "points": npts, "degree_viscous": 2 * n, "degree_ideal": 3 * n,
        "us": {k: 1e6 * v / npts for k, v in seconds.items()},
        "x_dry": seconds["viscous"] / seconds["dry"], "x_ideal": seconds["viscous"] / seconds["ideal"],
        "stable_pct": 100.0 * float((allv == ASYMPTOTICALLY_STABLE).mean()),
        "undecided": int((allv == UNDECIDED).sum()),
        "by": {name: int((by == code).sum()) for name, code in BY.items()},
        "re_max": float(reynolds.max()),
        "peer_us": 1e6 * peer_s / npts, "peer_differ": differ, "peer_at_boundary": at_boundary, "compared": compared,
        "peer_worst_rate": worst,
        "spurious_gap": gap, "closed_form_differ": closed,
    }


def atlas_rows(quick: bool, repeat: int) -> list[dict]:
    """The whole atlas of docs/figures/viscous-vs-ideal.png, ideal and viscous, one thread, cell by cell as by
    default: the ideal atlas proves boxes and skips nodes inside them; the viscous one computes every node."""
    import stabmap
    from viscous_figure import scenes

    out = []
    for liquid, scene in zip(("ideal", "viscous"), scenes(quick)):
        stabmap.compute_atlas(resample(scene, omega=3, C_1=3), progress=False, threads=1)  # load the kernels
        seconds, ds = cpu_median(lambda: stabmap.compute_atlas(scene, progress=False, threads=1), repeat)
        label = systems.of(scene).label
        whole = 100.0 * float((ds["cell"] == ds["cell"].attrs["flag_values"][list(ds["cell"].attrs["flag_meanings"].split()).index("whole_cell")]).mean())
        out.append({"liquid": liquid, "points": int(ds[label].size), "label": label, "seconds": seconds,
                    "us": 1e6 * seconds / ds[label].size, "whole_cell_pct": whole})
    for r in out:
        r["x_ideal"] = r["seconds"] / out[0]["seconds"]
    return out


def cases(quick: bool) -> list[tuple[int, str, str, str, int, int]]:
    """(n, support, spin, kind, scenes, points per scene) of every row: random chains, then identical bodies."""
    ns, lines, points = ((1, 2), 2, 12) if quick else ((1, 2, 3, 4, 6), 8, 100)
    rows = [(n, support, spin, "random", lines, points) for n in ns for support in ("fixed", "free") for spin in ("common", "distinct")]
    return rows + [(n, support, "common", "identical", lines, points) for n in ns[1:3] for support in ("fixed", "free")]


HEADER = ("| n | support | spin | bodies | points | dry us/pt (deg 2n) | ideal us/pt (deg 3n) | viscous us/pt (deg 2n) | x dry | x ideal "
          "| asympt. stable % | undecided | decided by | float peer us/pt | peer differs (at a boundary) | where: largest abs. rate [1/s] | closed form differs | largest Re |")
BY_SHORT = {"frozen_chain_unstable": "frozen", "first_order_balls": "balls", "first_order_arb": "arb",
            "multiple_root": "multiple", "zero_rate": "zero rate", "zero_root": "zero root", "degenerate": "degenerate"}


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="n = 1, 2, 2 scenes of 12 points a row, one run")
    parser.add_argument("--repeat", type=int, default=5, help="runs of each way; the median CPU time is kept (default 5)")
    parser.add_argument("--seed", type=int, default=31)
    args = parser.parse_args(argv)
    repeat = 1 if args.quick else args.repeat
    probe = point_arrays(random_scene(np.random.default_rng(args.seed), 3, "fixed", "distinct", 5, "dry"),
                         {"omega_1": np.linspace(*SPIN, 5)})
    mismatch = check_matrices(probe)
    if mismatch > 1e-10:
        raise AssertionError(f"the peer's M, G, K do not give the model's p (relative difference {mismatch:.2g})")
    print(f"# machine: {platform.machine()}, {os.cpu_count()} cores, {platform.python_implementation()} {platform.python_version()}; "
          f"one thread; CPU seconds, median of {repeat}; seed {args.seed}; the peer's M, G, K reproduce p to {mismatch:.1g}")
    print(HEADER)
    print("|" + "---|" * (HEADER.count("|") - 1))
    rows = []
    for n, support, spin, kind, lines, points in cases(args.quick):
        r = run_row(args.seed, n, support, spin, kind, lines, points, repeat)
        rows.append(r)
        by = ", ".join(f"{BY_SHORT.get(k, k)} {v}" for k, v in r["by"].items() if v)
        print(f"| {n} | {support} | {spin} | {kind} | {r['points']} | {r['us']['dry']:.1f} | {r['us']['ideal']:.1f} | {r['us']['viscous']:.1f} "
              f"| {r['x_dry']:.2f} | {r['x_ideal']:.2f} | {r['stable_pct']:.0f} | {r['undecided']} | {by} | {r['peer_us']:.1f} "
              f"| {r['peer_differ']} of {r['compared']} ({r['peer_at_boundary']}) | {r['peer_worst_rate']:.1g} | {'-' if r['closed_form_differ'] is None else r['closed_form_differ']} | {r['re_max']:.2f} |", flush=True)
    atlas = atlas_rows(args.quick, repeat)
    print()
    print("| whole atlas (the figure's heavy top) | points | label | seconds | us/pt | x ideal | cells proved whole % |")
    print("|---|---|---|---|---|---|---|")
    for r in atlas:
        print(f"| {r['liquid']} | {r['points']} | {r['label']} | {r['seconds']:.2f} | {r['us']:.1f} | {r['x_ideal']:.2f} | {r['whole_cell_pct']:.1f} |")
    total = sum(r["points"] for r in rows)
    shares = {name: 100.0 * sum(r["by"][name] for r in rows) / total for name in BY}
    print(f"all {total} points: undecided {100.0 * sum(r['undecided'] for r in rows) / total:.2f} %; decided by "
          + ", ".join(f"{name} {v:.2f} %" for name, v in shares.items() if v)
          + f"; the peer's dropped roots are at least {min(r['spurious_gap'] for r in rows):.2g} times the largest kept one")
    return {"rows": rows, "atlas": atlas}


if __name__ == "__main__":
    main()
