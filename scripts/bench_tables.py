"""Time the tables of a critical-values file (stabmap.read.table) as its number of lines grows.

A critical-values file of ``paper-n1-fixed-dry`` (omega x c_1) is computed once and tiled along a made-up second
axis, so that the tables see 200, 40 000 and 1 000 000 lines (points of the other axes) without hours of proofs:
the tables read only the stored arrays. Each table is timed once, after a warm-up on the untiled file.

    python scripts/bench_tables.py            # about a minute and 2 GiB at 1 M lines
    python scripts/bench_tables.py --quick    # a coarse file, 5 and 50 lines (the test suite runs it)
"""

from __future__ import annotations

import argparse
import dataclasses
import platform
import time

import numpy as np


def _base(quick: bool):
    import stabmap
    from stabmap.scene.grid import Axis

    scene = stabmap.example("paper-n1-fixed-dry")
    if quick:
        scene = dataclasses.replace(scene, grid=(Axis("omega", tuple(np.linspace(1.0, 60.0, 13))), Axis("c_1", (0.02, 0.1, 0.15, 0.2, 0.3))))
    return stabmap.critical(scene, "omega", progress=False)


def main(argv: list[str] | None = None) -> list[dict]:
    from stabmap.read.table import critical_summary, critical_table, intervals_frame, render_table

    args = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args.add_argument("--quick", action="store_true", help="a coarse file and few lines (a smoke test)")
    opts = args.parse_args(argv)
    base = _base(opts.quick)
    tables = {
        "to_dataframe": intervals_frame,
        "critical_table": critical_table,
        "summary": critical_summary,
        "csv": lambda ds: render_table(ds, "csv"),
        "text (40 rows)": lambda ds: render_table(ds, "text"),
    }
    for f in tables.values():  # warm-up: imports and pandas' first calls
        f(base)
    rows = []
    for tiles in ((1, 10) if opts.quick else (1, 200, 5000)):
        ds = base.expand_dims(K_9=np.arange(tiles, dtype=np.float64)).copy(deep=True)
        ds["K_9"].attrs["units"] = "N m rad-1"
        row = {"lines": ds.sizes["K_9"] * ds.sizes["c_1"]}
        for name, f in tables.items():
            t = time.perf_counter()
            out = f(ds)
            row[name] = time.perf_counter() - t
            if name == "csv":
                row["csv_rows"], row["csv_mb"] = out.count("\n"), len(out) / 1e6
        rows.append(row)
    print(f"machine: {platform.machine()}, python {platform.python_version()}")
    print("| lines | " + " | ".join(f"{k} s" for k in tables) + " | CSV rows | CSV MB |")
    print("|---" * (len(tables) + 3) + "|")
    for r in rows:
        print(f"| {r['lines']:,} | " + " | ".join(f"{r[k]:.3f}" for k in tables) + f" | {r['csv_rows']:,} | {r['csv_mb']:.1f} |")
    return rows


if __name__ == "__main__":
    main()
