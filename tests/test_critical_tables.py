"""Tables of critical-values files (stabmap.read.table): rows against Maievskii's closed form, in exact rationals.

A dry top on a fixed point is stable exactly when C^2 w^2 >= 4 (A + m c^2) m c g (for gyroscopes: N_c = 0 there,
N_c = 1 below). Every row of every table (the DataFrame, the CSV, the JSON, the text of `info`) is checked against
that inequality evaluated in exact rationals on the binary values of the numbers the table holds, so nothing here
compares stabmap with itself.
"""

from __future__ import annotations

import csv
import io
import json
from fractions import Fraction

import numpy as np
import pytest
import xarray as xr

import stabmap
from stabmap.cli import main
from stabmap.read.info import intervals
from stabmap.read.table import critical_table, render_table
from stabmap.systems.gyroscopes.scene import from_dict
from scenes import maievskii_stable, maievskii_w2, top_system

SCAN = (-60.0, 60.0)
C1 = [-0.1, 0.1, 1.0]  # hanging (stable everywhere), an ordinary top, one whose critical rate lies beyond the scan
M1 = [0.5, 2.0]


def _expected_intervals(c: float, m: float) -> int:
    """How many stable intervals [-60, 60] holds: 1 (stable throughout), 2 (|w| >= w*) or 0 (w* beyond 60)."""
    w2 = maievskii_w2(c, m)
    return 1 if w2 <= 0 else 2 if w2 <= Fraction(SCAN[1]) ** 2 else 0


@pytest.fixture(scope="module")
def crit():
    scene = from_dict(top_system({"omega": {"start": SCAN[0], "stop": SCAN[1], "num": 25}, "c_1": {"values": C1}, "m_1": {"values": M1}}))
    return stabmap.critical(scene, "omega", rtol=1e-10)


@pytest.fixture(scope="module")
def crit_file(crit, tmp_path_factory):
    return stabmap.write_atlas(crit, tmp_path_factory.mktemp("crit") / "crit.nc")


def _check_interval(c, m, lower, upper, lower_outer, upper_outer, from_start, to_end):
    """One stable interval against the closed form: its ends stable, the outer values unstable, within the tolerance."""
    assert maievskii_stable(lower, c, m) and maievskii_stable(upper, c, m)
    assert from_start == (lower == SCAN[0]) and to_end == (upper == SCAN[1])
    for end, outer in ((lower, lower_outer), (upper, upper_outer)):
        if end in SCAN:
            assert np.isnan(outer)
        else:
            assert not maievskii_stable(outer, c, m) and 0 < abs(end - outer) <= 1e-10 * max(abs(end), abs(outer))


def test_to_dataframe_has_one_row_per_interval_of_the_closed_form(crit):
    frame = crit.stabmap.to_dataframe()
    assert list(frame.columns) == ["c_1", "m_1", "interval", "omega_stable_lower", "omega_stable_upper", "omega_stable_lower_outer",
                                   "omega_stable_upper_outer", "from_scan_start", "to_scan_end", "proved_throughout"]
    assert frame.attrs["units"]["omega_stable_lower"] == "rad s-1" and frame.attrs["units"]["m_1"] == "kg"
    for c in C1:
        for m in M1:
            rows = frame[(frame.c_1 == c) & (frame.m_1 == m)]
            assert len(rows) == _expected_intervals(c, m), (c, m)
            assert list(rows.interval) == list(range(len(rows)))
            for r in rows.itertuples():
                _check_interval(c, m, r.omega_stable_lower, r.omega_stable_upper, r.omega_stable_lower_outer,
                                r.omega_stable_upper_outer, r.from_scan_start, r.to_scan_end)
                assert r.proved_throughout  # box proofs leave no gap for a dry top
            if len(rows) == 2:  # [-60, -w*] and [w*, 60]
                assert rows.omega_stable_lower.iloc[0] == SCAN[0] and rows.omega_stable_upper.iloc[1] == SCAN[1]


