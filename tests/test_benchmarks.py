"""Benchmark scripts run once in quick mode so they cannot rot (no timing is asserted)."""

from __future__ import annotations

import pytest

import runpy
import pathlib

SCRIPTS = pathlib.Path(__file__).resolve().parents[1] / "scripts"


def test_bench_kernel_quick(capsys):
    rows = runpy.run_path(str(SCRIPTS / "bench_kernel.py"))["main"](["--quick"])
    corners = runpy.run_path(str(SCRIPTS / "bench_kernel.py"))["CORNERS"]
    assert [(r["degree"], r["kind"]) for r in rows] == [(d, k) for d in (2, 6, 12) for k in ("mixed", "identical")] + [
        (12, c) for c in corners] + [(24, "mixed")]
    for r in rows:
        assert r["pts_per_s_1"] > 0 and r["peer_us"] > 0
        assert abs(sum(r["shares"].values()) - 100) < 1e-9
        assert 0 <= r["peer_wrong"] <= r["compared"] == r["points"]
    assert "| n | modes |" in capsys.readouterr().out


def test_bench_krein_quick(capsys):
    rows = runpy.run_path(str(SCRIPTS / "bench_krein.py"))["main"](["--quick"])
    assert rows and all(r["points"] > 0 for r in rows)
    for r in rows:
        # separators only where the count falls short: never more than between every two near-real approximations
        assert r["coarse"]["separators"] <= r["fine"]["separators"] <= r["poles"]["separators"]
    assert "coarse / fine / poles" in capsys.readouterr().out
    timed = runpy.run_path(str(SCRIPTS / "bench_krein.py"))["main"](["--quick", "--labels"])
    assert timed and timed[0]["us"] > 0


def test_bench_kreinbox_atlas_quick(capsys):
    rows = runpy.run_path(str(SCRIPTS / "bench_kreinbox.py"))["main"](["--atlas", "--quick"])
    assert rows  # the script checks that both ways give the same labels
    assert all(r["whole_pct"]["krein"] >= 0.0 for r in rows)
    assert "Krein first / without" in capsys.readouterr().out


def test_bench_kernel_density_quick():
    """The same chain at two spacings: only the number of points along the line changes."""
    rows = runpy.run_path(str(SCRIPTS / "bench_kernel.py"))["main"](["--density", "--quick"])
    assert [(r["degree"], r["points"]) for r in rows] == [(12, 8), (12, 16)]
    for r in rows:
        assert r["peer_us"] > 0 and r["peer_wrong"] <= r["compared"] == r["points"]


@pytest.mark.slow
def test_bench_atlas_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_atlas.py"))["main"](["--quick"])
    assert out["cold_cached_s"] > 0
    assert [r["points"] for r in out["growth"]] == [64, 256, 64, 256]
    assert "| scene | degree |" in capsys.readouterr().out


def test_bench_refine_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_refine.py"))["main"](["--quick"])
    rows = {(r["scene"], r["margin"]): r for r in out["rows"]}
    assert set(rows) == {(s, m) for s in ("paper-n1-fixed", "paper-n2-fixed") for m in (0, 1, 2)}
    # Margin 1 (the default) equals the dense atlas on both scenes, with several times fewer evaluations.
    assert all(rows[(s, 1)]["equal"] and rows[(s, 1)]["ratio"] > 3 for s in ("paper-n1-fixed", "paper-n2-fixed"))
    assert "| scene | degree | grid |" in capsys.readouterr().out


def test_bench_accuracy_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_accuracy.py"))["main"](["--quick"])
    rows = {(r[0], r[1]): r for r in out["rows"]}
    # The certified path with its fallback is never wrong; the table must contain the baselines it beats.
    for point_set in ("random-12", "random-24", "boundary", "repeated"):
        assert rows[(point_set, "stabmap certified + exact fallback")][3] == 0
        assert (point_set, "numpy.roots, tol 1e-10") in rows
    assert [a[0] for a in out["atlases"]] == ["paper-n1-fixed", "paper-n2-fixed", "paper-n3-fixed"]
    assert "| point set | method |" in capsys.readouterr().out


def test_bench_conditioning_quick(capsys):
    rows = runpy.run_path(str(SCRIPTS / "bench_conditioning.py"))["main"](["--quick"])
    for r in rows:
        exact, blur15, blur13 = r["shares"]
        assert 0 <= blur13 <= blur15 <= exact <= 1  # wider enclosures can only decide fewer points
    assert "| n | modes | degree |" in capsys.readouterr().out


