"""The project's tooling: pointers to files stay valid, the version comes from git, the markers are registered.

The lint stage itself (ruff, mypy, import-linter) runs in .ci/run before the tests; its configuration is in
pyproject.toml.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import stabmap

ROOT = Path(__file__).resolve().parent.parent
# A path ending in .md or .py: not the tail of a longer path, a URL or a template (``stabmap/paper/<name>.py``);
# ``../`` may lead it.
POINTER = re.compile(r"(?<![\w:/<>.-])((?:\.\./)*\w[\w./-]*\.(?:md|py))(?![\w/])")
# Files a page names on purpose although the repository does not hold them, with the page's reason.
NOT_IN_THE_REPOSITORY = {
    "ckpt_bench.py": "BENCHMARKS.md: a one-off script, 'kept out of the repository'",
    "stabmap/_version.py": "written by the build (setuptools-scm), ignored by git",
}


def _tracked() -> list[Path]:
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=False)
    if out.returncode:
        pytest.skip("not a git checkout: the pointers are checked where the sources are")
    return [ROOT / name for name in out.stdout.split()]


def pointers(text: str, code: bool) -> list[tuple[int, str]]:
    """(line, path) of every file path in ``text``; in code (``code``) only paths with a folder, so that module
    names such as ``scene.py`` beside their package in a comment are not taken for paths from the root."""
    found = []
    for number, line in enumerate(text.splitlines(), 1):
        for match in POINTER.finditer(line):
            path = match.group(1)
            if not code or "/" in path:
                found.append((number, path))
    return found


def resolves(path: str, page: Path, names: set[str]) -> bool:
    """Whether ``path``, named on ``page``, is a file of the repository: from the root, from the page's folder, or
    inside one of the top folders (``systems/base.py``); a bare name (``grid.py``) anywhere in it."""
    if path in NOT_IN_THE_REPOSITORY:
        return True
    for base in (ROOT, page.parent, ROOT / "stabmap", ROOT / "tests", ROOT / "scripts"):
        candidate = (base / path).resolve()
        if candidate.is_relative_to(ROOT) and candidate.exists():
            return True
    return "/" not in path and path in names


def test_every_file_the_pages_and_comments_name_exists():
    files = _tracked()
    names = {f.name for f in files} | {f.name for f in (ROOT / "kernels").glob("*.py")}
    stale = []
    for f in files:
        # this file's own examples of stale pointers are meant
        if f.suffix not in (".md", ".py") or f.is_relative_to(ROOT / "tests" / "data") or f == Path(__file__).resolve():
            continue
        for line, path in pointers(f.read_text(encoding="utf-8"), code=f.suffix == ".py"):
            if not resolves(path, f, names):
                stale.append(f"{f.relative_to(ROOT)}:{line}: {path}")
    assert not stale, "pointers to files that do not exist (outside the repository, or moved):\n" + "\n".join(stale)


@pytest.mark.parametrize(
    "text, code, expected",
    [
        ("see docs/cells.md and `stabmap/paper.py`", False, ["docs/cells.md", "stabmap/paper.py"]),
        ("the case of ../shared/REGIONS.md (100 values)", False, ["../shared/REGIONS.md"]),
        ("https://example.org/x/README.md and stabmap/paper/<name>.py", False, []),
        ("# scene.py and docs/speed.md, 'First run'", True, ["docs/speed.md"]),
    ],
)
def test_pointers_are_found(text, code, expected):
    assert [path for _, path in pointers(text, code)] == expected


def test_pointers_that_leave_the_repository_or_moved_are_stale(tmp_path):
    names = {"grid.py"}
    assert not resolves("../shared/REGIONS.md", ROOT / "docs" / "critical.md", names)  # exists beside the checkout only
    assert not resolves("stabmap/paper.py", ROOT / "README.md", names)  # now the package stabmap/paper/
    assert resolves("stabmap/paper/closed.py", ROOT / "README.md", names)
    assert resolves("systems/base.py", ROOT / "docs" / "systems.md", names)
    assert resolves("grid.py", ROOT / "README.md", names) and not resolves("grids.py", ROOT / "README.md", names)


def test_every_marker_the_tests_use_is_registered():
    # --strict-markers makes an unregistered marker an error at collection; this finds one before a run does.
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    assert "--strict-markers" in config["addopts"].split()
    registered = {m.split(":")[0].strip() for m in config["markers"]}
    builtin = {"parametrize", "skip", "skipif", "xfail", "usefixtures", "filterwarnings"}
    used = set()
    for f in (ROOT / "tests").glob("*.py"):
        used |= set(re.findall(r"pytest\.mark\.(\w+)", f.read_text(encoding="utf-8")))
    assert used - builtin <= registered, f"register these markers in pyproject.toml: {sorted(used - builtin - registered)}"


def test_the_version_is_a_pep440_version_and_the_cli_reports_it():
    packaging_version = pytest.importorskip("packaging.version")
    version = packaging_version.Version(stabmap.__version__)  # raises on anything PEP 440 does not allow
    assert version >= packaging_version.Version("0.1.dev0")
    out = subprocess.run([sys.executable, "-m", "stabmap", "--version"], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == f"stabmap {stabmap.__version__}"


def test_a_source_copy_without_git_or_build_gets_the_fallback(tmp_path):
    """A copy of stabmap/ with no git metadata, never built and not installed: the version is setuptools-scm's
    fallback from pyproject.toml, and ``import stabmap`` works."""
    copy = tmp_path / "stabmap"
    copy.mkdir()
    for name in ("__init__.py", "errors.py", "version.py"):
        (copy / name).write_bytes((ROOT / "stabmap" / name).read_bytes())
    fallback = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools_scm"]["fallback_version"]
    # no installed distribution answers instead (an editable install of another checkout, say)
    code = ("import importlib.metadata as m, sys\n"
            "def version(name): raise m.PackageNotFoundError(name)\n"
            "m.version = version\n"
            "sys.path.insert(0, sys.argv[1]); import stabmap; print(stabmap.__version__)")
    # nor an editable install's import hook, which outranks sys.path
    code = ("import sys; sys.meta_path = [f for f in sys.meta_path if not str(getattr(f, '__module__', '')).startswith('__editable__')]\n"
            + code + "; print(stabmap.__file__)")
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    version, where = out.stdout.split()
    assert Path(where).parent == copy and version == fallback


def test_contributing_installs_the_lint_tools_ci_pins():
    """CONTRIBUTING.md's lint section installs the very lint group .ci/run reads from pyproject.toml."""
    pinned = tomllib.loads((ROOT / "pyproject.toml").read_text())["dependency-groups"]["lint"]
    line = next(x for x in (ROOT / "CONTRIBUTING.md").read_text().splitlines() if x.startswith("pip install 'ruff"))
    assert re.findall(r"'([^']+)'", line.split("#")[0]) == pinned
    assert "dependency-groups" in (ROOT / ".ci" / "run").read_text()


def test_slow_tests_start_each_workers_share():
    """conftest.slow_first: the same tests, each worker's first share (as worksteal cuts it) led by slow ones."""
    from conftest import slow_first

    class Item:
        def __init__(self, n, slow):
            self.n, self.slow = n, slow

        def get_closest_marker(self, name):
            return object() if name == "slow" and self.slow else None

    items = [Item(n, n % 7 == 3) for n in range(101)]
    for workers in (1, 2, 3):
        out = slow_first(items, workers)
        assert sorted(i.n for i in out) == list(range(101))
        left, start = len(out), 0
        for w in range(workers if workers > 1 else 0):
            size = left // (workers - w)
            share = out[start : start + size]
            slow = [i.slow for i in share]
            assert slow == sorted(slow, reverse=True) and sum(slow) in (len(items[3::7]) // workers, -(-len(items[3::7]) // workers))
            start, left = start + size, left - size
    assert slow_first(items, 1) is items
