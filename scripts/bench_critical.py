"""Critical values: what box proofs between scan values cost and prove, against node bisection alone, in one run.

    python scripts/bench_critical.py            # the narrow-window case (tests/systems.py's WINDOW) and four bundled scenes (about a minute)
    python scripts/bench_critical.py --quick    # two small scenes; seconds; run once by the test suite

Each scene runs ``stabmap.critical`` along omega three ways, on all cores, kernels loaded before any timing:
  points only  box proofs switched off: changes searched for only between scan values whose labels differ,
               every other scan step an undecided gap (what critical values were before box proofs);
  plain boxes  box proofs on the coefficients enclosed over the box (no nodes);
  boxes at nodes  the default: boxes along omega in the spin-scaled model, along one mechanical axis at 2n + 1
               nodes (docs/certification.md, section 6).
Columns: compute seconds, midpoints decided, box proofs tried and proved, boundaries located, undecided gaps
and their total width.  The ways must agree on every boundary they all find.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from contextlib import contextmanager
from unittest import mock

import numpy as np

import stabmap
from stabmap.scene.grid import resample
from stabmap.systems.gyroscopes import boxes

# The narrow-window case (WINDOW in tests/systems.py): a stable window 0.108 rad/s wide near omega = 12 between scan values 1 rad/s apart
REGIONS = """
title = "two tops with small liquid modes: a narrow stable window"
support = "fixed"
g = 9.81
joints = [10.0]
[[bodies]]
m = 1.0
A = 0.02
C = 0.06
c = 0.1
s = 0.2
fluid = { E = [5e-4], kappa = [-2.5] }
[[bodies]]
m = 1.0
A = 0.05
C = 0.06
c = 0.05
fluid = { E = [5e-4], kappa = [4.5] }
[grid]
omega = { start = 0.5, stop = 99.5, num = 100 }
"""
FULL = ["paper-n1-fixed", "paper-n2-fixed", "paper-n3-fixed", "paper-n2-free"]
QUICK = {"paper-n2-fixed": {"omega": 60, "K_1": 20}}
WAYS = ("points only", "plain boxes", "boxes at nodes")


@contextmanager
def _way(way: str):
    """Switch box proofs off (points only) or their nodes off (plain boxes) for this process's threads."""
    if way == "points only":
        with mock.patch.object(type(stabmap.systems.of(stabmap.example("paper-n1-fixed"))), "box_axes", lambda self, scene: set()):
            yield
    elif way == "plain boxes":
        with mock.patch.object(boxes, "spin_rows", lambda *args: np.zeros(0, dtype=np.int64)), \
             mock.patch.object(boxes, "is_mechanical", lambda scene, key: False):
            yield
    else:
        yield


def scenes(quick: bool) -> list[tuple[str, object]]:
    out = [("narrow-window case", stabmap.loads_scene(REGIONS))]
    for name in (QUICK if quick else FULL):
        scene = stabmap.example(name)
        out.append((name, resample(scene, **QUICK[name]) if quick else scene))
    return out


def run(name: str, scene) -> list[dict]:
    rows, found = [], {}
    for way in WAYS:
        with _way(way):
            t0 = time.perf_counter()
            ds = stabmap.critical(scene, "omega", progress=False)
            seconds = time.perf_counter() - t0
        n = ds["n_undecided"].values.ravel()
        lo, hi = ds["undecided_lower"].values.reshape(n.size, -1), ds["undecided_upper"].values.reshape(n.size, -1)
        b = ds["boundary_lower"].values
        found[way] = np.sort(b[np.isfinite(b)])
        rows.append({
            "scene": name, "way": way, "points": int(ds.attrs["critical_scan_points"]) * n.size, "seconds": seconds,
            "midpoints": int(ds.attrs["critical_evaluated_points"]) - int(ds.attrs["critical_scan_points"]) * n.size,
            "box_proofs": int(ds.attrs["critical_box_proofs"]), "proved": int(ds.attrs["critical_boxes_proved"]),
            "boundaries": int(np.isfinite(b).sum()), "gaps": int(n.sum()), "gap_width": float(np.nansum(hi - lo)),
        })
    # every boundary node bisection finds, the box proofs find too (box proofs only add the hidden ones)
    for way in WAYS[1:]:
        assert np.all(np.isin(np.round(found["points only"], 6), np.round(found[way], 6))), (name, way)
    return rows


HEADER = "| scene | way | scan points | compute s | midpoints | box proofs (proved) | boundaries | undecided gaps (total width) |"


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two small scenes, for the test suite")
    args = ap.parse_args(argv)
    print(f"# machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, python {platform.python_version()}")
    warm = scenes(True)[0][1]
    for way in WAYS:
        with _way(way):
            stabmap.critical(resample(warm, omega=5), "omega", progress=False)  # load the kernels outside the timings
    print(HEADER)
    print("|" + "---|" * (HEADER.count("|") - 1))
    rows = []
    for name, scene in scenes(args.quick):
        for r in run(name, scene):
            rows.append(r)
            print(f"| {r['scene']} | {r['way']} | {r['points']:,} | {r['seconds']:.2f} | {r['midpoints']:,} | "
                  f"{r['box_proofs']:,} ({r['proved']:,}) | {r['boundaries']} | {r['gaps']:,} ({r['gap_width']:.3g}) |", flush=True)
    return {"rows": rows}


if __name__ == "__main__":
    main()