def test_bench_truncation_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_truncation.py"))["main"](["--quick"])
    rows = {(r["N"], r["tail"]): r for r in out["rows"]}
    assert set(rows) == {(N, t) for N in (1, 2, 4, 8) for t in (True, False)}
    assert rows[(8, True)]["max_err"] == 0.0  # the reference against itself
    # The lumped tail never makes the answer worse, and 4 modes with it are within 1 % everywhere.  (Since critical
    # values prove every scan step, they see an unstable band 100.29-101.09 rad/s at N = 4 and 8 that the scan
    # missed, and the onset at the largest aspect ratio is 1.1e-3 off at N = 4 against 9.0e-4 at N = 1: more modes
    # are not better at every aspect ratio, so that is no longer asserted.)
    assert all(rows[(N, True)]["max_err"] <= rows[(N, False)]["max_err"] for N in (1, 2, 4))
    assert rows[(4, True)]["off_1pct"] == 0
    assert "| scene | N | tail |" in capsys.readouterr().out


@pytest.mark.slow
def test_bench_cluster_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_cluster.py"))["main"](["--quick"])
    assert [(r["where"], r["n"]) for r in out["scaling"]] == [("threads", 1), ("threads", 2), ("local cluster", 1), ("local cluster", 2)]
    assert [r["tasks"] for r in out["overhead"]] == [2, 10, 40] * 2  # chunks long along omega, the fastest axis
    assert [(r["points"], r["how"]) for r in out["memory"]] == [(40000, "streamed"), (40000, "in-memory"), (160000, "write-only")]
    assert all(r["peak_mib"] > 0 for r in out["memory"])
    assert "| where | threads or workers |" in capsys.readouterr().out


def test_bench_exact_quick(capsys):
    rows = runpy.run_path(str(SCRIPTS / "bench_exact.py"))["main"](["--quick"])
    assert [r["degree"] for r in rows] == [6, 12]
    assert all(r["before"] >= r["roots"] > 0 and r["now"] > 0 and r["poly"] > 0 for r in rows)
    assert all(r["proved"] == r["points"] for r in rows)  # these random chains are all proved by the disks
    assert "| n | modes | degree |" in capsys.readouterr().out


def test_bench_read_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_read.py"))["main"](["--quick"])
    assert [(r["format"], r["command"]) for r in out["rows"]] == [
        (f, c) for f in ("nc", "zarr") for c in ("info", "query --boundaries omega", "plot")
    ]
    assert all(r["points"] == 1_000_000 and r["peak_mib"] >= r["startup_mib"] > 0 for r in out["rows"])
    assert "| format | points | command |" in capsys.readouterr().out


def test_bench_progress_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_progress.py"))["main"](["--quick"])
    assert [r["code"] for r in out["first"]] == ["this"] and out["first"][0]["run s"] > 0
    assert "| scene | code | first line s |" in capsys.readouterr().out


def test_bench_critical_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_critical.py"))["main"](["--quick"])
    rows = {(r["scene"], r["way"]): r for r in out["rows"]}
    window = "narrow-window case"
    # node bisection alone misses the window between two scan values; the box proofs at nodes find it
    # (three boundaries) and leave no gap; the plain enclosure proves none of the scan steps there, and stops
    assert rows[(window, "points only")]["boundaries"] == 1 and rows[(window, "points only")]["box_proofs"] == 0
    assert rows[(window, "boxes at nodes")]["boundaries"] == 3 and rows[(window, "boxes at nodes")]["gaps"] == 0
    assert rows[(window, "plain boxes")]["proved"] < rows[(window, "boxes at nodes")]["proved"]
    assert rows[("paper-n2-fixed", "boxes at nodes")]["gaps"] == 0
    assert "| scene | way |" in capsys.readouterr().out


def test_bench_cells_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_cells.py"))["main"](["--quick"])
    # compare() checks that cells and node by node give every node one label; each row's classes tile the grid
    for r in out["ladder"]:
        assert abs(sum(r["shares"].values()) - 1.0) < 1e-12 and r["shares"]["not_proved"] == 0.0
        assert r["node_proofs_per_cell"] > 0 and r["box_proofs_per_cell"] > 0
    # the stress scene: no boundary in a whole cell, and every whole cell's label holds inside it, exactly
    (stress,) = out["stress"]
    assert stress["boundaries"] >= 3 and stress["false_whole"] == 0 and stress["wrong_interior"] == 0 and stress["checked"] > 0
    assert "| scene | degree | points |" in capsys.readouterr().out


def test_bench_tables_quick(capsys):
    rows = runpy.run_path(str(SCRIPTS / "bench_tables.py"))["main"](["--quick"])
    # tiling the file ten times gives ten times the lines and the CSV rows (an interval and a boundary per line)
    assert [r["lines"] for r in rows] == [5, 50] and [r["csv_rows"] for r in rows] == [10, 100]
    assert "| lines | to_dataframe s |" in capsys.readouterr().out


def test_bench_rates_quick(capsys):
    rows = runpy.run_path(str(SCRIPTS / "bench_rates.py"))["main"](["--quick"])
    assert [(r["scene"], r["cells"], r["way"]) for r in rows] == [
        (s, c, w) for s in ("paper-n1-fixed", "paper-n2-fixed", "paper-n3-fixed") for c in (True, False) for w in ("plain", "growth", "frequencies")]
    for r in rows:  # the rate variables add 17 bytes a point to the plain atlas's 5, the frequencies 18 per root
        assert r["bytes"] == r["points"] * (5 + 17 * (r["way"] != "plain") + 18 * r["degree"] * (r["way"] == "frequencies"))
    assert "| scene | degree | points |" in capsys.readouterr().out


