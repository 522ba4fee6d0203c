"""Quick runs of the scripts behind docs/closed.md's figures in space (scripts/closed_michell.py,
scripts/closed_figures.py), so they cannot rot; their values checked against independent ones."""

from __future__ import annotations

import math
import pathlib
import runpy

SCRIPTS = pathlib.Path(__file__).resolve().parents[1] / "scripts"

# The discrete critical Gamma_c = m c2^2/c1^2 of the twisted ring (j = 1, m = 1), computed independently of stabmap
# (tests/closed_space_reference.py, critical_gamma: the Fourier blocks of its own spatial model, mpmath)
GAMMA_C = {8: 1.37930440271, 12: 1.60746281115}


def test_michell_quick(capsys, tmp_path):
    """--quick: n = 8, 12, m = 1, located by stabmap critical; Gamma_c matches, grows with n, stays below sqrt 3."""
    main = runpy.run_path(str(SCRIPTS / "closed_michell.py"))["main"]
    rows = main(["--quick", "--out", str(tmp_path / "michell.png")])
    assert [(r["n"], r["m"]) for r in rows] == [(8, 1), (12, 1)]
    for r in rows:
        assert [b[2:] for b in r["boundaries"]] == [("stable", "unstable")] and r["start"] == "stable"
        assert abs(r["gamma_c"] - GAMMA_C[r["n"]]) < 1e-8
    gammas = [r["gamma_c"] for r in rows]
    assert gammas == sorted(gammas) and gammas[-1] < math.sqrt(3)
    out = capsys.readouterr().out
    assert "| m | n | Gamma_c" in out and "1.607462811" in out
    assert (tmp_path / "michell.png").stat().st_size > 10_000


def test_space_figure_small(tmp_path):
    """closed_figures.space_figure on a small grid: the hinge's boundary in c2^2/c1^2 is r^2 (5 + 2 r)/4."""
    ns = runpy.run_path(str(SCRIPTS / "closed_figures.py"))
    lines = ns["space_figure"](tmp_path / "hinge.png", "hinge", (0.2, 2.6), (0.05, 20.0), 2**0.5, ("stable", "unstable"),
                               (0.5, 1.0), log_x=True, num=(6, 4), curve=(lambda r: r * r * (5 + 2 * r) / 4, "r² (5 + 2r)/4"))
    assert lines[0].startswith("hinge, ratio 0.5: unstable -> stable at c2²/c1² = 0.375 ")
    assert lines[1].startswith("hinge, ratio 1: unstable -> stable at c2²/c1² = 1.75 ")
    assert "undecided" not in lines[-1] and (tmp_path / "hinge.png").stat().st_size > 10_000
    assert abs(ns["HINGE_SPACE"] - 0.7807764064) < 1e-10