def test_summary_of_critical_values_and_of_an_atlas(crit):
    s = crit.stabmap.summary()
    expected = {(c, m): _expected_intervals(c, m) for c in C1 for m in M1}
    assert s["lines"] == 6 and s["stable_intervals"] == sum(expected.values())
    assert s["n_stable_intervals"] == {n: list(expected.values()).count(n) for n in set(expected.values())}
    assert s["undecided_gaps"] == 0 and s["intervals_with_gap_inside"] == 0
    # the stable length of each line: 120 (hanging), 2 (60 - w*), or 0, to the tolerance of the located ends
    for (c, m), n in expected.items():
        length = 120.0 if n == 1 else 2 * (60 - float(maievskii_w2(c, m)) ** 0.5) if n == 2 else 0.0
        assert float(s["per_line"]["stable_length"].sel(c_1=c, m_1=m)) == pytest.approx(length, abs=1e-7)
        assert int(s["per_line"]["n_boundaries"].sel(c_1=c, m_1=m)) == (2 if n == 2 else 0)
    assert s["stable_length"] == pytest.approx(float(s["per_line"]["stable_length"].sum()))
    assert s["smallest_stable"]["value"] == SCAN[0] and s["smallest_stable"]["outer"] is None
    # an atlas of the same scene: its summary counts its grid points, stable by the closed form
    atlas = stabmap.compute_atlas(from_dict(top_system({"omega": {"start": -60.0, "stop": 60.0, "num": 13}, "c_1": {"values": C1}})))
    a = atlas.stabmap.summary()
    omegas, cs = atlas["omega"].values, atlas["c_1"].values
    assert a["points"] == 39 and a["stable"] == sum(maievskii_stable(float(w), float(c), 1.0) for w in omegas for c in cs)


def test_misuse_names_the_fix(crit):
    atlas = stabmap.compute_atlas(from_dict(top_system({"omega": {"values": [1.0, 50.0]}})))
    with pytest.raises(stabmap.StabmapError, match=r"this Dataset is an atlas: ask it with ds.stabmap.boundaries"):
        atlas.stabmap.to_dataframe()
    with pytest.raises(stabmap.StabmapError, match=r"not a stabmap atlas or critical-values file .*stabmap.open_atlas"):
        xr.Dataset({"x": ("a", [1, 2])}).stabmap.summary()
    # plain to_dataframe crosses the padded dimensions: the accessor's table is the one with a row per interval
    assert len(crit.to_dataframe()) > len(crit.stabmap.to_dataframe())


def _run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def _check_csv_rows(rows: list[dict]):
    """Every row of the CSV against the closed form: intervals, boundaries (labels on both sides), lines with none."""
    kinds = {}
    for r in rows:
        c, m = float(r["c_1 [m]"]), float(r["m_1 [kg]"])
        kinds.setdefault((c, m), []).append(r["row"])
        num = {k: float(r[f"omega_{k} [rad s-1]"]) if r[f"omega_{k} [rad s-1]"] else np.nan for k in ("lower", "upper", "lower_outer", "upper_outer")}
        if r["row"] == "stable_interval":
            _check_interval(c, m, num["lower"], num["upper"], num["lower_outer"], num["upper_outer"],
                            r["from_scan_start"] == "True", r["to_scan_end"] == "True")
            assert r["proved_throughout"] == "True" and r["n_complex_pairs_below"] == ""
        elif r["row"] == "boundary":
            below, above = int(r["n_complex_pairs_below"]), int(r["n_complex_pairs_above"])
            assert {below, above} == {0, 1}
            assert maievskii_stable(num["lower"], c, m) == (below == 0) and maievskii_stable(num["upper"], c, m) == (above == 0)
            assert 0 < num["upper"] - num["lower"] <= 1e-10 * max(abs(num["lower"]), abs(num["upper"]))
            assert r["from_scan_start"] == "" and r["omega_lower_outer [rad s-1]"] == ""
        else:
            assert r["row"] == "no_stable_interval" and _expected_intervals(c, m) == 0
    for c in C1:
        for m in M1:
            n = _expected_intervals(c, m)
            want = {1: ["stable_interval"], 2: ["stable_interval", "boundary", "boundary", "stable_interval"], 0: ["no_stable_interval"]}[n]
            assert kinds[(c, m)] == want, (c, m)  # in order along omega


