"""The version of stabmap, taken from git by setuptools-scm when the package is built (pyproject.toml).

A built or installed copy has it in ``stabmap/_version.py``; a source copy never built (no git metadata, say)
reports the installed distribution's version if there is one, else ``0.1.0.dev0``, setuptools-scm's fallback.
"""

from __future__ import annotations

try:
    from ._version import __version__
except ImportError:  # a source tree that was never built
    from importlib.metadata import PackageNotFoundError, version

    try:
        __version__ = version("stabmap")
    except PackageNotFoundError:
        __version__ = "0.1.0.dev0"
