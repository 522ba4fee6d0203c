"""The kernel layer stays numba-only, and the name clash with PyPI's 'kernels' is caught."""

from __future__ import annotations

import ast
import pathlib

import kernels

FORBIDDEN = {"stabmap", "xarray", "dask", "matplotlib", "flint", "scipy"}


def test_kernels_import_nothing_of_the_labelled_layer():
    root = pathlib.Path(kernels.__file__).parent
    for path in root.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names = [node.module or ""]
            for name in names:
                assert name.split(".")[0] not in FORBIDDEN, f"{path.name} imports {name}"


def test_marker_present():
    assert kernels.STABMAP_KERNELS == 1