def test_query_csv_json_and_output_file(crit_file, capsys, tmp_path):
    code, out, err = _run(capsys, "query", crit_file, "--csv")
    assert code == 0 and err == ""
    reader = csv.DictReader(io.StringIO(out))
    assert reader.fieldnames[:4] == ["row", "c_1 [m]", "m_1 [kg]", "omega_lower [rad s-1]"]
    rows = list(reader)
    _check_csv_rows(rows)
    assert len(rows) == 4 * 2 + 2 * 1 + 2 * 1  # two lines of each of the three tops
    # -o writes the same text, atomically (no temporary left), and refuses to replace a file without --overwrite
    target = tmp_path / "crit.csv"
    assert _run(capsys, "query", crit_file, "--csv", "-o", target)[:2] == (0, f"wrote {target}\n")
    assert target.read_text() == out and sorted(p.name for p in tmp_path.iterdir()) == ["crit.csv"]
    code, out2, err = _run(capsys, "query", crit_file, "--csv", "-o", target)
    assert code == 2 and "already exists; add --overwrite" in err
    assert _run(capsys, "query", crit_file, "--csv", "-o", target, "--overwrite")[0] == 0
    # JSON: the same rows, NaN as null, units apart
    code, out, _ = _run(capsys, "query", crit_file, "--json")
    doc = json.loads(out)
    assert doc["along"] == "omega" and doc["units"]["omega_lower"] == "rad s-1" and len(doc["rows"]) == len(rows)
    for js, cs in zip(doc["rows"], rows):
        assert js["row"] == cs["row"] and js["omega_lower"] == (float(cs["omega_lower [rad s-1]"]) if cs["omega_lower [rad s-1]"] else None)
    # the file, opened lazily as the CLI opens it, has the same summary as the Dataset in memory
    with stabmap.open_atlas(crit_file, lazy=True) as ds:
        s = ds.stabmap.summary()
        assert (s["stable_intervals"], s["boundaries"], s["lines"]) == (6, 4, 6)
    # a selection of lines: the nearest grid value, every row of that line
    code, out, _ = _run(capsys, "query", crit_file, "--csv", "c_1=0.09", "m_1=0:1")
    picked = list(csv.DictReader(io.StringIO(out)))
    assert {(r["c_1 [m]"], r["m_1 [kg]"]) for r in picked} == {("0.1", "0.5")} and len(picked) == 4


def test_query_text_limit(crit_file, capsys):
    code, out, _ = _run(capsys, "query", crit_file, "--limit", "3")
    lines = out.splitlines()
    assert lines[0].startswith("critical values along omega [rad s-1]: 6 stable intervals and 4 boundaries on 6 lines of c_1, m_1")
    assert lines[1].split()[:3] == ["c_1", "[m]", "m_1"] and len(lines) == 1 + 1 + 3 + 2
    assert "... and 9 more rows (--limit 0 shows all" in out
    code, out, _ = _run(capsys, "query", crit_file, "--limit", "0")
    body = out.splitlines()[2:-1]
    assert len(body) == 12 and "more rows" not in out
    assert sum("no stable interval" in line for line in body) == 2
    code, _, err = _run(capsys, "query", crit_file, "--boundaries", "omega")
    assert code == 2 and "holds critical values, not an atlas" in err
    code, _, err = _run(capsys, "query", crit_file, "omega=3")
    assert code == 2 and "select the lines by their other axes: c_1, m_1" in err


def test_info_all_and_limit(crit_file, crit, capsys):
    def listed(out):
        return [line for line in out.splitlines() if line.startswith("c_1 = ")]

    code, out, _ = _run(capsys, "info", crit_file, "--limit", "2")
    assert code == 0 and len(listed(out)) == 2 and "... and 4 more points in the file (--all or --limit 0" in out
    for args in (["--all"], ["--limit", "0"]):
        code, out, _ = _run(capsys, "info", crit_file, *args)
        shown = listed(out)
        assert code == 0 and len(shown) == 6 and "more points" not in out
        for line in shown:  # "c_1 = 0.1, m_1 = 0.5: stable omega [rad s-1] -60 (scan start) to -7.38... (boundary); ..."
            where, _, text = line.partition(": stable omega [rad s-1] ")
            c, m = (float(part.split(" = ")[1].split()[0]) for part in where.split(", "))
            n = _expected_intervals(c, m)
            assert (text == "nowhere in the scan") == (n == 0)
            if n:
                ends = [float(e.split(" (")[0]) for piece in text.split("; ") for e in piece.split(" to ")]
                # printed to 10 digits: each end is a scan end or +-w* to that precision
                w = float(maievskii_w2(c, m)) ** 0.5 if n == 2 else None
                assert len(ends) == 2 * n and all(e in SCAN or abs(abs(e) - w) <= 1e-9 * w for e in ends)
    assert "6 stable intervals and 4 boundaries on 6 lines" in out
    code, _, err = _run(capsys, "info", crit_file, "--limit", "-1")
    assert code == 2 and "--limit -1: must be >= 0" in err
    with pytest.raises(stabmap.StabmapError, match=r"^limit=-1: must be >= 0"):  # the same check from Python
        intervals(crit, limit=-1)


