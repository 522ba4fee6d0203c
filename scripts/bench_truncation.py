"""Liquid-mode truncation: run time against error for cylinder cavities, with and without the lumped tail.

    python scripts/bench_truncation.py                 # N = 1..32, two scenes (about 10 minutes on 2 cores)
    python scripts/bench_truncation.py --quick         # N = 1, 2, 4 on small grids; seconds; run by the test suite
    python scripts/bench_truncation.py --plot docs/figures/truncation.png

Each scene is a top on a fixed point carrying a cylinder of water, with the cavity's half height
scanned (aspect ratio h/a). For every number of kept modes N, with the tail lumped into A and without,
and for modes = "auto" (the default: the fewest modes whose tail is at most 1e-2 of A, docs/cavities.md):
- the critical spin rate (the lower end of the first stable interval along omega, bracketed to
  1e-10 by ``stabmap.critical``) at every aspect ratio, against the reference;
- the share of atlas points (omega x aspect ratio) whose label differs from the reference atlas;
- the time to compute that atlas (all cores, kernels warm, modes found afresh) and the share decided
  in exact arithmetic.
The reference is the largest N with the tail (32; 8 in quick mode); the table also shows how far
the next smaller N is from it, as evidence that it has converged.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import numpy as np

from stabmap import loads_scene
from stabmap.run import atlas
from stabmap.systems.gyroscopes import liquid, scene
from stabmap.run.critical import critical
from stabmap.systems.gyroscopes.outputs import BY_EXACT

SCENE = """
title = "{title}"
support = "fixed"
g = 9.81
[[bodies]]
m = 3.0
A = 0.05
C = {C}
c = 0.2
cavity = {{ shape = "cylinder", radius = {a}, half_height = {a}, density = 1000.0, modes = {N}, tail = {tail} }}
[grid]
omega = {{ start = {w0}, stop = {w1}, num = {nw} }}
half_height_1 = {{ start = {h0}, stop = {h1}, num = {nh} }}
"""
SCENES = {  # name: (C, omega range, cavity radius); C/A' sets which cavity mode the nutation meets
    "slender top, C = 0.02": (0.02, (60.0, 200.0), 0.05),
    "squat top, C = 0.08": (0.08, (10.0, 60.0), 0.05),
    "slender top, small cavity a = 3 cm": (0.02, (60.0, 200.0), 0.03),
}
AUTO = "auto"
FULL = dict(modes=(1, 2, 4, 8, 16, 32), nw=80, nh=24)
QUICK = dict(modes=(1, 2, 4, 8), nw=24, nh=6)


def make(name: str, N: int | str, tail: bool, nw: int, nh: int) -> scene.Scene:
    C, (w0, w1), a = SCENES[name]
    modes = f'"{N}"' if N == AUTO else N
    text = SCENE.format(title=name, C=C, N=modes, tail="true" if tail else "false", w0=w0, w1=w1, nw=nw, nh=nh, a=a, h0=a / 4, h1=2 * a)
    return loads_scene(text)


def critical_spin(s: scene.Scene) -> np.ndarray:
    """Lower end of the first stable omega interval per aspect ratio (NaN: never stable in range)."""
    ds = critical(s, along="omega", progress=False)
    lower = ds["omega_stable_lower"]
    return lower.isel({d: 0 for d in lower.dims if d != "half_height_1"}).values


def run(name: str, N: int | str, tail: bool, nw: int, nh: int) -> dict:
    s = make(name, N, tail, nw, nh)
    cav = s.bodies[0].cavity
    liquid.forget_modes()  # every run pays for finding its modes, as a user's first run does
    t0 = time.perf_counter()
    ds = atlas.compute(s, progress=False)
    seconds = time.perf_counter() - t0
    return {
        "scene": name, "N": N, "kept": int(s.nmodes[0]), "tail_over_A": cav.tail_over_A, "tail": tail, "seconds": seconds,
        "exact_pct": 100.0 * float((ds.decided_by.values == BY_EXACT).mean()),
        "nc": ds.n_complex_pairs.values, "critical": critical_spin(s),
        "aspect": 2 * s.grid[1].array / cav.radius,
    }


def compare(row: dict, ref: dict) -> dict:
    err = np.abs(row["critical"] - ref["critical"]) / ref["critical"]
    err = np.where(np.isnan(row["critical"]) & np.isnan(ref["critical"]), 0.0, err)
    return {
        **row,
        "max_err": float(np.nanmax(np.where(np.isnan(err), np.inf, err))),
        "median_err": float(np.median(np.where(np.isnan(err), np.inf, err))),
        "off_1pct": int((~(err <= 0.01)).sum()),
        "mislabelled_pct": 100.0 * float((row["nc"] != ref["nc"]).mean()),
    }


def plot(rows: list[dict], refs: dict, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(refs)
    fig, axes = plt.subplots(1, len(names) + 1, figsize=(5.2 * (len(names) + 1), 4.4))
    for ax, name in zip(axes, names):
        ref = refs[name]
        ax.plot(ref["aspect"], ref["critical"], "k-", lw=2.5, alpha=0.35, label=f"reference N = {ref['N']} + tail")
        for r in rows:
            if r["scene"] == name and r["N"] in (1, 4) and r is not ref:
                ax.plot(r["aspect"], r["critical"], "-" if r["tail"] else "--", marker=".", label=f"N = {r['N']}{' + tail' if r['tail'] else ''}")
        ax.set(xlabel="cavity aspect ratio h/a", ylabel="critical spin rate [rad/s]", title=name)
        ax.legend(fontsize=7)
    ax = axes[-1]
    for name, marker in zip(names, "os"):
        for tail, colour in ((True, "C0"), (False, "C3")):
            sel = [r for r in rows if r["scene"] == name and r["tail"] == tail and r["N"] not in (refs[name]["N"], AUTO)]
            ax.loglog([r["seconds"] for r in sel], [max(r["max_err"], 1e-12) for r in sel], marker=marker, color=colour,
                      label=f"{name}, {'with' if tail else 'without'} tail")
            for r in sel:
                ax.annotate(str(r["N"]), (r["seconds"], max(r["max_err"], 1e-12)), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set(xlabel="time per atlas [s]", ylabel="max relative error of the critical spin", title="run time against error (labels: N)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small grids, N = 1, 2, 4 against N = 8")
    parser.add_argument("--plot", metavar="PNG", help="write the figure here")
    args = parser.parse_args(argv)
    if args.plot and not os.path.isdir(os.path.dirname(os.path.abspath(args.plot))):
        parser.error(f"--plot: the folder of {args.plot!r} does not exist")
    cfg = QUICK if args.quick else FULL
    names = list(SCENES)[:1] if args.quick else list(SCENES)
    atlas.compute(make(names[0], 1, True, 4, 2), progress=False)  # compile or load the kernels first
    rows, autos, refs = [], [], {}
    for name in names:
        ref = run(name, cfg["modes"][-1], True, cfg["nw"], cfg["nh"])
        refs[name] = ref
        for N in cfg["modes"]:
            for tail in (True, False):
                r = ref if (N, tail) == (ref["N"], True) else run(name, N, tail, cfg["nw"], cfg["nh"])
                rows.append(compare(r, ref))
                print(f"  {name}: N = {N:2d} tail = {tail!s:5}  {r['seconds']:.2f} s", file=sys.stderr)
        r = run(name, AUTO, True, cfg["nw"], cfg["nh"])
        autos.append(compare(r, ref))
        print(f"  {name}: N = auto ({r['kept']}) tail = True  {r['seconds']:.2f} s", file=sys.stderr)
    base = {name: next(r["seconds"] for r in rows if r["scene"] == name and r["N"] == 1 and r["tail"]) for name in names}
    print(f"`python scripts/bench_truncation.py{' --quick' if args.quick else ''}` on {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} cores; grid {cfg['nw']} omega x {cfg['nh']} aspect ratios (h/a 0.5 .. 4); reference N = {cfg['modes'][-1]} + tail\n")
    print("| scene | N | tail | critical spin: max rel. error | median | aspects off by > 1 % | labels differing | time per atlas (x N=1) | exact | tail / A |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in sorted(rows + autos, key=lambda r: list(SCENES).index(r["scene"])):
        n = f"auto: {r['kept']}" if r["N"] == AUTO else str(r["N"])
        print(f"| {r['scene']} | {n} | {'yes' if r['tail'] else 'no'} | {r['max_err']:.1e} | {r['median_err']:.1e} | "
              f"{r['off_1pct']} / {len(r['critical'])} | {r['mislabelled_pct']:.2f} % | {r['seconds']:.2f} s ({r['seconds'] / base[r['scene']]:.1f}x) | {r['exact_pct']:.0f} % | {r['tail_over_A']:.1e} |")
    if args.plot:
        plot(rows, refs, args.plot)
        print(f"\nwrote {args.plot}")
    strip = lambda r: {k: v for k, v in r.items() if k not in ("nc", "critical", "aspect")}  # noqa: E731
    return {"rows": [strip(r) for r in rows], "auto": [strip(r) for r in autos]}


if __name__ == "__main__":
    main()
