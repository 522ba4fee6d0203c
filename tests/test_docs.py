"""Every command, scene and Python example in README.md and docs/*.md runs: a doc that drifts from the code fails.

Each document is one test. Its fenced ```bash, ```toml and ```python blocks run in order in one temporary
directory, so a document's walkthrough chains: a scene written by one block is used by the commands of the next.

- ``bash``: the block runs with ``bash -e``; ``stabmap`` on PATH is this checkout (``python -m stabmap``),
  ``scripts/`` is linked into the directory.
- ``toml``: the block is a whole scene and is loaded with ``stabmap.loads_scene`` (the scene's own check).
- ``python``: the block is run in one namespace per document; a block of ``>>>`` lines is run as a doctest.

A block is changed by an HTML comment on the line just before its fence, which the rendered page does not show:

- ``<!-- doc-test: file NAME -->`` (toml): also write the scene to NAME for the blocks after it;
- ``<!-- doc-test: fragment -->`` (toml): a part of a scene shown alone; only its TOML syntax is checked;
- ``<!-- doc-test: no-install -->`` (bash): drop ``pip install ... &&`` prefixes (the tests run in the installed
  environment, which a test must not replace) and lines running the test suite itself;
- ``<!-- doc-test: slow -->``: run only in the slow variant of the document's test;
- ``<!-- doc-test: skip: REASON -->``: not run, for the reason given (e.g. it needs a running dask cluster).
"""

from __future__ import annotations

import doctest
import dataclasses
import os
import re
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^(?:<!-- doc-test: (?P<mark>.*?) -->\n)?```(?P<lang>bash|toml|python)\n(?P<body>.*?)^```", re.M | re.S)
# Pages another change edits at the same time; each is skipped, saying why, until its blocks are marked.
PENDING: dict[str, str] = {}  # page name -> why it cannot run yet
MARKS = re.compile(r"^(file \S+|fragment|no-install|slow|skip: .+)$")


@dataclass(frozen=True)
class Block:
    doc: str
    line: int
    lang: str
    body: str
    mark: str

    def where(self) -> str:
        return f"{self.doc}:{self.line} ({self.lang})"


def blocks(path: Path) -> list[Block]:
    text = path.read_text(encoding="utf-8")
    found = []
    for m in FENCE.finditer(text):
        mark = m.group("mark") or ""
        line = text.count("\n", 0, m.start("body"))
        assert not mark or MARKS.match(mark), f"{path.name}:{line}: unknown doc-test mark {mark!r}"
        found.append(Block(path.relative_to(ROOT).as_posix(), line, m.group("lang"), m.group("body"), mark))
    if path.name == "README.md" and found and not found[0].mark:
        # The README must open with its two commands, no comment before them: its first block is run as no-install.
        found[0] = dataclasses.replace(found[0], mark="no-install")
    return found


def _shim(directory: Path) -> dict:
    """An environment whose ``stabmap`` and ``python`` run this checkout."""
    bin_dir = directory / ".bin"
    bin_dir.mkdir()
    stabmap = bin_dir / "stabmap"
    stabmap.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m stabmap "$@"\n')
    stabmap.chmod(0o755)
    python = bin_dir / "python"
    python.symlink_to(sys.executable)
    env = dict(os.environ)
    env["PATH"] = f"{bin_dir}{os.pathsep}{env['PATH']}"
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    env["MPLBACKEND"] = "Agg"
    return env


def _bash(block: Block, cwd: Path, env: dict) -> None:
    body = block.body
    if block.mark == "no-install":
        lines = [re.sub(r"^pip install \S+ && ", "", line) for line in body.splitlines()]
        body = "\n".join(line for line in lines if not re.match(r"\s*python -m pytest\b", line))
    done = subprocess.run(["bash", "-e", "-c", body], cwd=cwd, env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, f"{block.where()} failed (exit {done.returncode}):\n{body}\n--- stdout\n{done.stdout}\n--- stderr\n{done.stderr}"


def _toml(block: Block, cwd: Path) -> None:
    import stabmap

    tomllib.loads(block.body)
    if block.mark == "fragment":
        return
    stabmap.loads_scene(block.body, source=block.where())
    if block.mark.startswith("file "):
        (cwd / block.mark.split()[1]).write_text(block.body, encoding="utf-8")


def _python(block: Block, namespace: dict) -> None:
    if block.body.lstrip().startswith(">>>"):
        import pandas

        # Tables print whole, as in a wide terminal, rather than cut to the width pandas guesses here.
        test = doctest.DocTestParser().get_doctest(block.body, namespace, block.where(), block.doc, block.line)
        runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
        with pandas.option_context("display.width", 250, "display.max_columns", None):
            runner.run(test, clear_globs=False)
        assert runner.failures == 0, f"{block.where()}: {runner.failures} doctest failures (see the captured output)"
    else:
        exec(compile(block.body, block.where(), "exec"), namespace)


def run_doc(path: Path, tmp_path: Path, monkeypatch, slow: bool) -> None:
    env = _shim(tmp_path)
    (tmp_path / "scripts").symlink_to(ROOT / "scripts")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict = {"__name__": "__doc_test__"}
    for block in blocks(path):
        if block.mark.startswith("skip: ") or (block.mark == "slow" and not slow):
            continue
        if block.lang == "bash":
            _bash(block, tmp_path, env)
        elif block.lang == "toml":
            _toml(block, tmp_path)
        else:
            _python(block, namespace)


def _slow_docs() -> list[Path]:
    return [p for p in DOCS if any(b.mark == "slow" for b in blocks(p))]


@pytest.mark.parametrize("path", DOCS, ids=lambda p: p.name)
def test_doc_runs(path, tmp_path, monkeypatch):
    if path.name in PENDING:
        pytest.skip(PENDING[path.name])
    run_doc(path, tmp_path, monkeypatch, slow=False)


@pytest.mark.slow
@pytest.mark.parametrize("path", _slow_docs(), ids=lambda p: p.name)
def test_doc_runs_with_its_slow_blocks(path, tmp_path, monkeypatch):
    run_doc(path, tmp_path, monkeypatch, slow=True)


def test_every_skip_says_why_and_the_readme_keeps_its_first_two_commands():
    for path in DOCS:
        for b in blocks(path):
            if b.mark.startswith("skip"):
                assert len(b.mark) > len("skip: ") + 10, f"{b.where()}: a skip must give its reason"
    first = blocks(ROOT / "README.md")[0]
    assert first.body == (
        "pip install . && stabmap atlas --example paper-n3-fixed -o atlas.nc --png atlas.png\n"
        "pip install '.[test]' && python -m pytest -q\n"
    )
    assert first.mark == "no-install"
