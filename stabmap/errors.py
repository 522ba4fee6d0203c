"""The one exception users see: a message that names the offending parameter and the fix.

The library names a parameter as Python spells it (``x='foo'``, ``sel={'K_1': 3}``); the command line, which
calls the same functions, names it as its flag (``--x foo``, ``--sel K_1=3``).  Messages therefore never write
a parameter's name themselves: they call :func:`given` (a parameter and its value) or :func:`param` (the name
alone), and ``stabmap.cli`` switches the spelling with :func:`cli_spelling` for the duration of a command.
"""

from __future__ import annotations

from contextlib import contextmanager
from contextvars import ContextVar

_FLAGS: ContextVar[dict[str, str] | None] = ContextVar("stabmap_flags", default=None)


class StabmapError(ValueError):
    """Bad input (scene, grid, query, file); the CLI prints the message and exits with status 2."""


def param(name: str) -> str:
    """The parameter ``name`` as the caller spells it: ``name`` in Python, its flag (``--max-panels``) on the
    command line."""
    flags = _FLAGS.get()
    return name if flags is None else flags.get(name, "--" + name.replace("_", "-"))


def given(name: str, value, key: str | None = None) -> str:
    """The parameter ``name`` with the ``value`` given to it, as the caller wrote it.

    ``key`` names an item of a mapping parameter (``sel``): ``sel={'K_1': 3}`` in Python, ``--sel K_1=3`` on
    the command line.  A ``value`` of ``...`` leaves the value to be filled in (``sel={'K_1': ...}``,
    ``--sel K_1=...``).
    """
    flags = _FLAGS.get()
    shown = "..." if value is ... else value
    if flags is None:
        shown = "..." if value is ... else repr(value)
        return f"{name}={{{key!r}: {shown}}}" if key is not None else f"{name}={shown}"
    return f"{param(name)} {key}={shown}" if key is not None else f"{param(name)} {shown}"


@contextmanager
def cli_spelling(flags: dict[str, str] | None = None):
    """Within the block, :func:`param` and :func:`given` spell parameters as command-line flags: ``flags`` maps a
    parameter to a flag whose name is not the parameter's with ``--`` and dashes (e.g. ``{"along": "--along"}``)."""
    token = _FLAGS.set(dict(flags or {}))
    try:
        yield
    finally:
        _FLAGS.reset(token)
