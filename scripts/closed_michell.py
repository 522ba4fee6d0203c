"""Michell's instability of the twisted ring, discretely: the critical Gamma_c = m c2^2/c1^2 of the ring of n bodies.

    PYTHONPATH=. python scripts/closed_michell.py            # the table below and docs/figures/closed-michell.png
    PYTHONPATH=. python scripts/closed_michell.py --quick    # n = 8, 12, m = 1 only, no figure: a few seconds

The continuous twisted ring (an elastic rod closed into a circle, twisted m times) is stable iff
Gamma = m c2^2/c1^2 < sqrt 3 (Michell 1889/90; c1^2 bending, c2^2 torsional stiffness).  stabmap's ring of n
equal bodies, winding j = 1 and twist m (scene keys ``twist`` and ``c2sq``) is an equilibrium for every c2^2;
``stabmap.critical`` locates, along c2sq, every change of its class in space to 1e-10.  Each row below is one
such run on a ring scene (n, m fixed, c1^2 = 1): the scan is logarithmic in c2sq over [0.02, 2.5/m] and the
boundary it locates from stable below to unstable above gives Gamma_c = m c2sq.  Everything printed or drawn is
computed by stabmap; this script only reads its results.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

import stabmap
from stabmap.run.critical import critical

ROOT = Path(__file__).resolve().parents[1]
SQRT3 = math.sqrt(3.0)
NS = (6, 8, 10, 12, 16, 24, 32, 48, 64)
MS = (1, 2, 3)
CLASSES = {0: "stable", 1: "unstable", -1: "degenerate", -2: "absent", -3: "undecided"}


def scene(n: int, m: int, num: int = 12):
    """The ring of n equal bodies, j = 1, twist m, c1^2 = 1, scanned along c2sq (log) over [0.02, 2.5/m]."""
    return stabmap.loads_scene(
        f'system = "closed"\nfamily = "ring"\nn = {n}\nj = 1\ntwist = {m}\nc1sq = 1.0\n'
        f'[grid]\nc2sq = {{ start = 0.02, stop = {2.5 / m!r}, num = {num}, scale = "log" }}\n'
    )


def locate(n: int, m: int, num: int = 12) -> dict:
    """One row: Gamma_c of the ring (n, m), or why there is none in the scan, and the seconds it took."""
    t0, c0 = time.perf_counter(), time.process_time()
    ds = critical(scene(n, m, num), "c2sq", progress=False)
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    lower = np.atleast_1d(ds["boundary_lower"].values)
    upper = np.atleast_1d(ds["boundary_upper"].values)
    below = np.atleast_1d(ds["stability_below"].values)
    above = np.atleast_1d(ds["stability_above"].values)
    row = {"n": n, "m": m, "seconds": seconds, "cpu": cpu, "points": int(ds.attrs.get("critical_evaluated_points", 0)),
           "start": CLASSES[int(ds["stability_at_scan_start"])], "boundaries": [], "gamma_c": math.nan}
    for lo, hi, b, a in zip(lower, upper, below, above):
        if np.isfinite(lo):
            row["boundaries"].append((m * float(lo), m * float(hi), CLASSES[int(b)], CLASSES[int(a)]))
    changes = [(lo, hi) for lo, hi, b, a in row["boundaries"] if (b, a) == ("stable", "unstable")]
    if len(row["boundaries"]) == 1 and changes:
        row["gamma_c"] = 0.5 * (changes[0][0] + changes[0][1])
    return row


def table(rows: list[dict]) -> list[str]:
    out = ["| m | n | Gamma_c = m c2²/c1² | sqrt 3 - Gamma_c | n² (sqrt 3 - Gamma_c) | seconds (CPU) | points |",
           "|---|---|---|---|---|---|---|"]
    for r in rows:
        if math.isfinite(r["gamma_c"]):
            d = SQRT3 - r["gamma_c"]
            cells = f"{r['gamma_c']:.11f} | {d:.3e} | {r['n'] ** 2 * d:.4f}"
        elif r["boundaries"]:
            cells = "; ".join(f"{b} -> {a} at Gamma {0.5 * (lo + hi):.10g}" for lo, hi, b, a in r["boundaries"]) + " | - | -"
        else:
            cells = f"none: {r['start']} over the whole scan | - | -"
        out.append(f"| {r['m']} | {r['n']} | {cells} | {r['seconds']:.1f} ({r['cpu']:.1f}) | {r['points']} |")
    return out


def figure(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, err) = plt.subplots(1, 2, figsize=(10.5, 4.8), constrained_layout=True, gridspec_kw={"width_ratios": [1.35, 1]})
    markers = {1: "o", 2: "s", 3: "^"}
    colours = {1: "#0072B2", 2: "#D55E00", 3: "#009E73"}
    for m in sorted({r["m"] for r in rows}):
        pts = [(r["n"], r["gamma_c"]) for r in rows if r["m"] == m and math.isfinite(r["gamma_c"])]
        if not pts:
            continue
        n, g = np.array(pts).T
        style = dict(marker=markers.get(m, "o"), color=colours.get(m), ms=5, lw=1.2)
        ax.plot(n, g, "-", label=f"m = {m}", **style)
        below = g < SQRT3
        for part, fill in ((below, colours.get(m)), (~below, "white")):  # hollow: Gamma_c above sqrt 3
            err.plot(n[part], np.abs(SQRT3 - g[part]), ls="none", mfc=fill, **{k: v for k, v in style.items() if k != "lw"})
        err.plot(n, np.abs(SQRT3 - g), "-", color=colours.get(m), lw=0.8)
    ax.axhline(SQRT3, color="k", ls="--", lw=1)
    ax.annotate("Michell (continuum): Γ = √3", (0.02, SQRT3), xycoords=("axes fraction", "data"), xytext=(0, 4),
                textcoords="offset points", fontsize=9)
    ns = sorted({r["n"] for r in rows})
    for a in (ax, err):
        a.set_xscale("log")
        a.set_xticks(ns)
        a.set_xticklabels([str(n) for n in ns])
        a.minorticks_off()
        a.set_xlabel("number of bodies n (log scale)")
        a.grid(alpha=0.3)
    ax.set_ylabel("critical Γ_c = m c2²/c1²  (dimensionless)")
    ax.set_ylim(0, 1.95)
    ax.legend(title="twist m", loc="lower right", fontsize=9)
    ax.set_title("twisted ring of n equal bodies (j = 1): stable in space iff Γ < Γ_c(n)", fontsize=9.5)
    err.set_yscale("log")
    ref = np.array([min(ns), max(ns)], dtype=float)
    err.plot(ref, 16.0 / ref**2, ":", color="#555555", lw=1, label="16/n²")
    err.legend(fontsize=8, loc="lower left")
    err.set_ylabel("|√3 − Γ_c|  (hollow: Γ_c above √3)")
    err.set_title("distance to Michell's √3", fontsize=9.5)
    missing = [r for r in rows if not math.isfinite(r["gamma_c"])]
    if missing:
        note = "; ".join(f"n = {r['n']}, m = {r['m']}: {r['start']} at every Γ" + (" (n = 4m)" if r["n"] == 4 * r["m"] else "")
                         for r in missing)
        import textwrap

        fig.supxlabel("\n".join(textwrap.wrap(f"not drawn: {note} (scan c2²/c1² in [0.02, 2.5/m])", 170)), fontsize=7.5)
    fig.suptitle("Γ_c located by stabmap critical along c2²/c1² to 1e-10 (c1² = 1)", fontsize=9)
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main(argv: list[str] | None = None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="n = 8, 12 and m = 1 only; no figure unless --out")
    parser.add_argument("--out", type=Path, default=None, help="the figure's path (default docs/figures/closed-michell.png)")
    parser.add_argument("--n", type=int, nargs="+", default=None, help="the ring sizes (default 6 8 10 12 16 24 32 48 64)")
    parser.add_argument("--m", type=int, nargs="+", default=None, help="the twists (default 1 2 3)")
    args = parser.parse_args(argv)
    ns = args.n or ((8, 12) if args.quick else NS)
    ms = args.m or ((1,) if args.quick else MS)
    rows = []
    t0 = time.perf_counter()
    for m in ms:
        for n in ns:
            if 2 * m >= n:
                continue
            rows.append(locate(n, m, 8 if args.quick else 12))
    for line in table(rows):
        print(line)
    print(f"total {time.perf_counter() - t0:.1f} s")
    out = args.out if args.out is not None else (None if args.quick else ROOT / "docs" / "figures" / "closed-michell.png")
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        figure(rows, out)
        print(f"wrote {out}")
    return rows


if __name__ == "__main__":
    main()
