"""``stabmap paper``: the source papers' results recomputed by the installed engine and checked.

One module per system (``stabmap/paper/<system>.py``, named by the system's ``paper`` member, so that
``check`` finds it through the registry), each with a ``run(out=..., **options)`` that computes, compares
with the paper's printed determinants or closed forms, and draws its figures:

- ``gyroscopes``: the cases n = 1, 2, 3 (seed 003; docs/paper-cases.md), against the printed determinants
  (22), (28)-(32) in exact arithmetic and the closed forms (23), (24), (33), (34) and the split;
- ``closed``: the hinge and six-body figure-eight families' boundaries along h2/h1, against docs/closed.md
  (docs/closed.md);
- ``reactions``: the square plate's atlas against G/4 and the paper's closed form (docs/reactions.md);
- ``viscous``: the gyroscopes' cases n = 1, 2, 3 with a viscous liquid, against the Kelvin-Tait-Chetaev criterion
  in exact arithmetic (docs/viscous.md).
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path

from .. import systems as registry
from ..errors import StabmapError, given, param


def _checked(name: str):
    """The paper check's module of the system ``name`` (``System.paper``), or a StabmapError saying why not."""
    if name not in registry.SYSTEMS:
        raise StabmapError(f"no paper check for system {name!r}: stabmap knows no such system; choose from: {', '.join(_with_checks())}")
    module = registry.get(name).paper
    if module is None:
        raise StabmapError(f"no paper check for system {name!r}: it declares none (its System's paper is None); "
                           f"choose from: {', '.join(_with_checks())}")
    return importlib.import_module(module)


def _with_checks() -> list[str]:
    return [n for n in registry.names() if registry.get(n).paper is not None]


def _options(run) -> set[str]:
    """The options a check's ``run`` takes beyond ``out``."""
    return {p.name for p in inspect.signature(run).parameters.values() if p.name != "out"}


def check(systems=None, *, out: str | Path | None = None, quick: bool = False, cases=None, rows: int | None = None) -> dict:
    """Run the papers' checks of ``systems`` (default: every registered system with a ``paper`` check); figures
    into ``out`` (None: none).

    Each check's ``run(out=..., ...)`` gets the options it takes: ``quick`` (coarse grids) where it takes it;
    ``cases`` and ``rows`` (the gyroscopes': some cases, rows per case) are an error unless a chosen check takes
    them.  Returns ``{"problems": [...], "text": str}``; ``problems`` is empty when everything agrees.
    """
    if rows is not None and rows < 1:
        raise StabmapError(f"{given('rows', rows)}: must be >= 1")
    named = {"cases": list(cases or ()), "rows": rows}
    named = {k: v for k, v in named.items() if v not in (None, [])}
    if systems:
        modules = {name: _checked(name) for name in systems}
    else:  # every check; given cases, those that take them
        modules = {name: _checked(name) for name in _with_checks()}
        if named:
            modules = {n: m for n, m in modules.items() if set(named) <= _options(m.run)} or modules
    for key in named:
        if not any(key in _options(m.run) for m in modules.values()):
            takes = [n for n in _with_checks() if key in _options(_checked(n).run)]
            raise StabmapError(f"{param(key)} applies to the paper check of {', '.join(takes) or 'no system'}, not to "
                               f"{', '.join(modules)}; add {' or '.join(repr(t) for t in takes)} to the systems, or drop {param(key)}")
    out = None if out is None else Path(out)
    texts, problems = [], []
    for name, module in modules.items():
        where = None if out is None else out / name
        options = _options(module.run)
        done = module.run(out=where, **{k: v for k, v in {"quick": quick, **named}.items() if k in options})
        texts.append(f"## {name}\n{done['text']}" + ("" if where is None else f"\nfigures in {where}/"))
        problems += done["problems"]
    texts.append("all agree with the papers" if not problems else f"{len(problems)} disagreements with the papers")
    return {"problems": problems, "text": "\n\n".join(texts)}