def test_bench_viscous_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_viscous.py"))["main"](["--quick"])
    rows = out["rows"]
    assert [(a["liquid"], a["label"]) for a in out["atlas"]] == [("ideal", "n_complex_pairs"), ("viscous", "asymptotic_stability")]
    assert [(r["n"], r["support"], r["spin"], r["kind"]) for r in rows] == [
        (n, s, w, "random") for n in (1, 2) for s in ("fixed", "free") for w in ("common", "distinct")] + [
        (2, s, "common", "identical") for s in ("fixed", "free")]
    for r in rows:
        assert sum(r["by"].values()) == r["points"] > 0  # every point decided by one named way
        assert r["undecided"] == sum(r["by"][k] for k in ("multiple_root", "zero_rate", "zero_root"))
        assert all(r["us"][k] > 0 for k in ("dry", "ideal", "viscous")) and r["peer_us"] > 0
        # every disagreement with the float peer is in the table, and none of stabmap's proved labels is compared twice
        assert 0 <= r["peer_at_boundary"] <= r["peer_differ"] <= r["compared"] == r["points"] - r["undecided"] - r["by"]["degenerate"]
        assert r["spurious_gap"] > 100  # the dropped roots are the spurious large ones, far from the physical
        assert r["re_max"] < 1
        if r["n"] == 1:  # one body: the classical criteria (C - A') omega^2 > m g c on a point, C > A free
            assert r["closed_form_differ"] == 0
    assert "| n | support | spin |" in capsys.readouterr().out


def test_viscous_figure_quick(tmp_path, capsys):
    out = runpy.run_path(str(SCRIPTS / "viscous_figure.py"))["main"](["--quick", "--out", str(tmp_path)])
    assert out["path"].is_file()
    # the curves drawn on the figure are the maps' boundaries: Maievskii's for the ideal liquid, (C - A') omega^2 > m g c
    assert out["ideal_off_closed_form"] == 0 and out["viscous_off_closed_form"] == 0
    assert out["lost"] > 0 and out["undecided"] == 0 and out["re_max"] < 1


def test_bench_onetop_quick():
    rows = runpy.run_path(str(SCRIPTS / "bench_onetop.py"))["main"](quick=True)
    assert len(rows) == 5
    for row in rows[2:]:
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[2] == "1000" and cells[-1] == "0"  # every random top proved by the filter or the kernels


def test_bench_allatonce_quick(capsys):
    rows = runpy.run_path(str(SCRIPTS / "bench_allatonce.py"), run_name="bench")["main"](["--quick"])
    assert len(rows) == 1 and rows[0]["points"] == 8
    assert rows[0]["us"]["peer"] > 0 and rows[0]["decided_pct"] > 0
    assert "| n | modes | degree |" in capsys.readouterr().out


def test_bench_allatonce_lines_quick():
    """--lines: the certificate alone on a small line set; a line's first point is a cold start."""
    rows = runpy.run_path(str(SCRIPTS / "bench_allatonce.py"), run_name="bench")["main"](["--lines", "12:0:mixed:6"])
    assert [(r["spec"], r["points"]) for r in rows] == [("12:0:mixed:6", 12)]
    assert 2 <= rows[0]["cold"] <= 12 and rows[0]["ratio"] > 0


def test_bench_rate_price_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_rate_price.py"))["main"](["--quick"])
    assert [r["scene"] for r in out["scenes"]][0] == "paper-n3-fixed" and out["ladder"]
    for r in out["scenes"] + out["ladder"]:
        assert r["width"] <= 1e-6  # every rate enclosed to the documented width, whatever the path
        assert sum(r["methods"].values()) == r["unstable"]
    for r in out["ladder"]:  # numpy's eigenvalues, an independent float solver, inside the proved bounds
        assert r["peer_outside"] == 0, r
    assert "growth_rate = false s" in capsys.readouterr().out


def test_bench_campbell_quick(capsys):
    out = runpy.run_path(str(SCRIPTS / "bench_campbell.py"))["main"](["--quick"])
    assert out["num"] == 200 and out["plot_png_s"] > 0 and out["png_kB"] > 0
    assert out["followed"] + out["ambiguous"] > 0
    assert "stabmap plot --campbell" in capsys.readouterr().out


def test_bench_readme_ways_quick(capsys):
    rows = runpy.run_path(str(SCRIPTS / "bench_readme_ways.py"))["main"](["--quick"])
    assert [r["grid"] for r in rows] == ["24 x 12 x 3"]
    assert all(r[k] > 0 for r in rows for k in ("default", "node-by-node", "plain"))
    assert "`--node-by-node` s" in capsys.readouterr().out
