"""The house rules: the kernel layer is numba only, modules import no private names and form no cycle,
and stabmap installs beside an unrelated top-level ``kernels`` package without either breaking."""

from __future__ import annotations

import ast
import base64
import hashlib
import importlib.metadata
import os
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import pytest

import stabmap
from stabmap import kernels

FORBIDDEN = {"stabmap", "xarray", "dask", "matplotlib", "flint", "scipy"}
PACKAGE = Path(stabmap.__file__).parent
ROOT = PACKAGE.parent


def _modules() -> dict[str, Path]:
    out = {}
    paths = [Path(d) / f for d, _, files in os.walk(PACKAGE, followlinks=True) for f in files if f.endswith(".py")]
    for path in paths:
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def _imports(name: str, path: Path, modules: dict) -> list[tuple[str, str]]:
    """(imported module, name taken from it) for every import of a stabmap module in ``path``, at any depth."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found += [(a.name, "") for a in node.names if a.name.split(".")[0] == "stabmap"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            if module.split(".")[0] != "stabmap":
                continue
            for a in node.names:
                sub = f"{module}.{a.name}"
                found.append((sub, "") if sub in modules else (module, a.name))
    return found


def test_kernels_import_nothing_of_the_labelled_layer():
    root = Path(kernels.__file__).parent
    for path in root.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names = [node.module or ""]
            for name in names:
                assert name.split(".")[0] not in FORBIDDEN, f"{path.name} imports {name}"


def test_no_private_names_and_no_back_references_to_the_package_root():
    modules = _modules()
    for name, path in modules.items():
        for module, taken in _imports(name, path, modules):
            private = taken.startswith("_") and not taken.endswith("__")
            assert not private, f"{name} imports the private {module}.{taken}"
            assert not (module == "stabmap" and taken and name != "stabmap"), f"{name} takes {taken} from the package root"


def test_no_import_cycles():
    modules = _modules()
    graph = {name: {m for m, _ in _imports(name, path, modules) if m in modules and m != name} for name, path in modules.items()}
    state: dict[str, int] = {}

    def visit(node, trail):
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                raise AssertionError("import cycle: " + " -> ".join(trail[trail.index(nxt):] + [nxt]))
            if nxt not in state:
                visit(nxt, trail + [nxt])
        state[node] = 2

    for name in sorted(graph):
        if name not in state:
            visit(name, [name])


def test_an_unrelated_top_level_kernels_package_breaks_neither(tmp_path):
    """PyPI has an unrelated 'kernels' package; stabmap installs its kernels as stabmap.kernels."""
    fake = tmp_path / "kernels"
    fake.mkdir()
    (fake / "__init__.py").write_text("WHO = 'the other kernels'\n")
    code = textwrap.dedent(
        """
        import kernels, stabmap
        from stabmap import kernels as ours
        scene = stabmap.loads_scene('omega = 30.0\\n[[bodies]]\\nm = 1.0\\nA = 0.02\\nC = 0.03\\nc = 0.1\\n'
                                    '[grid]\\nomega = { values = [1.0, 30.0] }\\n')
        nc = stabmap.compute_atlas(scene, progress=False, threads=1)["n_complex_pairs"].values.tolist()
        import kernels as again
        print(again.WHO, ours.count_block.__module__, nc)
        """
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)])}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split()[:3] == ["the", "other", "kernels"]
    assert "stabmap.kernels.block" in out.stdout and "[1, 0]" in out.stdout


def _installed_wheel_files() -> list[str] | None:
    """The files a regular ``pip install .`` of this very checkout put in place (its RECORD), or None: not installed,
    installed editable, or from other sources (a kernel file whose hash differs from the checkout's).  Every
    distribution named stabmap on the path is looked at: the checkout's own ``stabmap.egg-info``, which the build
    leaves beside the sources, comes first when the tests run from there, and has no RECORD."""
    for dist in importlib.metadata.distributions(name="stabmap"):
        files = {str(f): f for f in dist.files or ()}
        if all(_same(files.get(f"stabmap/kernels/{source.name}"), source) for source in (ROOT / "kernels").glob("*.py")):
            return list(files)
    return None


def _same(record, source: Path) -> bool:
    """Whether the RECORD entry ``record`` (or None) is the file ``source``, by its hash."""
    if record is None or record.hash is None:
        return False
    digest = base64.urlsafe_b64encode(hashlib.new(record.hash.mode, source.read_bytes()).digest()).rstrip(b"=").decode()
    return digest == record.hash.value


@pytest.mark.slow  # where it builds the wheel
def test_the_wheel_has_no_top_level_kernels_package(tmp_path):
    # The install the suite runs in (``pip install '.[test]'``) built a wheel of this checkout: its RECORD lists the
    # wheel's files.  Elsewhere (an editable install, say) a wheel is built here, which takes minutes.
    names = _installed_wheel_files()
    if names is None:
        out = subprocess.run(
            [sys.executable, "-m", "pip", "wheel", "--no-deps", "-w", str(tmp_path), str(ROOT)],
            capture_output=True, text=True, timeout=600,
        )
        assert out.returncode == 0, out.stderr
        names = zipfile.ZipFile(next(tmp_path.glob("stabmap-*.whl"))).namelist()
    assert "stabmap/kernels/block.py" in names
    assert not [n for n in names if n.startswith("kernels/")]
    # the build compiled the kernels into the package (setup.py): the first run loads them
    assert [n for n in names if n.startswith("stabmap/kernels/_cache/kernels-") and "block.decide_block-" in n and n.endswith(".nbi")]
