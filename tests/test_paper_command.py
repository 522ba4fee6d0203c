"""``stabmap paper``: the papers' checks as a command of the installed tool (stabmap/paper/)."""

from __future__ import annotations

import pytest

from stabmap import paper as papers
from stabmap import systems
from stabmap.cli import main
from stabmap.errors import StabmapError
from stabmap.systems.gyroscopes import paper
from stabmap.paper import gyroscopes as paper_cases

PNG = b"\x89PNG\r\n\x1a\n"


def test_closed_and_reactions_agree_with_their_papers_and_draw(tmp_path, capsys):
    assert main(["paper", "closed", "reactions", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "| closed-hinge | 3 | 3 |" in out and "| closed-figure-eight-6 | 2 | 2 |" in out
    assert "24.525 = G/4, 4" in out and "all agree with the papers" in out
    # in space, in words: the hinge leaves its plane at (sqrt 17 - 1)/4 (docs/closed.md), the paper's rings
    assert "- hinge: stable for h2/h1 in [0.05, 0.7807764064]; unstable for h2/h1 in [0.7807764064, 2]" in out
    assert "plane ring (27), j = 1, equal bodies: stable in space for n = 5, 6," in out
    assert "twisted ring (26), one turn of twist (m = 1), equal bodies: stable in space for n = 7, 8," in out
    for name in ("closed/closed-hinge", "closed/closed-figure-eight-6", "reactions/reactions-square-plate"):
        assert (tmp_path / f"{name}.png").read_bytes()[:8] == PNG


def test_gyroscope_cases_quick_with_figures(tmp_path, capsys):
    cases = ["paper-n1-fixed-dry", "paper-n1-free", "paper-n3-fixed-split"]
    argv = ["paper", "gyroscopes", "--quick", "--out", str(tmp_path)]
    assert main([*argv, *[a for c in cases for a in ("--case", c)]]) == 0
    out = capsys.readouterr().out
    for c in cases:
        assert f"| {c} |" in out
        assert (tmp_path / "gyroscopes" / f"{c}.png").read_bytes()[:8] == PNG
    assert "| 0 |\n" in out and "DISAGREES" not in out


def test_with_no_system_named_every_paper_is_checked(tmp_path, monkeypatch):
    """``stabmap paper`` alone runs all four checks, figures in one folder each, and gathers their disagreements.
    The checks themselves run elsewhere once each: every gyroscope case quick with its figure in
    tests/test_paper_cases.py, closed and reactions above, viscous quick in tests/test_viscous.py."""
    import importlib

    calls = {}
    for name in systems.names():
        def run(out=None, quick=False, _name=name):  # the options a check takes are read off its signature
            calls[_name] = {"out": out, "quick": quick}
            return {"problems": [f"{_name} disagrees"] if _name == "reactions" else [], "text": f"the {_name} table"}

        monkeypatch.setattr(importlib.import_module(systems.get(name).paper), "run", run)
    done = papers.check(out=tmp_path, quick=True)
    assert set(calls) == {"gyroscopes", "closed", "reactions", "viscous"}
    assert {name: kwargs["out"] for name, kwargs in calls.items()} == {name: tmp_path / name for name in calls}
    assert calls["gyroscopes"]["quick"] and calls["viscous"]["quick"]
    assert done["problems"] == ["reactions disagrees"]
    assert all(f"## {name}\nthe {name} table" in done["text"] for name in calls)


def test_a_window_narrower_than_the_scan_step_is_found_by_rescanning_that_step(capsys):
    # With 2 rows the split case checks c_1 = 0.1133, whose stable window (48.905, 49.337) lies inside one
    # scan step of the 60-value quick scan.  The split chain's repeated factors defeat the box proofs, so critical
    # values stop halving there and list the step as undecided; a fine scan of that step must find both ends.
    assert main(["paper", "gyroscopes", "--quick", "--rows", "2", "--case", "paper-n3-fixed-split"]) == 0
    out = capsys.readouterr().out
    assert "DISAGREES" not in out and "| 2 | 2 | 4, " in out  # 2 boundaries seen by the scan, 4 matched in all
    assert "NOTE: paper-n3-fixed-split: c_1 = 0.113333: a window narrower than the scan step" in out
    assert "48.90473524" in out and "49.33733592" in out


def test_a_closed_form_window_the_engine_does_not_find_is_a_disagreement(monkeypatch, capsys):
    real = paper_cases.closed_form_along

    def with_a_false_window(scene, case, row):  # a stable window the true polynomial does not have
        return sorted([*real(scene, case, row), (150.2, 1, 0), (150.3, 0, 1)])

    monkeypatch.setattr(paper_cases, "closed_form_along", with_a_false_window)
    assert main(["paper", "gyroscopes", "--quick", "--rows", "1", "--case", "paper-n1-fixed-dry"]) == 1
    out = capsys.readouterr().out
    assert "DISAGREES: paper-n1-fixed-dry" in out and "inside the scan step" in out and "a 65-value scan of it finds []" in out


def test_a_wrong_closed_form_exits_1(monkeypatch, capsys):
    original = paper.F_polynomial
    monkeypatch.setattr(paper, "F_polynomial", lambda A_prime, *args: original(A_prime * paper.q(1.01), *args))
    assert main(["paper", "gyroscopes", "--quick", "--rows", "2", "--case", "paper-n1-fixed-1mode"]) == 1
    captured = capsys.readouterr()
    assert "DISAGREES: paper-n1-fixed-1mode" in captured.out and "disagreements with the papers" in captured.err


def test_a_wrong_reaction_exits_1(monkeypatch, capsys):
    from stabmap.paper import reactions as plate

    monkeypatch.setattr(plate, "RTOL", -1.0)  # nothing can agree to a negative tolerance: the check must say so
    assert main(["paper", "reactions"]) == 1
    assert "DISAGREES: reactions-square-plate" in capsys.readouterr().out


@pytest.mark.parametrize("argv, message", [
    (["paper", "tops"], "no paper check for system 'tops'"),
    (["paper", "gyroscopes", "--case", "paper-n9"], "unknown paper case 'paper-n9' (--case)"),
    (["paper", "--rows", "0"], "--rows 0: must be >= 1"),
    (["paper", "closed", "--case", "paper-n1-free"], "--case applies to the paper check of gyroscopes, not to closed"),
])
def test_bad_arguments_are_one_line_and_exit_2(argv, message, capsys):
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_bad_arguments_from_python_name_the_parameters():
    with pytest.raises(StabmapError, match=r"rows=0: must be >= 1"):
        papers.check(["gyroscopes"], rows=0)
    with pytest.raises(StabmapError, match=r"cases applies to the paper check of gyroscopes, not to closed"):
        papers.check(["closed"], cases=["paper-n1-free"])


def test_a_system_without_a_paper_check_says_so(monkeypatch):
    # the check is found through the registry: a system whose paper is None has none, and runs no other's
    from stabmap import systems

    monkeypatch.setattr(systems.get("reactions"), "paper", None)
    with pytest.raises(StabmapError, match="no paper check for system 'reactions': it declares none"):
        papers.check(["reactions"])


def test_the_command_is_listed():
    from click.testing import CliRunner

    from stabmap.cli import cli

    result = CliRunner().invoke(cli, ["--help"])
    assert "paper" in result.output and "Recompute the source papers" in result.output
