"""Benchmark scripts run once in quick mode so they cannot rot (no timing is asserted)."""

from __future__ import annotations

import runpy
import pathlib

SCRIPTS = pathlib.Path(__file__).resolve().parents[1] / "scripts"


def test_bench_kernel_quick(capsys):
    rows = runpy.run_path(str(SCRIPTS / "bench_kernel.py"))["main"](["--quick"])
    assert [r["degree"] for r in rows] == [2, 6, 12]
    assert all(r["undecided_pct"] <= 100 for r in rows)
    assert "| n | modes |" in capsys.readouterr().out