def test_closed_chain_critical_table():
    # The twisted ring of twelve bodies: stable while m c2^2 / c1^2 < Gamma_c(12), computed independently of stabmap
    # (tests/test_closed_figures_space.py); closed chains prove points only, so every stretch between is a gap.
    crit = stabmap.critical(stabmap.example("closed-ring-twisted"), "c2sq", threads=1)
    table = critical_table(crit)
    assert list(table["row"]) == ["stable_interval", "undecided_gap", "boundary", "undecided_gap"]
    b = table[table.row == "boundary"].iloc[0]
    assert b.c2sq_lower < 1.60746281115 * (1 + 1e-9) and b.c2sq_upper > 1.60746281115 * (1 - 1e-9)
    assert (b.stability_below, b.stability_above) == ("stable", "unstable")
    iv = crit.stabmap.to_dataframe()
    assert len(iv) == 1 and not iv.proved_throughout[0] and iv.from_scan_start[0] and iv.c2sq_stable_upper[0] == b.c2sq_lower
    s = crit.stabmap.summary()
    assert s["lines"] == 1 and s["undecided_gaps"] == 2 and s["intervals_with_gap_inside"] == 1 and s["stable_length_proved"] == 0
    text = render_table(crit)
    assert "not proved stable inside its gaps" in text and "class stable -> unstable" in text


def test_closed_chain_csv_along_the_length_ratio(tmp_path, capsys):
    # The hinge against h2/h1 (docs/closed.md): stable below sqrt 2, unstable up to 2, degenerate at 2, no
    # equilibrium above. The CSV names each side of every boundary by its class.
    scene = tmp_path / "hinge.toml"
    scene.write_text('system = "closed"\nmodel = "planar"\nfamily = "hinge"\nc1sq = 2.0\n'
                     '[grid]\nratio = { start = 0.5, stop = 2.5, num = 41 }\n')
    out = tmp_path / "c.nc"
    assert main(["critical", str(scene), "--along", "ratio", "-o", str(out), "-q", "--threads", "1"]) == 0
    capsys.readouterr()
    code, text, _ = _run(capsys, "query", out, "--csv")
    rows = list(csv.DictReader(io.StringIO(text)))
    assert code == 0 and "ratio_lower" in rows[0]  # a dimensionless axis: no units in its header
    changes = [(float(r["ratio_lower"]), float(r["ratio_upper"]), r["stability_below"], r["stability_above"])
               for r in rows if r["row"] == "boundary"]
    assert [c[2:] for c in changes] == [("stable", "unstable"), ("unstable", "degenerate"), ("degenerate", "absent")]
    (lo, hi, *_), *rest = changes
    assert lo < 2 ** 0.5 <= hi and hi - lo <= 1e-10 * hi
    assert all(a <= 2.0 <= b for a, b, *_ in rest)
    stable = [r for r in rows if r["row"] == "stable_interval"]
    assert len(stable) == 1 and stable[0]["from_scan_start"] == "True" and stable[0]["proved_throughout"] == "False"
    assert [r["row"] for r in rows].count("undecided_gap") >= 2  # points only: every stretch between is a gap, and said


def test_query_output_file_for_an_atlas_question(tmp_path, capsys):
    atlas = stabmap.compute_atlas(from_dict(top_system({"omega": {"start": 1.0, "stop": 60.0, "num": 12}})))
    path = stabmap.write_atlas(atlas, tmp_path / "a.nc")
    code, printed, _ = _run(capsys, "query", path, "--fraction", "--csv")
    target = tmp_path / "f.csv"
    assert code == 0 and _run(capsys, "query", path, "--fraction", "--csv", "-o", target)[:2] == (0, f"wrote {target}\n")
    assert target.read_text() == printed
    row = next(csv.DictReader(io.StringIO(printed)))
    assert int(row["stable"]) == sum(maievskii_stable(float(w), 0.1, 1.0) for w in atlas["omega"].values)
