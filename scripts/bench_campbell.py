"""The Campbell diagram of a three-body chain (paper-n3-fixed, degree 12) over many spin rates: what each step costs.

    python scripts/bench_campbell.py            # 2000 spin rates
    python scripts/bench_campbell.py --quick    # 200; run once by the test suite

Steps, wall seconds on both cores (the minimum of ``--repeat`` runs, after one run that compiles):
- the atlas with labels only (``growth_rate = false``), the default atlas (growth rates), and the atlas with
  ``frequencies = true`` (every root enclosed, modes followed along omega), each written to a netCDF file;
- following the modes alone (``tracking.follow_modes`` on the stored roots);
- ``stabmap plot ATLAS --campbell -o c.png`` and ``-o c.html`` (the CLI's whole work in this process: read, draw,
  write).
It prints the links followed and ambiguous, and the critical speeds found.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import stabmap
from stabmap.cli import main as cli
from stabmap.scene.grid import Axis
from stabmap.systems.gyroscopes.tracking import AMBIGUOUS, FOLLOWED, follow_modes


def best(f, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="200 spin rates, one run each")
    ap.add_argument("--num", type=int, help="spin rates (default 2000; 200 with --quick)")
    ap.add_argument("--repeat", type=int, help="runs per step, the minimum kept (default 3; 1 with --quick)")
    args = ap.parse_args(argv)
    num = args.num or (200 if args.quick else 2000)
    repeat = args.repeat or (1 if args.quick else 3)
    base = stabmap.example("paper-n3-fixed")
    base = base.with_grid((Axis("omega", tuple(np.linspace(1.0, 200.0, num)), display_units="rpm"),))
    scenes = {"labels": dataclasses.replace(base, growth_rate=False), "default": base,
              "frequencies": dataclasses.replace(base, frequencies=True)}
    out: dict = {"num": num}
    with tempfile.TemporaryDirectory() as tmp:
        paths = {k: Path(tmp) / f"{k}.nc" for k in scenes}

        def atlas(k: str):
            paths[k].unlink(missing_ok=True)
            stabmap.compute_to_file(scenes[k], paths[k], progress=False)

        for k in scenes:
            atlas(k)  # compiles what it needs, outside the timing
            out[f"{k}_s"] = best(lambda k=k: atlas(k), repeat)
        ds = stabmap.open_atlas(paths["frequencies"])
        f, r, kind = (ds[n].values for n in ("frequency", "frequency_radius", "root_kind"))
        out["follow_s"] = best(lambda: follow_modes(ds.omega.values, np.sort(f, axis=1), r, kind), repeat)
        track = ds.mode_tracking.values[1:]
        out["followed"], out["ambiguous"] = int((track == FOLLOWED).sum()), int((track == AMBIGUOUS).sum())
        for ext in ("png", "html"):
            target = Path(tmp) / f"c.{ext}"
            out[f"plot_{ext}_s"] = best(lambda target=target: cli(["plot", str(paths["frequencies"]), "--campbell", "-o",
                                                                  str(target), "--overwrite"]), repeat)
            out[f"{ext}_kB"] = target.stat().st_size / 1e3
    print(f"# {platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"paper-n3-fixed over {num} spin rates; wall s, min of {repeat}")
    print(f"atlas: labels {out['labels_s']:.2f}, default (rates) {out['default_s']:.2f}, frequencies {out['frequencies_s']:.2f} "
          f"({out['frequencies_s'] / out['labels_s']:.1f}x labels)")
    print(f"following the modes: {out['follow_s']:.3f} s; links followed {out['followed']:,}, ambiguous {out['ambiguous']:,}")
    print(f"stabmap plot --campbell: png {out['plot_png_s']:.2f} s ({out['png_kB']:.0f} kB), "
          f"html {out['plot_html_s']:.2f} s ({out['html_kB']:.0f} kB)")
    return out


if __name__ == "__main__":
    main(sys.argv[1:])
