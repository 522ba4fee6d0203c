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
- ``<!-- doc-test: cluster -->`` (bash, python): needs a dask cluster at ``tcp://HOST:8786``; run, in the slow
  variant only, against a real one on loopback (below);
- ``<!-- doc-test: skip: REASON -->``: not run, for the reason given (e.g. it needs data the tests do not have).

A document's first cluster block starts its cluster (tests/doc_cluster.py): a scheduler on 127.0.0.1 at a free port and its workers, each
``dask ...`` command in its own process group (``dask`` on PATH is this interpreter's ``python -m dask``). The
scheduler's readiness (a client connects) and its workers' arrival are waited for, and the cluster serves the
document's later cluster blocks until the document ends, when every process group is stopped, pass or fail.
In a cluster block, ``HOST:8786`` (also inside ``tcp://HOST:8786``) becomes the real address before it runs.
The lines of a bash cluster block that start a cluster, ``dask scheduler ...`` and ``dask worker ...`` (they come
first), are the commands that start it: each runs in the background as written, plus the options a test on
loopback needs and the line does not set (scheduler: ``--host 127.0.0.1 --port N --no-dashboard``; worker:
``--nthreads 1 --no-dashboard``); the rest of the block then runs as any bash block. A block that needs a cluster
when none runs and starts none (a Python example, or commands given ``--scheduler tcp://HOST:8786``) gets one from
the harness: ``dask scheduler`` and two ``dask worker tcp://HOST:8786``, started in the same way.
"""

from __future__ import annotations

import doctest
import dataclasses
import json
import os
import re
import subprocess
import sys
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

from doc_cluster import PLACEHOLDER, STARTS_CLUSTER, Cluster, cluster_for, split_cluster_lines

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^(?:<!-- doc-test: (?P<mark>.*?) -->\n)?```(?P<lang>bash|toml|python)\n(?P<body>.*?)^```", re.M | re.S)
# Pages another change edits at the same time; each is skipped, saying why, until its blocks are marked.
PENDING: dict[str, str] = {}  # page name -> why it cannot run yet
MARKS = re.compile(r"^(file \S+|fragment|no-install|slow|cluster|skip: .+)$")


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
        assert mark != "cluster" or m.group("lang") != "toml", f"{path.name}:{line}: a scene needs no cluster"
        name = path.relative_to(ROOT).as_posix() if path.is_relative_to(ROOT) else path.name
        found.append(Block(name, line, m.group("lang"), m.group("body"), mark))
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
    dask = bin_dir / "dask"
    dask.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m dask "$@"\n')
    dask.chmod(0o755)
    python = bin_dir / "python"  # a script, not a link: a venv's python started through a link outside the venv loses it
    python.write_text(f'#!/bin/sh\nexec "{sys.executable}" "$@"\n')
    python.chmod(0o755)
    env = dict(os.environ)
    env["PATH"] = f"{bin_dir}{os.pathsep}{env['PATH']}"
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    env["MPLBACKEND"] = "Agg"
    return env


def _bash(block: Block, cwd: Path, env: dict, body: str | None = None) -> None:
    body = block.body if body is None else body
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


def _python(block: Block, namespace: dict, body: str | None = None) -> None:
    body = block.body if body is None else body
    if body.lstrip().startswith(">>>"):
        import pandas

        # Tables print whole, as in a wide terminal, rather than cut to the width pandas guesses here.
        test = doctest.DocTestParser().get_doctest(body, namespace, block.where(), block.doc, block.line)
        runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
        with pandas.option_context("display.width", 250, "display.max_columns", None):
            runner.run(test, clear_globs=False)
        assert runner.failures == 0, f"{block.where()}: {runner.failures} doctest failures (see the captured output)"
    else:
        exec(compile(body, block.where(), "exec"), namespace)


def run_doc(path: Path, tmp_path: Path, monkeypatch, slow: bool) -> Cluster | None:
    """Run the document's blocks; return the cluster they ran on (stopped by then), if any."""
    env = _shim(tmp_path)
    (tmp_path / "scripts").symlink_to(ROOT / "scripts")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict = {"__name__": "__doc_test__"}
    cluster: Cluster | None = None
    try:
        for block in blocks(path):
            if block.mark.startswith("skip: ") or (block.mark in ("slow", "cluster") and not slow):
                continue
            body = None
            if block.mark == "cluster":
                cluster, body = cluster_for(block, cluster, tmp_path, env)
            try:
                if block.lang == "bash":
                    _bash(block, tmp_path, env, body)
                elif block.lang == "toml":
                    _toml(block, tmp_path)
                else:
                    _python(block, namespace, body)
            except AssertionError as exc:
                if cluster is None:
                    raise
                raise AssertionError(f"{exc}\n--- the cluster's logs\n{cluster.logs()}") from None
    finally:
        if cluster is not None:
            cluster.stop()
    return cluster


def _slow_docs() -> list[Path]:
    return [p for p in DOCS if any(b.mark in ("slow", "cluster") for b in blocks(p))]


@pytest.mark.parametrize("path", DOCS, ids=lambda p: p.name)
def test_doc_runs(path, tmp_path, monkeypatch):
    if path.name in PENDING:
        pytest.skip(PENDING[path.name])
    run_doc(path, tmp_path, monkeypatch, slow=False)


@pytest.mark.slow
@pytest.mark.parametrize("path", _slow_docs(), ids=lambda p: p.name)
def test_doc_runs_with_its_slow_blocks(path, tmp_path, monkeypatch):
    run_doc(path, tmp_path, monkeypatch, slow=True)


def test_the_shims_python_is_this_interpreter_with_its_packages(tmp_path):
    """The docs' ``python`` is this interpreter with its environment: inside a venv, the venv (a link to the venv's
    python from another folder would start the base interpreter, without the venv's packages; .ci/run tests in a venv)."""
    env = _shim(tmp_path)
    code = "import sys, flint, xarray, matplotlib; print(sys.prefix); print(sys.base_prefix)"
    done = subprocess.run(["python", "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == [sys.prefix, sys.base_prefix]


def test_every_skip_says_why_and_the_readme_keeps_its_first_two_commands():
    for path in DOCS:
        for b in blocks(path):
            if b.mark.startswith("skip"):
                assert len(b.mark) > len("skip: ") + 10, f"{b.where()}: a skip must give its reason"
    first = blocks(ROOT / "README.md")[0]
    assert first.body == (
        "pip install . && stabmap atlas --example paper-n3-fixed -o atlas.nc --png atlas.png --overwrite\n"
        "pip install '.[test]' && python -m pytest -q\n"
    )
    assert first.mark == "no-install"


def test_the_readme_is_a_users_page_and_the_index_maps_every_doc():
    """The README stays short (its two commands, how to read the first picture, the words, the next commands) and
    docs/index.md links every page of docs/, so that a page added later cannot go unlisted."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(readme.splitlines()) <= 150
    for word in ("N_c", "necessary sense", "Proved", "Cell", "Undecided", "ds.stabmap", "docs/index.md", "CONTRIBUTING.md"):
        assert word in readme, word
    for developer_only in (".ci/run", "ruff", "mypy", "seed 003", "kernels/"):
        assert developer_only not in readme, developer_only
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    linked = set(re.findall(r"\]\(([^)#]+)\)", index))
    pages = {p.name for p in (ROOT / "docs").iterdir() if p.suffix in (".md", ".ipynb") and p.name != "index.md"}
    assert pages <= linked, sorted(pages - linked)
    assert all((ROOT / "docs" / target).exists() for target in linked), sorted(t for t in linked if not (ROOT / "docs" / t).exists())


CLUSTER_BASH = """<!-- doc-test: cluster -->
```bash
dask scheduler                      # prints tcp://HOST:8786
dask worker tcp://HOST:8786         # the worker line as a reader would type it
echo "tcp://HOST:8786" > address.txt
```
"""
CLUSTER_PYTHON = """<!-- doc-test: cluster -->
```python
import json, os
from distributed import Client

with Client("tcp://HOST:8786") as client:
    pids = {"scheduler": client.run_on_scheduler(os.getpid), "workers": sorted(client.run(os.getpid).values()),
            "nannies": sorted(client.run(os.getppid).values())}
with open("pids.json", "w") as f:
    json.dump(pids, f)
```
"""


def _doc(tmp_path: Path, text: str) -> Path:
    (tmp_path / "run").mkdir()
    doc = tmp_path / "doc.md"
    doc.write_text(text)
    return doc


def _gone(pid: int, wait: float = 5) -> bool:
    import psutil

    deadline = time.monotonic() + wait
    while True:
        try:
            if psutil.Process(pid).status() == psutil.STATUS_ZOMBIE:  # dead, its parent not told yet
                return True
        except psutil.NoSuchProcess:
            return True
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)


def test_a_cluster_block_is_recognised_and_the_address_substituted(tmp_path):
    first, second = blocks(_doc(tmp_path, CLUSTER_BASH + CLUSTER_PYTHON))
    assert (first.lang, first.mark, second.lang, second.mark) == ("bash", "cluster", "python", "cluster")
    starts, rest = split_cluster_lines(first.body)
    assert [s.split("#")[0].strip() for s in starts] == ["dask scheduler", "dask worker tcp://HOST:8786"]
    assert rest.strip() == 'echo "tcp://HOST:8786" > address.txt'
    cluster = Cluster(tmp_path, {})  # not started: its commands only
    port = cluster.port
    assert cluster.substitute(rest + second.body).count(f"tcp://127.0.0.1:{port}") == 2
    assert cluster.substitute("HOST:8786 tcp://HOST:8786") == f"127.0.0.1:{port} tcp://127.0.0.1:{port}"
    assert cluster.command(starts[0]) == (f"dask scheduler --host 127.0.0.1 --port {port} --no-dashboard", "scheduler")
    assert cluster.command(starts[1]) == (f"dask worker tcp://127.0.0.1:{port} --nthreads 1 --no-dashboard", "worker")
    assert cluster.command("dask worker tcp://HOST:8786 --nthreads 4")[0] == (
        f"dask worker tcp://127.0.0.1:{port} --nthreads 4 --no-dashboard")
    with pytest.raises(AssertionError, match="come first"):
        split_cluster_lines("stabmap examples\ndask scheduler\n")
    with pytest.raises(AssertionError, match="sets the scheduler's address"):
        cluster.command("dask scheduler --port 8786")


def test_every_block_that_names_the_placeholder_address_runs_on_a_cluster():
    for path in DOCS:
        for b in blocks(path):
            if PLACEHOLDER in b.body or any(STARTS_CLUSTER.match(line) for line in b.body.splitlines()):
                assert b.mark == "cluster" or b.mark.startswith("skip: "), f"{b.where()}: mark it <!-- doc-test: cluster -->"


def test_a_cluster_document_runs_on_its_own_cluster_and_leaves_no_process(tmp_path, monkeypatch):
    doc = _doc(tmp_path, CLUSTER_BASH + CLUSTER_PYTHON)
    (tmp_path / "fast").mkdir()
    assert run_doc(doc, tmp_path / "fast", monkeypatch, slow=False) is None  # the fast variant starts nothing
    assert not (tmp_path / "fast" / "address.txt").exists()
    run = tmp_path / "run"
    cluster = run_doc(doc, run, monkeypatch, slow=True)
    assert (run / "address.txt").read_text().strip() == cluster.address != "tcp://HOST:8786"
    pids = json.loads((run / "pids.json").read_text())
    # The block's own worker line, run once as written: one worker, under its nanny (the line's process).
    assert len(pids["workers"]) == 1 and pids["nannies"] == [cluster.procs[1][1].pid]
    left = [pid for pid in [pids["scheduler"], *pids["workers"], *pids["nannies"]] if not _gone(pid)]
    assert not left, f"processes left running after the document: {left}"


def test_a_failing_cluster_block_still_stops_the_cluster_the_harness_gave_it(tmp_path, monkeypatch):
    fails = CLUSTER_PYTHON[: CLUSTER_PYTHON.rindex("```")] + "raise RuntimeError('the block fails')\n```\n"
    doc = _doc(tmp_path, fails)
    with pytest.raises(RuntimeError, match="the block fails"):
        run_doc(doc, tmp_path / "run", monkeypatch, slow=True)
    pids = json.loads((tmp_path / "run" / "pids.json").read_text())
    assert len(pids["workers"]) == 2  # no block started one: the harness's two
    left = [pid for pid in [pids["scheduler"], *pids["workers"], *pids["nannies"]] if not _gone(pid)]
    assert not left, f"processes left running after the failed document: {left}"


def test_a_failing_bash_block_shows_the_cluster_logs_and_stops_the_lines_it_started(tmp_path, monkeypatch):
    import psutil

    doc = _doc(tmp_path, CLUSTER_BASH.replace("address.txt\n", "address.txt\nexit 3\n"))
    with pytest.raises(AssertionError, match=r"(?s)failed \(exit 3\).*the cluster's logs.*--- dask scheduler --host"):
        run_doc(doc, tmp_path / "run", monkeypatch, slow=True)
    port = (tmp_path / "run" / "address.txt").read_text().strip().rsplit(":", 1)[1]
    left = [p.pid for p in psutil.process_iter(["cmdline"]) if port in " ".join(p.info["cmdline"] or []) and not _gone(p.pid, 0)]
    assert not left, f"the block's scheduler or worker is still running: {left}"
